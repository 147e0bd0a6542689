"""Oblique impacts: tangential contact laws limited by Coulomb friction, a sphere's oblique
impact on a plane with its normal law's contact and the sphere's spin, the rigid-body
impulse theory, and fitting the tangential law to measured rebounds (issue 27)."""

from .batch import oblique_impact_batch as oblique_impact_batch
from .fit import ObliqueFit as ObliqueFit, fit_oblique as fit_oblique
from .impact import (
    ObliqueOptions as ObliqueOptions,
    incidence as incidence,
    oblique_impact as oblique_impact,
    two_spheres as two_spheres,
)
from .results import ObliqueResult as ObliqueResult
from .tangential import (
    TANGENTIAL_LAW_NAMES as TANGENTIAL_LAW_NAMES,
    TANGENTIAL_LAWS as TANGENTIAL_LAWS,
    AbstractTangentialLaw as AbstractTangentialLaw,
    LinearHistoryLaw as LinearHistoryLaw,
    MindlinLaw as MindlinLaw,
    TangentialSpec as TangentialSpec,
    shear_modulus_star as shear_modulus_star,
    tangential_law as tangential_law,
)
from .theory import rigid_oblique as rigid_oblique
from .track import TrackRebounds as TrackRebounds, track_rebounds as track_rebounds
