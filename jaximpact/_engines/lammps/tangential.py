"""LAMMPS's tangential models: the `tangential ...` clause after any normal model's in
`pair_coeff` (and `fix wall/gran granular`). src/GRANULAR/gran_sub_mod_tangential.cpp
(22Jul2025): `linear_history` `F_t = -k xi`; `mindlin` `F_t = -k a xi`, `a = (R x)^0.5`;
`mindlin/force` `dF_t = -k a dxi`; the `_rescale` ones scale the history by `a_new / a_old`
where `a` shrinks; each capped at `mu |F_n|`, the history rescaled to the cap while sliding:
jaximpact's laws of those names (`k = kt`, or `8 G*`). The export writes `k` (LAMMPS's
`NULL` is a wall of the sphere's material), so any G* goes."""

import dataclasses

from ..base import AbstractTangentialModel, Design
from . import script


@dataclasses.dataclass(frozen=True)
class Granular(AbstractTangentialModel):
    """One tangential `model` (as `pair_coeff` spells it), its k the law's `kt` (N/m) or with
    `mindlin` `8 G_star` (Pa); no damping (xgammat 0: LAMMPS scales it with the normal
    damping, as neither `ct` nor EDEM's `beta` does)."""

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


TANGENTIAL = {
    "linear_history": Granular("linear_history", mindlin=False),
    "mindlin": Granular("mindlin"),
    "mindlin_force": Granular("mindlin/force"),
    "mindlin_rescale": Granular("mindlin_rescale"),
    "mindlin_rescale_force": Granular("mindlin_rescale/force"),
}


def tangential_clause(tangential) -> str:
    """The `tangential ...` clause for a tangential law, or a one-line ValueError."""
    model = TANGENTIAL.get(tangential.name)
    if model is None:
        raise ValueError(
            f"LAMMPS takes the tangential laws {', '.join(TANGENTIAL)}, not {tangential.name!r}"
        )
    model.check(tangential, timestep=None)
    return model.clause(tangential)
