"""One oblique impact of a sphere on a rigid plane (or of two spheres, through effective
values): `oblique_impact`, integrated with diffrax in segments of one tangential mode
(sticking or sliding), each ended by an event with a root finder, so that the
stick-slip transitions are placed to the solver's tolerance and differentiable."""

import dataclasses
import functools
import math
from typing import NamedTuple

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import ArrayLike

from .._checks import MemberChecks, is_traced
from .._compiling import solve_jit
from .._laws import AbstractLaw
from .._solve.adjoint import (
    auto_adjoint,
    differentiation_kinds,
    reverse_only,
    through_forward_jacobian,
)
from .._solve.impact import check_custom_law
from .._solve.options import CUSTOM_RTOL, DEFAULT_RTOL
from .._solve.phases import solve_broke
from .._solve.precision import resolvable_tolerances
from .._solve.roots import BracketedNewton
from .._status import Status
from .._tracing import anchors
from .dynamics import SLIP, STICK, ObliqueDynamics
from .results import _NOT_RESULTS, ObliqueResult
from .tangential import AbstractTangentialLaw

SEPARATIONS = ("force", "penetration")
# where the tangential force acts, as the share f of the overlap x taken off the lever arm
# R - f x: the undeformed surface (LAMMPS), halfway through the overlap (LIGGGHTS, MuJoCo,
# Drake, Yade between spheres), the plane's surface (Yade's wall)
CONTACT_POINTS = {"surface": 0.0, "midpoint": 0.5, "plane": 1.0}


def lever_share(contact_point) -> float:
    """The share `f` of the overlap off the lever arm `R - f x` for `contact_point` (a name
    of `CONTACT_POINTS` or a number in [0, 1]), or a one-line ValueError."""
    if isinstance(contact_point, str):
        if contact_point not in CONTACT_POINTS:
            names = ", ".join(map(repr, CONTACT_POINTS))
            raise ValueError(
                f"contact_point must be one of {names} or a number f in [0, 1] (the lever "
                f"arm R - f x), got {contact_point!r}"
            )
        return CONTACT_POINTS[contact_point]
    try:
        share = float(contact_point)
    except (TypeError, ValueError):
        share = math.nan
    if not 0.0 <= share <= 1.0:
        raise ValueError(
            "contact_point must be one of 'surface', 'midpoint', 'plane' or a number f in "
            f"[0, 1] (the lever arm R - f x), got {contact_point!r}"
        )
    return share


# the time (units of t*) after first touch at which the first-touch mode is decided
# (`_first_touch`): limit and trial force grow as powers of the time there
FIRST_TOUCH = 1e-6
# how far (in the contact's force units, m v_n^2 / x*, and their rates) a segment may end
# beyond its tangential condition before it counts as overtaken: the forces near the end
# of contact carry the solve's error (1e-12 measured), which must not count
OVERTAKEN = 1e-8
# two mode changes this close in time (units of t*) are one instant: a ping-pong (`_segment`)
PING_PONG = 1e-9


class ObliqueOptions(eqx.Module):
    """Everything static about an oblique solve (one compiled program per value); see
    `oblique_impact` for the meanings."""

    separation: str = eqx.field(static=True)
    solver: object = eqx.field(static=True)
    adjoint: object = eqx.field(static=True)
    rtol: float = eqx.field(static=True)
    atol: float = eqx.field(static=True)
    max_steps: int = eqx.field(static=True)
    max_segments: int = eqx.field(static=True)
    tau_max: float = eqx.field(static=True)
    rest_tol: float = eqx.field(static=True)
    land: bool = eqx.field(static=True, default=False)
    lever_share: float = eqx.field(static=True, default=0.0)


class ObliqueInputs(NamedTuple):
    """The sphere and its impact, the numbers of one oblique solve (SI units; arrays are
    traced, Python numbers static under `eqx.filter_jit`): see `oblique_impact`."""

    m: ArrayLike  # mass (kg)
    R: ArrayLike  # radius (m)
    v_n: ArrayLike  # normal speed, approaching > 0 (m/s)
    v_t: ArrayLike  # the centre's tangential speed (m/s)
    omega: ArrayLike  # spin (rad/s)
    inertia: ArrayLike  # I / (m R^2)
    g: ArrayLike  # gravity along the inward normal (m/s^2)


class ObliqueOutcome(NamedTuple):
    """What a solve (either path) ends with, in SI units, for `oblique_result`."""

    v_n_out: ArrayLike  # outgoing normal speed (m/s, leaving > 0)
    v_t_out: ArrayLike  # outgoing tangential speed of the centre (m/s)
    omega_out: ArrayLike  # outgoing spin (rad/s)
    x_end: ArrayLike  # overlap at the end of contact (m)
    T: ArrayLike  # contact duration (s)
    status: ArrayLike  # `Status` (int32)
    switches: ArrayLike  # stick-slip switches
    steps: ArrayLike  # steps taken (the solver's; the grid's loop iterations)


def _conditions(dyn: ObliqueDynamics, separation: str, rest_tol: float):
    """Real-valued event conditions, positive before their event, in order of precedence
    (where two cross in one step diffrax takes the first in order, not the earlier in
    time: `_segments` redoes a segment whose tangential limit was crossed before the
    contact's end within its last step, with the normal conditions muted, the last item
    of the solve's `args`): the end of contact (maximum compression while compressing,
    for a law split there), the body moving back in, the body at rest, the surface (a
    user's law), the end of the tangential mode."""
    normal, size = dyn.normal, dyn.size

    def end(t, y, args, **kwargs):
        _, _, compressing, mute, _ = args
        y_n = y[:size]
        if separation == "force":
            gap = normal.force_gap(y_n, compressing)
        else:
            gap = normal.penetration_gap(y_n)
        return jnp.where(mute, 1.0, jnp.where(compressing, normal.velocity(y_n), gap))

    def back_in(t, y, args, **kwargs):
        _, _, compressing, mute, _ = args
        return jnp.where(compressing | mute, 1.0, -normal.velocity(y[:size]))

    def at_rest(t, y, args, **kwargs):
        _, _, compressing, mute, _ = args
        y_n = y[:size]
        net = normal.force(y_n, compressing) - normal.gamma
        return jnp.where(mute, 1.0, jnp.abs(normal.velocity(y_n)) + jnp.abs(net) - rest_tol)

    def mode_ends(t, y, args, **kwargs):
        mode, sense, compressing, _, pinned = args
        return jnp.where(pinned, 1.0, dyn.switch(y, mode, sense, compressing))

    conditions = [end, back_in, at_rest]
    if separation == "force" and normal.surface_gap(normal.y0()) is not None:

        def surface(t, y, args, **kwargs):
            _, _, compressing, mute, _ = args
            return jnp.where(compressing | mute, 1.0, normal.surface_gap(y[:size]))

        conditions.append(surface)
    conditions.append(mode_ends)
    return tuple(conditions)


def _land(setup: "_Setup", masks, tau, y, tau_event, args):
    """The state and time at the segment's event (units of `x*`, `v_n`, `t*`), from the
    segment's start `(tau, y)` and the event time `tau_event` diffrax found, with
    derivatives that use the vector field, not the interpolant's slope.

    diffrax returns the state at an event from its dense interpolant, whose derivative in
    time is less accurate than the solution (measured: 3.5e-5 against 1e-10): where the
    event time depends on a parameter, that error enters every derivative through
    `y'(t_event) dt_event/dtheta`, and a stick-slip transition whose effects cancel
    (the force is continuous there) showed it as a gradient 1e-4 off. Here the segment is
    integrated again to the event time found (a solve that ends on it, no interpolation),
    and one Newton step on the fired condition `g` places it, `dt = -g / (grad g . f)`:
    its value moves by the root finder's 1e-13 at most, its derivatives are the implicit
    function theorem's with the exact vector field."""
    dyn, options, conditions = setup.dyn, setup.options, setup.conditions
    t_star = jax.lax.stop_gradient(tau_event)
    solved = dfx.diffeqsolve(
        setup.term,
        options.solver,
        tau,
        t_star,
        None,
        y,
        args=args,
        stepsize_controller=setup.controller,
        saveat=dfx.SaveAt(t1=True),
        adjoint=options.adjoint,
        max_steps=options.max_steps,
        throw=False,
    )
    y_star = solved.ys[-1]

    def fired_condition(z):
        values = [
            jnp.where(mask, cond(t_star, z, args), 0.0)
            for mask, cond in zip(masks, conditions, strict=True)
        ]
        return sum(values[1:], values[0])

    rate = dyn.rhs(y_star, *args[:3])
    value, slope = jax.jvp(fired_condition, (y_star,), (rate,))
    slope = jax.lax.stop_gradient(slope)
    usable = jnp.any(jnp.stack(list(masks))) & (slope != 0)
    shift = jnp.where(usable, -value / jnp.where(usable, slope, 1.0), 0.0)
    return y_star + rate * shift, t_star + shift


def _first_touch(dyn: ObliqueDynamics, y0, compressing):
    """The tangential mode at first touch and its sense.

    Limit and trial force both start from their values at first touch (0 for Hertz) and
    grow as powers of the time, which decide: the contact is integrated sticking over a
    short time `FIRST_TOUCH t*` (a small solve of its own, no derivatives), and it sticks
    where the limit still holds the trial force there, slides otherwise. Hertz with a
    constant spring (`t^1.5` against `t`) slides; with a normal damping that grows as
    `x^0.25` (Tsuji) it sticks; Hertz-Mindlin (both `t^1.5`) sticks where Maw et al.'s
    `psi_1 < 1` (force history) or `8 G* R^0.5 u < mu c v_n` (displacement history). A
    contact that does not slip (`u = 0`) sticks."""
    frozen = jax.lax.stop_gradient((dyn, y0))
    dyn_, y0_ = frozen
    stuck = dfx.diffeqsolve(
        dfx.ODETerm(lambda t, y, args: dyn_.rhs(y, STICK, 1.0, compressing)),
        dfx.Tsit5(),
        0.0,
        FIRST_TOUCH,
        None,
        y0_,
        stepsize_controller=dfx.PIDController(rtol=1e-8, atol=1e-14),
        saveat=dfx.SaveAt(t1=True),
        max_steps=512,
        throw=False,
    ).ys[-1]
    trial = dyn_.tested(stuck)
    u0 = dyn_.slip(y0_)
    holds = dyn_.cap(stuck, compressing) >= jnp.abs(trial)
    sense = jnp.where(trial != 0, -jnp.sign(trial), jnp.sign(u0))
    slides = (u0 != 0) & ~holds
    return jnp.where(slides, SLIP, STICK).astype(jnp.int32), sense


class _Setup(NamedTuple):
    """What every segment of one oblique solve shares (`_segments`)."""

    dyn: ObliqueDynamics
    options: ObliqueOptions
    conditions: tuple
    event: dfx.Event
    term: dfx.ODETerm
    controller: dfx.PIDController
    held_status: int
    has_surface: bool
    tau_max: jax.Array


def _segment(setup: _Setup, carry, _):
    """One segment of `_segments`' scan: solve in the current tangential mode until an
    event, then decide the status and the next mode (the carry of `_segments`)."""
    dyn, options, event = setup.dyn, setup.options, setup.event
    term, controller, has_surface = setup.term, setup.controller, setup.has_surface
    normal, size = dyn.normal, dyn.size
    y, tau, mode, sense, compressing, mute, t_stop, alive, status, switches, steps, pin = carry
    pinned, last_change = pin
    args = (mode, sense, compressing, mute, pinned)
    t1 = jnp.where(alive, t_stop, tau)
    sol = dfx.diffeqsolve(
        term,
        options.solver,
        tau,
        t1,
        None,
        y,
        args=args,
        stepsize_controller=controller,
        event=event,
        saveat=dfx.SaveAt(t1=True),
        adjoint=options.adjoint,
        max_steps=options.max_steps,
        throw=False,
    )
    y1, tau1 = sol.ys[-1], sol.ts[-1]
    masks = sol.event_mask
    if options.land:
        y1, tau1 = _land(setup, masks, tau, y, tau1, args)
    ended = (masks[0] & ~compressing) | (masks[3] if has_surface else False)
    at_max = masks[0] & compressing
    switched = masks[-1]
    fired = jnp.any(jnp.stack(list(masks)))
    out_of_steps = sol.result == dfx.RESULTS.max_steps_reached
    broke = solve_broke(sol.result)
    # the tangential limit crossed before the segment's end: within its last step,
    # before a normal event that diffrax, taking conditions in order, put first (the
    # segment is solved again from its start to that event's time, the normal
    # conditions muted: its last step then ends where the limit's condition is < 0,
    # and its own event is found; near the end of contact the limit |F_n| dips to 0
    # and rises again past it, so a solve beyond that time would step over the
    # crossing), or within its first step, which began with the limit's condition at 0
    # (the mode changes at once, where the segment began)
    # (judged with the normal force's sign at the segment's start: |F_n| has a kink
    # where the contact ends, and the sliding condition, a rate, jumps there)
    # (or with its sign at the segment's end where it is clearly away from zero there: under
    # the penetration criterion the force turns to pulling before the overlap closes, and
    # the segment's event conditions followed |F_n| through that)
    sign = jnp.where(normal.force(y[:size], compressing) < 0, -1.0, 1.0)
    force_end = normal.force(y1[:size], compressing)
    sign = jnp.where(jnp.abs(force_end) > OVERTAKEN, jnp.sign(force_end), sign)
    overtaken = (
        alive
        & ~switched
        & ~broke
        & ~pinned
        & (dyn.switch(y1, mode, sense, compressing, sign) < -OVERTAKEN)
        & jnp.all(jnp.isfinite(y1))
    )
    # armed: the condition began at or above 0 within roundoff (a spring just held at the
    # limit starts at -1e-16, then rises: its later crossing is found by a redo; one that
    # truly falls at once is found by the redo's finding none, below)
    armed = dyn.switch(y, mode, sense, compressing) > -OVERTAKEN
    redo = overtaken & armed & ~mute
    at_once = overtaken & ~redo
    # a sticking segment that still ended beyond Coulomb's limit: a failure, never a
    # silent force beyond mu |F_n|
    beyond = (mode == STICK) & (
        jnp.abs(dyn.tested(y1)) > (1.0 + 1e-6) * dyn.cap(y1, compressing) + OVERTAKEN
    )
    failed = ~overtaken & ~out_of_steps & (broke | ~jnp.all(jnp.isfinite(y1)) | beyond)
    y1_n = y1[:size]
    leaving = normal.velocity(y1_n) < 0
    stuck = at_max & (normal.force(y1_n, False) - normal.gamma <= 0)
    # a redo that found no crossing before its stop: nothing to trust
    failed = failed | (mute & ~switched & ~overtaken & alive)
    horizon = ~fired & ~out_of_steps & ~failed
    captured = (ended & ~leaving) | masks[1] | horizon
    status_now = jnp.where(
        out_of_steps,
        Status.out_of_steps,
        jnp.where(
            failed,
            Status.failed,
            jnp.where(
                ended & leaving,
                Status.separated,
                jnp.where(
                    stuck | masks[2], setup.held_status, jnp.where(captured, Status.captured, -1)
                ),
            ),
        ),
    )
    done = (status_now >= 0) & ~overtaken
    # the tangential mode changes: sticking -> sliding against the trial force;
    # sliding -> sticking with the spring at the limit it was held at
    change = alive & ~done & ((switched & ~redo) | at_once)
    y_at = jnp.where(at_once, y, y1)
    tau_at = jnp.where(at_once, tau, tau1)
    # a change at the instant of the previous one: neither mode holds there (the limit
    # mu |F_n| falling to 0 near the contact's end, the spring at it, the sliding speed
    # 0), and the modes would take turns for ever. The contact slides on at the limit
    # (the force of a spring held there) with its tangential condition muted until the
    # next normal event: `pinned`.
    pinning = change & (jnp.abs(tau_at - last_change) <= PING_PONG)
    to_slip = change & (mode == STICK)
    to_stick = change & (mode == SLIP) & ~pinning
    y_next = jnp.where(to_stick, dyn.held(y_at, sense, compressing), y_at)
    y_next = jnp.where(redo, y, y_next)
    sense_next = jnp.where(to_slip, -jnp.sign(dyn.tested(y_at)), sense)
    mode_next = jnp.where(pinning, SLIP, jnp.where(change, 1 - mode, mode))
    carry = (
        jnp.where(alive, y_next, y),
        jnp.where(alive & ~redo, tau_at, tau),
        mode_next,
        sense_next,
        compressing & ~(alive & at_max & ~overtaken),
        alive & redo,
        jnp.where(alive & redo, jax.lax.stop_gradient(tau1), setup.tau_max),
        alive & ~done,
        jnp.where(alive & done, status_now, status).astype(jnp.int32),
        switches + change.astype(jnp.int32),
        steps + jnp.where(alive, sol.stats["num_steps"], 0),
        (alive & pinning, jnp.where(change, tau_at, last_change)),
    )
    return carry, None


def _segments(dyn: ObliqueDynamics, y0, options: ObliqueOptions):
    """Integrate the contact segment by segment (a `lax.scan` of `max_segments` solves,
    those after the end skipped); return the final state, time, status, switch and step
    counts (nondimensional)."""
    normal = dyn.normal
    conditions = _conditions(dyn, options.separation, options.rest_tol)
    event = dfx.Event(
        conditions,
        root_finder=BracketedNewton(rtol=1e-13, atol=1e-13),
        direction=(False,) * len(conditions),
    )
    term = dfx.ODETerm(lambda t, y, args: dyn.rhs(y, *args[:3]))
    controller = dfx.PIDController(rtol=options.rtol, atol=options.atol)
    tau_max = jnp.asarray(options.tau_max, dtype=float)
    setup = _Setup(
        dyn=dyn,
        options=options,
        conditions=conditions,
        event=event,
        term=term,
        controller=controller,
        held_status=Status.stuck if normal.has_dry else Status.captured,
        has_surface=len(conditions) == 5,
        tau_max=tau_max,
    )

    compressing = jnp.asarray(normal.split)
    mode, sense = _first_touch(dyn, y0, compressing)
    # the first FIRST_TOUCH t* in the chosen mode, where the mode's condition starts at 0
    # (both forces vanish at first touch): from there it is strictly positive, and a
    # change of mode within the first step of the solve cannot go unseen (a condition
    # must be > 0 before its event)
    y_in = dfx.diffeqsolve(
        term,
        options.solver,
        0.0,
        FIRST_TOUCH,
        None,
        y0,
        args=(mode, sense, compressing, jnp.asarray(False), jnp.asarray(False)),
        stepsize_controller=dfx.PIDController(rtol=options.rtol, atol=1e-14),
        saveat=dfx.SaveAt(t1=True),
        adjoint=options.adjoint,
        max_steps=512,
        throw=False,
    ).ys[-1]
    # every entry of the carry starts as it leaves a segment (`_tracing`)
    float_anchor, no = anchors(dyn, y_in)
    zero = no.astype(jnp.int32)
    tau0 = FIRST_TOUCH + float_anchor
    carry = (
        y_in,
        tau0,
        mode | zero,
        sense + float_anchor,
        compressing | no,
        no,
        tau_max + float_anchor,
        ~no,
        zero - 1,
        zero,
        zero,
        (no, float_anchor - 1.0),
    )
    carry, _ = jax.lax.scan(
        functools.partial(_segment, setup), carry, None, length=options.max_segments
    )
    y, tau, _, _, _, _, _, alive, status, switches, steps, _ = carry
    # still going after max_segments solves: counted as out of steps
    status = jnp.where(alive, Status.out_of_steps, status).astype(jnp.int32)
    return y, tau, status, switches, steps


def _safe_ratio(a, b):
    """`a / b`, NaN where `b == 0` (no meaning there), without a NaN gradient elsewhere."""
    nonzero = b != 0
    return jnp.where(nonzero, a / jnp.where(nonzero, b, 1.0), jnp.nan)


def _safe_angle(t, n):
    """`arctan2(t, n)`, 0 where both vanish (a finite gradient)."""
    zero = (t == 0) & (n == 0)
    return jnp.where(zero, 0.0, jnp.arctan2(jnp.where(zero, 1.0, t), jnp.where(zero, 1.0, n)))


@solve_jit
def solve_oblique(law, tangential, inputs: ObliqueInputs, options: ObliqueOptions):
    """The compiled part of `oblique_impact` (no input checks): the `ObliqueResult` of
    `inputs` (SI units)."""
    m, R, v_n, v_t, omega, inertia, g = inputs
    normal = law.dynamics(m=m, v0=v_n, g=g)
    spring = tangential.dynamics(m=m, R=R, inertia=inertia, x_star=normal.x_star, v_n=v_n)
    y_n0 = normal.y0()
    loss = options.lever_share * normal.x_star / R if options.lever_share else None
    dyn = ObliqueDynamics(
        normal=normal, tangential=spring, size=int(y_n0.shape[0]), lever_loss=loss
    )
    y0 = jnp.concatenate([y_n0, jnp.stack([jnp.zeros(()), v_t / v_n, R * omega / v_n])])
    y, tau, status, switches, steps = _segments(dyn, y0, options)
    y_n = y[: dyn.size]
    separated = status == Status.separated
    v_n_out = jnp.where(separated, -normal.velocity(y_n) * v_n, 0.0)
    x_end = normal.position(y_n) * normal.x_star
    outcome = ObliqueOutcome(
        v_n_out=v_n_out,
        v_t_out=y[dyn.size + 1] * v_n,
        omega_out=y[dyn.size + 2] * v_n / R,
        x_end=x_end,
        T=tau * normal.t_star,
        status=status,
        switches=switches,
        steps=steps,
    )
    return oblique_result(inputs, outcome)


def oblique_result(
    inputs: ObliqueInputs, outcome: ObliqueOutcome, *, path="integrated"
) -> ObliqueResult:
    """The `ObliqueResult` of a solve's `outcome` from `inputs` (SI units; every path's):
    the fields that follow from the outgoing velocities, NaN where the solve failed."""
    m, R, v_n, v_t, omega, inertia, g = inputs
    v_n_out, v_t_out, omega_out, x_end, T, status, switches, steps = outcome
    u_in = v_t - R * omega
    u_out = v_t_out - R * omega_out
    moment = inertia * m * R**2
    energy_in = 0.5 * m * (v_n**2 + v_t**2) + 0.5 * moment * omega**2
    energy_out = 0.5 * m * (v_n_out**2 + v_t_out**2) + 0.5 * moment * omega_out**2
    fields = dict(
        e=v_n_out / v_n,
        e_t=_safe_ratio(v_t_out, v_t),
        e_t_contact=_safe_ratio(u_out, u_in),
        v_n_out=v_n_out,
        v_t_out=v_t_out,
        omega_out=omega_out,
        u_out=u_out,
        angle_in=_safe_angle(v_t, v_n),
        angle_out=_safe_angle(v_t_out, v_n_out),
        angle_in_contact=_safe_angle(u_in, v_n),
        angle_out_contact=_safe_angle(u_out, v_n_out),
        T=T,
        impulse_n=m * (v_n_out + v_n),
        impulse_t=m * (v_t_out - v_t),
        dissipated=energy_in - energy_out + m * g * x_end,
        status=status,
        num_switches=switches,
        num_steps=steps,
    )
    failure = (status == Status.out_of_steps) | (status == Status.failed)
    for key, value in fields.items():
        if key not in _NOT_RESULTS:
            fields[key] = jnp.where(failure, jnp.nan, value)
    return ObliqueResult(**fields, path=path)


def _differentiated(*trees) -> bool:
    """Whether any input is traced for differentiation (forward or reverse mode)."""
    return bool(differentiation_kinds(*trees))


def checked_settings(law, tangential, separation: str, rtol):
    """The laws and `separation` checked, and `rtol` (its default where None: the table's
    laws', or a user's law's) checked to lie in (0, 1): `oblique_impact`'s and
    `oblique_impact_batch`'s one-line refusals."""
    _check_laws(law, tangential)
    if separation not in SEPARATIONS:
        raise ValueError(f"separation must be one of {SEPARATIONS}, got {separation!r}")
    if rtol is None:
        rtol = DEFAULT_RTOL if law.spec is not None else CUSTOM_RTOL
    if not (isinstance(rtol, (int, float)) and 0 < rtol < 1):
        raise ValueError(f"rtol must be a number in (0, 1), got {rtol!r}")
    return rtol


def checked_inputs(checks: MemberChecks, m, R, v_n, v_t, omega, inertia, g) -> ObliqueInputs:
    """The sphere's and the impact's inputs (SI units) checked by `checks`, as
    `solve_oblique` takes them: `m`, `R`, `v_n`, `inertia` > 0, `g` >= 0, all finite."""
    return ObliqueInputs(
        checks.positive("mass m", m, "kg"),
        checks.positive("radius R", R, "m"),
        checks.positive("normal speed v_n (approaching)", v_n, "m/s"),
        checks.values(v_t, _never, _not_finite("tangential speed v_t", v_t, "m/s"), 0.0),
        checks.values(omega, _never, _not_finite("spin omega", omega, "rad/s"), 0.0),
        checks.positive("inertia factor (I / (m R^2))", inertia, harmless=0.4),
        checks.nonnegative("gravity g", g, "m/s^2"),
    )


def _never(a):
    return a != a  # only NaN and inf (`check_values` refuses them) are bad


def _not_finite(name, value, unit):
    return f"{name} must be a finite number ({unit}), got {value}"


def _check_laws(law, tangential):
    if isinstance(law, AbstractTangentialLaw):
        raise ValueError(
            f"oblique_impact takes the normal law first: oblique_impact(jaximpact.law(...), "
            f"tangential_law(...), ...); got the tangential law {law.name!r} in its place"
        )
    if not isinstance(law, AbstractLaw):
        raise TypeError(
            "oblique_impact needs a normal law from jaximpact.law(...) or "
            f"jaximpact.custom_law(...) first, got {type(law).__name__}"
        )
    if tangential is None or isinstance(tangential, AbstractLaw):
        what = "nothing" if tangential is None else f"the normal law {tangential.name!r}"
        raise ValueError(
            "oblique_impact needs a tangential law second (tangential_law('linear_history', "
            f"kt=..., mu=...) or tangential_law('mindlin', G=..., nu=..., mu=...)), got {what}"
        )
    if not isinstance(tangential, AbstractTangentialLaw):
        raise TypeError(
            "the tangential law must come from tangential_law(...), got "
            f"{type(tangential).__name__}"
        )


def oblique_impact(
    law: AbstractLaw,
    tangential: AbstractTangentialLaw,
    *,
    m,
    R,
    v_n,
    v_t,
    omega=0.0,
    inertia=0.4,
    g=0.0,
    separation: str = "force",
    contact_point="surface",
    solver=None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int = 4096,
    max_segments: int = 16,
    tau_max: float = 1e4,
    rest_tol: float = 1e-7,
    adjoint=None,
    land_events: bool | None = None,
    throw: bool | None = None,
) -> ObliqueResult:
    """One oblique impact of a sphere (mass `m` in kg, radius `R` in m, moment of inertia
    `inertia m R^2`: 0.4 a solid sphere, 2/3 a thin shell) on a rigid plane.

    The sphere arrives with normal speed `v_n > 0` (m/s, approaching), tangential speed
    `v_t` of its centre (m/s) and spin `omega` (rad/s), signed so that its contact point
    slips at `u = v_t - R omega` (rolling without slip: `omega = v_t / R`). The normal
    contact is `law`'s (any law of the table, or a user's law), integrated in its own
    units exactly as `impact` integrates it (`m x'' = -F_n + m g`); the tangential force
    `F_t` of `tangential` acts at the contact point,

        m v_t' = F_t,    I omega' = -R F_t,    |F_t| <= mu |F_n|,

    sticking (the spring loaded by the slip `u`) or sliding (`F_t = -s mu |F_n|`, `s` the
    sense of sliding) in segments, each ended by an event with a root finder where the
    spring reaches the limit or the sliding stops (so `e_t` is exact to the tolerance and
    differentiable across the transitions). At first touch the mode follows the limit of
    the forces' ratio (`_first_touch`; Maw et al.'s `psi_1 < 1` for Mindlin's force
    history). A contact that slides throughout gives the rigid-body impulse result exactly
    where `F_n >= 0` throughout: `v_t_out = v_t - s mu (1 + e) v_n`,
    `R omega_out = R omega + s mu (1 + e) v_n / inertia` (`rigid_oblique`).

    Two spheres: pass the effective values of `two_spheres(m1, R1, m2, R2)` (`m* = m1 m2 /
    (m1 + m2)`, `R* = R1 R2 / (R1 + R2)`, `inertia*` from `1/m* + R*^2/I* = 1/m1 + 1/m2 +
    R1^2/I1 + R2^2/I2`), the relative normal and tangential velocities of the centres
    and a spin with `v_t - R* omega` the relative slip of the contact points; the
    tangential impulse `impulse_t` acts on sphere 1 (`-impulse_t` on sphere 2), whence each
    sphere's velocity and spin.

    - `g` (m/s^2): gravity along the inward normal (0: an isolated impact).
    - `separation`: `"force"` (contact ends where the normal force returns to zero) or
      `"penetration"` (where the overlap does), as in `impact`.
    - `contact_point`: where the tangential force acts, as the lever arm `R - f x` in the
      slip and the torque (`x` the overlap): `"surface"` (`f = 0`, the equations above;
      LAMMPS), `"midpoint"` (`f = 1/2`, halfway through the overlap: LIGGGHTS, MuJoCo,
      Drake, Yade between spheres), `"plane"` (`f = 1`, on the plane: Yade's wall) or a
      number `f` in [0, 1]. Two equal spheres through their effective values: each
      sphere's share over 2 (`"midpoint"` there is `f = 1/4`). The choices differ by about
      `f x_max / R` (measured: 0.004 in e_t at 5 degrees for Kharaz's sphere, `x_max / R =
      0.006`, at `f = 1/2`).
    - `solver` (default `diffrax.Tsit5()`), `rtol`, `atol` (default `rtol`): in the normal
      contact's units (default as `impact`'s: 1e-11 for a law of the table, 1e-12 for a
      user's law); `max_steps` per segment; `max_segments`: the most segments (one
      per tangential mode, one more at maximum compression for a law split there);
      `tau_max`, `rest_tol` as in `impact`.
    - `adjoint`: default picks the cheapest diffrax adjoint for the transformation in use
      (under `jax.grad` alone, the forward-mode Jacobian transposed, as `impact`).
    - `land_events`: integrate each segment a second time to its event (`_land`), so that
      derivatives across the transitions use the vector field, not diffrax's interpolant
      (whose slope is 1e-5 off; a gradient through a stick-slip transition was 1e-4 off
      without it). `None` (default): when the call is differentiated (a `jax.grad` or
      `jax.jvp` tracer among the inputs; under `jax.grad(jax.jit(...))` that cannot be
      seen: pass `True`). It doubles the integration.
    - `throw`: `None` (default): an eager call whose solve failed raises; `True`: raise
      unless separated (`eqx.error_if`); `False`: never (failed fields are NaN).

    Returns an `ObliqueResult`. Composes with `jax.jit`, `jax.vmap` (scalars in, `vmap`
    for a batch, e.g. over incidence angles with `incidence`) and `jax.grad`. Bad values
    (`m`, `R`, `v_n`, `inertia` not > 0, `g` < 0, not finite) raise a one-line `ValueError`
    eagerly; under a transformation that member is NaN with status `invalid`.

    **Example**:
    `oblique_impact(jaximpact.law("hertz_rate", c=2.6e10, b1=0.0),
    tangential_law("mindlin", G=1.5e11, nu=0.23, mu=0.092), m=2.6e-4, R=2.5e-3, v_n=3.0,
    v_t=2.5).e_t` is the Kharaz alumina sphere's tangential restitution at 40 degrees.
    """
    rtol = checked_settings(law, tangential, separation, rtol)
    share = lever_share(contact_point)
    for name, value in (("atol", atol), ("rest_tol", rest_tol)):
        if value is not None and not (isinstance(value, (int, float)) and 0 < value < 1):
            raise ValueError(f"{name} must be a number in (0, 1), got {value!r}")
    for name, value in (("max_steps", max_steps), ("max_segments", max_segments)):
        if not (isinstance(value, int) and value >= 1):
            raise ValueError(f"{name} must be a whole number >= 1, got {value!r}")
    if not (isinstance(tau_max, (int, float)) and tau_max > 0 and math.isfinite(tau_max)):
        raise ValueError(f"tau_max must be a finite number > 0, got {tau_max!r}")
    # eager: a one-line ValueError; traced: a bad member is NaN and invalid (`MemberChecks`)
    checks = MemberChecks()
    inputs = checked_inputs(checks, m, R, v_n, v_t, omega, inertia, g)
    values = [jnp.asarray(a, dtype=float) for a in inputs]
    if any(jnp.ndim(a) for a in values):
        raise ValueError(
            "oblique_impact takes scalar m, R, v_n, v_t, omega, inertia and g; "
            "use jax.vmap for a batch (e.g. over incidence angles)"
        )
    check_custom_law(law, values[2])
    rtol, atol, rest_tol = resolvable_tolerances(rtol, rtol if atol is None else atol, rest_tol)
    options = ObliqueOptions(
        separation=separation,
        solver=dfx.Tsit5() if solver is None else solver,
        adjoint=auto_adjoint(law, tangential, *values) if adjoint is None else adjoint,
        land=_differentiated(law, tangential, *values) if land_events is None else land_events,
        rtol=float(rtol),
        atol=float(atol),
        max_steps=max_steps,
        max_segments=max_segments,
        tau_max=float(tau_max),
        rest_tol=float(rest_tol),
        lever_share=share,
    )
    if adjoint is None and reverse_only(law, tangential, *values):
        # jax.grad: the forward-mode Jacobian, transposed (`adjoint.by_forward_jacobian`)
        forward = dataclasses.replace(options, adjoint=dfx.ForwardMode())
        result = through_forward_jacobian(
            lambda law, tangential, *v: solve_oblique(law, tangential, ObliqueInputs(*v), forward),
            law,
            tangential,
            *values,
            closes_over=law.spec is None,
        )
    else:
        result = solve_oblique(law, tangential, ObliqueInputs(*values), options)
    result = checks.refuse(result, status=Status.invalid)
    if throw is not False and not is_traced(result.status) and np.ndim(result.status) == 0:
        status = Status(int(result.status))
        if status.is_failure:
            raise RuntimeError(
                f"the oblique impact's solve ended {status.name} (after "
                f"{int(result.num_switches)} stick-slip switches): raise max_steps "
                f"({max_steps}) or max_segments ({max_segments}), or loosen rtol "
                f"({rtol:g}); throw=False returns NaN with the status"
            )
    if throw:
        result = eqx.error_if(
            result,
            result.status != Status.separated,
            "the oblique impact did not end in separation (stuck, captured or failed)",
        )
    return result


def incidence(speed, angle):
    """`(v_n, v_t) = (speed cos(angle), speed sin(angle))` for an incidence `angle` in
    radians from the normal, in [0, pi/2) (a concrete angle beyond pi/2 is refused: degrees
    given for radians; `jnp.deg2rad` converts).

    **Example**: `incidence(3.9, jnp.deg2rad(40.0))`.
    """
    if not is_traced(angle):
        a = np.asarray(angle, dtype=float)
        if np.any(~np.isfinite(a)) or np.any(np.abs(a) >= 0.5 * math.pi):
            bad = a.ravel()[np.argmax(~np.isfinite(a.ravel()) | (np.abs(a.ravel()) >= 1.5707))]
            raise ValueError(
                f"incidence angle {bad:g} is not in radians in [0, pi/2): pass jnp.deg2rad(degrees)"
            )
    angle = jnp.asarray(angle, dtype=float)
    return speed * jnp.cos(angle), speed * jnp.sin(angle)


def two_spheres(m1, R1, m2, R2, inertia1=0.4, inertia2=0.4) -> dict:
    """The effective `m`, `R`, `inertia` of two spheres in contact (kg, m; inertia factors
    `I_i / (m_i R_i^2)`), for `oblique_impact(law, tangential, **two_spheres(...), v_n=...,
    v_t=..., omega=...)`: `m* = m1 m2 / (m1 + m2)`, `R* = R1 R2 / (R1 + R2)`, and the
    factor that gives the contact points' relative slip its true inertia,
    `(1 + 1/inertia*) / m* = 1/m1 + 1/m2 + R1^2/I1 + R2^2/I2`, i.e.
    `inertia* = 1 / (m* (1/(inertia1 m1) + 1/(inertia2 m2)))`.

    **Example**: `two_spheres(0.0117, 0.01, 0.0117, 0.01)` has `m = 0.00585`, `R = 0.005`
    and `inertia = 0.4` (two equal solid spheres slip as one on a plane).
    """
    m = m1 * m2 / (m1 + m2)
    R = R1 * R2 / (R1 + R2)
    spin = R1**2 / (inertia1 * m1 * R1**2) + R2**2 / (inertia2 * m2 * R2**2)
    return dict(m=m, R=R, inertia=1.0 / (m * spin))
