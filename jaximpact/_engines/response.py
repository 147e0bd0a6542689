"""The inverse of an export: what given engine parameters realise, as the engine's
continuous law (`engine_response`) and through its own time stepping (`stepped_response`)."""

import numpy as np

from .base import AbstractEngine, contact_mass
from .materials import check_positive
from .registry import engine as _engine
from .targets import curve


def _normal_for(chosen: AbstractEngine, parameters: dict):
    """The normal model of `chosen` that an engine's `parameters` are for: of the rows whose
    needed `KEYS` (beyond those every row needs) the parameters hold, and whose `NAME` is
    the parameters' `normal` where they name one, the one that holds the most; else the
    first row (the default design)."""
    rows = list(chosen.NORMAL.values())
    needs = [{k.name for k in model.KEYS if k.needed} for model in rows]
    common = set.intersection(*needs)
    named = parameters.get("normal")
    held = [
        (len(need - common), i)
        for i, (model, need) in enumerate(zip(rows, needs, strict=True))
        if need - common <= set(parameters) and named in (None, model.NAME)
    ]
    return rows[max(held, key=lambda h: (h[0], -h[1]), default=(0, 0))[1]]


def _inputs(engine: str, parameters: dict, m, speeds):
    """`(chosen, model, m, speeds)`: the engine `engine`, its normal model for `parameters`,
    the mass (kg) and the speeds (m/s) checked (one-line ValueErrors)."""
    chosen = _engine(engine)
    m = check_positive("m", m, "kg")
    speeds = [check_positive("speed", v, "m/s") for v in np.atleast_1d(speeds)]
    return chosen, _normal_for(chosen, parameters), m, speeds


def engine_response(engine: str, parameters: dict, *, m, speeds, radius=None):
    """The inverse: e(v) and T(v) (continuous law of the engine) that given engine parameters
    produce, for a body of mass `m` (kg; two-sphere engines: each sphere) at each speed of
    `speeds` (m/s). Parameters: the names of the engine's `KEYS` (MuJoCo `solref`,
    `timestep` for refsafe; LAMMPS, LIGGGHTS, Chrono `E` (Pa), `coeff_restitution`,
    `poisson`, `limit_damping`; Yade `tc` (s), `en`; Drake `point_contact_stiffness` (N/m),
    `hunt_crossley_dissipation` (s/m)); `"geometry": "wall"` (LAMMPS, LIGGGHTS, Chrono,
    Yade): one sphere on a wall of its material. The step is not part of this answer:
    `stepped_response` gives what the stepping realises. Returns `(law, separation, e, T)`."""
    chosen, model, m, speeds = _inputs(engine, parameters, m, speeds)
    law, separation = model.response(parameters, m=m, radius=radius)
    e, T = curve(law, contact_mass(chosen, m, parameters.get("geometry")), speeds, separation)
    return law, separation, e, T


def stepped_response(engine: str, parameters: dict, *, m, speeds, radius=None):
    """What the engine's own time stepping realises with `parameters` at each speed (m/s):
    `(timestep, e, T, e_min, e_max)`, e and T the mean over where the first touch falls
    inside a step and `e_min`, `e_max` their extremes. Modelled (replicas checked against
    the engines): MuJoCo at its `timestep` (default 0.002 s), LAMMPS and LIGGGHTS with a
    `timestep` (velocity Verlet), Yade with a `timestep` (leapfrog, and its NewtonIntegrator
    `damping`, default 0 here), Drake with `time_step > 0` (its implicit discrete step, the
    Lagged, Similar and TAMSI approximations). `None` where the step does not apply or is
    not known: a two-sphere engine without a `timestep`, Drake's continuous plant
    (error-controlled integration: no step error), and Chrono (its stepper not modelled);
    each engine's `STEPPING` says which."""
    _, model, m, speeds = _inputs(engine, parameters, m, speeds)
    stepping = model.stepper(parameters, m=m, radius=radius)
    if stepping is None:
        return None
    runs = [stepping.run(v) for v in speeds]
    return (
        stepping.timestep,
        [float(np.mean(es)) for es, _ in runs],
        [float(np.mean(Ts)) for _, Ts in runs],
        [float(np.min(es)) for es, _ in runs],
        [float(np.max(es)) for es, _ in runs],
    )
