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
E_RANGE_TOL = 0.002  # half-spread of e over start phases (relative) a recommended step allows
_BIAS_TOL = 0.001  # relative error of the phase-mean e and T a recommended step allows
_WARN_TOL = 0.005  # spread or bias (relative) above which an export warns about its step
_MIN_STEPS, _MAX_STEPS = 400, 51200  # steps per contact a recommended step searches
# What an export refuses (`unrealised`): a contact resolved by fewer steps than this, or a
# realised (phase-mean) e or T further than this (relative) from the target
RESOLVED_STEPS = 5
REFUSE_TOL = 0.05


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


def nice_down(h: float) -> float:
    """`h` (s) rounded down to two significant digits (a number one types into an input)."""
    scale = 10.0 ** math.floor(math.log10(h))
    return float(f"{math.floor(h / scale * 10.0 * (1 + 1e-12)) / 10.0 * scale:.2g}")


def step_and_response(run, e: float, T: float, timestep, *, engine: str, step: str):
    """`(h, es, Ts, warnings)` for an engine whose stepping `run(h) -> (e, T)` per start phase
    realises the target `e` and `T` (s): `h` the given `timestep` (s) or, when None,
    `recommended_step`; what `run` realises at `h`; and a warning (its step called `step` in
    `engine`'s words) where e spreads or misses `e` by more than 0.5 %."""
    h = recommended_step(run, T, e) if timestep is None else float(timestep)
    es, Ts = run(h)
    warnings = []
    if (es.max() - es.min()) / 2 > _WARN_TOL * es.mean() or abs(es.mean() / e - 1) > _WARN_TOL:
        warnings.append(
            f"{step} {h:.3g} s gives {Ts.mean() / h:.0f} steps per contact: {engine} realises "
            f"e = {es.min():.4g} to {es.max():.4g} (asked {e:.4g}); use {nice_down(T / 400):.3g} s "
            "or less"
        )
    return h, es, Ts, warnings


def recommended_step(run, T: float, e: float | None = None) -> float:
    """The time step (s) an export recommends for a contact of duration `T` (s): the first of
    `nice_down(T / N)`, N = 400, 800, ... 51200 steps per contact, at which `run(h) -> (e, T)`
    per start phase spreads e by at most `E_RANGE_TOL` of its mean and, when the target `e`
    is given, whose phase means are within 0.1 % of `e` and `T`."""
    steps = _MIN_STEPS
    while True:
        h = nice_down(T / steps)
        es, Ts = run(h)
        ok = (es.max() - es.min()) / 2 <= E_RANGE_TOL * es.mean()
        if e is not None:
            ok = ok and abs(es.mean() / e - 1) < _BIAS_TOL and abs(Ts.mean() / T - 1) < _BIAS_TOL
        if ok or steps >= _MAX_STEPS:
            return h
        steps *= 2


def realised(es, Ts, h: float) -> dict:
    """What an engine stepping at `h` (s) realises, from its start phases `es`, `Ts`: the
    means `e` and `T` (s), their ranges and the steps per contact."""
    return dict(
        e=float(es.mean()),
        T=float(Ts.mean()),
        e_range=(float(es.min()), float(es.max())),
        T_range=(float(Ts.min()), float(Ts.max())),
        steps_per_contact=float(Ts.mean() / h),
        timestep=h,
    )


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
    if not (math.isfinite(e) and math.isfinite(T)) or e < 0 or e > 1 + _WARN_TOL or T <= 0:
        return f"{got}, not an impact"
    if steps_per_contact is not None and steps_per_contact < RESOLVED_STEPS:
        return (
            f"its step resolves the contact by {steps_per_contact:.2g} steps (fewer than "
            f"{RESOLVED_STEPS})"
        )
    miss_e = abs(e / target_e - 1) if target_e > 0 else abs(e)
    miss_T = 0.0 if target_T is None else abs(T / target_T - 1)
    if max(miss_e, miss_T) > REFUSE_TOL:
        return f"{got} (more than {REFUSE_TOL:.0%} off)"
    return None
