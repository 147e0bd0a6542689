"""Exact impacts of the linear laws with a constant force: Kelvin-Voigt with gravity,
Bingham (eq. 7), Bingham in compression only (eq. 9) and Maxwell (eqs. 10-11).

In the natural units of a linear spring (`t* = sqrt(m/c)` s, `x* = v0 t*` m, forces in
`c x*` N, `tau = t/t*`, `X = x/x*`, `V = v/v0`) every phase of these contacts is the unit
oscillator `Y'' + 2 s Y' + Y = 0` about a shifted equilibrium, with `s = b/(2 sqrt(m c))`
(Kelvin-Voigt and Bingham) or `s = sqrt(m c)/(2 b)` (Maxwell, whose force obeys it). Its
state is known in closed form; the instants that end a phase (maximum compression
`V = 0`, the force back to 0, `X` back to 0, the body back at rest) are either closed
forms or the root of a function that is monotone on a known bracket (bisection to the
last bit, then one Newton step that carries the implicit derivative), so no ODE is
integrated. Every formula holds for any damping (under-, critically and over-damped), by
`jnp.where` between the regimes with harmless values fed to the discarded branch, so
values and gradients are NaN-free everywhere. The statuses and the meaning of `T` when
the body does not leave are those of the integrated path (`_solve/phases.py`): held at
maximum compression (`T = t_max`), back at rest with `v` returning to 0 inside the
surface, or at rest when `|V| + |F - m g|/(c x*)` falls to `rest_tol`.
"""

import jax
import jax.numpy as jnp

from .._status import Status
from .closed_forms import _arctan_ratio, _cos_continued, _sin_ratio, maxwell_creep

# |r| below this: the C/S forms (no cancellation between the modes near critical damping)
_NEAR = 1e-4
_BISECTIONS = 64  # halvings of a bracket: 2^-64 of its width, below float64's resolution


def _first_zero(k, r):
    """First `tau > 0` where `C(tau) = k S(tau)` (`C = cos(sqrt(r) tau)`,
    `S = sin(sqrt(r) tau)/sqrt(r)`, continued to cosh/sinh for `r < 0`), and whether it
    exists: always when `r > 0`; for `r <= 0` only when `k > sqrt(-r)`.
    `atan(sqrt(r)/k)/sqrt(r)` for `k > 0` (through `_arctan_ratio`), `atan2(sqrt(r), k)/sqrt(r)`
    otherwise."""
    k_pos = k > 0
    k_safe = jnp.where(k_pos, k, 1.0)
    u = r / k_safe**2
    exists_pos = k_pos & (u > -1.0)
    t_pos = _arctan_ratio(jnp.where(exists_pos, u, 0.0)) / k_safe
    under = r > 0
    w = jnp.sqrt(jnp.where(under, r, 1.0))
    t_neg = jnp.arctan2(w, jnp.where(under & ~k_pos, k, -1.0)) / w
    return jnp.where(k_pos, t_pos, t_neg), exists_pos | under


def _state(s, r, y0, v0, t):
    """`(Y, V)` at `t` of `Y'' + 2 s Y' + Y = 0` (`r = 1 - s^2`) from `(y0, v0)` at 0.

    `Y = exp(-s t) (y0 C + (v0 + s y0) S)`, `V = exp(-s t) (v0 C - (y0 + s v0) S)`;
    far over-damped (`r < -1e-4`) as two single exponentials (`l2 = -s - q`, `l1 = 1/l2`),
    which neither overflow at long times nor cancel."""
    far = r < -_NEAR
    q = jnp.sqrt(jnp.where(far, -r, 1.0))
    fast = -jnp.where(far, s, 1.0) - q
    slow = 1.0 / fast
    gap = slow - fast
    a1 = (v0 - fast * y0) / gap
    a2 = (slow * y0 - v0) / gap
    t_far = jnp.where(far, t, 0.0)
    e1, e2 = jnp.exp(slow * t_far), jnp.exp(fast * t_far)
    y_far = a1 * e1 + a2 * e2
    v_far = slow * a1 * e1 + fast * a2 * e2
    r_near = jnp.where(far, 0.0, r)
    t_near = jnp.where(far, 0.0, t)
    decay = jnp.exp(-s * t_near)
    cos_, sin_ = _cos_continued(r_near, t_near), _sin_ratio(r_near, t_near)
    y_near = decay * (y0 * cos_ + (v0 + s * y0) * sin_)
    v_near = decay * (v0 * cos_ - (y0 + s * v0) * sin_)
    return jnp.where(far, y_far, y_near), jnp.where(far, v_far, v_near)


def _monotone_root(h, args, lo, hi, increasing=False):
    """The root of `h(t, args)`, monotone on `[lo, hi]` (decreasing unless `increasing`),
    by bisection to the last bit with the arguments frozen, then one Newton step with
    them live: its value moves by rounding only, and its derivative is the implicit one,
    `-(dh/dargs)/(dh/dt)`. A bracket without a root gives one of its ends (callers
    discard it); a flat `h` there gives no NaN."""
    frozen = jax.lax.stop_gradient(args)
    lo, hi = jax.lax.stop_gradient(lo), jax.lax.stop_gradient(hi)

    def halve(_, bounds):
        a, b = bounds
        mid = 0.5 * (a + b)
        value = h(mid, frozen)
        left = (value < 0) if not increasing else (value > 0)
        return jnp.where(left, a, mid), jnp.where(left, mid, b)

    lo, hi = jax.lax.fori_loop(0, _BISECTIONS, halve, (lo, hi))
    t = 0.5 * (lo + hi)
    value, slope = jax.jvp(lambda t: h(t, args), (t,), (jnp.ones_like(t),))
    slope = jax.lax.stop_gradient(slope)
    good = jnp.isfinite(slope) & (jnp.abs(slope) > 1e-300)
    return t - jnp.where(good, value / jnp.where(good, slope, 1.0), 0.0)


def _newton_root(h, args, start, steps=40):
    """A root of `h(t, args)` by Newton from `start` (arguments frozen), then one step
    with them live (the implicit derivative). Returns `(t, converged)`."""
    frozen = jax.lax.stop_gradient(args)

    def newton(_, t):
        value, slope = jax.jvp(lambda t: h(t, frozen), (t,), (jnp.ones_like(t),))
        good = jnp.isfinite(value) & jnp.isfinite(slope) & (jnp.abs(slope) > 1e-300)
        step = jnp.where(good, value / jnp.where(good, slope, 1.0), 0.0)
        return jnp.maximum(t - step, 0.5 * t)  # never through 0 (times are > 0)

    t = jax.lax.fori_loop(0, steps, newton, jax.lax.stop_gradient(start))
    value, slope = jax.jvp(lambda t: h(t, args), (t,), (jnp.ones_like(t),))
    slope = jax.lax.stop_gradient(slope)
    converged = jnp.isfinite(value) & (jnp.abs(value) < 1e-9)
    good = converged & jnp.isfinite(slope) & (jnp.abs(slope) > 1e-300)
    return t - jnp.where(good, value / jnp.where(good, slope, 1.0), 0.0), converged


def _rest_time(s, r, y0, v0, rest_tol):
    """The instant at which `|V| + |Y + 2 s V|` (speed plus net force, units of `v0` and
    `c x*`) of the oscillator from `(y0, v0)` falls to `rest_tol`, the integrated path's
    rest event: Newton on its logarithm, from the slow mode's estimate (far over-damped)
    or the envelope's `exp(-s t)` (near critical). Returns `(t, converged)`; meant for the
    over- and near-critically damped, where the motion creeps to rest."""
    far = r < -_NEAR
    q = jnp.sqrt(jnp.where(far, -r, 1.0))
    fast = -jnp.where(far, s, 1.0) - q
    slow = 1.0 / fast
    a1 = jnp.abs((v0 - fast * y0) / (slow - fast))
    size = jnp.maximum(a1 * (jnp.abs(slow) + jnp.abs(1.0 + 2.0 * s * slow)), 1e-300)
    start_far = jnp.log(rest_tol / size) / slow
    amplitude = jnp.maximum(jnp.abs(y0) + jnp.abs(v0), 1e-300)
    start_near = jnp.log(amplitude / rest_tol) / jnp.maximum(s, 1e-3)
    start = jnp.maximum(jnp.where(far, start_far, start_near), 1e-3)

    def excess(t, args):
        s, r, y0, v0 = args
        y, v = _state(s, r, y0, v0, t)
        return jnp.log(jnp.abs(v) + jnp.abs(y + 2.0 * s * v) + 1e-300) - jnp.log(rest_tol)

    return _newton_root(excess, (s, r, y0, v0), start)


def linear_impact(c, b, p_in, p_out, m, v0, g, separation, *, dry, rest_tol=1e-7):
    """Exact impact of `m x'' = -(c x + b v + P_phase) + m g`, `x(0) = 0`, `x'(0) = v0`.

    `P_phase = p_in` (N) while `v > 0`, `-p_out` after: Kelvin-Voigt (eq. 1) with
    `p_in = p_out = 0`, Bingham (eq. 7, `F = c x + b v + P sgn(v)`) with `p_in = p_out = P`,
    Bingham in compression (eq. 9) with `b = 0`, `p_in = P`, `p_out = 0`. `c` in N/m, `b` in
    N s/m, `m` in kg, `v0` in m/s, `g` (m/s^2) along the inward normal.

    In `tau = t/t*` (`t* = sqrt(m/c)`), `X = x/x*` (`x* = v0 t*`): compression is the unit
    oscillator (`s = b/(2 sqrt(m c))`) about `X1 = gamma - D_in` (`gamma = g t*/v0`,
    `D = P/(c x*)`), from `Y = D_in - gamma`, `V = 1`; maximum compression where
    `C = (D_in - gamma + s) S` (`_first_zero`). There the body is held (`stuck` when
    `dry`, else `captured`; `T = t_max`) unless `c x_max - p_out > m g`; then restitution is
    the oscillator about `X2 = gamma + D_out` from `Y = A = X_max - X2`, `V = 0`:
    `X = X2 + A exp(-s s') (C + s S)`, `F/(c x*) = gamma + A exp(-s s') (C - s S)`.
    The force (decreasing until `s' = 2 atan(sqrt(r)/s)/sqrt(r)`, its minimum) and `X`
    (decreasing until `V = 0` again at `s' = pi/sqrt(r)`) each reach 0 at most once on
    their bracket: the end of contact of `"force"` and `"penetration"`. A body that does
    not leave comes back to rest at `V = 0` (under-damped) or creeps to rest (the
    `rest_tol` instant, as `impact` defines it); either is `held` with `e = 0`.

    Returns a dict of `e, T, x_max, t_max, F_max, status` and `x_end` (m, where contact
    ended, for the work of gravity).
    """
    t_star = jnp.sqrt(m / c)
    x_star = v0 * t_star
    scale = c * x_star
    s = 0.5 * b * t_star / m
    r = (1.0 - s) * (1.0 + s)
    d_in, d_out = p_in / scale, p_out / scale
    gamma = g * t_star / v0
    held = Status.stuck if dry else Status.captured

    # compression: Y = X - (gamma - d_in), from (d_in - gamma, 1)
    y1 = d_in - gamma
    t_top, has_top = _first_zero(y1 + s, r)
    t_rest1, rest1 = _rest_time(s, r, y1, jnp.ones_like(y1), rest_tol)
    creep = ~has_top | (rest1 & (t_rest1 < t_top) & (r < 0.01))
    t_max = jnp.where(creep, t_rest1, t_top)
    y_top, _ = _state(s, r, y1, 1.0, t_max)
    x_max = y_top - y1
    # force in compression: gamma + Y + 2 s V = gamma + exp(-s t) (P C + Q S); its peak
    big_p, big_q = y1 + 2.0 * s, (1.0 - 2.0 * s**2) - s * y1
    rising = big_q - s * big_p > 0
    k_peak = (s * big_q + r * big_p) / jnp.where(rising, big_q - s * big_p, 1.0)
    t_peak, has_peak = _first_zero(k_peak, r)
    t_peak = jnp.where(rising & has_peak, jnp.minimum(t_peak, t_max), 0.0)

    def compression_force(t):
        y, v = _state(s, r, y1, 1.0, t)
        return gamma + y + 2.0 * s * v

    f_max = jnp.maximum(jnp.maximum(compression_force(0.0), compression_force(t_peak)),
                        compression_force(t_max))  # fmt: skip

    # restitution from (A, 0) about gamma + d_out
    x_eq = gamma + d_out
    amplitude = x_max - x_eq
    moves = ~creep & (amplitude > 0)
    a = jnp.where(moves, amplitude, 1.0)
    under = r > 0
    w = jnp.sqrt(jnp.where(under, r, 1.0))
    t_back = jnp.pi / w  # V back to 0 (under-damped only)
    args = (s, r, a, x_eq, gamma)
    if separation == "force":
        t_one, _ = _first_zero(s, r)
        hi = 2.0 * t_one  # the force's minimum

        def gap(t, args):
            s, r, a, x_eq, gamma = args
            y, v = _state(s, r, a, 0.0, t)
            return gamma + y + 2.0 * s * v

    else:
        hi = jnp.where(under, t_back, 1.0)

        def gap(t, args):
            s, r, a, x_eq, gamma = args
            y, _ = _state(s, r, a, 0.0, t)
            return x_eq + y

    leaves = gap(hi, args) < 0
    if separation == "penetration":
        leaves = leaves & under
    t_leave = _monotone_root(gap, args, jnp.zeros_like(hi), hi)
    t_rest2, rest2 = _rest_time(s, r, a, jnp.zeros_like(a), rest_tol)
    rest2 = rest2 & (~under | (t_rest2 < t_back))
    leaves = moves & leaves & ~(rest2 & (t_rest2 < t_leave))
    t_stop = jnp.where(rest2, t_rest2, t_back)
    t_out = jnp.where(leaves, t_leave, jnp.where(moves, t_stop, 0.0))
    y_end, v_end = _state(s, r, a, 0.0, t_out)
    x_end = jnp.where(moves, x_eq + y_end, x_max)
    status = jnp.where(leaves, Status.separated, held)
    return dict(
        e=jnp.where(leaves, -v_end, 0.0),
        T=(t_max + jnp.where(moves, t_out, 0.0)) * t_star,
        x_max=x_max * x_star,
        t_max=t_max * t_star,
        F_max=f_max * scale,
        status=status,
        x_end=x_end * x_star,
    )


def maxwell_impact(c, b, m, v0, separation, *, rest_tol=1e-7):
    """Exact impact of the Maxwell law (eqs. 10-11) without gravity, any damping, both
    separation criteria. `c` (N/m) spring in series with the dashpot `b` (N s/m).

    With `mu = sqrt(m c)/b`, `s = mu/2`, `t* = sqrt(m/c)`, `x* = v0 t*`, `Phi = F/(c x*)`:
    `Phi'' + mu Phi' + Phi = 0`, `Phi(0) = 0`, `Phi'(0) = 1`, so `Phi = exp(-s tau) S`,
    `V = Phi' + mu Phi = exp(-s tau)(C + s S)`, `X = Phi + mu (1 - V)`.
    Under-damped (`mu < 2`, `w = sqrt(1 - s^2)`): maximum compression at
    `w tau = atan2(w, -s)`, force peak at `w tau = atan2(w, s)`; the force returns to 0 at
    `tau = pi/w` (`e = exp(-s pi/w)`, the paper's formulas), `X` returns to 0 before `V`
    does again (at `tau_max + pi/w`) or not at all (captured). Near critical damping the
    body comes to rest first (`|V| + |Phi|` falls to `rest_tol`, `impact`'s rest event,
    monotone on a known bracket in each phase): captured. Over-damped (`mu >= 2`): it
    creeps in for ever (`maxwell_creep`), captured at its rest instant.
    Returns a dict of `e, T, x_max, t_max, F_max, status` and `x_end` (m).
    """
    t_star = jnp.sqrt(m / c)
    x_star = v0 * t_star
    mu = jnp.sqrt(m * c) / b
    s = 0.5 * mu
    under = mu < 2.0
    r = jnp.where(under, (1.0 - s) * (1.0 + s), 0.75)
    s_u = jnp.where(under, s, 0.5)  # a harmless under-damped value for the over-damped
    w = jnp.sqrt(r)
    log_tol = jnp.log(rest_tol)

    def phi_v(t, s):
        decay = jnp.exp(-s * t)
        sin_ = _sin_ratio((1.0 - s) * (1.0 + s), t)
        return decay * sin_, decay * (_cos_continued((1.0 - s) * (1.0 + s), t) + s * sin_)

    def position(t, s):
        phi, v = phi_v(t, s)
        return phi + 2.0 * s * (1.0 - v)

    def log_rest(t, s):  # log(|V| + |Phi|) - log(tol)
        phi, v = phi_v(t, s)
        return jnp.log(jnp.abs(v) + jnp.abs(phi) + 1e-300) - log_tol

    t_top = jnp.arctan2(w, -s_u) / w
    t_peak = jnp.arctan2(w, s_u) / w
    t_climb = jnp.arctan2(w, 1.0 + s_u) / w  # |V| + |Phi| decreases from here to t_top
    t_zero = jnp.pi / w  # the force back to 0
    t_back = t_top + t_zero  # V back to 0
    phi_top, _ = phi_v(t_top, s_u)
    rest_in = phi_top < rest_tol
    t_rest_in = _monotone_root(log_rest, s_u, t_climb, t_top)
    decay = jnp.exp(-s_u * t_zero)  # |V| + |Phi| where the force is back to 0
    rest_out = ~rest_in & (decay < rest_tol)
    t_rest_out = _monotone_root(log_rest, s_u, t_top, t_zero)
    if separation == "force":
        leaves = ~rest_in & ~rest_out
        t_leave = t_zero
    else:
        # X decreases from t_top to t_back; rest after the force's zero: |V| + |Phi|
        # decreases from t_climb + pi/w to t_back
        rest_late = ~rest_in & ~rest_out & (decay * phi_top < rest_tol)
        t_rest_late = _monotone_root(log_rest, s_u, t_climb + t_zero, t_back)
        t_rest_out = jnp.where(rest_out, t_rest_out, t_rest_late)
        rest_out = rest_out | rest_late
        t_leave = _monotone_root(position, s_u, t_top, t_back)
        leaves = ~rest_in & (position(t_back, s_u) < 0) & ~(rest_out & (t_rest_out < t_leave))
    t_end = jnp.where(
        leaves, t_leave, jnp.where(rest_in, t_rest_in, jnp.where(rest_out, t_rest_out, t_back))
    )
    phi_end, v_end = phi_v(t_end, s_u)
    t_max = jnp.where(rest_in, t_rest_in, t_top)
    force_peak, _ = phi_v(t_peak, s_u)
    # over-damped: the creep (harmless mu elsewhere)
    mu_over = jnp.where(under, 3.0, mu)
    tau_rest, x_rest, _, force_creep = maxwell_creep(mu_over, rest_tol)
    status = jnp.where(under & leaves, Status.separated, Status.captured)
    x_end = jnp.where(under, position(t_end, s_u), x_rest)
    return dict(
        e=jnp.where(under & leaves, -v_end, 0.0),
        T=jnp.where(under, t_end, tau_rest) * t_star,
        x_max=jnp.where(under, position(t_max, s_u), x_rest) * x_star,
        t_max=jnp.where(under, t_max, tau_rest) * t_star,
        F_max=jnp.where(under, force_peak, force_creep) * c * x_star,
        status=status,
        x_end=x_end * x_star,
    )
