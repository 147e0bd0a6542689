"""XLA's compiler notes kept off the user's terminal while the library's fits compile.

XLA's CPU compiler writes "Algebraic simplifier is likely stuck in a circular
simplification loop" at error level for diffrax's loops: dozens of lines on stderr during a
first `calibrate`, each harmless (the program compiles and runs right). The command line
silences them with `TF_CPP_MIN_LOG_LEVEL=3` before JAX loads; in Python, JAX is already
loaded. `quiet_compiler` raises XLA's C++ log threshold for the duration of one call and
puts back the level the process had, `TF_CPP_MIN_LOG_LEVEL`'s (JAX sets it to 1 when it
loads). A user who asked to see more (`TF_CPP_MIN_LOG_LEVEL=0`, `jax_logging_level`) keeps
exactly that: nothing is changed then.
"""

import contextlib
import functools
import os
import warnings

# absl's levels: 0 info, 1 warning, 2 error, 3 fatal (jax._src.logging_config._tf_cpp_map)
_FATAL_ONLY = 3


def _process_level() -> int | None:
    """The C++ log level this process runs at, or `None` where the user chose one to see
    (`jax_logging_level`, or `TF_CPP_MIN_LOG_LEVEL=0`): then nothing is changed. JAX sets
    `TF_CPP_MIN_LOG_LEVEL=1` when it loads, unless it was set."""
    import jax

    if jax.config.jax_logging_level not in (None, "NOTSET"):
        return None
    try:
        level = int(os.environ.get("TF_CPP_MIN_LOG_LEVEL", "1"))
    except ValueError:
        return None
    return None if level == 0 else level


@contextlib.contextmanager
def quiet_compiler():
    """Within the block, XLA's C++ log lines below fatal are not printed, unless the user
    asked for more (`TF_CPP_MIN_LOG_LEVEL=0`, `jax.config.update("jax_logging_level",
    ...)`); after it, the process's level again."""
    try:
        from jax._src.lib import utils
    except ImportError:  # a JAX without the setter: its notes stay
        yield
        return
    level = _process_level()
    if level is None or level >= _FATAL_ONLY or not hasattr(utils, "absl_set_min_log_level"):
        yield
        return
    utils.absl_set_min_log_level(_FATAL_ONLY)
    try:
        yield
    finally:
        utils.absl_set_min_log_level(level)


def quietly_compiled(fn):
    """`fn` run inside `quiet_compiler` (for the public entry points that compile fits).
    The warnings `fn` gives are raised again from here once it returns (or raises), so that
    they name the caller's line as `fn`'s own `stacklevel=2` did, under the user's filters
    (`error` included)."""

    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        caught = []
        try:
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                with quiet_compiler():
                    result = fn(*args, **kwargs)
        finally:  # raised again if `fn` raises too: a warning before an error is not lost
            for warning in caught:
                warnings.warn(warning.message, warning.category, stacklevel=2)
        return result

    return wrapper
