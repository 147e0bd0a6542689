"""A root finder for diffrax's events that keeps its bracket: Newton's method, falling
back to bisection wherever a Newton step would leave the interval that holds the root.
Every integrated impact ends its events with it, head-on (`phases.py`) and oblique
(`_oblique/impact.py`).

diffrax finds an event's time with an optimistix root finder on the step's interpolant,
over the step `[lower, upper]` in which the condition changed sign. Two things rule out
optimistix's own finders:

- `optx.Newton` is clipped to that step, and a condition that grows like a square root
  from the start of contact (the stick-slip conditions of a Hertz contact:
  `K u - 1.5 mu X^0.5 V`, K small) sends it from the step's end past `lower` to `t = 0`,
  where the derivative vanishes: the root find failed and the solve with it (a linear
  spring of 5e6 N/m on Kharaz's sphere at 5 degrees). It also solves its scalar Newton step
  through a lineax operator and QR, which cost a user's law's first `impact` about 2 s of
  its 6 s of tracing and compiling (benchmarks/first_calls.md).
- `optx.Bisection` takes a scalar only, and diffrax hands the root finder every condition
  of the event at once (a tuple, all zero but the one that fired).

Here the conditions are summed to that scalar, and each iterate is Newton's where it stays
inside the bracket, the bracket's midpoint otherwise; the derivative of the event time
comes from optimistix's implicit function theorem as before.
"""

from collections.abc import Callable
from typing import Any, ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jaxtyping import Array, Scalar


def _scalar(fn, y, args):
    out, aux = fn(y, args)
    leaves = jax.tree_util.tree_leaves(out)
    return sum(leaves[1:], leaves[0]), aux


class _State(eqx.Module):
    lower: Scalar
    upper: Scalar
    negative_at_lower: Array
    diff: Scalar
    value: Scalar


class BracketedNewton(optx.AbstractRootFinder):
    """Newton's method safeguarded by bisection inside `options["lower"]`,
    `options["upper"]` (a scalar root; a pytree of outputs is summed). Stops where a step
    is below `atol + rtol |t|`, the bracket is that narrow, or the value is exactly 0."""

    rtol: float
    atol: float
    norm: ClassVar[Callable] = jnp.abs

    def init(self, fn, y, args, options, f_struct, aux_struct, tags):
        lower = jnp.asarray(options["lower"], jnp.result_type(y))
        upper = jnp.asarray(options["upper"], jnp.result_type(y))
        value_lower, _ = _scalar(fn, lower, args)
        inf = jnp.asarray(jnp.inf, lower.dtype)
        return _State(lower, upper, value_lower < 0, inf, inf)

    def step(self, fn, y, args, options, state: _State, tags):
        def scalar(t):
            return _scalar(fn, t, args)

        (value, aux), (slope, _) = jax.jvp(scalar, (y,), (jnp.ones_like(y),))
        same_as_lower = (value < 0) == state.negative_at_lower
        lower = jnp.where(same_as_lower, y, state.lower)
        upper = jnp.where(same_as_lower, state.upper, y)
        usable = jnp.isfinite(slope) & (slope != 0)
        newton = y - value / jnp.where(usable, slope, 1.0)
        # `y` is now an end of the bracket: a converged Newton step lands on it (or within
        # the tolerance of it), which is the root, not a step out of the bracket
        converged = jnp.abs(newton - y) < self._scale(y)
        inside = usable & (
            converged
            | ((newton > jnp.minimum(lower, upper)) & (newton < jnp.maximum(lower, upper)))
        )
        new_y = jnp.where(inside, newton, 0.5 * (lower + upper))
        new_y = jnp.where(value == 0, y, new_y)
        return new_y, _State(lower, upper, state.negative_at_lower, new_y - y, value), aux

    def _scale(self, y):
        return self.atol + self.rtol * jnp.abs(y)

    def terminate(self, fn, y, args, options, state: _State, tags):
        scale = self._scale(y)
        done = (
            (jnp.abs(state.diff) < scale)
            | (jnp.abs(state.upper - state.lower) < scale)
            | (state.value == 0)
        )
        return done, optx.RESULTS.successful

    def postprocess(self, fn, y, aux, args, options: dict[str, Any], state, tags, result):
        return y, aux, {}
