"""Value checks that raise a clear error eagerly and survive `jax.jit`."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np


def _is_concrete(value) -> bool:
    return not isinstance(value, jax.core.Tracer)


def check_values(value, bad, message: str):
    """Return `value`; raise `ValueError(message)` where `bad(value)` holds.

    Concrete inputs are checked at once (a one-line `ValueError`); traced inputs through
    `eqx.error_if`, so the check survives `jit` (and raises at run time).
    """
    if _is_concrete(value):
        array = np.asarray(value, dtype=float)
        if np.any(~np.isfinite(array)) or np.any(bad(array)):
            raise ValueError(message)
        return value
    array = jnp.asarray(value)
    return eqx.error_if(value, jnp.any(~jnp.isfinite(array) | bad(array)), message)


def check_positive(name: str, value, unit: str = ""):
    """Require a finite value > 0."""
    unit = f" {unit}" if unit else ""
    return check_values(
        value, lambda a: a <= 0, f"{name} must be a finite number > 0{unit}, got {_show(value)}"
    )


def check_nonnegative(name: str, value, unit: str = ""):
    """Require a finite value >= 0."""
    unit = f" {unit}" if unit else ""
    return check_values(
        value, lambda a: a < 0, f"{name} must be a finite number >= 0{unit}, got {_show(value)}"
    )


def _show(value) -> str:
    if _is_concrete(value):
        array = np.asarray(value)
        return str(array.item()) if array.size == 1 else f"an array with {array.size} values"
    return "a traced value"
