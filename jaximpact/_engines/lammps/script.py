"""What LAMMPS's normal models (`hertz.py`: hertz/material; `jkr.py`, `jkr_viscoelastic.py`,
`dmt.py`) share: the script of an export's scene (`snippet`), the commands that join a
normal and a tangential clause (`commands`), the effective mass and radius of its contact
(`effective`, `contact_mass`, `with_effective_radius`), the parameters of a `pair_style
granular` design (`granular_parameters`), and for the cohesive models their scenes, checked
inputs, Hertz groups, stepped design and stepper (`cohesive_scenes`, `material`,
`hertz_groups`, `cohesive_design`, `cohesive_stepper`)."""

import math

from .. import _stepping
from ..base import Design, Key, Stepping, sphere_radius
from ..materials import check_poisson, check_positive

# the keys every LAMMPS normal model shares (`AbstractNormalModel.KEYS`)
DAMP = Key("damp", "1/(m s), viscoelastic damping: b = damp meff Reff^0.5")
COHESION = Key("cohesion", "J/m^2, the surface energy (half the work of adhesion)")
POISSON = Key("poisson", "default 0.3", needed=False)
TIMESTEP = Key("timestep", "s; without it, no stepping", needed=False)

# LAMMPS's granular pair requires a tangential model: without a tangential law, the
# frictionless one
FRICTIONLESS = "tangential linear_nohistory 0 0"


def snippet(parameters) -> str:
    """The LAMMPS commands of a design's `parameters`: units, atom style, its pair style and
    coefficients (and wall, for the drop test), `fix nve/sphere` and the time step."""
    return "\n".join(
        [
            "units si",
            "atom_style sphere",
            "comm_modify vel yes",
            parameters["pair_style"],
            parameters["pair_coeff"],
            *([parameters["fix_wall"]] if parameters.get("fix_wall") else []),
            "fix 1 all nve/sphere",
            parameters["timestep"],
        ]
    )


def commands(normal: str, tangential: str, *, limit_damping: bool, wall: bool) -> dict:
    """`pair_coeff` (and with `wall` the `fix wall/gran` on the plane z = 0) of the normal
    model's clause `normal` (`hertz/material ...`) and the `tangential` clause, as LAMMPS's
    own `pair_coeff` reads them, `limit_damping` last."""
    text = f"{normal} {tangential}" + (" limit_damping" if limit_damping else "")
    out = {"pair_coeff": f"pair_coeff * * {text}"}
    if wall:
        out["fix_wall"] = f"fix wall all wall/gran granular {text} zplane 0.0 NULL"
    return out


def with_effective_radius(parameters, radius) -> dict:
    """`parameters` with `R_eff` (m) from the spheres' `radius` (m) where not given: `R` on
    a wall (`geometry` "wall"), `R/2` between two spheres; a one-line ValueError without a
    radius."""
    if parameters.get("R_eff") is not None:
        return dict(parameters)
    geometry = parameters.get("geometry", "spheres")
    radius = sphere_radius("lammps", radius, geometry)
    return {**parameters, "R_eff": radius if geometry == "wall" else radius / 2.0}


def granular_parameters(
    clause: str,
    h: float,
    *,
    E: float,
    poisson: float,
    wall: bool,
    R_eff: float | None = None,
    **model,
) -> dict:
    """An export's `parameters` for LAMMPS's `pair_style granular` with the normal model's
    `clause` and no tangential force, at time step `h` (s): the commands, Young's modulus
    `E` (Pa), `poisson`, `R_eff` (m, where the model has one), the model's own values
    (`model`, SI units), and with `wall` the `fix wall/gran` on the plane z = 0."""
    lines = commands(
        clause, FRICTIONLESS, limit_damping=model.get("limit_damping", False), wall=wall
    )
    parameters = {
        "pair_style": "pair_style granular",
        "pair_coeff": lines["pair_coeff"],
        "timestep": f"timestep {h:.6g}",
        "timestep_s": h,
        "youngs_modulus": E,
        "poisson": poisson,
        **model,
        **({} if R_eff is None else {"R_eff": R_eff}),
        "units": "units si",
    }
    if wall:
        parameters["fix_wall"] = lines["fix_wall"]
        parameters["geometry"] = "wall"
    return parameters


def effective(m: float, radius: float, geometry: str = "spheres") -> tuple[float, float]:
    """`(m_eff, R_eff)` of the contact: two equal spheres (`m/2`, `R/2`) or a sphere on a
    flat wall (`m`, `R`: `fix wall/gran` takes the particle's own mass and radius, the wall's
    curvature radius being 0 for a plane; src/GRANULAR/fix_wall_gran.cpp). Both have
    `E_eff = E/(2 (1 - nu^2))`: the pair mixes two spheres of one material, and the wall's
    `mix_stiffnessE_wall(E, nu)` (src/GRANULAR/gran_sub_mod.cpp) gives the same, i.e. the
    wall is of the sphere's own material, not rigid."""
    if geometry == "wall":
        return m, radius
    return m / 2.0, radius / 2.0


def contact_mass(parameters, m: float) -> float:
    """The effective mass (kg) of `parameters`' contact: `m` on a wall (`geometry` "wall"),
    else `m/2` (two spheres of mass `m`)."""
    return m if parameters.get("geometry", "spheres") == "wall" else m / 2.0


def emix(E: float, poisson: float) -> float:
    """LAMMPS's `Emix` (Pa) of one material, `E / (2 (1 - nu^2))`, pair and wall alike."""
    return E / (2.0 * (1.0 - poisson) * (1.0 + poisson))


def _non_negative(name: str, value, unit: str) -> float:
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a finite number >= 0 {unit}, got {value!r}")
    return float(value)


def material(parameters, *, damped: bool, adhesive: bool = True) -> tuple[float, ...]:
    """`(E, poisson, cohesion)`, with `damped` also `damp`, of a cohesive model's
    `parameters` (`E` or an export's `youngs_modulus`, Pa; `cohesion` J/m^2, > 0 where
    `adhesive`, else >= 0; `damp` >= 0, 1/(m s)), checked (one-line ValueErrors)."""
    E = check_positive("E", parameters.get("E", parameters.get("youngs_modulus")), "Pa")
    nu = check_poisson("poisson", parameters.get("poisson", 0.3))
    cohesion = parameters["cohesion"]
    if adhesive:
        cohesion = check_positive("cohesion", cohesion, "J/m^2")
    else:
        cohesion = _non_negative("cohesion", cohesion, "J/m^2")
    damp = (_non_negative("damp", parameters["damp"], "(1/(m s))"),) if damped else ()
    return E, nu, cohesion, *damp


def hertz_groups(parameters, m: float, E: float, nu: float, damp: float = 0.0):
    """`(c, b, R_eff)` of a cohesive contact's `parameters` (`R_eff` m) for spheres of mass
    `m` (kg): LAMMPS's `c = 4/3 Emix Reff^0.5` (N/m^1.5) and `b = damp meff Reff^0.5`
    (N s/m^1.5) of Young's modulus `E` (Pa), Poisson's ratio `nu` and `damp` (1/(m s))."""
    R_eff = check_positive("R_eff", parameters["R_eff"], "m")
    root = math.sqrt(R_eff)
    return 4.0 / 3.0 * emix(E, nu) * root, damp * contact_mass(parameters, m) * root, R_eff


def cohesive_scenes(model: str, wall_model: str, extra: str = "") -> dict:
    """A cohesive model's `SCENES`: the `pair_style granular` `model` between two spheres,
    `fix wall/gran granular wall_model` for the wall, `extra` after "no gravity"."""
    return {
        "spheres": "two equal spheres, each of mass m and radius `radius`, colliding head-on at "
        f"relative speed v0 (pair_style granular, {model}; no gravity{extra})",
        "wall": "a sphere of mass m and radius `radius` hitting a fixed flat wall (fix "
        f"wall/gran granular {wall_model}, the sphere's own material) head-on at speed v0 (no "
        f"gravity{extra})",
    }


def cohesive_design(
    replica, clause: str, scene, stepping: dict, *, e, T, timestep, separation, note, **shown
) -> Design:
    """The `Design` of a cohesive model (`jkr`, damped `jkr`, `dmt`) with the model's
    `clause` in `scene`: the replica's `stepping` parameters (`E` Pa, `poisson`, `R_eff` m,
    the model's own; the wall's geometry added) at the time step that realises `e` and `T`
    (s) at `scene.v0`, or at the `timestep` given (`_stepping.replicated`), the
    model's `note` (a warning, or None) after the stepping's, and `shown` (the model's own
    values, SI units) among its parameters."""
    stepping, es, Ts, warnings = _stepping.replicated(
        replica, stepping, scene, e, T, timestep, engine="LAMMPS", step="timestep"
    )
    h, E, poisson, R_eff = (stepping[k] for k in ("timestep", "E", "poisson", "R_eff"))
    parameters = granular_parameters(
        clause, h, E=E, poisson=poisson, R_eff=R_eff, wall=scene.wall, **shown
    )
    warnings += [note] if note else []
    return Design.stepped(parameters, es, Ts, h, warnings, separation, stepping, clause=clause)


def cohesive_stepper(replica, check, parameters, *, m, radius) -> Stepping | None:
    """`replica` at `parameters["timestep"]` (s), `parameters` with their effective radius
    and checked by `check`, or None without a timestep."""
    if parameters.get("timestep") is None:
        return None
    h = check_positive("timestep", parameters["timestep"], "s")
    full = {**with_effective_radius(parameters, radius), "timestep": h}
    check(full)
    return Stepping(h, lambda v: replica(full, m, v))
