"""jaximpact: impact force laws, integrated exactly and differentiably, and fitted to data."""

import importlib.metadata

from . import closed_forms as closed_forms
from ._impact import ImpactResult as ImpactResult
from ._impact import impact as impact
from ._laws import (
    LAW_NAMES as LAW_NAMES,
)
from ._laws import (
    LAWS as LAWS,
)
from ._laws import (
    AbstractLaw as AbstractLaw,
)
from ._laws import (
    CustomLaw as CustomLaw,
)
from ._laws import (
    Law as Law,
)
from ._laws import (
    custom_law as custom_law,
)
from ._laws import (
    law as law,
)
from ._powers import safe_pow as safe_pow
from ._status import Status as Status

try:
    __version__ = importlib.metadata.version("jaximpact")
except importlib.metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0"
