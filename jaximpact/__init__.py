"""jaximpact: impact force laws, integrated exactly and differentiably, and fitted to data."""

import importlib.metadata

from . import closed_forms as closed_forms
from ._calibrate import Fit as Fit, calibrate as calibrate
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
from ._model_choice import compare_laws as compare_laws, starting_law as starting_law
from ._plotting import plot_impact as plot_impact
from ._powers import safe_pow as safe_pow
from ._status import Status as Status

try:
    __version__ = importlib.metadata.version("jaximpact")
except importlib.metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0"
