"""The inverse of an export: what engine parameters realise, continuously (`engine_response`)
and through the engine's stepping (`stepped_response`)."""

import numpy as np

from .base import AbstractEngine, contact_mass
from .materials import check_positive
from .registry import engine as _engine
from .targets import curve


def _normal_for(chosen: AbstractEngine, parameters: dict):
    """The normal model `parameters` are for: of the rows whose own needed keys they hold (and
    `NAME` their `normal`, where named), the one with most; else the first."""
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
    """`(chosen, model, m, speeds)`, checked."""
    chosen = _engine(engine)
    m = check_positive("m", m, "kg")
    speeds = [check_positive("speed", v, "m/s") for v in np.atleast_1d(speeds)]
    return chosen, _normal_for(chosen, parameters), m, speeds


def engine_response(engine: str, parameters: dict, *, m, speeds, radius=None):
    """`(law, separation, e, T)`: the engine's continuous law for `parameters` (its `KEYS`;
    `"geometry": "wall"`: one sphere on a wall), for mass `m` (kg, each sphere's), and its e
    and T (s) at `speeds` (m/s). `stepped_response` adds the stepping."""
    chosen, model, m, speeds = _inputs(engine, parameters, m, speeds)
    law, separation = model.response(parameters, m=m, radius=radius)
    e, T = curve(law, contact_mass(chosen, m, parameters.get("geometry")), speeds, separation)
    return law, separation, e, T


def stepped_response(engine: str, parameters: dict, *, m, speeds, radius=None):
    """`(timestep, e, T, e_min, e_max)`: what the engine's stepping realises with
    `parameters` at `speeds` (m/s), phase means and e's extremes; None where no stepping
    applies or is replicated (each engine's `STEPPING` says which)."""
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
