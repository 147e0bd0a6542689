"""LAMMPS's tangential models for jaximpact's tangential laws: the `tangential ...` clause of
`pair_style granular`'s `pair_coeff` (and of `fix wall/gran granular`), shared by the Hertz
and the JKR normal models (`lammps.py`, `lammps_jkr.py`).

LAMMPS doc pair_granular; src/GRANULAR/gran_sub_mod_tangential.cpp (release 22Jul2025):
`linear_history` is a spring with displacement history `F_t = -k xi`; `mindlin`,
`F_t = -k a xi` with the contact radius `a = (R x)^0.5`; `mindlin/force`, the force history
`dF_t = -k a dxi`; `mindlin_rescale` and `mindlin_rescale/force` the same with the history
scaled by `a_new / a_old` at each step where the contact radius shrinks; each capped at
`mu |F_n|` (the normal force with its damping), the history rescaled to the cap while
sliding. These are the equations of jaximpact's `linear_history`, `mindlin`,
`mindlin_force`, `mindlin_rescale` and `mindlin_rescale_force` (`k = kt`, or `k = 8 G*`),
whose spring is
set to the limit it was held at when it sticks again. LAMMPS's own `k = NULL` for a wall
is `8 E / (4 (2 - nu)(1 + nu))`, the G* of a sphere on a wall of its own material; the
export writes `k` itself, so any G* goes.
"""

NO_TANGENTIAL = "tangential linear_nohistory 0 0"
# jaximpact tangential law -> LAMMPS tangential model
TANGENTIAL_MODELS = {"linear_history": "linear_history", "mindlin": "mindlin",
                     "mindlin_force": "mindlin/force", "mindlin_rescale": "mindlin_rescale",
                     "mindlin_rescale_force": "mindlin_rescale/force"}  # fmt: skip


def tangential_clause(tangential) -> str:
    """The `tangential ...` clause of `pair_coeff` (and `fix wall/gran`) for a jaximpact
    tangential law: `linear_history kt 0 mu` (kt in N/m), `mindlin 8G* 0 mu` and
    `mindlin/force 8G* 0 mu` (LAMMPS's k = 8 G*, in Pa, times the contact radius
    `(R x)^0.5`: Mindlin's `k_t = 8 G* (R x)^0.5`), no tangential damping (xgammat 0:
    LAMMPS scales it with the normal damping, which a constant `ct` does not match)."""
    name = tangential.name
    if name not in TANGENTIAL_MODELS:
        raise ValueError(
            f"LAMMPS takes the tangential laws {', '.join(TANGENTIAL_MODELS)}, not {name!r}"
        )
    params = {k: float(v) for k, v in tangential.params.items()}
    if params.get("ct", 0.0) != 0.0:
        raise ValueError(
            "LAMMPS scales its tangential damping with the normal one (xgammat), which a "
            f"constant ct = {params['ct']:g} N s/m does not match: export with ct=0"
        )
    if params.get("beta", 0.0) != 0.0:
        raise ValueError(
            "LAMMPS scales its tangential damping with the normal one (xgammat) and caps spring "
            f"plus damper, not as EDEM's damper 2 (5/6)^0.5 beta (m k_t)^0.5 (beta = "
            f"{params['beta']:g}): export with beta=0"
        )
    k = params["kt"] if name == "linear_history" else 8.0 * params["G_star"]
    return f"tangential {TANGENTIAL_MODELS[name]} {k:.10g} 0 {params['mu']:.10g}"


def with_tangential(parameters: dict, tangential) -> dict:
    """A design's `parameters` with `tangential_clause(tangential)` in `pair_coeff` and
    `fix_wall` in place of no tangential force, and under `tangential`."""
    clause = tangential_clause(tangential)
    out = dict(parameters, tangential=clause)
    for key in ("pair_coeff", "fix_wall"):
        if key in out:
            assert NO_TANGENTIAL in out[key]
            out[key] = out[key].replace(NO_TANGENTIAL, clause)
    return out
