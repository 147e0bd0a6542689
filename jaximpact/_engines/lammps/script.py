"""What LAMMPS's normal models share: the script (`snippet`, `commands`), the contact's
effective mass and radius, a `pair_style granular` design's parameters, and the cohesive
models' (`jkr`, damped `jkr`, `dmt`) scenes, inputs, design and stepper."""

import math

from .. import _stepping
from ..base import Design, Key, Stepping, sphere_radius
from ..materials import check_poisson, check_positive

DAMP = Key("damp", "1/(m s), viscoelastic damping: b = damp meff Reff^0.5")
COHESION = Key("cohesion", "J/m^2, the surface energy (half the work of adhesion)")
POISSON = Key("poisson", "default 0.3", needed=False)
TIMESTEP = Key("timestep", "s; without it, no stepping", needed=False)

# pair_style granular requires a tangential model: without a tangential law, this one
FRICTIONLESS = "tangential linear_nohistory 0 0"


def snippet(parameters) -> str:
    """The LAMMPS script of a design's `parameters`."""
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
    """`pair_coeff` (and with `wall` the `fix wall/gran` at z = 0) of the `normal` and
    `tangential` clauses, `limit_damping` last."""
    text = f"{normal} {tangential}" + (" limit_damping" if limit_damping else "")
    out = {"pair_coeff": f"pair_coeff * * {text}"}
    if wall:
        out["fix_wall"] = f"fix wall all wall/gran granular {text} zplane 0.0 NULL"
    return out


def with_effective_radius(parameters, radius) -> dict:
    """`parameters` with `R_eff` (m) from `radius` (m) where not given: `R` on a wall, else
    `R/2`."""
    if parameters.get("R_eff") is not None:
        return dict(parameters)
    geometry = parameters.get("geometry", "spheres")
    radius = sphere_radius("lammps", radius, geometry)
    return {**parameters, "R_eff": radius if geometry == "wall" else radius / 2.0}


def granular_parameters(clause: str, h: float, *, E, poisson, wall, R_eff=None, **model) -> dict:
    """An export's `parameters` of the normal `clause` without tangential force at step `h`
    (s): the commands, `E` (Pa), `poisson`, `R_eff` (m), the `model`'s own values (SI)."""
    clamped = model.get("limit_damping", False)
    lines = commands(clause, FRICTIONLESS, limit_damping=clamped, wall=wall)
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
    """`(m_eff, R_eff)`: `(m/2, R/2)` for two spheres, `(m, R)` on a wall (fix_wall_gran.cpp);
    both have `E_eff = E/(2 (1 - nu^2))` (`mix_stiffnessE_wall`: the wall of the sphere's
    material, not rigid)."""
    if geometry == "wall":
        return m, radius
    return m / 2.0, radius / 2.0


def contact_mass(parameters, m: float) -> float:
    """The effective mass (kg): `m` on a wall, else `m/2`."""
    return m if parameters.get("geometry", "spheres") == "wall" else m / 2.0


def emix(E: float, poisson: float) -> float:
    """LAMMPS's `Emix = E / (2 (1 - nu^2))` (Pa) of one material."""
    return E / (2.0 * (1.0 - poisson) * (1.0 + poisson))


def _non_negative(name: str, value, unit: str) -> float:
    if not (math.isfinite(value) and value >= 0):
        raise ValueError(f"{name} must be a finite number >= 0 {unit}, got {value!r}")
    return float(value)


def material(parameters, *, damped: bool, adhesive: bool = True) -> tuple[float, ...]:
    """`(E, poisson, cohesion[, damp])` of a cohesive model's `parameters`, checked (`E` or
    `youngs_modulus`, Pa; `cohesion` > 0 where `adhesive`, J/m^2; `damp` >= 0, 1/(m s))."""
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
    """`(c, b, R_eff)`: `c = 4/3 Emix Reff^0.5` (N/m^1.5), `b = damp meff Reff^0.5` (N s/m^1.5)."""
    R_eff = check_positive("R_eff", parameters["R_eff"], "m")
    root = math.sqrt(R_eff)
    return 4.0 / 3.0 * emix(E, nu) * root, damp * contact_mass(parameters, m) * root, R_eff


def cohesive_scenes(model: str, wall_model: str, extra: str = "") -> dict:
    """A cohesive model's `SCENES` (`extra` after "no gravity")."""
    return {
        "spheres": "two equal spheres, each of mass m and radius `radius`, colliding head-on at "
        f"relative speed v0 (pair_style granular, {model}; no gravity{extra})",
        "wall": "a sphere of mass m and radius `radius` hitting a fixed flat wall (fix "
        f"wall/gran granular {wall_model}, the sphere's own material) head-on at speed v0 (no "
        f"gravity{extra})",
    }


def cohesive_design(replica, clause, scene, stepping, aim, *, separation, note=None, **shown):
    """The `Design` of a cohesive model's `clause` in `scene`: the `replica`'s `stepping`
    parameters (`E` Pa, `poisson`, `R_eff` m, its own) at the step that realises `aim`, `(e, T,
    timestep)` (`_stepping.replicated`), the model's `note` after the stepping's warnings and
    its own values `shown` (SI) among the parameters."""
    e, T, timestep = aim
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
    """`replica` at `parameters["timestep"]` (s), `parameters` checked by `check`, or None."""
    if parameters.get("timestep") is None:
        return None
    h = check_positive("timestep", parameters["timestep"], "s")
    full = {**with_effective_radius(parameters, radius), "timestep": h}
    check(full)
    return Stepping(h, lambda v: replica(full, m, v))
