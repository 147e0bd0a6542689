"""LIGGGHTS's `pair_style gran model hertz`, the material as `fix property/global` (checked
against LIGGGHTS 3.8.0 in tests/engines). LIGGGHTS-PUBLIC 3.8 (3d5c00f),
`src/normal_model_hertz.h` lines 231-261: `kn = 4/3 Y* sqrt(R* delta)`, `Sn = 2 Y* sqrt(R*
delta)`, `gamman = -2 sqrt(5/6) betaeff sqrt(Sn meff)`, `Fn = kn delta - gamman vn` (zero where
negative with `limitForce`); `src/global_properties.cpp`: `1/Y* = (1 - nu1^2)/Y1 + (1 -
nu2^2)/Y2`, `betaeff = ln e / sqrt(ln^2 e + pi^2)`: LAMMPS's `hertz/material` with `damping
coeff_restitution` term for term, the same design and stepping (`limitForce on` is
`limit_damping`). Its sanity checks: `0.05 < coefficientRestitution <= 1`, `0 <=
poissonsRatio <= 0.5`, `5e6 <= youngsModulus <= 1e9` Pa unless `soft_particles yes` /
`hard_particles yes` (the snippet adds the line)."""

import dataclasses

from ..base import AbstractNormalModel, Design, Stepping
from ..lammps import hertz

MIN_COEFFICIENT = 0.05  # createCoeffRest: "0.05 < coefficientRestitution <= 1 required"
_DESIGN_KEYS = (  # the values of LAMMPS's design an export keeps (and tangential.py)
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
    """The line LIGGGHTS needs for a modulus outside [5e6, 1e9] Pa (`createYoungsModulus`)."""
    if youngs_modulus > 1e9:
        return "hard_particles yes"
    if youngs_modulus < 5e6:
        return "soft_particles yes"
    return None


def render(p: dict, limit_damping: bool, extra: str | None, wall: bool) -> dict:
    """LAMMPS's design values `p` in LIGGGHTS's words (`extra`: the sanity-range line; `wall`:
    the primitive wall z = 0; `p`'s `friction` from tangential.py)."""
    settings = " limitForce on" if limit_damping else ""  # after the models
    if p.get("friction") is not None and not p["tangential_damping"]:
        settings += " tangential_damping off"
    pair = "peratomtypepair 1"
    material = (
        ("youngsModulus", "peratomtype", p["youngs_modulus"]),
        ("poissonsRatio", "peratomtype", p["poisson"]),
        ("coefficientRestitution", pair, p["coeff_restitution"]),
        ("coefficientFriction", pair, p.get("friction") or 0),
    )
    parameters = {
        "pair_style": "pair_style gran model hertz tangential history" + settings,
        "pair_coeff": "pair_coeff * *",
        **{
            name: f"fix m{i} all property/global {name} {kind} {value:.10g}"
            for i, (name, kind, value) in enumerate(material, 1)
        },
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
    """LIGGGHTS's `model hertz`: LAMMPS's `hertz/material` in its words (the module's
    docstring)."""

    NAME = "hertz"
    LAW = hertz.HertzMaterial.LAW
    KEYS = hertz.HertzMaterial.KEYS  # limit_damping: its limitForce
    STEPPING = hertz.HertzMaterial.STEPPING  # fix nve/sphere: the same velocity Verlet
    MASS_DEPENDS = "its youngsModulus scales with the mass"
    ALLOWS_LIMIT_DAMPING = True
    NEAREST = "its tsuji law"
    SCENES = None

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        """LAMMPS's design; on a wall, a primitive `fix wall/gran` of the sphere's type (`reff =
        radi`, `Y* = Y/(2 (1 - nu^2))`): LAMMPS's wall term for term."""
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
        return _LAMMPS.law_parameters(parameters, m)

    def response(self, parameters, *, m, radius=None):
        clamped = bool(parameters.get("limit_damping", False))
        return hertz.tsuji_response("liggghts", parameters, m=m, radius=radius, clamped=clamped)

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        return _LAMMPS.stepper(parameters, m=m, radius=radius)
