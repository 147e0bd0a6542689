"""Oblique impacts on the phase-angle grid: the normal contact and the tangential stick and
slip stepped together on the fixed grid of `grid_contact` (shared/notes/performance-4.md,
design (b); DESIGN.md, "Off the curves"), with no diffrax event search.

The normal force does not depend on the tangential state, so the contact's phase-plane
angle `theta = atan2(X, V)`, graded as `pi (1 - cos(pi s))/2`, is the independent
variable of the whole oblique contact: the state `(X, V, tau, Q, U_c, W)` (the normal
contact in its natural units, then `ObliqueDynamics`' tangential part) is stepped in `s`
by the 13-stage 8th-order tableau of `diffrax.Dopri8`, `d y/ds = theta_s f(y)/theta_dot`,
`f` the equations in the contact's time (`dynamics.py`), from first touch (`s = 0`) to the
end of contact (`s = 1` where it is `X = 0`).

A stick-slip transition inside a step is an event on the fixed grid: the step that
crosses the tangential condition (`ObliqueDynamics.switch`) is not taken; the crossing is
placed on the cubic Hermite interpolant of the condition's values and rates at the step's
two ends, the next step ends there (a shorter Runge-Kutta step, as exact as the others),
one Newton step along the vector field puts it on the condition's zero (`_land`'s rule),
the mode changes, and the grid resumes from there. A force criterion's end inside the
surface is placed the same way. Each such event costs two steps; a member has at most
`MAX_EVENTS` of them.

A member the grid cannot serve to the integrated path's tolerance is said to be so
(`served` False) and must be solved by `oblique_impact`'s event-terminated solve: the
normal contact's own conditions (`grid_contact`: heavy damping, a stalled angle, stuck),
a force that pulls inside the contact (the limit `mu |F_n|` has a kink there), more events
than the grid's budget, an event not placed to `LAND_TOL` of a step, two at one instant
(modes that take turns), and an error estimate (the tableau's embedded solution, summed
over the steps taken) above `GRID_ACCEPT` of the contact's normal scales or of its
tangential velocities.

Two rules see the transitions that the step ends do not, independently of the estimate
(which measures the steps' truncation, not a transition left out: it missed each case
below, or saw it by a hair). A pair of transitions inside one step (the condition dips
below zero and comes back between the step's ends) leaves both ends and their slopes
positive, so the interpolant finds nothing; the exact condition of the present mode
(`_Oblique.watched`: the sticking margin, the sliding excess, and the force criterion's
end) is evaluated at four stages of every step taken (`WATCH_GAP`: no two points more than
0.28 of a step apart, the widest gap that all ten nodes inside a step leave too), and a
value below `-DIP_TOL` declines the member
(a damped contact's last stick, in its last 0.03 % of the time: 2 switches instead of 3,
4.6e-8 off, estimate 5e-9). A chatter of transitions a step apart or closer, which the
grid places but cannot resolve (each one is a Newton step on a cubic whose error is of
the order of the step), declines it when two are closer than `MIN_GAP` of a grid step (a
linear spring, 6 switches instead of 2, e_t 3e-3 off, estimate 1.4e-10).
tests/oblique/test_oblique_grid.py checks both over angles from 2 to 70 degrees, mu from
0.05 to 0.5, both tangential laws, undamped and damped: every row whose switches are not
the oracle's is declined by these rules alone.
"""

import math

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp

from .._solve.grid import E_FLOOR, GRID_ACCEPT, GRID_RTOL, _combine, _Contact, _tableau
from .._status import Status
from .._tracing import anchors
from .dynamics import SLIP, STICK, ObliqueDynamics
from .impact import ObliqueInputs, ObliqueOptions, ObliqueOutcome, _first_touch, oblique_result

# grid steps over s in [0, 1] (even: maximum compression is a grid point): the tangential
# oscillation and the stick-slip splits ask for more than the normal contact's 24
OBLIQUE_STEPS = 32
# events (stick-slip transitions and a force criterion's end inside the surface) a member
# may have on the grid; each costs two steps of the loop
MAX_EVENTS = 6
# a condition below -DETECT at a step's end (or on its interpolant within the step) has
# crossed (units of the contact's force, m v_n^2 / x*): the conditions start at 0 after a
# transition, within roundoff
DETECT = 1e-13
# the Newton step that puts an event on its condition's zero may move it by this share of
# a grid step at most (its error is second order in the move: 1e-14 of the state)
LAND_TOL = 1e-6
# Newton steps (each a Runge-Kutta step from the start of the event's step) an event may
# take beyond the first before it is placed to `LAND_TOL` (measured on
# benchmarks/oblique_batch.py's 1,000 rows of `linear_history`: 2 left 59 rows to the
# integrated path, 41 of them for want of a third or fourth step; with 4, all 982 rows
# served are within 6.7e-10 of the scipy oracle, their switches its own)
MAX_LANDINGS = 4
# two events closer than this in s are one instant: modes that take turns (integrated)
SAME_INSTANT = 1e-9
# a step's stage below this (units of the contact's force) in the present mode's conditions
# (`_Oblique.watched`) is a transition the step-end interpolant missed: not served
# (roundoff leaves about 1e-16 on a condition that starts at 0 after a transition)
DIP_TOL = 1e-12
# two transitions closer than this share of a grid step are not resolved by it: not served
# (the chatters measured were 2e-8 of a step apart or placed out of order; pairs 0.37 of a
# step apart and more were right to 1e-11, 0.8 to 5e-9; a quarter of a step is about the
# widest spacing of the stages that `DIP_TOL` watches)
MIN_GAP = 0.25
# the stages at which `DIP_TOL` watches the present mode's conditions: the fewest of the
# tableau's nodes inside a step that leave no gap wider than this share of it (4 of the 10,
# at 0.1475, 0.375, 0.65 and 0.925; all 10 leave the same widest gap, 0.65 to 0.925).
# Measured against all 10: tests/oblique/test_oblique_grid.py's sweep still sees every
# miscounted row, and 18 of its 72 damped Mindlin rows that a dip at the other six stages
# declined are served, their switches the oracle's, within 8.4e-10 of it
# (benchmarks/oblique_grid_coverage.md); the grid's pass is no faster for it (a scratch
# same-process comparison over 1,000 undamped rows: within its run-to-run spread)
WATCH_GAP = 0.28
_SAMPLES = 16  # points of the interpolant searched for a crossing within a step
_BISECT = 8  # bisections of the interpolant within a sample's interval (polynomials only)
_POLISH = 3  # then Newton's iterations on it


class _Oblique:
    """One oblique contact in the normal contact's natural units, state
    `y = (X, V, tau, Q, U_c, W)`."""

    def __init__(self, contact: _Contact, spring, lever_loss, force_end: bool):
        self.contact, self.spring, self.loss = contact, spring, lever_loss
        self.force_end = force_end

    def lever(self, X):
        if self.loss is None:
            return 1.0
        return 1.0 - self.loss * jnp.maximum(X, 0.0)

    def slip(self, y):
        return y[4] - self.lever(y[0]) * y[5]

    def force(self, y, compressing):
        return self.contact.force(y[0], y[1], compressing)

    def tested(self, y):
        return self.spring.tested(y[3], y[0], self.slip(y))

    def rates(self, y, mode, sense, compressing):
        """`f(y)`: the state's rates in the contact's time, and the normal force."""
        X, V, Q = y[0], y[1], y[3]
        F = self.force(y, compressing)
        u = self.slip(y)
        stick = mode == STICK
        tangential = jnp.where(
            stick, self.spring.trial(Q, X, u), -sense * self.spring.mu * jnp.abs(F)
        )
        dq = jnp.where(stick, self.spring.stick_rate(Q, X, u, V), 0.0)
        spin = -self.spring.inv_inertia * self.lever(X) * tangential
        one = jnp.ones_like(X)
        return jnp.stack([V, -F, one, dq, tangential, spin]), F

    def rhs(self, s, y, mode, sense, compressing):
        """`dy/ds`, `theta_dot` and the normal force."""
        f, F = self.rates(y, mode, sense, compressing)
        X, V = y[0], y[1]
        theta_dot = (V * V + X * F) / (X * X + V * V)
        w = 0.5 * math.pi**2 * jnp.sin(math.pi * s) / theta_dot
        return f * w, theta_dot, F

    def step(self, s, y, h, mode, sense, compressing):
        """One Runge-Kutta step of length `h` from `(s, y)`: the state, the difference of
        the embedded solution, the least `theta_dot` and normal force at its stages, and
        the least value of the present mode's conditions (`watched`) at its stages inside
        the step (nodes below 1)."""
        a, b, b_err, c = _tableau()
        k, least, low = self.rhs(s, y, mode, sense, compressing)
        ks = [k]
        dip = jnp.full_like(least, jnp.inf)
        watch = _watched_stages(c)
        for stage, (row, node) in enumerate(zip(a, c, strict=True)):
            z = y + h * _combine(row, ks)
            k, theta_dot, F = self.rhs(s + node * h, z, mode, sense, compressing)
            ks.append(k)
            least = jnp.minimum(least, theta_dot)
            low = jnp.minimum(low, F)
            if stage in watch:
                dip = jnp.minimum(dip, self.watched(z, mode, sense, compressing))
        return y + h * _combine(b, ks), h * _combine(b_err, ks), least, low, dip

    def watched(self, y, mode, sense, compressing):
        """The least of the conditions that end the present mode at `y`: the switch
        condition and, in restitution under the force criterion, the end's."""
        value = self.switch(y, mode, sense, compressing)
        if self.force_end:
            value = jnp.where(compressing, value, jnp.minimum(value, self.edge(y)))
        return value

    def switch(self, y, mode, sense, compressing):
        """`ObliqueDynamics.switch`: positive while the present mode holds."""
        cap = self.spring.mu * jnp.abs(self.force(y, compressing))
        margin = cap - jnp.abs(self.tested(y))
        q = self.spring.held(sense, cap, y[0], self.slip(y))
        held = y.at[3].set(q)

        def excess(z):
            return -sense * self.tested(z) - self.spring.mu * jnp.abs(self.force(z, compressing))

        direction = self.rates(held, STICK, sense, compressing)[0]
        slide = jax.jvp(excess, (held,), (direction,))[1]
        return jnp.where(mode == STICK, margin, slide)

    def edge(self, y):
        """The force criterion's condition (restitution): positive while the force pushes."""
        return self.contact.edge(y[0], y[1])

    def conditions(self, s, y, mode, sense, compressing):
        """The switch and end conditions at `(s, y)` and their rates in `s`."""

        def both(z):
            end = self.edge(z) if self.force_end else jnp.ones_like(z[0])
            return jnp.stack([self.switch(z, mode, sense, compressing), end])

        direction = self.rhs(s, y, mode, sense, compressing)[0]
        return jax.jvp(both, (y,), (direction,))


def _watched_stages(nodes) -> frozenset:
    """The stages (indices into `nodes`, the tableau's `c` after the first stage) at which
    a step watches its conditions: from the step's start, each time the farthest node
    within `WATCH_GAP`, until the step's end is within it."""
    inside = sorted((node, i) for i, node in enumerate(nodes) if node < 1.0)
    chosen, last = set(), 0.0
    while 1.0 - last > WATCH_GAP:
        reach = [(node, i) for node, i in inside if last < node <= last + WATCH_GAP]
        if not reach:
            raise ValueError(f"the tableau leaves a gap wider than {WATCH_GAP} of a step")
        last, i = reach[-1]
        chosen.add(i)
    return frozenset(chosen)


def _hermite(g0, d0, g1, d1, h, sigma):
    """The cubic with values `g0`, `g1` and slopes `d0`, `d1` at 0 and `h`, at `sigma`."""
    t = sigma / h
    h00, h10 = (1 + 2 * t) * (1 - t) ** 2, t * (1 - t) ** 2
    h01, h11 = t * t * (3 - 2 * t), t * t * (t - 1)
    return h00 * g0 + h10 * h * d0 + h01 * g1 + h11 * h * d1


def _first_root(g0, d0, g1, d1, h):
    """Whether the interpolant of a condition falls below `-DETECT` within `(0, h]`, and
    where it first crosses 0 (bisection between the first such sample and the one
    before, then Newton's iteration on the cubic; polynomials only, unrolled)."""
    grid = h * jnp.arange(1, _SAMPLES + 1) / _SAMPLES
    values = _hermite(g0, d0, g1, d1, h, grid[:, None] if jnp.ndim(h) else grid)
    below = values < -DETECT
    crossed = jnp.any(below)
    j = jnp.argmax(below)
    hi = h * (j + 1) / _SAMPLES
    lo = h * j / _SAMPLES
    for _ in range(_BISECT):
        mid = 0.5 * (lo + hi)
        neg = _hermite(g0, d0, g1, d1, h, mid) < 0
        lo, hi = jnp.where(neg, lo, mid), jnp.where(neg, mid, hi)
    sigma = 0.5 * (lo + hi)
    for _ in range(_POLISH):
        value, slope = jax.jvp(
            lambda t: _hermite(g0, d0, g1, d1, h, t), (sigma,), (jnp.ones_like(sigma),)
        )
        nxt = sigma - value / jnp.where(slope == 0, 1.0, slope)
        sigma = jnp.where((nxt >= lo) & (nxt <= hi), nxt, sigma)
    return crossed, sigma


def grid_oblique(
    law,
    tangential,
    inputs: ObliqueInputs,
    options: ObliqueOptions,
    *,
    mode,
    sense,
    steps: int = OBLIQUE_STEPS,
) -> dict:
    """One oblique contact of `inputs` (SI units; no gravity: `inputs.g` is not read) on
    the grid, with `options`' separation and lever arm, from first touch in the tangential
    `mode` and `sense` (`impact._first_touch`'s). Returns the outgoing `e` (`v_n_out /
    v_n`), `V_t` and `W` (the centre's tangential velocity and `R omega` in units of
    `v_n`), `X` (the overlap at the end, units of `x*`), `tau` (the duration, units of
    `t*`), `t_star`, `x_star`, `switches`, `iterations` (steps of the loop), `served` and
    `estimate` (module docstring)."""
    if steps % 2:
        raise ValueError(f"the grid needs an even number of steps, got {steps}")
    m, R, v_n, v_t, omega, inertia, _ = inputs
    separation, lever_share = options.separation, options.lever_share
    contact = _Contact(law, m, v_n)
    spring = tangential.dynamics(m=m, R=R, inertia=inertia, x_star=contact.x_star, v_n=v_n)
    loss = lever_share * contact.x_star / R if lever_share else None
    # the force criterion's end is inside the surface only where the law's force can
    # vanish there (not the Hunt-Crossley family's: `PowerDynamics.gap`)
    at_surface = getattr(law.dynamics(m=m, v0=v_n, g=0.0), "gap", None) == "x"
    force_end = separation == "force" and not at_surface
    ob = _Oblique(contact, spring, loss, force_end)
    h = 1.0 / steps
    half = steps // 2
    # the carry starts as it leaves a step, batched and with a tangent (`_tracing`)
    anchor, no = anchors(contact, spring, inputs)
    zero = anchor + jnp.zeros_like(v_n)
    y0 = jnp.stack([zero, zero + 1.0, zero, zero, v_t / v_n, R * omega / v_n])
    big = zero + jnp.inf
    count = no.astype(jnp.int32)
    # carry: s, k (the grid step the member is in), y, mode, sense, pending event (0 none,
    # 1 switch, 2 end), where it lands, done, ok, events, switches, err, least theta_dot,
    # least force, y at s = 1/2, last event's s, iterations
    init = (
        zero,
        count,
        y0,
        jnp.asarray(mode, jnp.int32),
        jnp.asarray(sense, zero.dtype),
        count,
        zero,
        no,
        ~no,
        count,
        count,
        zero + jnp.zeros(6),
        big,
        big,
        y0,
        zero - 1.0,
        count,
        count,
        None,
        big,
        big,
    )
    mode0, sense0 = init[3], init[4]
    (sw_init, end_init), (dsw_init, dend_init) = ob.conditions(
        zero, y0, mode0, sense0, jnp.asarray(True)
    )
    init = (*init[:-3], (sw_init, dsw_init, end_init, dend_init, ~no), big, big)

    def body(carry):
        (
            s,
            k,
            y,
            md,
            sn,
            pending,
            s_land,
            done,
            ok,
            events,
            switches,
            err,
            least,
            low,
            y_mid,
            last,
            iters,
            tries,
            start,
            dip,
            gap,
        ) = carry
        sw0, dsw0, end0, dend0, known = start
        compressing = k < half
        s_grid = (k + 1) * h
        landing = pending > 0
        target = jnp.where(landing, s_land, s_grid)
        length = jnp.where(done, 0.0, target - s)
        y1, dy, least1, low1, dip1 = ob.step(s, y, length, md, sn, compressing)
        # a regular step: has a condition crossed within it?
        (sw1, end1), (dsw1, dend1) = ob.conditions(target, y1, md, sn, compressing)
        # the switch condition's slope at the start is not known after a transition: the
        # quadratic through its value there and its value and slope at the end
        safe = jnp.where(length == 0, 1.0, length)
        dsw0 = jnp.where(known, dsw0, dsw1 - 2.0 * (sw0 + dsw1 * length - sw1) / safe)
        hit_sw, at_sw = _first_root(sw0, dsw0, sw1, dsw1, length)
        if force_end:
            hit_end, at_end = _first_root(end0, dend0, end1, dend1, length)
            hit_end = hit_end & ~compressing
        else:
            hit_end, at_end = no, big
        at_end = jnp.where(hit_end, at_end, big)
        at_sw = jnp.where(hit_sw, at_sw, big)
        crossing = ~done & ~landing & (hit_sw | hit_end)
        kind = jnp.where(at_end <= at_sw, 2, 1).astype(jnp.int32)
        # a landing: one Newton step along the vector field onto the condition's zero
        f1 = ob.rhs(target, y1, md, sn, compressing)[0]
        g = jnp.where(pending == 2, end1, sw1)
        dg = jnp.where(pending == 2, dend1, dsw1)
        usable = dg != 0
        shift = jnp.where(usable, -g / jnp.where(usable, dg, 1.0), 0.0)
        y_at, s_at = y1 + shift * f1, target + shift
        close = usable & (jnp.abs(shift) <= LAND_TOL * h)
        # not close enough: the next step ends at the Newton step's point instead (from
        # the same start), at most `MAX_LANDINGS` times an event
        trying = ~done & landing
        retry = trying & ~close & (tries < MAX_LANDINGS)
        landed = trying & ~retry
        land_ok = close
        # the mode changes where a switch lands (sliding -> sticking with the spring held
        # at the limit; sticking -> sliding against the tested force)
        to_switch = landed & (pending == 1)
        cap = spring.mu * jnp.abs(ob.force(y_at, compressing))
        held = y_at.at[3].set(spring.held(sn, cap, y_at[0], ob.slip(y_at)))
        to_stick = to_switch & (md == SLIP)
        y_switched = jnp.where(to_stick, held, y_at)
        sense_next = jnp.where(to_switch & (md == STICK), -jnp.sign(ob.tested(y_at)), sn)
        mode_next = jnp.where(to_switch, 1 - md, md)
        ended = landed & (pending == 2)
        advance = ~done & ~landing & ~crossing
        k_next = jnp.where(advance, k + 1, k)
        y_next = jnp.where(advance, y1, jnp.where(landed, y_switched, y))
        s_next = jnp.where(advance, s_grid, jnp.where(landed, s_at, s))
        taken = advance | landed
        err = err + jnp.where(taken, jnp.abs(dy), 0.0)
        least = jnp.where(taken, jnp.minimum(least, least1), least)
        low = jnp.where(taken, jnp.minimum(low, low1), low)
        y_mid = jnp.where(advance & (k + 1 == half), y1, y_mid)
        instant = landed & (jnp.abs(s_at - last) <= SAME_INSTANT)
        dip = jnp.where(taken, jnp.minimum(dip, dip1), dip)
        gap = jnp.where(landed & (last >= 0), jnp.minimum(gap, s_at - last), gap)
        ok = ok & (~landed | (land_ok & ~instant))
        events = events + crossing.astype(jnp.int32)
        switches = switches + to_switch.astype(jnp.int32)
        last = jnp.where(landed, s_at, last)
        pending_next = jnp.where(crossing, kind, jnp.where(landed, 0, pending))
        s_land_next = jnp.where(crossing, s + jnp.where(kind == 2, at_end, at_sw), s_land)
        s_land_next = jnp.where(retry, jnp.clip(s_at, s, s_grid), s_land_next)
        pending_next = jnp.where(retry, pending, pending_next)
        # the conditions at the next step's start: the end's where it advanced; after a
        # transition, the new mode's switch condition is 0 with a zero slope where sliding
        # stopped (the spring held at the limit, which the sticking motion leaves at the
        # rate `slide_excess`, 0 there), or the rate at which the sticking margin fell
        # where sliding begins (its slope not known); the end's condition is neither
        # mode's
        fresh = jnp.where(md == STICK, -dsw1 / f1[2], 0.0)
        start = (
            jnp.where(advance, sw1, jnp.where(to_switch, fresh, sw0)),
            jnp.where(advance, dsw1, jnp.where(to_switch, 0.0, dsw0)),
            jnp.where(advance | landed, end1 + shift * dend1, end0),
            jnp.where(advance | landed, dend1, dend0),
            jnp.where(
                advance | (to_switch & (md == SLIP)), True, jnp.where(to_switch, False, known)
            ),
        )
        tries = jnp.where(retry, tries + 1, 0)
        done_next = done | ended | (advance & (k + 1 == steps)) | (events > MAX_EVENTS)
        return (
            s_next,
            k_next,
            y_next,
            mode_next,
            sense_next,
            pending_next.astype(jnp.int32),
            s_land_next,
            done_next,
            ok,
            events,
            switches,
            err,
            least,
            low,
            y_mid,
            last,
            iters + 1,
            tries,
            start,
            dip,
            gap,
        )

    limit = steps + (2 + MAX_LANDINGS) * MAX_EVENTS + 1

    def going(carry):  # under vmap: until every member is done
        return ~carry[7] & (carry[16] < limit)

    carry = jax.lax.while_loop(going, body, init)
    (
        s,
        k,
        y,
        _,
        _,
        _,
        _,
        done,
        ok,
        events,
        switches,
        err,
        least,
        low,
        y_mid,
        _,
        iters,
        _,
        _,
        dip,
        gap,
    ) = carry
    e = -y[1]
    tau = y[2]
    x_max = y_mid[0]
    scale_t = jnp.maximum(jnp.maximum(jnp.abs(y0[4]), jnp.abs(y0[5])), 1e-300)
    estimate = jnp.max(
        jnp.stack(
            [
                err[0] / x_max,
                err[1] / jnp.abs(e),
                err[2] / jnp.abs(tau),
                err[4] / scale_t,
                err[5] / scale_t,
            ]
        )
    )
    stuck = contact.force(x_max, zero, False) <= 0
    values = jnp.stack([e, tau, x_max, y[4], y[5], estimate])
    served = (
        done
        & ok
        & (events <= MAX_EVENTS)
        & jnp.all(jnp.isfinite(values))
        & (estimate <= GRID_ACCEPT)
        & (least > 0)
        & (low >= 0)
        & (e >= E_FLOOR)
        & (dip >= -DIP_TOL)
        & (gap >= MIN_GAP * h)
        & ~stuck
    )
    return dict(
        e=e,
        V_t=y[4],
        W=y[5],
        X=y[0],
        tau=tau,
        t_star=contact.t_star,
        x_star=contact.x_star,
        switches=switches,
        iterations=iters,
        served=served,
        estimate=estimate,
        dip=dip,
        gap=gap,
    )


def grid_applies(law, tangential, options: ObliqueOptions) -> bool:
    """Whether members of `law` and `tangential` with `options` may try the grid: a normal
    force that is a function of `(x, v)` (`has_state` False), a history that is not
    rescaled on unloading (its shrink `v/(2x)` is singular where the contact ends), the
    default solver and `rtol` not finer than `GRID_RTOL` (the grid meets 1e-9). Gravity is
    the caller's to rule out (the grid has none)."""
    return (
        not law.has_state
        and not tangential.spec.rescaled
        and isinstance(options.solver, dfx.Tsit5)
        and options.rtol >= GRID_RTOL
    )


@eqx.filter_jit
def solve_oblique_grid(law, tangential, m, R, v_n, v_t, omega, inertia, options: ObliqueOptions):
    """`solve_oblique` on the grid, without gravity: `(ObliqueResult, served)`; a member
    not served must be solved again by `solve_oblique` (its fields here are not
    results)."""
    return grid_outcome(law, tangential, m, R, v_n, v_t, omega, inertia, options)[:2]


def grid_outcome(
    law, tangential, m, R, v_n, v_t, omega, inertia, options: ObliqueOptions, *, steps=OBLIQUE_STEPS
):
    """`solve_oblique_grid`'s `(ObliqueResult, served)` and `grid_oblique`'s dict (what
    decided `served`: the tests and benchmarks/oblique_grid_coverage.py read it), on a
    grid of `steps` steps."""
    normal = law.dynamics(m=m, v0=v_n, g=0.0)
    spring = tangential.dynamics(m=m, R=R, inertia=inertia, x_star=normal.x_star, v_n=v_n)
    y_n0 = normal.y0()
    dyn = ObliqueDynamics(normal=normal, tangential=spring, size=int(y_n0.shape[0]))
    y0 = jnp.concatenate([y_n0, jnp.stack([jnp.zeros(()), v_t / v_n, R * omega / v_n])])
    # a first touch near Coulomb's limit (Maw et al.'s psi_1 near 1) is served too: a
    # window of 2x about it, declined while an event had 2 Newton steps to land
    # (`MAX_LANDINGS`), held 29 of benchmarks/oblique_batch.py's 1,000 `mindlin` rows
    # that the grid gives within 8e-11 of the scipy oracle with its switches, and 41 rows
    # within 0.1 % of the limit were within 4.3e-11
    mode, sense = _first_touch(dyn, y0, jnp.asarray(normal.split))
    inputs = ObliqueInputs(m, R, v_n, v_t, omega, inertia, 0.0)
    out = grid_oblique(law, tangential, inputs, options, mode=mode, sense=sense, steps=steps)
    outcome = ObliqueOutcome(
        v_n_out=out["e"] * v_n,
        v_t_out=out["V_t"] * v_n,
        omega_out=out["W"] * v_n / R,
        x_end=out["X"] * out["x_star"],
        T=out["tau"] * out["t_star"],
        status=jnp.full(jnp.shape(v_n), Status.separated, jnp.int32),
        switches=out["switches"],
        steps=out["iterations"],
    )
    result = oblique_result(inputs, outcome, path="grid")
    return result, out["served"], out
