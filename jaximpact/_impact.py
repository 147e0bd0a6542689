"""One impact: the contact integrated with diffrax and ended by events."""

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import optimistix as optx
from jaxtyping import Array

from . import _closed_forms
from ._adjoint import auto_adjoint
from ._checks import check_nonnegative, check_positive
from ._laws import AbstractLaw
from ._precision import resolvable_tolerances
from ._status import Status

SEPARATIONS = ("force", "penetration")
METHODS = ("auto", "integrate", "closed_form")


class ImpactResult(eqx.Module):
    """What one impact gives (SI units).

    - `e`: coefficient of restitution `-v_out / v0` (0 unless `status == separated`).
    - `T`: contact duration (s), from first touch to separation; for `stuck` the time at
      which the body came to rest; for `captured` the time the solve gave up (the horizon
      `tau_max t*`, or the instant its speed and net force fell below `rest_tol`; in closed
      form for over-damped Kelvin-Voigt under `"penetration"` and for over-damped Maxwell,
      `mu = sqrt(m c)/b >= 2` without gravity, which never reaches maximum compression).
      Its derivatives are those of that instant (finite); `e` of a captured member is 0
      with derivative 0.
    - `x_max` (m), `t_max` (s): maximum penetration and when it is reached.
    - `F_max` (N): largest contact force (at first touch, at the first force peak in
      compression, or at maximum compression, whichever is largest).
    - `dissipated` (J): kinetic energy taken by the contact, `m v0^2 (1 - e^2)/2` plus the
      work of gravity over the final penetration.
    - `v_out` (m/s): velocity at separation (negative: leaving).
    - `status`: a `jaximpact.Status` as an integer array; `num_steps`: solver steps.
    - `x_max`, `t_max`, `F_max` are `None` under `impact(..., peaks=False)`, which skips the
      events that find them (a law split at maximum compression still gives `x_max`).
    - `path`: `"closed_form"` or `"integrated"`.
    - `ts`, `x`, `v`, `F`: time histories, only when `impact(..., ts=...)` asked for them.
    """

    e: Array
    T: Array
    dissipated: Array
    v_out: Array
    status: Array
    num_steps: Array
    path: str = eqx.field(static=True)
    x_max: Array | None = None
    F_max: Array | None = None
    t_max: Array | None = None
    ts: Array | None = None
    x: Array | None = None
    v: Array | None = None
    F: Array | None = None

    @property
    def separated(self) -> Array:
        return self.status == Status.separated

    @property
    def status_name(self) -> str:
        """The status as a word (for a single impact, not a batch)."""
        return Status(int(self.status)).name


# Phases of one contact, integrated one after the other by the same compiled solve.
_TO_PEAK = 0  # compression, until the first force peak or maximum compression
_TO_MAX_COMPRESSION = 1  # compression, until v = 0
_TO_SEPARATION = 2  # restitution, until separation or rest
_WHOLE = 3  # a smooth law's whole contact in one go (no peaks asked for)


def _phase_plan(dynamics, peaks: bool) -> tuple[int, ...]:
    """Which phases a contact needs: a law whose force jumps at maximum compression (a dry
    force) is split there; the peak values need their own events; otherwise one phase."""
    if peaks:
        return (_TO_PEAK, _TO_MAX_COMPRESSION, _TO_SEPARATION)
    if dynamics.split:
        return (_TO_MAX_COMPRESSION, _TO_SEPARATION)
    return (_WHOLE,)


def _event_conditions(dynamics, separation, plan, rest_tol):
    """Three real-valued conditions per phase, each positive before its event.

    `_TO_PEAK` ends at maximum compression (`V = 0`) or at the first force peak
    (`dF/dt = 0`); `_TO_MAX_COMPRESSION` at `V = 0`; `_TO_SEPARATION` and `_WHOLE` at
    separation or when the body stops moving out inside the surface (`V` back to 0: stuck
    or captured). In every phase, the third ends a body creeping to rest: speed and net
    force both below `rest_tol` (over-damped contacts that never separate).
    """

    def first(t, y, args, **kwargs):
        if separation == "force":
            gap = dynamics.force_gap(y, args < _TO_SEPARATION)
        else:
            gap = dynamics.position(y)
        return jnp.where(args < _TO_SEPARATION, dynamics.velocity(y), gap)

    def second(t, y, args, **kwargs):
        velocity = dynamics.velocity(y)
        condition = jnp.where(args == _TO_MAX_COMPRESSION, velocity, -velocity)
        if _TO_PEAK in plan:
            condition = jnp.where(args == _TO_PEAK, dynamics.force_rate(y, True), condition)
        return condition

    def at_rest(t, y, args, **kwargs):
        net_force = dynamics.force(y, args < _TO_SEPARATION) - dynamics.gamma
        return jnp.abs(dynamics.velocity(y)) + jnp.abs(net_force) - rest_tol

    return first, second, at_rest


def _integrate(
    dynamics,
    *,
    plan,
    separation,
    tau_grid,
    solver,
    rtol,
    atol,
    max_steps,
    tau_max,
    rest_tol,
    adjoint,
    hold=None,
):
    """Run the phases of `plan`; return the state and time at the end of each
    (nondimensional), stacked along a leading axis. `hold` (a boolean): skip every phase
    (a contact known in closed form never to return, see `AbstractDynamics.creeping`)."""
    term = dfx.ODETerm(lambda t, y, args: dynamics.rhs(y, args < _TO_SEPARATION))
    event = dfx.Event(
        _event_conditions(dynamics, separation, plan, rest_tol),
        root_finder=optx.Newton(rtol=1e-13, atol=1e-13),
        direction=(False, False, False),
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
        fired = sol.event_mask[0] | sol.event_mask[1] | sol.event_mask[2]
        out_of_steps = sol.result == dfx.RESULTS.max_steps_reached
        y_end, tau_end = sol.ys[0][-1], sol.ts[0][-1]
        record = dict(
            y=y_end,
            tau=tau_end,
            tau_start=tau,
            skipped=skip,
            alive=alive,
            first=sol.event_mask[0],
            second=sol.event_mask[1],
            rest=sol.event_mask[2],
            out_of_steps=out_of_steps,
            steps=sol.stats["num_steps"],
        )
        if tau_grid is not None:
            record["grid"] = sol.ys[1]
        at_rest = sol.event_mask[2]
        return (y_end, tau_end, alive & (skip | fired) & ~at_rest & ~out_of_steps), record

    carry = (dynamics.y0(), jnp.zeros_like(tau_max), jnp.asarray(True))
    if len(plan) == 1:
        _, record = phase_solve(carry, jnp.asarray(plan[0]))
        return jax.tree_util.tree_map(lambda a: a[None], record)
    _, phases = jax.lax.scan(phase_solve, carry, jnp.asarray(plan))
    return phases


def _assemble_integrated(dynamics, phases, plan, *, m, v0, g, tau_grid, creep=None):
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
    out_of_steps = jnp.any(phases["out_of_steps"])
    held = Status.stuck if dynamics.has_dry else Status.captured
    status = jnp.where(
        out_of_steps,
        Status.out_of_steps,
        jnp.where(separated, Status.separated, jnp.where(rested, held, Status.captured)),
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
    return ImpactResult(**result, path="integrated")


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


class ImpactOptions(eqx.Module):
    """Everything static about an impact solve (see `impact` for the meanings)."""

    separation: str = eqx.field(static=True)
    closed_form: bool = eqx.field(static=True)
    solver: dfx.AbstractSolver = eqx.field(static=True)
    rtol: float = eqx.field(static=True)
    atol: float = eqx.field(static=True)
    max_steps: int = eqx.field(static=True)
    tau_max: float = eqx.field(static=True)
    rest_tol: float = eqx.field(static=True)
    adjoint: dfx.AbstractAdjoint = eqx.field(static=True)
    peaks: bool = eqx.field(static=True)


@eqx.filter_jit
def solve_impact(law, m, v0, g, ts, options: ImpactOptions) -> ImpactResult:
    """The compiled part of `impact`, cached per law structure and options; no input
    checks (callers inside the library that have validated their inputs use it)."""
    dynamics = law.dynamics(m=m, v0=v0, g=g)
    if options.closed_form:
        closed = _closed_forms.closed_form_for(law, options.separation)
        fields = closed(law, m=m, v0=v0, rest_tol=options.rest_tol)
        return ImpactResult(**fields, path="closed_form")
    tau_grid = None if ts is None else ts / dynamics.t_star
    plan = _phase_plan(dynamics, options.peaks or tau_grid is not None)
    # with a time grid the histories need the integration itself
    creep = dynamics.creeping(options.rest_tol) if tau_grid is None else None
    phases = _integrate(
        dynamics,
        plan=plan,
        separation=options.separation,
        tau_grid=tau_grid,
        solver=options.solver,
        rtol=options.rtol,
        atol=options.atol,
        max_steps=options.max_steps,
        tau_max=options.tau_max,
        rest_tol=options.rest_tol,
        adjoint=options.adjoint,
        hold=None if creep is None else creep["captured"],
    )
    return _assemble_integrated(
        dynamics, phases, plan, m=m, v0=v0, g=g, tau_grid=tau_grid, creep=creep
    )


def impact(
    law: AbstractLaw,
    *,
    m,
    v0,
    separation: str = "force",
    g=0.0,
    ts=None,
    method: str = "auto",
    solver: dfx.AbstractSolver | None = None,
    rtol: float = 1e-10,
    atol: float | None = None,
    max_steps: int = 4096,
    tau_max: float = 1e4,
    rest_tol: float = 1e-7,
    adjoint: dfx.AbstractAdjoint | None = None,
    peaks: bool = True,
    throw: bool = False,
) -> ImpactResult:
    """One impact of a body of mass `m` (kg) hitting the surface at speed `v0` (m/s).

    Integrates `m x'' = -F(x, x') + m g` from `x = 0`, `x' = v0` in the law's natural units
    (`x*`, `t* = x*/v0`), in three phases ended by events with a root finder (to the first
    force peak, to maximum compression, to separation), so `e` and `T` are exact to the
    tolerance and differentiable. `separation="force"` ends contact where the force returns
    to zero, `"penetration"` where `x` returns to zero.

    - `g`: gravity along the inward normal (m/s^2), 0 for an isolated impact.
    - `ts`: times (s from first touch) at which to return `x`, `v`, `F`; nothing is stored
      otherwise.
    - `method`: `"auto"` uses an exact closed form where one holds for every parameter value
      (Kelvin-Voigt, with `g = 0` and no `ts`; Maxwell's formulas hold only where it is
      under-damped, which is not known before run time, so it is integrated),
      `"integrate"` always integrates, `"closed_form"` insists on one.
    - `solver` (default `diffrax.Tsit5()`), `rtol`, `atol` (default `rtol`): in the
      nondimensional variables, so they are relative to the contact's own scales.
    - `tau_max`: horizon in units of `t*`; a contact still going on there is `captured`.
    - `rest_tol`: a body whose speed (in units of `v0`) plus net force (in units of
      `m v0^2/x*`) falls below this is at rest: `captured` (or `stuck`), `T` is that time.
    - In float32 (JAX's x64 off) `rtol`, `atol` below 1e-7 and `rest_tol` below 1e-5 are
      raised to those values, with a warning: finer ones cannot be met in that precision.
    - `adjoint`: default picks the cheapest diffrax adjoint for the transformation in use
      (`ForwardMode` under `jax.jacfwd`, `RecursiveCheckpointAdjoint` otherwise).
    - `peaks`: find `x_max`, `t_max`, `F_max` (extra events); `False` integrates a smooth
      law in a single phase, which is what fitting e and T needs.
    - `throw`: raise if the impact did not end in separation (not usable under `vmap`).

    **Example**:
    `impact(law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5).e` is about 0.83.
    """
    if not isinstance(law, AbstractLaw):
        raise TypeError(
            f"impact needs a law from jaximpact.law(...) or jaximpact.custom_law(...), "
            f"got {type(law).__name__}"
        )
    if separation not in SEPARATIONS:
        raise ValueError(f"separation must be one of {SEPARATIONS}, got {separation!r}")
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    m = jnp.asarray(check_positive("mass m", m, "kg"), dtype=float)
    v0 = jnp.asarray(check_positive("impact speed v0", v0, "m/s"), dtype=float)
    g_is_zero = isinstance(g, (int, float)) and g == 0
    g = jnp.asarray(check_nonnegative("gravity g", g, "m/s^2"), dtype=float)
    if jnp.ndim(m) or jnp.ndim(v0) or jnp.ndim(g):
        raise ValueError("impact takes scalar m, v0 and g; use jax.vmap for a batch")

    closed = _closed_forms.closed_form_for(law, separation) if ts is None and g_is_zero else None
    if method == "closed_form" and closed is None:
        raise ValueError(
            f"no closed form for law {getattr(law, 'name', 'custom')!r} with "
            f"separation={separation!r}, g={float(g)} and ts={'given' if ts is not None else None}"
        )
    if ts is not None:
        ts = jnp.asarray(ts, dtype=float)
        if ts.ndim != 1:
            raise ValueError("ts must be a 1-D array of times in seconds")
    rtol, atol, rest_tol = resolvable_tolerances(rtol, rtol if atol is None else atol, rest_tol)
    options = ImpactOptions(
        separation=separation,
        closed_form=closed is not None and method != "integrate",
        solver=dfx.Tsit5() if solver is None else solver,
        rtol=rtol,
        atol=atol,
        max_steps=max_steps,
        tau_max=tau_max,
        rest_tol=rest_tol,
        adjoint=auto_adjoint(law, m, v0, g, ts) if adjoint is None else adjoint,
        peaks=peaks,
    )
    result = solve_impact(law, m, v0, g, ts, options)
    if throw:
        result = eqx.error_if(
            result,
            result.status != Status.separated,
            "the impact did not end in separation (stuck, captured or out of steps)",
        )
    return result
