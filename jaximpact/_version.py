"""The installed package's version (`0.0.0` when run from a source tree)."""

import importlib.metadata

try:
    __version__ = importlib.metadata.version("jaximpact")
except importlib.metadata.PackageNotFoundError:  # running from a source tree
    __version__ = "0.0.0"
