"""The integrated path of `impact`: one contact solved with diffrax, in phases ended by
events (to the force peak, to maximum compression, to separation or rest), and its result
assembled into an `ImpactResult`. Imported only when an impact is integrated (diffrax and
optimistix take about half a second to import)."""

import diffrax as dfx
import jax
import jax.numpy as jnp

from .._status import Status
from .._tracing import anchors
from .results import ImpactResult
from .roots import BracketedNewton

# Phases of one contact, integrated one after the other by the same compiled solve.
_TO_PEAK = 0  # compression, until the first force peak or maximum compression
_TO_MAX_COMPRESSION = 1  # compression, until v = 0
_TO_SEPARATION = 2  # restitution, until separation or rest
_WHOLE = 3  # a smooth law's whole contact in one go (no peaks asked for)


def phase_plan(dynamics, peaks: bool) -> tuple[int, ...]:
    """Which phases a contact needs: a law whose force jumps at maximum compression (a dry
    force) is split there; the peak values need their own events; otherwise one phase."""
    if peaks:
        return (_TO_PEAK, _TO_MAX_COMPRESSION, _TO_SEPARATION)
    if dynamics.split:
        return (_TO_MAX_COMPRESSION, _TO_SEPARATION)
    return (_WHOLE,)


# the speed (units of v0) at which restitution's "moving in again" condition fires, not 0:
# at maximum compression, where restitution starts, a damped law's V = W - beta X^(p+1)/(p+1)
# is a cancellation whose noise (up to beta rtol X, 1e-12 at rtol 1e-12) tripped that
# condition on the first step (an over-damped Kelvin-Voigt, b 25x critical, reported
# captured at maximum compression under another XLA rounding, where it separates)
_TURN_NOISE = 1e-10


def _event_conditions(dynamics, separation, plan, rest_tol):
    """Three real-valued conditions per phase, each positive before its event.

    `_TO_PEAK` ends at the first force peak (`dF/dt = 0`) or at maximum compression
    (`V = 0`), the peak's condition first: where both cross in one step (light damping puts
    the peak within a step of maximum compression) diffrax takes the first condition in
    order, not the earlier one in time (diffrax issue #639), and the peak, which never comes
    after maximum compression, would be missed; `_TO_MAX_COMPRESSION` at `V = 0`;
    `_TO_SEPARATION` and `_WHOLE` at
    separation or when the body stops moving out inside the surface (`V` back to 0, within
    `_TURN_NOISE`: stuck or captured). In every phase, the third ends a body creeping to
    rest: speed and net force both below `rest_tol` (over-damped contacts that never
    separate).
    """

    def first(t, y, args, **kwargs):
        if separation == "force":
            gap = dynamics.force_gap(y, args < _TO_SEPARATION)
        else:
            gap = dynamics.penetration_gap(y)
        condition = jnp.where(args < _TO_SEPARATION, dynamics.velocity(y), gap)
        if _TO_PEAK in plan:
            condition = jnp.where(args == _TO_PEAK, dynamics.force_rate(y, True), condition)
        return condition

    def second(t, y, args, **kwargs):
        velocity = dynamics.velocity(y)
        condition = jnp.where(args == _TO_MAX_COMPRESSION, velocity, _TURN_NOISE - velocity)
        if _TO_PEAK in plan:
            condition = jnp.where(args == _TO_PEAK, velocity, condition)
        return condition

    def at_rest(t, y, args, **kwargs):
        net_force = dynamics.force(y, args < _TO_SEPARATION) - dynamics.gamma
        return jnp.abs(dynamics.velocity(y)) + jnp.abs(net_force) - rest_tol

    conditions = (first, second, at_rest)
    if separation == "force" and dynamics.surface_gap(dynamics.y0()) is not None:
        # a user's law: the surface ends contact too (after the force's own zero in order,
        # since where both cross in one step diffrax takes the first condition in order)

        def surface(t, y, args, **kwargs):
            return jnp.where(args < _TO_SEPARATION, 1.0, dynamics.surface_gap(y))

        conditions = conditions + (surface,)
    return conditions


def _back_to_the_turn(dynamics, phase, turned, y, tau_start, tau):
    """The time a body stopped moving out (`V = 0`), where restitution's turn condition fired
    at `V = _TURN_NOISE` (it ends `_TO_SEPARATION` and `_WHOLE`): one Newton step back,
    `tau - V/(dV/dtau)`, exact to `O(_TURN_NOISE^2)` (a captured body's T within 1e-9 of the
    closed form's, where the threshold alone moved it by `_TURN_NOISE/(dV/dtau)`)."""
    velocity, rate = jax.jvp(dynamics.velocity, (y,), (dynamics.rhs(y, False),))
    back = jnp.where(rate > 0, velocity / jnp.where(rate > 0, rate, 1.0), 0.0)
    is_turn = turned & (phase >= _TO_SEPARATION)  # restitution's phases
    return jnp.where(is_turn, jnp.maximum(tau - back, tau_start), tau)


def solve_broke(result):
    """Whether a diffrax solve itself failed (`result`: its `RESULTS`): the step size fell
    below its minimum, too many steps were rejected, or an internal error; running out of
    steps (`max_steps_reached`) is reported apart."""
    return (
        (result == dfx.RESULTS.dt_min_reached)
        | (result == dfx.RESULTS.max_steps_rejected)
        | (result == dfx.RESULTS.internal_error)
    )


def integrate_phases(dynamics, options, *, plan, tau_grid, hold=None):
    """Run the phases of `plan` as `options` (an `ImpactOptions`: separation, solver,
    tolerances, horizon, adjoint) say; return the state and time at the end of each
    (nondimensional), stacked along a leading axis. `hold` (a boolean): skip every phase
    (a contact known in closed form never to return, see `AbstractDynamics.creeping`)."""
    separation, solver, adjoint, max_steps = (
        options.separation,
        options.solver,
        options.adjoint,
        options.max_steps,
    )
    rtol, atol, tau_max, rest_tol = options.rtol, options.atol, options.tau_max, options.rest_tol
    term = dfx.ODETerm(lambda t, y, args: dynamics.rhs(y, args < _TO_SEPARATION))
    conditions = _event_conditions(dynamics, separation, plan, rest_tol)
    event = dfx.Event(
        conditions,
        root_finder=BracketedNewton(rtol=1e-13, atol=1e-13),
        direction=(False,) * len(conditions),
    )
    controller = dfx.PIDController(rtol=rtol, atol=atol)
    tau_max = jnp.asarray(tau_max, dtype=float)

    def phase_solve(carry, phase):
        y, tau, alive = carry
        rest_push = dynamics.force(y, False) - dynamics.gamma
        skip = (
            ~alive
            | ((phase == _TO_MAX_COMPRESSION) & (dynamics.velocity(y) <= 0))
            | ((phase == _TO_SEPARATION) & (rest_push <= 0))
        )
        if hold is not None:
            skip = skip | hold
        t1 = jnp.where(skip, tau, tau_max)
        subs = [dfx.SubSaveAt(t1=True)]
        if tau_grid is not None:
            subs.append(dfx.SubSaveAt(ts=jnp.clip(tau_grid, tau, t1)))
        sol = dfx.diffeqsolve(
            term,
            solver,
            tau,
            t1,
            None,
            y,
            args=phase,
            stepsize_controller=controller,
            event=event,
            saveat=dfx.SaveAt(subs=subs),
            adjoint=adjoint,
            max_steps=max_steps,
            throw=False,
        )
        # the surface (a user's law under the force criterion) ends contact as the force
        # does: it counts as the first condition
        first = sol.event_mask[0] if len(conditions) == 3 else sol.event_mask[0] | sol.event_mask[3]
        fired = first | sol.event_mask[1] | sol.event_mask[2]
        out_of_steps = sol.result == dfx.RESULTS.max_steps_reached
        y_end, tau_end = sol.ys[0][-1], sol.ts[0][-1]
        tau_end = _back_to_the_turn(dynamics, phase, sol.event_mask[1], y_end, tau, tau_end)
        # the solve itself failed, or its state is not a number; a root finder that did
        # not meet its 1e-13 (an ill-conditioned event, e.g. heavy Kelvin-Voigt damping
        # where F crosses zero with slope c v_out ~ 0) still placed the event: not a failure
        broke = solve_broke(sol.result)
        failed = ~skip & ~out_of_steps & (broke | ~jnp.all(jnp.isfinite(y_end)))
        record = dict(
            y=y_end,
            tau=tau_end,
            tau_start=tau,
            skipped=skip,
            alive=alive,
            first=first,
            second=sol.event_mask[1],
            rest=sol.event_mask[2],
            out_of_steps=out_of_steps,
            failed=failed,
            steps=sol.stats["num_steps"],
        )
        if tau_grid is not None:
            record["grid"] = sol.ys[1]
        at_rest = sol.event_mask[2]
        going_on = alive & (skip | fired) & ~at_rest & ~out_of_steps & ~failed
        return (y_end, tau_end, going_on), record

    # the carry starts as it leaves a phase, batched and with a tangent (`_tracing`)
    zero, no = anchors(dynamics, tau_max, tau_grid)
    carry = (dynamics.y0() + zero, zero + jnp.zeros_like(tau_max), ~no)
    if len(plan) == 1:
        _, record = phase_solve(carry, jnp.asarray(plan[0]))
        return jax.tree_util.tree_map(lambda a: a[None], record)
    _, phases = jax.lax.scan(phase_solve, carry, jnp.asarray(plan))
    return phases


def integrated_contact(dynamics, options, *, m, v0, g, tau_grid=None, hold=None, creep=None):
    """One contact integrated as `options` (an `ImpactOptions`) say: its `ImpactResult`
    (path `"integrated"`) and the penetration where it ended (m). `hold` skips every phase
    (see `integrate_phases`); `creep`: a contact known in closed form never to return
    (`AbstractDynamics.creeping`), held and assembled from that form."""
    plan = phase_plan(dynamics, options.peaks or tau_grid is not None)
    phases = integrate_phases(dynamics, options, plan=plan, tau_grid=tau_grid, hold=hold)
    result = assemble_integrated(
        dynamics, phases, plan, m=m, v0=v0, g=g, tau_grid=tau_grid, creep=creep
    )
    return result, dynamics.position(phases["y"][-1]) * dynamics.x_star


def assemble_integrated(dynamics, phases, plan, *, m, v0, g, tau_grid, creep=None):
    x_star, t_star, scale = dynamics.x_star, dynamics.t_star, dynamics.force_scale
    last = len(plan) - 1
    y_end = phases["y"][last]
    stuck_at_max = (
        (phases["alive"][last] & phases["skipped"][last])
        if plan[last] == _TO_SEPARATION
        else jnp.asarray(False)
    )
    rested = phases["second"][last] | stuck_at_max | jnp.any(phases["rest"])
    # a force that vanishes while the body is not moving out (creeping to rest) is a capture
    separated = phases["first"][last] & ~rested & (dynamics.velocity(phases["y"][last]) < 0)
    out_of_steps = jnp.any(phases["out_of_steps"] & phases["alive"])
    failed = jnp.any(phases["failed"] & phases["alive"])
    held = Status.stuck if dynamics.has_dry else Status.captured
    status = jnp.where(
        out_of_steps,
        Status.out_of_steps,
        jnp.where(
            failed,
            Status.failed,
            jnp.where(separated, Status.separated, jnp.where(rested, held, Status.captured)),
        ),
    )
    v_end = dynamics.velocity(y_end)
    e = jnp.where(status == Status.separated, -v_end, 0.0)
    x_end = dynamics.position(y_end) * x_star
    result = dict(
        e=e,
        T=phases["tau"][last] * t_star,
        dissipated=0.5 * m * v0**2 * (1.0 - e**2) + m * g * x_end,
        v_out=jnp.where(status == Status.separated, v_end * v0, 0.0),
        status=status.astype(jnp.int32),
        num_steps=jnp.sum(phases["steps"]),
    )
    if _TO_MAX_COMPRESSION in plan:
        k = plan.index(_TO_MAX_COMPRESSION)
        result["x_max"] = dynamics.position(phases["y"][k]) * x_star
        result["t_max"] = phases["tau"][k] * t_star
    if _TO_PEAK in plan:
        candidates = [dynamics.y0(), phases["y"][plan.index(_TO_PEAK)], phases["y"][k]]
        forces = jnp.stack([dynamics.force(y, True) for y in candidates])
        result["F_max"] = jnp.max(forces) * scale
    if creep is not None:
        # never returns (over-damped Maxwell): captured at the closed-form rest instant,
        # sinking in all along (x_max at that instant), no integration was run
        held = creep["captured"]
        result["status"] = jnp.where(held, Status.captured, result["status"]).astype(jnp.int32)
        result["e"] = jnp.where(held, 0.0, result["e"])
        result["v_out"] = jnp.where(held, 0.0, result["v_out"])
        result["T"] = jnp.where(held, creep["tau"] * t_star, result["T"])
        result["dissipated"] = jnp.where(
            held, 0.5 * m * v0**2 + m * g * creep["x"] * x_star, result["dissipated"]
        )
        if "x_max" in result:
            result["x_max"] = jnp.where(held, creep["x"] * x_star, result["x_max"])
            result["t_max"] = jnp.where(held, creep["tau"] * t_star, result["t_max"])
        if "F_max" in result:
            result["F_max"] = jnp.where(held, creep["force_peak"] * scale, result["F_max"])
    if tau_grid is not None:
        result.update(_histories(dynamics, phases, plan, tau_grid, v0, g))
    return ImpactResult(**without_failures(result), path="integrated")


_NOT_RESULTS = ("status", "num_steps")


def without_failures(fields: dict) -> dict:
    """Every result field of a failed solve (`out_of_steps`, `failed`) set to NaN: a
    failure is never presented as a number (its status says why)."""
    status = fields["status"]
    failure = (status == Status.out_of_steps) | (status == Status.failed)
    out = dict(fields)
    for key, value in fields.items():
        if key in _NOT_RESULTS or value is None:
            continue
        shape = jnp.shape(failure) + (1,) * (jnp.ndim(value) - jnp.ndim(failure))
        mask = jnp.reshape(failure, shape)
        out[key] = jnp.where(mask, jnp.nan, value)
    return out


def _histories(dynamics, phases, plan, tau_grid, v0, g):
    """x, v, F on the requested grid: inside contact from the phase that covers each time,
    outside it the free flight (approach before 0, departure after T)."""
    x_star, t_star = dynamics.x_star, dynamics.t_star
    x = jnp.zeros_like(tau_grid) + tau_grid * x_star  # approach: x = v0 t
    v = jnp.zeros_like(tau_grid) + v0
    force = jnp.zeros_like(tau_grid)
    for k, phase in enumerate(plan):
        inside = (tau_grid >= phases["tau_start"][k]) & (tau_grid <= phases["tau"][k])
        inside = inside & ~phases["skipped"][k]
        ys = jnp.where(inside[:, None], phases["grid"][k], dynamics.y0()[None, :])
        x = jnp.where(inside, jax.vmap(dynamics.position)(ys) * x_star, x)
        v = jnp.where(inside, jax.vmap(dynamics.velocity)(ys) * v0, v)
        compressing = phase < _TO_SEPARATION
        forces = jax.vmap(dynamics.force, in_axes=(0, None))(ys, compressing)
        force = jnp.where(inside, forces * dynamics.force_scale, force)
    y_end, tau_end = phases["y"][-1], phases["tau"][-1]
    after = jnp.maximum(tau_grid - tau_end, 0.0) * t_star
    x_end, v_end = dynamics.position(y_end) * x_star, dynamics.velocity(y_end) * v0
    flying = tau_grid > tau_end
    x = jnp.where(flying, x_end + v_end * after + 0.5 * g * after**2, x)
    v = jnp.where(flying, v_end + g * after, v)
    force = jnp.where(flying, 0.0, force)
    return dict(ts=tau_grid * t_star, x=x, v=v, F=force)
