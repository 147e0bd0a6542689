"""jaximpact: impact force laws, integrated exactly and differentiably, and fitted to data."""

import importlib.metadata
import os
import sys

if os.path.basename(sys.argv[0]) == "jaximpact":
    # the command line: XLA's CPU compiler logs harmless "algebraic simplifier ... circular"
    # notes at error level for diffrax's loops; the level is read when jax loads, so it is
    # set here, before the imports below, and only for the `jaximpact` console script
    os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
    # equinox's run-time checks inside the compiled fits (lineax's, in the implicit
    # derivative of diffrax's event times) are host callbacks, and JAX does not store a
    # program with host callbacks in its persistent cache; as NaN instead (which the fits
    # already report as a failed solve) the second `jaximpact calibrate` skips XLA's
    # compilation: 14 s -> 8 s (benchmarks/first_calls.md). Inputs are checked before.
    os.environ.setdefault("EQX_ON_ERROR", "nan")

from . import closed_forms as closed_forms
from ._batch import impact_batch as impact_batch, run_batch as run_batch, write_table as write_table
from ._bounce import BounceResult as BounceResult, bounce as bounce
from ._calibrate import Fit as Fit, calibrate as calibrate
from ._design import (
    bumper_design as bumper_design,
    drop_design as drop_design,
    propagate_uncertainty as propagate_uncertainty,
    sensitivity_map as sensitivity_map,
)
from ._euler import euler_bounce as euler_bounce
from ._fit_bounces import BounceFit as BounceFit, fit_bounces as fit_bounces
from ._impact import ImpactResult as ImpactResult, impact as impact
from ._laws import (
    LAW_NAMES as LAW_NAMES,
    LAWS as LAWS,
    AbstractLaw as AbstractLaw,
    CustomLaw as CustomLaw,
    Law as Law,
    custom_law as custom_law,
    law as law,
)
from ._maps import plot_map as plot_map, restitution_map as restitution_map
from ._model_choice import compare_laws as compare_laws, starting_law as starting_law
from ._paper import reproduce_paper as reproduce_paper
from ._plotting import plot_impact as plot_impact
from ._powers import safe_pow as safe_pow
from ._status import Status as Status

# engines: material inputs and exports to MuJoCo, Drake, LAMMPS (issue 14)
from ._engines import (
    Export as Export,
    effective_mass as effective_mass,
    effective_radius as effective_radius,
    export as export,
    hertz_stiffness as hertz_stiffness,
)

try:
    __version__ = importlib.metadata.version("jaximpact")
except importlib.metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0"
