"""Exact solutions: fast paths for `impact` and oracles for the tests.

- Kelvin-Voigt `m x'' = -c x - b x'` under both separation criteria, for any damping.
- Maxwell (eqs. 10-11) under the force criterion, under-damped (`4 b^2 > m c`): the
  paper's formulas, kept as an oracle (`impact` uses `closed_forms_linear.maxwell_impact`,
  which holds for every damping and both criteria).
- The exact impacts the law table's rows hold (`LawSpec.closed_form`, taken by `impact`,
  `bounce` and `exact_batch` through `AbstractLaw.closed_form`), each for any gravity
  `g >= 0`: `kelvin_voigt_closed_form`, `bingham_closed_form` (eq. 7),
  `bingham_compression_closed_form` (eq. 9) and `maxwell_closed_form` (eqs. 10-11), the
  last three through `closed_forms_linear` (and Kelvin-Voigt's with gravity).
- The undamped power-law spring `F = c x^n`: `x_max` and `T`.
- The restitution of the Hunt-Crossley family `F = c x^n (1 + D v)`, a function of
  `D v0` only (through the Lambert W function).
All in SI units; every function is differentiable and NaN-free, including at critical
damping (`b^2 = 4 m c`), where the under- and over-damped formulas meet.
"""

import dataclasses
import functools
import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax.scipy.special import gammaln

from .._checks import is_traced
from .._status import Status
from .closed_forms_linear import (
    LinearCoefficients,
    linear_impact,
    maxwell_creep as maxwell_creep,  # where dynamics.py reads it
    maxwell_gravity_impact,
    maxwell_impact,
)
from .oscillator import _arctan_ratio, _cos_continued, _newton_root, _sin_ratio


def kelvin_voigt(c, b, m, v0, separation="force", *, rest_tol=1e-7):
    """Exact impact of `m x'' = -c x - b x'`, `x(0) = 0`, `x'(0) = v0`.

    With `s = b/(2m)` and `r = c/m - s^2` (`r < 0` over-damped):
    `x(t) = v0 exp(-s t) S(t)`, `S = sin(sqrt(r) t)/sqrt(r)` (sinh when `r < 0`).
    Force criterion (eq. 5): `T = 2 atan(sqrt(r)/s)/sqrt(r)` for every damping, and
    `e = exp(-s T)`. Penetration criterion: `T = pi/sqrt(r)`, `e = exp(-s T)`, and no
    separation at all when `r <= 0` (status captured; `T` is when `|v|/v0 + |F|/(m v0^2/x*)`
    falls to `rest_tol`, `x* = v0 sqrt(m/c)`, as `impact` defines it). Maximum compression
    at `t_max = T_force / 2`. Returns a dict of `e, T, x_max, t_max, F_max, status`.
    """
    s = b / (2.0 * m)
    r = c / m - s**2
    s_safe = jnp.where(s > 0, s, 1.0)
    t_force = jnp.where(
        s > 0,
        2.0 * _arctan_ratio(r / s_safe**2) / s_safe,
        jnp.pi / jnp.sqrt(jnp.where(s > 0, 1.0, r)),
    )
    t_max = 0.5 * t_force
    x_max = v0 * jnp.exp(-s * t_max) * _sin_ratio(r, t_max)
    # force peak inside compression only while b^2 < m c (damping ratio < 1/2)
    r_pos = jnp.where(r > 0, r, 1.0)
    angle = jnp.arctan2(jnp.sqrt(r_pos), s)
    t_peak = jnp.clip((3.0 * angle - jnp.pi) / jnp.sqrt(r_pos), 0.0, t_max)
    x_peak = v0 * jnp.exp(-s * t_peak) * _sin_ratio(r, t_peak)
    v_peak = v0 * jnp.exp(-s * t_peak) * (_cos_continued(r, t_peak) - s * _sin_ratio(r, t_peak))
    f_max = jnp.maximum(b * v0, c * x_peak + b * v_peak)
    if separation == "force":
        T, status = t_force, jnp.asarray(Status.separated)
    else:
        returns = r > 0
        t_star = jnp.sqrt(m / c)
        # the rest time exists for over-damped values only: feed a harmless over-damped
        # problem to the others, so no NaN reaches a gradient through the discarded branch
        s_nd = jnp.where(returns, 2.0, s * t_star)
        r_nd = jnp.where(returns, -3.0, r * t_star**2)
        rest = _rest_time(s_nd, r_nd, rest_tol, 2.0 * s_nd, jnp.where(returns, 1.0, t_max / t_star))
        T = jnp.where(returns, jnp.pi / jnp.sqrt(r_pos), rest * t_star)
        status = jnp.where(returns, Status.separated, Status.captured)
    e = jnp.where(status == Status.separated, jnp.exp(-s * T), 0.0)
    return dict(e=e, T=T, x_max=x_max, t_max=t_max, F_max=f_max, status=status)


def _rest_time(s, r, rest_tol, beta, tau_start):
    """Nondimensional time at which an over-damped `X'' + beta X' + X = 0` (`X(0) = 0`,
    `X'(0) = 1`, `s = beta/2`, `r = 1 - s^2 < 0`) reaches `|V| + |X + beta V| = rest_tol`
    (Newton on its logarithm, from the slow mode's estimate). The modes are written as
    single exponentials, `X = (exp(l1 tau) - exp(l2 tau))/(l1 - l2)`, which cannot overflow.
    Call it with over-damped values only (`impact` substitutes safe ones elsewhere)."""
    q = jnp.sqrt(-r)
    slow, fast = -s + q, -s - q
    start = jnp.maximum(jnp.log(rest_tol) / slow, tau_start)

    def excess(tau, args):
        slow, fast, beta, rest_tol = args
        x = (jnp.exp(slow * tau) - jnp.exp(fast * tau)) / (slow - fast)
        v = (slow * jnp.exp(slow * tau) - fast * jnp.exp(fast * tau)) / (slow - fast)
        return jnp.log(jnp.abs(v) + jnp.abs(x + beta * v)) - jnp.log(rest_tol)

    tau, _ = _newton_root(excess, (slow, fast, beta, rest_tol), start)
    return jnp.where(jnp.isfinite(tau), tau, start)


def maxwell(c, b, m, v0):
    """Exact impact of the Maxwell law (eqs. 10-11) under the force criterion.

    With `t* = sqrt(m/c)`, `mu = sqrt(m c)/b`, `a = mu/2`, `w = sqrt(1 - a^2)` (needs
    `a < 1`, i.e. `4 b^2 > m c`): `T = pi t*/w`, `e = exp(-a pi/w)` (the paper's formulas),
    maximum compression at `w tau = pi - atan(w/a)` with
    `X = exp(-a tau)((w^2 - a^2)/w sin(w tau) - 2 a cos(w tau)) + 2 a`, and peak force
    `F_max = c x* exp(-a tau_p)` at `tau_p = atan(w/a)/w`, with `x* = v0 t*`.
    Outside its range (over-damped) the values are NaN-free but meaningless; `impact`
    takes `closed_forms_linear.maxwell_impact`, which holds everywhere.
    """
    t_star = jnp.sqrt(m / c)
    x_star = v0 * t_star
    a = 0.5 * jnp.sqrt(m * c) / b
    under = a < 1.0
    w = jnp.sqrt(jnp.where(under, 1.0 - a**2, 1.0))
    tau_max = (jnp.pi - jnp.arctan2(w, a)) / w
    x_max = (
        jnp.exp(-a * tau_max)
        * ((w**2 - a**2) / w * jnp.sin(w * tau_max) - 2 * a * jnp.cos(w * tau_max))
        + 2 * a
    )
    tau_peak = jnp.arctan2(w, a) / w
    return dict(
        e=jnp.exp(-a * jnp.pi / w),
        T=jnp.pi * t_star / w,
        x_max=x_max * x_star,
        t_max=tau_max * t_star,
        F_max=c * x_star * jnp.exp(-a * tau_peak),
        status=jnp.where(under, Status.separated, Status.captured),
    )


def power_spring(c, n, m, v0):
    """Undamped `F = c x^n`: `x_max = ((n+1) m v0^2/(2c))^(1/(n+1))` and
    `T = 2 (x_max/v0) B(1/(n+1), 1/2)/(n+1)` (B the Beta function); `e = 1`.
    For Hertz (`n = 1.5`) `T = K (m^2/(c^2 v0))^(1/5)` with `K = 3.2181`."""
    x_max = ((n + 1.0) * m * v0**2 / (2.0 * c)) ** (1.0 / (n + 1.0))
    k = 1.0 / (n + 1.0)
    beta = jnp.exp(gammaln(k) + gammaln(0.5) - gammaln(k + 0.5))
    T = 2.0 * x_max / v0 * beta / (n + 1.0)
    return dict(
        e=jnp.ones_like(T),
        T=T,
        x_max=x_max,
        t_max=0.5 * T,
        F_max=c * x_max**n,
        status=jnp.asarray(Status.separated),
    )


_SMALL_ALPHA = 0.1  # below it, `alpha - log(1 + alpha)` by its series (no cancellation)
_SMALL_W = 1.0  # below it, `w - 1 + exp(-w)` by its series


def _horner(u, coefficients):
    out = jnp.zeros_like(u)
    for a in reversed(coefficients):
        out = out * u + a
    return out


# (u - log(1 + u))/u^2 = sum (-u)^k/(k + 2), and (w - 1 + exp(-w))/w^2 = sum (-w)^k/(k + 2)!
_PHI = [1.0 / (k + 2) for k in range(30)]  # used for |u| < 0.1: 0.1^30 is far below eps
_PSI = [1.0 / math.factorial(k + 2) for k in range(24)]  # used for 0 <= w < 1
_EXPREL = [1.0 / math.factorial(k + 1) for k in range(24)]  # (1 - exp(-w))/w, 0 <= w < 1


def _restitution_ratio(t, alpha):
    """`k(alpha t)/R(alpha)` with `k(w) = w - 1 + exp(-w)` and `R(a) = a - log(1 + a)`,
    each to full relative precision: as `t^2 psi(w)/phi(alpha)` (series) for small alpha."""
    w = alpha * t
    small_a = alpha < _SMALL_ALPHA
    small_w = w < _SMALL_W
    a_big = jnp.where(small_a, 1.0, alpha)
    w_big = jnp.where(small_w, 2.0, w)
    w_small = jnp.where(small_w, w, 0.5)
    k_big = jnp.where(small_w, w_small**2 * _horner(-w_small, _PSI), w_big + jnp.expm1(-w_big))
    ratio_big = k_big / (a_big - jnp.log1p(a_big))
    ratio_small = t**2 * _horner(-w_small, _PSI) / _horner(-jnp.where(small_a, alpha, 0.0), _PHI)
    return jnp.where(small_a, ratio_small, ratio_big)


def _check_alpha(alpha):
    if is_traced(alpha):
        return
    values = np.asarray(alpha)
    if values.dtype.kind not in "biuf":
        raise TypeError(f"alpha must be a real number or array, not {values.dtype}")
    bad = ~(values >= 0)
    if np.any(bad):
        index = tuple(int(i) for i in np.argwhere(bad)[0]) if values.ndim else ()
        where = f" at index {index[0] if len(index) == 1 else index}" if index else ""
        raise ValueError(f"alpha = D v0 must be >= 0 (got {values[bad].flat[0]}{where})")


def hunt_crossley_restitution(alpha):
    """Exact `e` of `F = c x^n (1 + D v)` with `alpha = D v0` (>= 0), any `n`, both criteria.

    From `m v dv/dx = -c x^n (1 + D v)`: `-alpha e - ln(1 - alpha e) = alpha - ln(1 + alpha)`,
    i.e. `e = (1 + W0(-(1 + alpha) exp(-(1 + alpha)))) / alpha` (W0 the principal Lambert W).
    Solved for `w = -ln(1 - alpha e)` from `w - 1 + exp(-w) = alpha - ln(1 + alpha)` by
    Newton on `log(w/alpha)` (a number near 1 for every alpha, so no bracket to lose and
    full relative precision from `alpha = 1e-300` to `1e300`), then `e = (1 - exp(-w))/alpha`.
    Elementwise on arrays; `jax.grad` differentiates it implicitly (the last Newton step).
    `e = 1 - 2 alpha/3 + O(alpha^2)` near 0 (`e = 1`, `de/dalpha = -2/3` at 0); `e -> 1/alpha`
    as `alpha -> inf` (0 at inf). Negative or NaN alpha is refused (ValueError) when
    concrete; under `jit` it gives NaN.

        >>> float(hunt_crossley_restitution(0.375))  # a = 0.1 s/m, v0 = 2.5 m/s
        0.7991...
    """
    _check_alpha(alpha)
    return _hunt_crossley_restitution(jnp.asarray(alpha, dtype=float))


@jax.jit
def _hunt_crossley_restitution(alpha):
    """The compiled body of `hunt_crossley_restitution` (one program per shape: a call
    costs microseconds, not the quarter second of the operations run one by one)."""
    valid = (alpha >= 0) & jnp.isfinite(alpha)
    a = jnp.where(valid, alpha, 1.0)

    def residual(u, a):
        return jnp.log(_restitution_ratio(jnp.exp(u), a))

    # start: w = sqrt(2 R) for small R (k(w) ~ w^2/2), w = R + 1 for large R (k(w) ~ w - 1)
    small = a < _SMALL_ALPHA
    phi = _horner(-jnp.where(small, a, 0.0), _PHI)  # R/alpha^2 for small alpha
    r = jnp.where(small, 1.0, a - jnp.log1p(a))
    u = jnp.where(
        small,
        0.5 * jnp.log(2.0 * phi),
        jnp.where(r < 1.0, 0.5 * jnp.log(2.0 * r), jnp.log1p(r)) - jnp.log(a),
    )
    u = jax.lax.stop_gradient(u)
    a_const = jax.lax.stop_gradient(a)
    ones = jnp.ones_like(u)
    for _ in range(6):  # measured: 4 reach 2e-16 everywhere from this start
        f, df = jax.jvp(lambda u: residual(u, a_const), (u,), (ones,))
        u = u - f / df
    # one more step, with the gradient: du/dalpha = -(dH/dalpha)/(dH/du) at the root
    u = jax.lax.stop_gradient(u)
    f, df = jax.jvp(lambda u: residual(u, a), (u,), (ones,))
    u = u - f / jax.lax.stop_gradient(df)
    t = jnp.exp(u)
    w = a * t
    small_w = w < _SMALL_W
    w_big = jnp.where(small_w, 1.0, w)
    exprel = jnp.where(
        small_w, _horner(-jnp.where(small_w, w, 0.0), _EXPREL), -jnp.expm1(-w_big) / w_big
    )
    e = t * exprel  # (1 - exp(-w))/alpha, with e = 1 at alpha = 0
    return jnp.where(valid, e, jnp.where(alpha == jnp.inf, 0.0, jnp.nan))


def exact_batch(law, *, m, v0, separation: str, g=0.0, rest_tol=1e-7) -> dict | None:
    """`e`, `T` (s) and `status` (numpy arrays) of a batch of impacts of `law`, whose
    parameters are numbers or 1-D arrays of one length, from the exact solution its row of
    the law table declares (`LawSpec.closed_form`, read through `AbstractLaw.closed_form`:
    every parameter value, and every `g >= 0` where the row says `closed_form_gravity`), or
    `None` where the row has none. `m` (kg), `v0` (m/s), `g` (m/s^2) are numbers. One
    compiled program per row and criterion (`jit` of `vmap`), whatever the batch's values.
    """
    g_is_zero = isinstance(g, (int, float)) and g == 0
    closed = law.closed_form(separation, g_is_zero=g_is_zero)
    if closed is None:
        return None
    params = law.parameters
    shape = np.broadcast_shapes(*(np.shape(v) for v in params.values()))
    # checked when `law` was built; `replace` would take one number per parameter
    batch = dataclasses.replace(
        law,
        params={
            k: jnp.broadcast_to(jnp.asarray(v, float), shape or (1,)) for k, v in params.items()
        },
    )
    solve = _batch_solve(law.spec.closed_form, separation, rest_tol, float(g))
    out = solve(batch, jnp.asarray(m, float), jnp.asarray(v0, float))
    return {k: np.asarray(out[k]).reshape(shape) for k in ("e", "T", "status")}


@functools.cache
def _batch_solve(closed_form, separation, rest_tol, g):
    """The compiled batch of a row's closed form (`exact_batch`), cached by row builder;
    `g` (a number) is built in, so that `g = 0` compiles the formulas without gravity only."""
    closed = closed_form(separation)

    def one(law, m, v0):
        return closed(law, m=m, v0=v0, g=g, rest_tol=rest_tol)

    return eqx.filter_jit(eqx.filter_vmap(one, in_axes=(eqx.if_array(0), None, None)))


def _finish(fields, m, v0, g=0.0, with_end=False):
    """The `ImpactResult` fields of a closed form's dict (`x_end`, m, where contact ended:
    the work of gravity `m g x_end` is dissipated too, as on the integrated path); with
    `with_end`, `x_end` is kept (what a bounce needs to start the next flight)."""
    e = fields["e"]
    separated = fields["status"] == Status.separated
    fields = dict(fields)
    x_end = fields.pop("x_end", 0.0)
    fields["status"] = jnp.asarray(fields["status"]).astype(jnp.int32)
    fields["dissipated"] = 0.5 * m * v0**2 * (1.0 - e**2) + m * g * x_end
    fields["v_out"] = jnp.where(separated, -e * v0, 0.0)
    fields["num_steps"] = jnp.asarray(0)
    if with_end:
        fields["x_end"] = jnp.zeros_like(fields["T"]) + x_end
    return fields


# the horizon (units of t*) of a contact that never ends: `impact`'s default `tau_max`
TAU_MAX = 1e4


def _where_no_gravity(g, without_gravity, with_gravity, args):
    """`without_gravity(args)` where `g = 0`, else `with_gravity(args)`: decided once where
    `g` is known (a number, or a concrete array, as given: `jnp.asarray` of a number
    inside a trace is a tracer), else a `lax.cond` (a select under `vmap`, where both
    run)."""
    if not is_traced(g):
        return (without_gravity if bool(np.all(np.asarray(g) == 0)) else with_gravity)(args)
    return jax.lax.cond(jnp.all(g == 0), without_gravity, with_gravity, args)


def kelvin_voigt_closed_form(separation):
    """Kelvin-Voigt (eq. 1): eq. 5's formulas (`kelvin_voigt`) at `g = 0`, the piecewise
    oscillator (`closed_forms_linear.linear_impact`) under gravity; any damping.

    The closed forms built here are `f(law, *, m, v0, g, rest_tol, tau_max, with_end)`:
    `rest_tol` and `tau_max` as in `impact`, and `with_end=True` keeps `x_end` (m, the
    penetration where contact ended) among the fields, for `bounce`."""

    def impact_fields(law, *, m, v0, g=0.0, rest_tol, tau_max=TAU_MAX, with_end=False):
        c, b = law.params["c"], law.params["b"]
        given_g, g = g, jnp.asarray(g, dtype=jnp.result_type(float))

        def without_gravity(args):
            c, b, m, v0, g = args
            fields = kelvin_voigt(c, b, m, v0, separation, rest_tol=rest_tol)
            fields["status"] = jnp.asarray(fields["status"]).astype(jnp.int32)
            return dict(fields, x_end=jnp.zeros_like(fields["T"]))

        def with_gravity(args):
            c, b, m, v0, g = args
            zero = jnp.zeros_like(c)
            coefficients = LinearCoefficients(c, b, zero, zero)
            fields = linear_impact(coefficients, m, v0, g, separation, dry=False, rest_tol=rest_tol)
            fields["status"] = jnp.asarray(fields["status"]).astype(jnp.int32)
            return fields

        args = jnp.broadcast_arrays(c, b, m, v0, g)
        # eq. 5's formulas where g = 0 (a select under vmap, one branch otherwise)
        fields = _where_no_gravity(given_g, without_gravity, with_gravity, args)
        return _finish(fields, m, v0, g, with_end)

    return impact_fields


def _linear_impact(p_in, p_out, damped, dry):
    """Bingham-type laws: `p_in(P)`, `p_out(P)` the dry force in each phase (N)."""

    def build(separation):
        def impact_fields(law, *, m, v0, g=0.0, rest_tol, tau_max=TAU_MAX, with_end=False):
            c, pressure = law.params["c"], law.params["P"]
            b = law.params["b"] if damped else jnp.zeros_like(c)
            coefficients = LinearCoefficients(c, b, p_in(pressure), p_out(pressure))
            fields = linear_impact(coefficients, m, v0, g, separation, dry=dry, rest_tol=rest_tol)
            return _finish(fields, m, v0, g, with_end)

        return impact_fields

    return build


def maxwell_closed_form(separation):
    """Maxwell (eqs. 10-11), every damping: `closed_forms_linear.maxwell_impact` at
    `g = 0`, `closed_forms_linear.maxwell_gravity_impact` under gravity (any `g >= 0`)."""

    def impact_fields(law, *, m, v0, g=0.0, rest_tol, tau_max=TAU_MAX, with_end=False):
        c, b = law.params["c"], law.params["b"]
        given_g, g = g, jnp.asarray(g, dtype=jnp.result_type(float))

        def without_gravity(args):
            c, b, m, v0, g = args
            fields = maxwell_impact(c, b, m, v0, separation, rest_tol=rest_tol)
            return dict(fields, status=jnp.asarray(fields["status"]).astype(jnp.int32))

        def with_gravity(args):
            c, b, m, v0, g = args
            fields = maxwell_gravity_impact(
                c, b, m, v0, g, separation, rest_tol=rest_tol, tau_max=tau_max
            )
            return dict(fields, status=jnp.asarray(fields["status"]).astype(jnp.int32))

        args = jnp.broadcast_arrays(c, b, m, v0, g)
        fields = _where_no_gravity(given_g, without_gravity, with_gravity, args)
        return _finish(fields, m, v0, g, with_end)

    return impact_fields


# Bingham (eq. 7) and Bingham in compression (eq. 9): `linear_impact`, any `g`
bingham_closed_form = _linear_impact(lambda p: p, lambda p: p, damped=True, dry=True)
bingham_compression_closed_form = _linear_impact(
    lambda p: p, jnp.zeros_like, damped=False, dry=False
)
