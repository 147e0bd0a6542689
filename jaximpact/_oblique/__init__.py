"""Oblique impacts: tangential contact laws limited by Coulomb friction, a sphere's oblique
impact on a plane with its normal law's contact and the sphere's spin, the rigid-body
impulse theory, and fitting the tangential law to measured rebounds (issue 27).

The names load with their module on first use (PEP 562), so that a module that needs one
table (`tangential`: the command line's parser, the engines' registry) does not import
diffrax with the integrated impact and its batch."""

from .._lazy import lazy_names

_NAMES = {
    "oblique_impact_batch": "batch",
    "ObliqueFit": "fit",
    "fit_oblique": "fit",
    "ObliqueOptions": "impact",
    "incidence": "impact",
    "oblique_impact": "impact",
    "two_spheres": "impact",
    "ObliqueResult": "results",
    "TANGENTIAL_LAW_NAMES": "tangential",
    "TANGENTIAL_LAWS": "tangential",
    "AbstractTangentialLaw": "tangential",
    "LinearHistoryLaw": "tangential",
    "MindlinLaw": "tangential",
    "TangentialSpec": "tangential",
    "shear_modulus_star": "tangential",
    "tangential_law": "tangential",
    "rigid_oblique": "theory",
    "TrackRebounds": "track",
    "track_rebounds": "track",
}
__all__ = sorted(_NAMES)

__getattr__ = lazy_names(__name__, _NAMES, globals())
