"""Replicas of the engines' time stepping of one head-on contact (numpy; tests/engines checks
them against the engines), and the step an export recommends. Each contact starts at
`PHASES` inside a step (first touch `phase * h` after its start): e depends on it."""

import math

import numpy as np

PHASES = (np.arange(16) + 0.5) / 16
STEP_TOL = 0.005  # the recommended step's tolerance (relative; `realises`)
_COARSEST_STEPS, MAX_STEPS = 10, 51200  # steps per contact a recommended step searches
_BISECTIONS = 5  # halvings of log(h) between a step that realises and one twice as coarse
RESOLVED_STEPS, REFUSE_TOL = 5, 0.05  # what an export refuses (`unrealised`)
_E_SLACK = 0.005  # e above 1 by less than this is round-off, not a gain of energy


def step_until_separated(step, h, v0, phases=PHASES, max_steps=2_000_000):
    """`(e, T)` per start phase of a contact stepped by `step(x, v) -> (x1, v1, pushing)`
    (penetration m, approach speed m/s) from `x = -phase v0 h` until the force is zero again;
    `T` (s): the steps with a force times `h`."""
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
    """MuJoCo's Euler: `a = accel(x, v)` while `x > 0`, `v += h a`, `x += h v`."""

    def step(x, v):
        a = np.where(x > 0, accel(np.maximum(x, 0.0), v), 0.0)
        v_new = v + h * a
        return x + h * v_new, v_new, a != 0

    return step_until_separated(step, h, v0, phases, max_steps)


def velocity_verlet(accel, h, v0, phases=PHASES, max_steps=2_000_000):
    """LAMMPS's `fix nve/sphere`: half kick, drift, force at the new positions and half-step
    velocities, half kick."""
    a = np.zeros(np.shape(phases))

    def step(x, v):
        nonlocal a
        v_half = v + 0.5 * h * a
        x_new = x + h * v_half
        a = np.where(x_new > 0, accel(np.maximum(x_new, 0.0), v_half), 0.0)
        return x_new, v_half + 0.5 * h * a, a != 0

    return step_until_separated(step, h, v0, phases, max_steps)


def cohesive_verlet(force, holds, h, m_eff, v0, phases=PHASES, max_steps=10_000_000):
    """`velocity_verlet` on a cohesive contact (`jkr`, `dmt`): `force(x, v)` (N, pushing
    apart), `holds(x, attached)` whether the contact exists at `x`, mass `m_eff` (kg). A body
    held (turning back in before it lets go) gives `e = 0`, T the steps until then."""
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
    """`x` > 0 rounded down to three digits, as text (4.9996 reads 4.99, not 5)."""
    if not (x > 0 and math.isfinite(x)):
        return f"{x:g}"
    scale = 10.0 ** (math.floor(math.log10(x)) - 2)
    return f"{math.floor(x / scale * (1 + 1e-12)) * scale:.3g}"


def nice_down(h: float) -> float:
    """`h` (s) rounded down to two significant digits (a number one types into an input)."""
    scale = 10.0 ** math.floor(math.log10(h))
    return float(f"{math.floor(h / scale * 10.0 * (1 + 1e-12)) / 10.0 * scale:.2g}")


def realises(es, Ts, e: float | None, T: float, tol: float = STEP_TOL) -> bool:
    """Whether every phase's e is within `tol` (relative) of `e` and the phase-mean T of `T`
    (s); `e` None: of their own mean, T not judged (MuJoCo corrects its means after)."""
    es, Ts = np.asarray(es, float), np.asarray(Ts, float)
    if not (np.all(np.isfinite(es)) and np.all(np.isfinite(Ts))):
        return False
    if e is None:
        centre = float(es.mean())
        return centre > 0 and bool(np.all(np.abs(es - centre) <= tol * centre))
    e_ok = np.all(np.abs(es - e) <= tol * e) if e > 0 else np.all(es == 0.0)
    return bool(e_ok) and abs(float(Ts.mean()) / T - 1.0) <= tol


def per_contact(h: float, T: float) -> str:
    """`"T/45"`: the step `h` (s) as a share of `T` (s), below 10 rounded down (`_floor3`)."""
    steps = T / h
    return f"T/{steps:.0f}" if steps >= 10 else f"T/{_floor3(steps)}"


def describe_step(h: float, T: float | None) -> str:
    """`"1.1e-06 s (T/45)"`: `h` (s) with `per_contact` where `T` (s) is given."""
    if not T or not h:
        return f"{h:.3g} s"
    return f"{h:.3g} s ({per_contact(h, T)})"


def replicated(replica, params: dict, scene, e: float, T: float, timestep, *, engine, step):
    """`(params, es, Ts, warnings)`: `params` at `timestep` (s; None: `recommended_step`),
    what `replica(params, m, v0)` realises there in `scene`, and a warning where that misses
    `STEP_TOL` (its step named `step` in `engine`'s words)."""
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
    """The coarsest step (s, `nice_down`) at which `run(h) -> (e, T)` per phase `realises`
    the target: halving from T/10 until it does, then bisecting log(h) against the step
    twice as coarse; T/51200 where none does. A step that fails does not realise it."""
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
    """Why the engine cannot realise `target_e`, `target_T` (s) with `parameters`, in one
    line, or None: a parameter not finite; no impact (e or T not finite, e outside [0, 1]
    with `_E_SLACK`, T <= 0); fewer than `RESOLVED_STEPS` steps per contact; or the phase-mean
    e or T more than `REFUSE_TOL` off."""
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
