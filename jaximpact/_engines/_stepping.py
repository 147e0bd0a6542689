"""Replicas of the engines' time stepping for one head-on contact, in numpy, and the time step
an export recommends from them.

They predict what an engine realises (its discretisation included) without running it; the
engine tests check them against the engines themselves. Each contact is started at several
phases inside a time step (the first touch falls `phase * h` after a step's start), since
the realised e depends on it at first order in the step.
"""

import math

import numpy as np

PHASES = (np.arange(16) + 0.5) / 16
# The export's tolerance (relative): at its recommended step the engine realises e within it
# of the target wherever the first touch falls inside a step (every start phase), and T (the
# mean over start phases; each contact is counted in whole steps) within it; a given step
# that misses it is warned about (`replicated`).
STEP_TOL = 0.005
_COARSEST_STEPS, MAX_STEPS = 10, 51200  # steps per contact a recommended step searches
_BISECTIONS = 5  # halvings of log(h) between a step that realises and one twice as coarse
# What an export refuses (`unrealised`): a contact resolved by fewer steps than this, or a
# realised (phase-mean) e or T further than this (relative) from the target
RESOLVED_STEPS = 5
REFUSE_TOL = 0.05
_E_SLACK = 0.005  # e above 1 by less than this is round-off, not a gain of energy


def step_until_separated(step, h, v0, phases=PHASES, max_steps=2_000_000):
    """`(e, T)` per start phase of a contact stepped by `step(x, v) -> (x1, v1, pushing)`
    (arrays: penetration `x` in m, approach speed `v` in m/s, whether the step's force is
    non-zero) from `x = -phase v0 h` until the force is zero again; `T` (s) is the number of
    steps with a non-zero force times `h`."""
    x = -v0 * h * np.asarray(phases, float)
    v = np.full_like(x, v0)
    steps = np.zeros_like(x)
    started = np.zeros(x.shape, bool)
    done = np.zeros(x.shape, bool)
    for _ in range(max_steps):
        x1, v1, pushing = step(x, v)
        x, v = np.where(done, x, x1), np.where(done, v, v1)
        started |= pushing
        done |= started & ~pushing
        steps += pushing & ~done
        if done.all():
            return -v / v0, steps * h
    raise RuntimeError("the replica did not finish the contact; the time step is far too small")


def semi_implicit_euler(accel, h, v0, phases=PHASES, max_steps=2_000_000):
    """MuJoCo's Euler: `a_k = accel(x_k, v_k)`, `v += h a`, `x += h v`; the contact is
    active while `x > 0` at a step's start. `accel(x, v)` is the contact acceleration along
    the penetration `x` (<= 0, it never pulls). Returns `(e, T)` per phase, `T` the number of
    steps with a non-zero force times `h`."""

    def step(x, v):
        a = np.where(x > 0, accel(np.maximum(x, 0.0), v), 0.0)
        v_new = v + h * a
        return x + h * v_new, v_new, a != 0

    return step_until_separated(step, h, v0, phases, max_steps)


def velocity_verlet(accel, h, v0, phases=PHASES, max_steps=2_000_000):
    """LAMMPS's `fix nve` (and `nve/sphere`): half kick, drift, force from the new
    positions and the half-step velocities, half kick. `accel(x, v)` as above."""
    a = np.zeros(np.shape(phases))

    def step(x, v):
        nonlocal a
        v_half = v + 0.5 * h * a
        x_new = x + h * v_half
        a = np.where(x_new > 0, accel(np.maximum(x_new, 0.0), v_half), 0.0)
        return x_new, v_half + 0.5 * h * a, a != 0

    return step_until_separated(step, h, v0, phases, max_steps)


def cohesive_verlet(force, holds, h, m_eff, v0, phases=PHASES, max_steps=10_000_000):
    """`(e, T)` per start phase of LAMMPS's `fix nve/sphere` (velocity Verlet) on a contact
    that can hold the body (a cohesive normal model, `jkr` or `dmt`): `force(x, v)` (N,
    pushing apart) at overlap `x` (m) and the half-step approach speed `v` (m/s), `holds(x,
    attached)` whether the contact exists at `x` given that it did before, effective mass
    `m_eff` (kg), impact speed `v0` (m/s). T (s) is the number of steps with a contact times
    `h`; a body the contact holds (its speed turns back in before it lets go) gives `e = 0`
    and T the steps until then (as `impact`'s `captured`)."""
    x = -v0 * h * np.asarray(phases, float)
    v = np.full_like(x, v0)  # approach speed, d delta / dt
    a = np.zeros_like(x)
    attached = np.zeros(x.shape, bool)
    started = np.zeros(x.shape, bool)
    done = np.zeros(x.shape, bool)
    captured = np.zeros(x.shape, bool)
    leaving = np.zeros(x.shape, bool)
    steps = np.zeros_like(x)
    for _ in range(max_steps):
        v_half = v + 0.5 * h * a
        x_new = x + h * v_half
        attach = holds(x_new, attached)
        pushing = np.where(attach, force(np.where(attach, x_new, 0.0), v_half), 0.0)
        a_new = -pushing / m_eff
        v_new = v_half + 0.5 * h * a_new
        live = ~done
        x, v, a = np.where(live, x_new, x), np.where(live, v_new, v), np.where(live, a_new, a)
        attached = np.where(live, attach, attached)
        started |= attach
        turned_in = leaving & attach & (v > 0.0)  # held: turns back in before letting go
        leaving |= started & (v < 0.0)
        ends = live & ((started & ~attach) | turned_in)
        captured |= ends & turned_in
        steps += live & attach & ~turned_in
        done |= ends
        if done.all():
            return np.where(captured, 0.0, -v / v0), steps * h
    raise RuntimeError("the replica did not finish the contact; the time step is far too small")


def _floor3(x: float) -> str:
    """`x` > 0 rounded down to three significant digits, as text: 4.9996 reads 4.99, never
    the 5 it falls short of."""
    if not (x > 0 and math.isfinite(x)):
        return f"{x:g}"
    scale = 10.0 ** (math.floor(math.log10(x)) - 2)
    return f"{math.floor(x / scale * (1 + 1e-12)) * scale:.3g}"


def nice_down(h: float) -> float:
    """`h` (s) rounded down to two significant digits (a number one types into an input)."""
    scale = 10.0 ** math.floor(math.log10(h))
    return float(f"{math.floor(h / scale * 10.0 * (1 + 1e-12)) / 10.0 * scale:.2g}")


def realises(es, Ts, e: float | None, T: float, tol: float = STEP_TOL) -> bool:
    """Whether a stepping's `(e, T)` per start phase is within `tol` (relative) of the
    target: every phase's e within `tol` of `e` and the phase-mean T within `tol` of `T`
    (s). `e` None: the phases' e within `tol` of their own mean, and T not judged (a design
    that corrects its mean e and T for the step afterwards, as MuJoCo's)."""
    es, Ts = np.asarray(es, float), np.asarray(Ts, float)
    if not (np.all(np.isfinite(es)) and np.all(np.isfinite(Ts))):
        return False
    if e is None:
        centre = float(es.mean())
        return centre > 0 and bool(np.all(np.abs(es - centre) <= tol * centre))
    e_ok = np.all(np.abs(es - e) <= tol * e) if e > 0 else np.all(es == 0.0)
    return bool(e_ok) and abs(float(Ts.mean()) / T - 1.0) <= tol


def per_contact(h: float, T: float) -> str:
    """The step `h` (s) as a share of the contact's duration `T` (s): `"T/45"` (T over the
    step, rounded; below 10 steps rounded down to three digits, so that 4.996 steps never
    reads as 5)."""
    steps = T / h
    return f"T/{steps:.0f}" if steps >= 10 else f"T/{_floor3(steps)}"


def describe_step(h: float, T: float | None) -> str:
    """`h` (s) for people, with `per_contact` beside it: `"1.1e-06 s (T/45)"` (without a
    duration `T`, s, or a step, the step alone)."""
    if not T or not h:
        return f"{h:.3g} s"
    return f"{h:.3g} s ({per_contact(h, T)})"


def replicated(replica, params: dict, scene, e: float, T: float, timestep, *, engine, step):
    """`(params, es, Ts, warnings)` for an engine whose stepping `replica(params, m, v0) ->
    (e, T)` per start phase in `scene` (its `m` kg, `v0` m/s; on a wall, `params` with
    `geometry` "wall") realises the target `e` and `T` (s): `params` with the `timestep`
    given (s) or, when None, `recommended_step`; what `replica` realises there; and a
    warning (its step called `step` in `engine`'s words) where that misses the export's
    tolerance (`realises`, `STEP_TOL`), naming the recommended step."""
    params = {**params, **({"geometry": "wall"} if scene.wall else {})}

    def run(h):
        return replica({**params, "timestep": h}, scene.m, scene.v0)

    h = recommended_step(run, T, e) if timestep is None else float(timestep)
    es, Ts = run(h)
    warnings = []
    if not realises(es, Ts, e, T):
        coarsest = recommended_step(run, T, e)
        warnings.append(
            f"{step} {h:.3g} s gives {Ts.mean() / h:.0f} steps per contact: {engine} realises "
            f"e = {es.min():.4g} to {es.max():.4g}, T = {Ts.mean():.4g} s (asked {e:.4g}, "
            f"{T:.4g} s; {STEP_TOL:.1%} allowed); use {describe_step(coarsest, T)} or less"
        )
    return {**params, "timestep": h}, es, Ts, warnings


def recommended_step(run, T: float, e: float | None = None, tol: float = STEP_TOL) -> float:
    """The time step (s) an export recommends for a contact of duration `T` (s): the
    coarsest at which the engine's stepping `run(h) -> (e, T)` per start phase realises the
    target `e` and `T` within `tol` (`realises`; `e` None: e's spread over start phases
    alone), rounded down to two digits (`nice_down`). The search halves the step from T/10
    until it realises the target, then bisects log(h) between that step and the one twice
    as coarse (which did not), so that a step twice the recommended one misses the target;
    T/51200 where none down to it does. A stepping that fails at a step (no separation, a
    non-finite value) does not realise the target there."""
    passed = []  # the steps that realised the target

    def ok(h: float) -> bool:
        try:
            with np.errstate(all="ignore"):
                es, Ts = run(h)
        except (RuntimeError, ValueError, FloatingPointError, OverflowError):
            return False
        good = realises(es, Ts, e, T, tol)
        if good:
            passed.append(h)
        return good

    fine = T / _COARSEST_STEPS
    if ok(fine):
        coarse = None
    else:
        coarse = fine
        while True:
            fine = coarse / 2.0
            if T / fine > MAX_STEPS:
                return nice_down(T / MAX_STEPS)
            if ok(fine):
                break
            coarse = fine
    if coarse is not None:  # the boundary lies between fine (realises) and coarse (does not)
        for _ in range(_BISECTIONS):
            middle = math.sqrt(fine * coarse)
            if ok(middle):
                fine = middle
            else:
                coarse = middle
    # rounded down to two digits: the coarsest that still realises it (near the boundary
    # e moves with where the first touch falls, not monotonically with the step)
    for h in sorted({nice_down(h) for h in passed}, reverse=True):
        if ok(h):
            return h
    return nice_down(min(passed) / 2.0)


def unrealised(e, T, *, target_e: float, target_T, steps_per_contact, parameters: dict):
    """Why an engine cannot realise the target `target_e`, `target_T` (s) with its exported
    `parameters`, or None where it can. It cannot when (in this order):

    - a parameter is not a finite number (NaN or an overflow in the design);
    - what it realises is not an impact: e or T (s) not finite, e outside [0, 1] (0.5 % of
      slack for round-off at e = 1), T <= 0;
    - its step does not resolve the contact: fewer than `RESOLVED_STEPS` (5) steps per
      contact (`steps_per_contact`: target T over the step; None where no step applies);
    - what it realises (the mean over where first touch falls inside a step) misses the
      target e or T by more than `REFUSE_TOL` (5 %, ten times the 0.5 % that warns).

    The reason is one line naming what the engine would realise."""
    for key, value in parameters.items():
        values = value if isinstance(value, (list, tuple)) else [value]
        for v in values:
            if isinstance(v, float) and not math.isfinite(v):
                return f"its {key} is not a finite number ({v})"
    with np.errstate(all="ignore"):
        e, T = float(e), float(T)
    asked = f"e = {target_e:.4g}" + ("" if target_T is None else f", T = {target_T:.4g} s")
    got = f"it would realise e = {e:.4g}, T = {T:.4g} s instead of {asked}"
    if not (math.isfinite(e) and math.isfinite(T)) or e < 0 or e > 1 + _E_SLACK or T <= 0:
        return f"{got}, not an impact"
    if steps_per_contact is not None and steps_per_contact < RESOLVED_STEPS:
        return (
            f"its step resolves the contact in only {_floor3(steps_per_contact)} steps (T "
            f"over the step; it needs at least {RESOLVED_STEPS})"
        )
    miss_e = abs(e / target_e - 1) if target_e > 0 else abs(e)
    miss_T = 0.0 if target_T is None else abs(T / target_T - 1)
    if max(miss_e, miss_T) > REFUSE_TOL:
        return f"{got} (more than {REFUSE_TOL:.0%} off)"
    return None
