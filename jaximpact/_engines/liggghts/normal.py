"""LIGGGHTS: two equal spheres through `pair_style gran model hertz` with the material
properties as `fix property/global`, by its source; checked against LIGGGHTS 3.8.0 (Debian's
`liggghts` package) in tests/engines.

LIGGGHTS-PUBLIC 3.8 (commit 3d5c00f), `src/normal_model_hertz.h`,
`NormalModel<HERTZ>::surfacesIntersect` (lines 231-261): `kn = 4/3 Y* sqrt(R* delta)`,
`Sn = 2 Y* sqrt(R* delta)`, `gamman = -2 sqrt(5/6) betaeff sqrt(Sn meff)`,
`Fn = kn delta - gamman vn`, set to 0 when negative if `limitForce` is on;
`src/global_properties.cpp`: `createYeff` `1/Y* = (1 - nu1^2)/Y1 + (1 - nu2^2)/Y2`,
`createBetaEff` `betaeff = ln e / sqrt(ln^2 e + pi^2)`; `reff = ri rj/(ri + rj)`,
`meff = mi mj/(mi + mj)`. Since `2 sqrt(5/6) sqrt(2 Y* sqrt(R*) m*) = sqrt(5) sqrt(m* 4/3 Y*
sqrt(R*))`, this is LAMMPS's `hertz/material` with `damping coeff_restitution` term for term
(law `tsuji_restitution`): the same design, the same velocity-Verlet stepping
(`fix nve/sphere`). The contact lasts while the spheres overlap (`separation="penetration"`,
the coefficient given is the e realised); `limitForce on` keeps the force non-attractive
(`separation="force"`), as LAMMPS's `limit_damping`, and the export then inverts that law.
Sanity checks (`global_properties.cpp`): `0.05 < coefficientRestitution <= 1`,
`0 <= poissonsRatio <= 0.5`, and in SI `5e6 <= youngsModulus <= 1e9` Pa unless
`soft_particles yes` / `hard_particles yes` (the snippet adds the line when needed).
"""

import dataclasses

from ..base import AbstractNormalModel, Design, Stepping
from ..lammps import hertz

MIN_COEFFICIENT = 0.05  # createCoeffRest: "0.05 < coefficientRestitution <= 1 required"
# the values of LAMMPS's design a LIGGGHTS export keeps (and of tangential.py)
_DESIGN_KEYS = (
    "timestep",
    "timestep_s",
    "youngs_modulus",
    "coeff_restitution",
    "poisson",
    "k",
    "b",
    "friction",
    "G_star",
    "tangential_beta",
    "tangential_damping",
)
_LAMMPS = hertz.HertzMaterial()  # the same contact, design and stepping, in other words


def particle_range_line(youngs_modulus: float) -> str | None:
    """The line LIGGGHTS needs for a modulus outside its SI sanity range [5e6, 1e9] Pa
    (`src/global_properties.cpp`, `createYoungsModulus`), or None."""
    if youngs_modulus > 1e9:
        return "hard_particles yes"
    if youngs_modulus < 5e6:
        return "soft_particles yes"
    return None


def render(p: dict, limit_damping: bool, extra: str | None, wall: bool) -> dict:
    """LAMMPS's design parameters `p` in LIGGGHTS's words: `fix property/global` lines for
    the material, `pair_style gran model hertz`, `limitForce` for `limit_damping`, the
    sanity-range line `extra`, and with `wall` the primitive wall z = 0; with `p`'s
    `friction` (tangential.py) its coefficientFriction and, for an undamped
    tangential law, `tangential_damping off`."""
    settings = " limitForce on" if limit_damping else ""  # after the models
    if p.get("friction") is not None and not p["tangential_damping"]:
        settings += " tangential_damping off"
    parameters = {
        "pair_style": "pair_style gran model hertz tangential history" + settings,
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
        "coefficientFriction": (
            "fix m4 all property/global coefficientFriction peratomtypepair 1 "
            f"{p.get('friction') or 0:.10g}"
        ),
        "timestep": p["timestep"],
        **{k: p[k] for k in _DESIGN_KEYS if k in p},
        "limitForce": limit_damping,
        "units": "units si",
        "particle_range": extra,
    }
    if wall:
        parameters["fix_wall"] = (
            "fix wall all wall/gran model hertz tangential history primitive type 1 zplane 0.0"
            + settings  # after the wall, or it is refused
        )
        parameters["geometry"] = "wall"
    return parameters


class Hertz(AbstractNormalModel):
    """LIGGGHTS's `pair_style gran model hertz` with the material as `fix property/global`:
    LAMMPS's `hertz/material` contact term for term, in LIGGGHTS's words and within its
    sanity checks (the module's docstring has the sources)."""

    NAME = "hertz"
    LAW = hertz.HertzMaterial.LAW
    KEYS = hertz.HertzMaterial.KEYS  # limit_damping: its limitForce
    STEPPING = hertz.HertzMaterial.STEPPING  # fix nve/sphere: the same velocity Verlet
    MASS_DEPENDS = "its youngsModulus scales with the mass"
    ALLOWS_LIMIT_DAMPING = True
    NEAREST = "its tsuji law"
    SCENES = None

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        """LAMMPS's design in LIGGGHTS's names. `geometry="wall"`: a sphere on a primitive
        `fix wall/gran` of its own material (atom type 1). Its contact, `fix_wall_gran.cpp`
        and `normal_model_hertz.h`: the particle's own mass and radius (`reff = radi` on a
        wall), `Y*` from the sphere's type and the wall's (`createYeff`, type 1 with type 1:
        `Y/(2 (1 - nu^2))`), i.e. LAMMPS's `fix wall/gran` term for term (checked: the two
        engines give the same e and T to every digit printed)."""
        if poisson < 0:
            raise ValueError(f"LIGGGHTS requires 0 <= poissonsRatio <= 0.5, got {poisson:g}")
        out = _LAMMPS.design(
            e, T, scene, poisson=poisson, timestep=timestep, limit_damping=limit_damping
        )
        p = out.parameters
        if p["coeff_restitution"] <= MIN_COEFFICIENT:
            separation = "force" if limit_damping else "penetration"
            floor = hertz.impact_at_unit_scales(MIN_COEFFICIENT, separation)[0]
            raise ValueError(
                f"LIGGGHTS cannot realise e = {e:g}: it refuses coefficientRestitution <= 0.05 "
                f"(src/global_properties.cpp), whose e is {floor:.4g}"
                + (" with limitForce on" if limit_damping else "")
            )
        extra = particle_range_line(p["youngs_modulus"])
        warnings = out.warnings
        if extra:
            warnings += (
                f"youngsModulus {p['youngs_modulus']:.4g} Pa is outside LIGGGHTS's SI sanity "
                f"range [5e6, 1e9] Pa: the snippet adds '{extra}'",
            )
        parameters = render(p, limit_damping, extra, scene.wall)
        return dataclasses.replace(out, parameters=parameters, warnings=warnings, clause=None)

    def law_parameters(self, parameters, m):
        """As LAMMPS's: `tsuji`'s `c` = k and `b`."""
        return _LAMMPS.law_parameters(parameters, m)

    def response(self, parameters, *, m, radius=None):
        """`(law, separation)`: as LAMMPS's (`limit_damping` is `limitForce on`)."""
        clamped = bool(parameters.get("limit_damping", False))
        return hertz.tsuji_response("liggghts", parameters, m=m, radius=radius, clamped=clamped)

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        """`fix nve/sphere`: LAMMPS's velocity Verlet."""
        return _LAMMPS.stepper(parameters, m=m, radius=radius)
