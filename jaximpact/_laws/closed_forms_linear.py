"""Exact impacts of the linear laws with a constant force: Kelvin-Voigt with gravity,
Bingham (eq. 7), Bingham in compression only (eq. 9) and Maxwell (eqs. 10-11), with and
without gravity. The oscillator they share is `oscillator.py`.

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
surface, at rest when `|V| + |F - m g|/(c x*)` falls to `rest_tol`, or (Maxwell with
gravity, whose dashpot lets the body sink in at `m g/b` for ever) at the horizon `tau_max`.
"""

from typing import NamedTuple

import jax
import jax.numpy as jnp
from jaxtyping import Array

from .._status import Status
from .oscillator import (
    _NEAR,
    _arctan_ratio,
    _cos_continued,
    _first_zero,
    _monotone_root,
    _newton_root,
    _sin_ratio,
    _state,
)


def _creep_rates(mu):
    """`(s, q2, near, fast, slow)` of `maxwell_creep`'s modes: `s = mu/2`, `q2 = s^2 - 1`,
    `near` within 1e-2 of critical damping in `q` (the sinh form, no cancellation), and
    the rates `l2 = -s - q`, `l1 = 1/l2` (`l1 l2 = 1`, without the cancellation of
    `-s + q`)."""
    s = 0.5 * mu
    q2 = s**2 - 1.0
    near = q2 < 1e-4
    fast = -s - jnp.sqrt(jnp.where(near, 1.0, q2))
    return s, q2, near, fast, 1.0 / fast


def _creep_modes(mu, tau):
    """`(Phi, V)` at `tau` of `maxwell_creep`'s over-damped Maxwell contact (`mu >= 2`)."""
    s, q2, near, fast, slow = _creep_rates(mu)
    gap = slow - fast
    r_near = -jnp.where(near, q2, 0.0)
    e1, e2 = jnp.exp(slow * tau), jnp.exp(fast * tau)
    phi_far, v_far = (e1 - e2) / gap, (slow * e2 - fast * e1) / gap
    decay = jnp.exp(-s * tau)
    sin_r = _sin_ratio(r_near, tau)
    phi_near = decay * sin_r
    v_near = decay * (_cos_continued(r_near, tau) + s * sin_r)
    return jnp.where(near, phi_near, phi_far), jnp.where(near, v_near, v_far)


def maxwell_creep(mu, rest_tol):
    """Over-damped Maxwell without gravity (`mu = sqrt(m c)/b >= 2`), nondimensional.

    `V'' + mu V' + V = 0`, `V(0) = 1`, `V'(0) = 0` stays positive for all time when
    `mu >= 2`: the body never reaches maximum compression, it sinks in while the force
    relaxes (status captured). With the roots `l2 < l1 < 0` of `l^2 + mu l + 1` and
    `e_i = exp(l_i tau)`: `Phi = (e1 - e2)/(l1 - l2)`, `V = (l1 e2 - l2 e1)/(l1 - l2)`,
    `X = Phi + mu (1 - V)` (since `Phi = -V'`). Returns `(tau_rest, X(tau_rest), tau_peak,
    Phi(tau_peak))`: the instant `V + Phi` falls to `rest_tol` (what `impact` calls at rest;
    Newton on its logarithm, differentiated implicitly) and the force peak `Phi' = 0`.
    Call it with `mu >= 2` only (callers substitute a safe value elsewhere); near critical
    damping the modes are written `exp(-mu tau/2) sinh(q tau)/q` (series in `q`)."""
    s, q2, near, fast, slow = _creep_rates(mu)
    gap = slow - fast
    start = jnp.where(near, -jnp.log(rest_tol), jnp.log(rest_tol * gap / (1.0 - fast)) / slow)
    start = jnp.maximum(start, 1.0)

    def excess(tau, args):
        mu, rest_tol = args
        phi, v = _creep_modes(mu, tau)
        return jnp.log(phi + v) - jnp.log(rest_tol)

    tau_rest, _ = _newton_root(excess, (mu, rest_tol), start)
    tau_rest = jnp.where(jnp.isfinite(tau_rest), tau_rest, start)
    phi, v = _creep_modes(mu, tau_rest)
    # Phi' = 0 where tanh(q tau) = q/s
    tau_peak = _arctan_ratio(-q2 / s**2) / s
    return tau_rest, phi + mu * (1.0 - v), tau_peak, _creep_modes(mu, tau_peak)[0]


def _placeholder(value):
    """What a skipped root solve gives in its place (a `lax.cond` branch not taken): a
    value of the right shape, finite, and without a derivative."""
    return jax.lax.stop_gradient(value)


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


class LinearCoefficients(NamedTuple):
    """The linear law `F = c x + b v + P_phase`: stiffness `c` (N/m), damping `b` (N s/m),
    and the dry force `p_in` in compression, `p_out` in restitution (N)."""

    c: Array | float
    b: Array | float
    p_in: Array | float
    p_out: Array | float


def linear_impact(law: LinearCoefficients, m, v0, g, separation, *, dry, rest_tol=1e-7):
    """Exact impact of `m x'' = -(c x + b v + P_phase) + m g`, `x(0) = 0`, `x'(0) = v0`,
    for the coefficients `law` (`LinearCoefficients`: `c`, `b`, `p_in`, `p_out`).

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
    c, b, p_in, p_out = law
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
    # the rest instant matters without a top or near critical damping: computed (Newton)
    # only where some member needs it (a select under vmap)
    t_rest1, rest1 = jax.lax.cond(
        jnp.any(~has_top | (r < 0.01)),
        lambda: _rest_time(s, r, y1, jnp.ones_like(y1), rest_tol),
        lambda: (_placeholder(t_top + s + r + y1), jnp.zeros(jnp.shape(t_top + s + r + y1), bool)),
    )
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

    f_max = jnp.maximum(
        jnp.maximum(compression_force(0.0), compression_force(t_peak)), compression_force(t_max)
    )

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
    # no rest before V is back to 0 where |V| + |Y + 2 s V| >= |(Y, V)|/(1 + 2 s) >=
    # a exp(-2 s t)/(1 + 2 s) (the energy Y^2 + V^2 falls at most as exp(-4 s t)) stays
    # above rest_tol until t_back: the rest instant (Newton) only where some member needs it
    floor = a * jnp.exp(-2.0 * s * jnp.where(under, t_back, 0.0)) / (1.0 + 2.0 * s)
    t_rest2, rest2 = jax.lax.cond(
        jnp.any(moves & ~(under & (floor > 2.0 * rest_tol))),
        lambda: _rest_time(s, r, a, jnp.zeros_like(a), rest_tol),
        lambda: (_placeholder(t_back + s + a), jnp.zeros(jnp.shape(t_back + s + a), bool)),
    )
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


def _zero_after(s, r, y, yp):
    """The first `t > 0` at which the under-damped oscillator (`r > 0`) from `(y, yp)` at
    `t = 0` is zero: at most `pi/sqrt(r)`, which it is when `y = 0`."""
    zero = y == 0
    k = -(yp + s * y) / jnp.where(zero, 1.0, y)
    return _first_zero(jnp.where(zero, -1e300, k), r)[0]


def _maxwell_under(s, gamma, rest_tol, tau_max, separation):
    """Maxwell with gravity, under-damped (`s < 1`): the nondimensional contact (see
    `maxwell_gravity_impact`). Returns `(t_max, t_end, t_peak, leaves)` and the functions
    of time `state` (`X, V, Phi`). Its event instants are found side by side, in one root
    finder's loop per round (round 2's rest instants only where some member rests)."""
    s, gamma = jnp.broadcast_arrays(s, gamma)
    r = (1.0 - s) * (1.0 + s)
    half = jnp.pi / jnp.sqrt(r)  # between consecutive zeros of any solution
    args = (s, gamma)
    log_tol = jnp.log(rest_tol)

    def with_psi(s, gamma, t, psi, dpsi):
        phi = psi + gamma
        v = dpsi + 2.0 * s * phi
        return phi + 2.0 * s * (1.0 - v + gamma * t), v, phi, psi, dpsi

    def state(t, args):
        s, gamma = args
        return with_psi(s, gamma, t, *_state(s, (1.0 - s) * (1.0 + s), -gamma, 1.0, t))

    def lean_state(t, args):  # the same for r > 0 in a few operations (no derivatives)
        s, gamma = args
        w = jnp.sqrt((1.0 - s) * (1.0 + s))
        decay, cos_, sin_ = jnp.exp(-s * t), jnp.cos(w * t), jnp.sin(w * t) / w
        psi = decay * (-gamma * cos_ + (1.0 - s * gamma) * sin_)
        dpsi = decay * (cos_ - (s - gamma) * sin_)
        return with_psi(s, gamma, t, psi, dpsi)

    def log_rest(t):  # log(|V| + |Phi - gamma|) - log(rest_tol): at rest below 0
        _, v, _, psi, _ = state(t, args)
        return jnp.log(jnp.abs(v) + jnp.abs(psi) + 1e-300) - log_tol

    def roots(brackets):
        """The roots of `(kind, lo, hi)`: each kind (`X`, `V`, `-V`, `Phi` or the rest
        excess) has one sign change on its bracket, positive first."""
        kinds = [k for k, _, _ in brackets]

        def picks(state):
            def h(t, args):
                x, v, phi, psi, _ = state(t, args)
                rest = jnp.log(jnp.abs(v) + jnp.abs(psi) + 1e-300) - log_tol
                table = dict(x=x, v=v, minus_v=-v, force=phi, rest=rest)
                return jnp.stack([table[k][i] for i, k in enumerate(kinds)])

            return h

        lo = jnp.stack([lo for _, lo, _ in brackets])
        hi = jnp.stack([hi for _, _, hi in brackets])
        return list(_monotone_root(picks(state), args, lo, hi, fast=picks(lean_state)))

    def rest_bracket(lo, hi, sign_v, sign_psi):
        """Where the first rest instant on `[lo, hi]` (shorter than `pi/w`) lies, and
        whether there is one, given that `V` and `Psi` keep the signs given there and
        `|V| + |Psi| >= rest_tol` at `lo`: it is `sign_v V + sign_psi Psi`, whose slope
        `-sign_v Psi + sign_psi Psi'` solves the oscillator, zero at most once inside; it
        falls below `rest_tol` first on `[lo, argmin]` (`argmin` among `lo`, that zero and
        `hi`), where it is above `rest_tol`, then below (one sign change)."""
        _, _, _, psi, dpsi = state(lo, args)
        ddpsi = -psi - 2.0 * s * dpsi
        t_turn = lo + _zero_after(
            s, r, -sign_v * psi + sign_psi * dpsi, -sign_v * dpsi + sign_psi * ddpsi
        )
        inside = t_turn < hi
        at_turn, at_hi = log_rest(jnp.where(inside, t_turn, hi)), log_rest(hi)
        end = jnp.where(inside & (at_turn < at_hi), t_turn, hi)
        return end, jnp.minimum(jnp.where(inside, at_turn, at_hi), at_hi) < 0

    # Psi = Phi - gamma from (-gamma, 1): zero at t1 (V at its maximum), t2 = t1 + pi/w (V
    # at its minimum), t3; the force peak t_peak where Psi' = 0 (Psi' from (1, gamma - 2 s))
    # and its minimum t_min = t_peak + pi/w; t_peak < t1 + pi/w < t_min
    t1 = jnp.where(gamma > 0, _zero_after(s, r, -gamma, 1.0), 0.0)
    t2, t3 = t1 + half, t1 + 2.0 * half
    t_peak = _zero_after(s, r, 1.0, gamma - 2.0 * s)
    t_min = t_peak + half
    # round 1: maximum compression, V falling (V' = -Psi) from t1 to t2 (0 there or never);
    # V back to 0, rising from t2 to t3; the force back to 0 (Psi = -gamma < 0: after t2),
    # falling until t_min
    brackets = [("v", t1, t2), ("minus_v", t2, t3)]
    if separation == "force":
        brackets.append(("force", t2, jnp.maximum(t_min, t2)))
    t_top, t_back, *t_zero = roots(brackets)
    top = state(t2, args)[1] < 0
    # rest while compressing: on [t1, end] |V| + |Psi| = V + Psi >= 1 until its slope's
    # last zero, then falls: below rest_tol at the end or not at all; coming back: Psi > 0
    # on [t_top, t2], < 0 on [t2, t_back]
    end_in = jnp.where(top, t_top, t2)
    rest_in = log_rest(end_in) < 0
    end_a, rest_a = rest_bracket(t_top, t2, -1.0, 1.0)
    end_b, rest_b = rest_bracket(t2, t_back, -1.0, -1.0)
    # round 2: X back to 0 (falling from t_top to t_back); the rest instants, where some
    # member rests (a select under vmap)
    if separation == "penetration":
        (t_surface,) = roots([("x", t_top, t_back)])
    rests = [("rest", t1, end_in), ("rest", t_top, end_a), ("rest", t2, end_b)]
    t_rest_in, t_rest_a, t_rest_b = jax.lax.cond(
        jnp.any(rest_in | rest_a | rest_b),
        lambda: roots(rests),
        lambda: [_placeholder(hi) for _, _, hi in rests],
    )
    creeps = ~top & ~rest_in  # V stays above its value at t2 > 0: sinks in for ever
    t_max = jnp.where(rest_in, t_rest_in, jnp.where(creeps, tau_max, t_top))
    beyond = t_max >= tau_max
    t_max = jnp.minimum(t_max, tau_max)
    returns = top & ~rest_in & ~beyond
    if separation == "force":
        crosses = (state(t_min, args)[2] < 0) & (t_zero[0] < t_back)
        t_leave = t_zero[0]
    else:
        crosses = state(t_back, args)[0] < 0
        t_leave = t_surface
    rest_out = rest_a | rest_b
    t_rest_out = jnp.where(rest_a, t_rest_a, t_rest_b)
    leaves = returns & crosses & ~(rest_out & (t_rest_out < t_leave))
    t_held = jnp.where(rest_out, t_rest_out, t_back)
    t_end = jnp.where(returns, jnp.where(leaves, t_leave, t_held), t_max)
    late = t_end > tau_max
    return (
        t_max,
        jnp.minimum(t_end, tau_max),
        jnp.minimum(t_peak, t_max),
        leaves & ~late,
        lambda t: state(t, args)[:3],
    )


def _maxwell_over(s, gamma, rest_tol, tau_max, active):
    """Maxwell with gravity, critically or over-damped (`s >= 1`): the body never reaches
    maximum compression. It sinks in for ever (at the dashpot's speed `m g/b` in the end)
    unless that speed is below `rest_tol v0` (`2 s gamma < rest_tol`): then it comes to
    rest where `V + Psi` falls to `rest_tol`, after `Psi`'s one zero (before it `V >= 1`);
    `L = V + Psi - 2 s gamma` is a solution of the oscillator, which rises and then decays
    to 0: Newton on `log L`, from its slow mode's estimate (only where an `active` member
    rests). Returns `(t_end, t_peak)` and the functions of time `state` (`X, V, Phi`)."""
    r = (1.0 - s) * (1.0 + s)
    args = (s, gamma)
    margin = rest_tol - 2.0 * s * gamma
    rests = (margin > 0) & active
    margin = jnp.where(rests, margin, rest_tol)

    def state(t, args):
        s, gamma = args
        psi, dpsi = _state(s, (1.0 - s) * (1.0 + s), -gamma, 1.0, t)
        phi = psi + gamma
        v = dpsi + 2.0 * s * phi
        return phi + 2.0 * s * (1.0 - v + gamma * t), v, phi, psi, dpsi

    def excess(t, args):  # log(L) - log(margin)
        _, v, _, psi, _ = state(t, args)
        return jnp.log(jnp.abs(v + psi - 2.0 * args[0] * args[1]) + 1e-300) - jnp.log(margin)

    l0, dl0 = 1.0 - (2.0 * s + 1.0) * gamma, 1.0 + gamma
    far = r < -_NEAR
    q = jnp.sqrt(jnp.where(far, -r, 1.0))
    fast = -jnp.where(far, s, 2.0) - q
    slow = 1.0 / fast
    slow_part = jnp.maximum((dl0 - fast * l0) / (slow - fast), 1e-300)
    start = jnp.where(
        far,
        jnp.log(margin / slow_part) / slow,
        jnp.log((jnp.abs(l0) + jnp.abs(dl0)) / margin) / s,
    )
    start = jnp.maximum(start, 1.0)
    t_rest = jax.lax.cond(
        jnp.any(rests), lambda: _newton_root(excess, args, start)[0], lambda: _placeholder(start)
    )
    t_end = jnp.minimum(jnp.where(rests, t_rest, tau_max), tau_max)
    k_peak = s - gamma
    t_peak, has_peak = _first_zero(k_peak, r)
    t_peak = jnp.where(has_peak, jnp.minimum(t_peak, t_end), t_end)
    return t_end, t_peak, lambda t: state(t, args)[:3]


def maxwell_gravity_impact(c, b, m, v0, g, separation, *, rest_tol=1e-7, tau_max=1e4):
    """Exact impact of the Maxwell law (eqs. 10-11) with gravity `g >= 0` (m/s^2, along
    the inward normal), any damping, both separation criteria: `m x'' = -F + m g`,
    `dF/dt = c (v - F/b)`, `x(0) = 0`, `v(0) = v0`, `F(0) = 0`.

    In `tau = t/t*` (`t* = sqrt(m/c)`), `X = x/x*` (`x* = v0 t*`), `Phi = F/(c x*)`, with
    `mu = sqrt(m c)/b = 2 s` and `gamma = g t*/v0`: `X' = V`, `V' = gamma - Phi`,
    `Phi' = V - mu Phi`. The net push `Psi = Phi - gamma` is the unit oscillator
    `Psi'' + mu Psi' + Psi = 0` from `Psi(0) = -gamma`, `Psi'(0) = 1` (homogeneous part;
    `Phi = gamma` is the constant particular solution), and
    `V = Psi' + mu Phi`, `X = Phi + mu (1 - V) + mu gamma tau` (integrating `V`).
    `V - mu gamma` solves the oscillator too, with its extrema at the zeros of `Psi`: the
    body sinks at the dashpot's speed `mu gamma` (`m g/b`) in the end, and reaches maximum
    compression only if `V`'s first minimum (at `Psi`'s second zero) is below 0, never
    when `mu >= 2`. Then the phases and their ending events are those of the integrated
    path (`_solve/phases.py`), each the one root of a function with one sign change on a
    bracket set by zeros of the oscillator (`pi/w` apart, `w = sqrt(1 - s^2)`): `V = 0`
    (maximum compression, and `V` back to 0 inside the surface: captured), the force
    back to 0 (`"force"`, before its minimum at the force peak plus `pi/w`) or `X` back
    to 0 (`"penetration"`), and rest, `|V| + |Phi - gamma|` below `rest_tol` (captured).
    A body that never reaches maximum compression nor rest is captured at the horizon
    `tau_max` (units of `t*`), where the integration gives up; so is an event after it.
    At `g = 0` this is `maxwell_impact`'s impact (which `maxwell_closed_form` takes there).

    `c` (N/m), `b` (N s/m), `m` (kg), `v0` (m/s). Returns a dict of `e, T, x_max, t_max,
    F_max, status` and `x_end` (m, where contact ended).
    """
    t_star = jnp.sqrt(m / c)
    x_star = v0 * t_star
    s = 0.5 * jnp.sqrt(m * c) / b
    gamma = g * t_star / v0
    under = s < 1.0
    # each regime from harmless values where the other holds (no NaN in either branch)
    t_max, t_end, t_peak, leaves, state_u = _maxwell_under(
        jnp.where(under, s, 0.5), gamma, rest_tol, tau_max, separation
    )
    t_over, t_peak_over, state_o = _maxwell_over(
        jnp.where(under, 1.5, s), gamma, rest_tol, tau_max, ~under
    )

    def at(t_under, t_over):
        t = jnp.where(under, t_under, t_over)
        return t, [jnp.where(under, a, b) for a, b in zip(state_u(t), state_o(t), strict=True)]

    t_max, (x_max, _, f_top) = at(t_max, t_over)
    t_end, (x_end, v_end, _) = at(t_end, t_over)
    _, (_, _, f_peak) = at(t_peak, t_peak_over)
    leaves = under & leaves
    return dict(
        e=jnp.where(leaves, -v_end, 0.0),
        T=t_end * t_star,
        x_max=x_max * x_star,
        t_max=t_max * t_star,
        F_max=jnp.maximum(jnp.maximum(f_peak, f_top), 0.0) * c * x_star,
        status=jnp.where(leaves, Status.separated, Status.captured),
        x_end=x_end * x_star,
    )
