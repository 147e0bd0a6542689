"""JAX's persistent compilation cache, for Python users and the command line alike.

A compiled program is kept on disk (`$JAXIMPACT_CACHE_DIR`, default
`$XDG_CACHE_HOME/jaximpact/jax`, else `~/.cache/jaximpact/jax`), so a second process skips
XLA's compilation. Set `JAXIMPACT_CACHE_DIR=` (empty) to turn it off; a cache directory the
user gave JAX itself (`JAX_COMPILATION_CACHE_DIR`, `jax.config`) is left as it is.
"""

import os
from pathlib import Path

CACHE_ENV = "JAXIMPACT_CACHE_DIR"
_done = False


def cache_dir() -> Path | None:
    """`$JAXIMPACT_CACHE_DIR` (empty: none), else `$XDG_CACHE_HOME/jaximpact/jax`, else
    `~/.cache/jaximpact/jax`."""
    if CACHE_ENV in os.environ:
        value = os.environ[CACHE_ENV].strip()
        return Path(value).expanduser() if value else None
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "jaximpact" / "jax"


def enable_persistent_cache(min_compile_time_secs: float = 0.1) -> None:
    """Point JAX's persistent compilation cache at `cache_dir()` (once per process)."""
    global _done
    if _done:
        return
    _done = True
    import jax

    if jax.config.jax_compilation_cache_dir is not None:
        return
    path = cache_dir()
    if path is None:
        return
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return  # an unwritable cache is not worth failing for
    jax.config.update("jax_compilation_cache_dir", str(path))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", min_compile_time_secs)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
