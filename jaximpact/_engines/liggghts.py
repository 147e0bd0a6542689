"""LIGGGHTS: two equal spheres through `pair_style gran model hertz` with the material
properties as `fix property/global`, by its documented formula (not run here: LIGGGHTS has
no wheel).

LIGGGHTS doc `gran_model_hertz` (LIGGGHTS-PUBLIC 3.8): `F_n = k_n delta - gamma_n v_n`,
`k_n = 4/3 Y* sqrt(R* delta)`, `gamma_n = -2 sqrt(5/6) beta sqrt(S_n m*) >= 0`,
`S_n = 2 Y* sqrt(R* delta)`, `beta = ln e / sqrt(ln^2 e + pi^2)`, `1/Y* = (1 - nu1^2)/Y1 +
(1 - nu2^2)/Y2`, `1/R* = 1/R1 + 1/R2`, `1/m* = 1/m1 + 1/m2`. Since
`2 sqrt(5/6) sqrt(2 Y* sqrt(R*) m*) = sqrt(5) sqrt(m* 4/3 Y* sqrt(R*))`, this is LAMMPS's
`hertz/material` with `damping coeff_restitution` term for term (law `tsuji_restitution`):
the same design, the same velocity-Verlet stepping (`fix nve/sphere`). The contact lasts while
the spheres overlap (`separation="penetration"`, the coefficient given is the e realised);
`limitForce on` keeps the force non-attractive (`separation="force"`), as LAMMPS's
`limit_damping`, and the export then inverts that law as it does for LAMMPS.
"""

from . import lammps

NAME = "liggghts"
SCENE = lammps.SCENE
law = lammps.law


def design(e, T, *, m, v0, radius, poisson=0.3, timestep=None, limit_damping=False):
    out = lammps.design(
        e, T, m=m, v0=v0, radius=radius, poisson=poisson, timestep=timestep,
        limit_damping=limit_damping,
    )  # fmt: skip
    p = out["parameters"]
    out["parameters"] = {
        "pair_style": "pair_style gran model hertz tangential history"
        + (" limitForce on" if limit_damping else ""),
        "pair_coeff": "pair_coeff * *",
        "youngsModulus": (
            f"fix m1 all property/global youngsModulus peratomtype {p['youngs_modulus']:.10g}"
        ),
        "poissonsRatio": (
            f"fix m2 all property/global poissonsRatio peratomtype {p['poisson']:.10g}"
        ),
        "coefficientRestitution": (
            "fix m3 all property/global coefficientRestitution peratomtypepair 1 "
            f"{p['coeff_restitution']:.10g}"
        ),
        "coefficientFriction": "fix m4 all property/global coefficientFriction peratomtypepair 1 0",
        "timestep": p["timestep"],
        **{
            k: p[k]
            for k in ("timestep_s", "youngs_modulus", "coeff_restitution", "poisson", "k", "b")
        },
        "limitForce": limit_damping,
        "units": "units si",
    }
    return out


def snippet(parameters) -> str:
    return "\n".join(
        [
            "units si",
            "atom_style granular",
            "communicate single vel yes",
            parameters["youngsModulus"],
            parameters["poissonsRatio"],
            parameters["coefficientRestitution"],
            parameters["coefficientFriction"],
            parameters["pair_style"],
            parameters["pair_coeff"],
            "fix integr all nve/sphere",
            parameters["timestep"],
        ]
    )
