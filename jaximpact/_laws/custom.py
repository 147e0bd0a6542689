"""The user's own law: `custom_law(fn, **params)` wraps a pure JAX function
`fn(x, v, params) -> F`."""

from collections.abc import Callable

import equinox as eqx
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._checks import check_values
from .base import AbstractLaw
from .dynamics import scaled_dynamics
from .named_law import as_arrays


class CustomLaw(AbstractLaw):
    """A user's law `F = fn(x, v, params)` in SI units (N), built by `custom_law`."""

    fn: Callable = eqx.field(static=True)
    params: dict[str, Array]
    name: str = eqx.field(static=True, default="custom")

    @property
    def parameters(self):
        return dict(self.params)

    def replace(self, **params):
        unknown = sorted(set(params) - set(self.params))
        if unknown:
            raise ValueError(
                f"this custom law has no parameter {', '.join(unknown)}; "
                f"it has {', '.join(self.params)}"
            )
        return CustomLaw(self.fn, {**self.params, **_finite_arrays(params)}, self.name)

    def dynamics(self, *, m, v0, g):
        return scaled_dynamics(self.fn, self.params, m=m, v0=v0, g=g)

    def force(self, x, v, **_):
        """Contact force (N) at penetration `x` (m) and velocity `v` (m/s)."""
        return self.fn(jnp.asarray(x, dtype=float), jnp.asarray(v, dtype=float), self.params)


def custom_law(fn: Callable, **params) -> CustomLaw:
    """Wrap a user's force law `fn(x, v, params) -> F` (SI units, N, positive pushing out).

    `fn` must be a pure JAX function of the penetration `x` (m), the velocity `v` (m/s)
    and the dict `params`; it is called with `x` slightly below 0 by the solver's last
    step, so guard fractional powers with `jaximpact.safe_pow`.

    **Example**:
    `custom_law(lambda x, v, p: p["k"] * x + p["d"] * safe_pow(x, 0.5) * v, k=2e6, d=800.0)`.
    """
    if not callable(fn):
        raise ValueError("custom_law needs a function f(x, v, params) as its first argument")
    if not params:
        raise ValueError("custom_law needs the law's parameters as keywords, e.g. k=2e6")
    return CustomLaw(fn, _finite_arrays(params))


def _finite_arrays(params):
    """The parameters as arrays, each finite (any sign: the user's law decides)."""
    return {
        key: check_values(value, _never, f"custom law: parameter {key} must be a finite number")
        for key, value in as_arrays(params).items()
    }


def _never(array):
    return np.zeros(np.shape(array), bool)
