"""Powers of the penetration that never give a NaN value or gradient."""

import jax.numpy as jnp
from jaxtyping import Array, ArrayLike


def safe_pow(x: ArrayLike, p: ArrayLike) -> Array:
    """`x**p` for `x > 0`, and 0 (with gradient 0) for `x <= 0`.

    The double `where` keeps `inf * 0` out of the backward pass, so that fractional
    powers such as `x**0.5` are safe where the solver samples `x` slightly below 0.

    **Example**: `safe_pow(jnp.array([-1.0, 4.0]), 0.5)` is `[0.0, 2.0]`.
    """
    x = jnp.asarray(x)
    positive = x > 0
    return jnp.where(positive, jnp.where(positive, x, 1.0) ** p, 0.0)


def contact_pow(x: ArrayLike, p) -> Array:
    """`x**p` as a contact law uses it.

    A Python integer exponent (0, 1, 2, ...) gives the plain power, continued smoothly below
    0: clipping a polynomial law puts a kink inside the solver's last step and costs
    accuracy. Any other exponent, or one given as an array, goes through `safe_pow`
    (zero below 0).
    """
    if isinstance(p, (int, float)) and float(p).is_integer() and p >= 0:
        return jnp.asarray(x) ** int(p)
    return safe_pow(x, p)
