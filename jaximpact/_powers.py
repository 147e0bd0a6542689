"""Powers of the penetration that never give a NaN value or gradient, and that cost a
square root and a few multiplies where the exponent is a constant multiple of 1/2."""

import functools
import numbers

import jax
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

# the largest |exponent| evaluated by multiplies (x^8 by three squarings, a few ulps);
# larger ones stay `pow`
MAX_HALF_POWER = 8.0


def half_steps(p) -> int | None:
    """`2 p` where `p` is a static number (not an array) that is a multiple of 1/2 with
    `|p| <= MAX_HALF_POWER`, so that `x**p` is a square root and multiplies; else `None`
    (an array, traced or not, a general exponent such as 0.25 or 1.3: `pow`)."""
    if isinstance(p, bool) or not isinstance(p, numbers.Real):
        return None
    twice = 2.0 * float(p)
    if not twice.is_integer() or abs(p) > MAX_HALF_POWER:
        return None
    return int(twice)


def half_power(x: ArrayLike, k: int) -> Array:
    """`x**(k/2)` for `x > 0` and a Python integer `k`, by multiplies and one square root
    (XLA's `pow` with a non-integer exponent costs about 10x `x * sqrt(x)` on CPU).

    Within about 2 ulps of `x**(k/2)` (correctly rounded steps: `sqrt`, then a product with
    `x^m` by repeated multiplication), and so is its derivative, `(k/2) x^(k/2 - 1)` by the
    same rule (`x^1.5`: `1.5 sqrt(x)`; `x^0.5`: `0.5 / sqrt(x)`). `x <= 0` is the caller's
    to guard, as for `pow` (`safe_pow` does: 0 with gradient 0).

    **Example**: `half_power(4.0, 3)` is `8.0` (`4 * sqrt(4)`).
    """
    x = jnp.asarray(x)
    if k % 2:
        return _odd_half_power(x, k)
    if k >= 0:
        return _integer_power(x, k // 2)
    # 1/x first, so that x^m never underflows where x^-m is finite
    return _integer_power(1.0 / x, -k // 2)


def _integer_power(x, m):
    """`x^m` by repeated multiplication (`integer_pow`, as `x**2` is written); `m >= 0`."""
    return x if m == 1 else x**m


@functools.partial(jax.custom_jvp, nondiff_argnums=(1,))
def _odd_half_power(x, k):
    root = jnp.sqrt(x)
    if k == 1:
        return root
    if k == -1:
        return 1.0 / root
    m = (abs(k) - 1) // 2
    if k > 0:  # x^(m + 1/2) = x^(m - 1) (x sqrt(x)): the most accurate order measured
        high = x * root
        return high if m == 1 else _integer_power(x, m - 1) * high
    # 1/x first, so that x^(m + 1/2) never underflows where x^-(m + 1/2) is finite
    return _integer_power(1.0 / x, m) / root


@_odd_half_power.defjvp
def _odd_half_power_jvp(k, primals, tangents):
    (x,), (dx,) = primals, tangents
    return _odd_half_power(x, k), dx * (0.5 * k * half_power(x, k - 2))


def safe_pow(x: ArrayLike, p: ArrayLike) -> Array:
    """`x**p` for `x > 0`, and 0 (with gradient 0) for `x <= 0`.

    The double `where` keeps `inf * 0` out of the backward pass, so that fractional
    powers such as `x**0.5` are safe where the solver samples `x` slightly below 0.
    A static exponent that is a multiple of 1/2 (a Python or numpy number: 0.5, 1.5, 2.5,
    2.0) is evaluated by `half_power`, a square root and multiplies, about 10x cheaper than
    `pow` and within a few ulps of it; any other exponent, or one given as an array, by
    `pow`.

    **Example**: `safe_pow(jnp.array([-1.0, 4.0]), 0.5)` is `[0.0, 2.0]`.
    """
    x = jnp.asarray(x)
    positive = x > 0
    inside = jnp.where(positive, x, 1.0)
    k = half_steps(p)
    power = inside**p if k is None else half_power(inside, k)
    return jnp.where(positive, power, 0.0)


def contact_pow(x: ArrayLike, p) -> Array:
    """`x**p` as a contact law uses it.

    A Python integer exponent (0, 1, 2, ...) gives the plain power, continued smoothly below
    0: clipping a polynomial law puts a kink inside the solver's last step and costs
    accuracy. Any other exponent, or one given as an array, goes through `safe_pow`
    (zero below 0): by a square root and multiplies where it is a static multiple of 1/2
    (the table's 0.5, 1.5, 2.5), by `pow` otherwise (a traced exponent, e.g.
    Hunt-Crossley's `n`, or 0.25).
    """
    if isinstance(p, (int, float)) and float(p).is_integer() and p >= 0:
        return jnp.asarray(x) ** int(p)
    return safe_pow(x, p)
