"""LAMMPS's tangential models for jaximpact's tangential laws: the `tangential ...` clause of
`pair_style granular`'s `pair_coeff` (and of `fix wall/gran granular`), which follows the
clause of any of its normal models (`hertz.py`, `jkr.py`, `jkr_viscoelastic.py`, `dmt.py`).

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

import dataclasses

from ..base import AbstractTangentialModel, Design
from . import script


@dataclasses.dataclass(frozen=True)
class Granular(AbstractTangentialModel):
    """One tangential model of LAMMPS's `pair_style granular`: its name (`model`, as
    `pair_coeff` spells it) and its spring constant, the law's `kt` (N/m) or, for Mindlin's
    models (`mindlin`: k = 8 G*, in Pa, times the contact radius), 8 times its `G_star`;
    no tangential damping (xgammat 0: LAMMPS scales it with the normal damping, which a
    constant `ct` or EDEM's `beta` does not match)."""

    model: str
    mindlin: bool = True
    MODEL = "LAMMPS's granular tangential models"
    FRICTION = None
    CONTACT_POINT = {"wall": 0.0, "spheres": 0.0}  # on the undeformed surface

    def clause(self, tangential) -> str:
        """`tangential MODEL k 0 mu` of `pair_coeff` for `tangential`."""
        params = {k: float(v) for k, v in tangential.params.items()}
        k = 8.0 * params["G_star"] if self.mindlin else params["kt"]
        return f"tangential {self.model} {k:.10g} 0 {params['mu']:.10g}"

    def check(self, tangential, *, timestep) -> None:
        params = {k: float(v) for k, v in tangential.params.items()}
        if params.get("ct", 0.0) != 0.0:
            raise ValueError(
                "LAMMPS scales its tangential damping with the normal one (xgammat), which a "
                f"constant ct = {params['ct']:g} N s/m does not match: export with ct=0"
            )
        if params.get("beta", 0.0) != 0.0:
            raise ValueError(
                "LAMMPS scales its tangential damping with the normal one (xgammat) and caps "
                "spring plus damper, not as EDEM's damper 2 (5/6)^0.5 beta (m k_t)^0.5 (beta = "
                f"{params['beta']:g}): export with beta=0"
            )

    def poisson(self, design: Design, tangential) -> None:
        return None

    def parameters(self, design: Design, tangential) -> dict:
        """The design's parameters with the clause in `pair_coeff` and `fix_wall`, after
        the normal model's (`design.clause`), and under `tangential`."""
        clause = self.clause(tangential)
        p = design.parameters
        lines = script.commands(
            design.clause, clause, wall="fix_wall" in p, limit_damping=p.get("limit_damping", False)
        )
        return {**p, "tangential": clause, **lines}

    def realised(self, parameters, tangential):
        return tangential

    def notes(self, parameters, tangential) -> list[str]:
        return []

    def oblique(self, parameters, *, m, radius, v_n, v_t):
        return None


# jaximpact tangential law -> LAMMPS tangential model: the rows of `Lammps.TANGENTIAL`
TANGENTIAL = {
    "linear_history": Granular("linear_history", mindlin=False),
    "mindlin": Granular("mindlin"),
    "mindlin_force": Granular("mindlin/force"),
    "mindlin_rescale": Granular("mindlin_rescale"),
    "mindlin_rescale_force": Granular("mindlin_rescale/force"),
}


def tangential_clause(tangential) -> str:
    """The `tangential ...` clause of `pair_coeff` (and `fix wall/gran`) for a jaximpact
    tangential law (`linear_history kt 0 mu`, kt in N/m; `mindlin 8G* 0 mu`, ...), or a
    one-line ValueError for one LAMMPS does not take."""
    model = TANGENTIAL.get(tangential.name)
    if model is None:
        raise ValueError(
            f"LAMMPS takes the tangential laws {', '.join(TANGENTIAL)}, not {tangential.name!r}"
        )
    model.check(tangential, timestep=None)
    return model.clause(tangential)
