"""An impact read off the universal curves: no ODE solve.

For a one-group law (`F = c x^n + b x^p v`, no gravity, no dry force) the outputs are
`e(beta)`, `T = t* tau(beta)`, `x_max = x* X(beta)`, `t_max = t* tau_m(beta)` and
`F_max = (m v0^2/x*) f(beta)`, with `x* = (m v0^2/c)^(1/(n+1))`, `t* = x*/v0` and
`beta = b x*^(p+1)/(m v0)`. Below `BETA_MIN` each curve is continued by its elastic limit
and first-order slope (so the gradient at `b = 0` is the slope), above the table's end by
the power law of its last piece (`ln f` linear in `ln beta`).
"""

import functools

import jax
import jax.numpy as jnp
import numpy as np

from .._status import Status
from . import chebyshev
from .curve import BETA_MIN, Curves
from .shapes import CurveKey
from .store import curves_for

_SLOPE_BETA = 1e-6  # where the first-order slope is read off the series


@functools.cache
def _ends(curves: Curves):
    """Constants of the two continuations, per output: the value and slope `df/dbeta` at
    `BETA_MIN`, and `ln f` and `d ln f / d ln beta` at the table's end."""
    breaks, coefficients = curves.breaks, curves.coefficients
    s_lo, s_hi, s_slope = breaks[0], breaks[-1], np.log(_SLOPE_BETA)
    h = 1e-4
    low = np.exp(chebyshev.evaluate_numpy(breaks, coefficients, s_lo)[0])
    at = lambda s: chebyshev.evaluate_numpy(breaks, coefficients, [s - h, s + h])
    d_slope = at(s_slope + h)  # inside the piece, a central difference in s
    log_slope = (d_slope[1] - d_slope[0]) / (2 * h)
    value_slope = np.exp(chebyshev.evaluate_numpy(breaks, coefficients, s_slope + h)[0])
    slope = value_slope * log_slope / np.exp(s_slope + h)
    top = at(s_hi - h)
    log_top = chebyshev.evaluate_numpy(breaks, coefficients, s_hi)[0]
    top_slope = (top[1] - top[0]) / (2 * h)
    return low, slope, log_top, top_slope


def curve_values(curves: Curves, beta, outputs: tuple[int, ...]):
    """The outputs (indices into `reference.OUTPUTS`) at `beta` (a JAX scalar), as one
    array; differentiable, NaN-free for every `beta >= 0`."""
    low, slope, log_top, top_slope = (a[list(outputs)] for a in _ends(curves))
    s_lo, s_hi = float(curves.breaks[0]), float(curves.breaks[-1])
    inside = (beta > BETA_MIN) & (jnp.log(jnp.where(beta > BETA_MIN, beta, 1.0)) < s_hi)
    s = jnp.clip(jnp.log(jnp.where(beta > BETA_MIN, beta, BETA_MIN)), s_lo, s_hi)
    series = jnp.exp(chebyshev.evaluate(curves.breaks, curves.coefficients, s, list(outputs)))
    elastic = low + slope * (beta - BETA_MIN)
    s_above = jnp.log(jnp.where(beta > 1.0, beta, 1.0))
    tail = jnp.exp(log_top + top_slope * (s_above - s_hi))
    return jnp.where(inside, series, jnp.where(beta <= BETA_MIN, elastic, tail))


def serves(key: CurveKey) -> bool:
    """Whether the curves give every impact of `key` (not a shape with a capture)."""
    return curves_for(key).capture is None


def similarity_fields(dynamics, key: CurveKey, *, m, v0, peaks: bool) -> dict:
    """`ImpactResult` fields from a `PowerDynamics` (its `beta`, `x_star`, `t_star`)."""
    curves = curves_for(key)
    outputs = (0, 1, 2, 3, 4) if peaks else (0, 1)
    values = curve_values(curves, dynamics.beta, outputs)
    # a damping that only dissipates gives e <= 1; near the elastic limit the series' own
    # error (<= 3e-12) could put e just above it: clamped, with the slope kept (at b = 0
    # the derivative is the elastic limit's)
    excess = jax.lax.stop_gradient(jnp.maximum(values[0] - 1.0, 0.0))
    return fields_from_values(dynamics, values, values[0] - excess, m=m, v0=v0)


def fields_from_values(dynamics, values, e, *, m, v0, gravity_work=None) -> dict:
    """`ImpactResult` fields of a separated impact from the nondimensional outputs
    `values` (e, T/t*, and with peaks x_max/x*, t_max/t*, F_max/(m v0^2/x*)), with `e`
    already clamped; `gravity_work` (J): gravity's work over the final penetration, added
    to the energy taken."""
    dissipated = 0.5 * m * v0**2 * (1.0 - e**2)
    fields = dict(
        e=e,
        T=values[1] * dynamics.t_star,
        dissipated=dissipated if gravity_work is None else dissipated + gravity_work,
        v_out=-e * v0,
        status=jnp.asarray(Status.separated, dtype=jnp.int32),
        num_steps=jnp.asarray(0),
    )
    if values.shape[0] > 2:  # the peaks
        fields.update(
            x_max=values[2] * dynamics.x_star,
            t_max=values[3] * dynamics.t_star,
            F_max=values[4] * dynamics.force_scale,
        )
    return fields


def beta_for_restitution(curves: Curves, e):
    """The `beta` at which the curve gives restitution `e` (bisection in `ln beta` on the
    monotone `e(beta)`, `optimistix`): `BETA_MIN` for `e` at its elastic limit and above,
    the power-law tail beyond the table."""
    import optimistix as optx

    lower, upper = np.log(BETA_MIN), float(curves.breaks[-1]) + 20.0
    # an `e` below the curve's far end has no root: take that end (the fit then reports
    # the target unmet) instead of leaving the bisection without a bracket
    log_floor = jnp.log(curve_values(curves, jnp.exp(upper), (0,))[0])
    log_e = jnp.clip(jnp.log(jnp.clip(e, 1e-300, 1.0)), log_floor * (1 - 1e-9), 0.0)

    def excess(s, target):
        return jnp.log(curve_values(curves, jnp.exp(s), (0,))[0]) - target

    # `excess` falls from >= 0 at `lower` to < 0 at `upper` (`log_e` clipped): `flip=True`
    # is what optimistix would detect, without its check (a host callback) or two calls
    solution = optx.root_find(
        excess,
        optx.Bisection(rtol=1e-14, atol=1e-14, flip=True),
        jnp.asarray(0.5 * (lower + upper)),
        args=log_e,
        options=dict(lower=lower, upper=upper),
        max_steps=200,
        throw=False,
    )
    return jnp.exp(solution.value)
