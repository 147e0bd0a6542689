"""JAX's persistent compilation cache, turned on by the command line (`jaximpact ...`) and by
a Python user who asks for it (`jaximpact.enable_cache()`); importing the library or reading
its names leaves JAX's configuration alone.

A compiled program is kept on disk (`$JAXIMPACT_CACHE_DIR`, default
`$XDG_CACHE_HOME/jaximpact/jax`, else `~/.cache/jaximpact/jax`), so a second process skips
XLA's compilation; a fit's programs are also kept as traced (`_stored`, in
`jaximpact-programs/` there), so it skips their tracing too.
"""

import os
from pathlib import Path

CACHE_ENV = "JAXIMPACT_CACHE_DIR"


def cache_dir() -> Path | None:
    """`$JAXIMPACT_CACHE_DIR` (empty: none), else `$XDG_CACHE_HOME/jaximpact/jax`, else
    `~/.cache/jaximpact/jax`."""
    if CACHE_ENV in os.environ:
        value = os.environ[CACHE_ENV].strip()
        return Path(value).expanduser() if value else None
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "jaximpact" / "jax"


def enable_cache(path=None, *, min_compile_time_secs: float = 0.1) -> Path | None:
    """Keep JAX's compiled programs on disk, so that a second process skips XLA's compilation
    (JAX's persistent compilation cache), and a fit's programs as traced, so that it skips
    tracing them (`jaximpact-programs/` in the same directory): sets `jax_compilation_cache_dir`,
    `jax_persistent_cache_min_compile_time_secs` and `jax_persistent_cache_min_entry_size_bytes`
    of `jax.config` for the whole process. The command line does this itself; the library
    changes nothing of JAX's configuration unless this is called.

    - `path`: the directory (default: `$JAXIMPACT_CACHE_DIR`; set empty, no cache; unset,
      `$XDG_CACHE_HOME/jaximpact/jax`, else `~/.cache/jaximpact/jax`).
    - `min_compile_time_secs`: programs that compile faster than this are not kept.

    A cache directory already given to JAX (`JAX_COMPILATION_CACHE_DIR`, `jax.config`) is
    left as it is, and a directory that cannot be made is skipped. Returns the directory in
    use (None: none).

    **Example**: `jaximpact.enable_cache()` at the top of a script.
    """
    import jax

    if jax.config.jax_compilation_cache_dir is not None:
        return Path(jax.config.jax_compilation_cache_dir)
    path = cache_dir() if path is None else Path(path).expanduser()
    if path is None:
        return None
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return None  # an unwritable cache is not worth failing for
    jax.config.update("jax_compilation_cache_dir", str(path))
    jax.config.update("jax_persistent_cache_min_compile_time_secs", min_compile_time_secs)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
    return path
