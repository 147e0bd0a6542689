"""What LAMMPS's normal models (`hertz.py`: hertz/material; `jkr.py`, `jkr_viscoelastic.py`,
`dmt.py`) share: the script of an export's scene (`snippet`), the commands that join a
normal and a tangential clause (`commands`), the effective radius of its contact
(`with_effective_radius`), the parameters of a `pair_style granular` design
(`granular_parameters`), and for the cohesive models the stepped design
(`cohesive_stepping`)."""

from .. import _stepping
from ..base import Key
from ..materials import check_positive

# the keys every LAMMPS normal model shares (`AbstractNormalModel.KEYS`)
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
    wall = parameters.get("geometry", "spheres") == "wall"
    if radius is None:
        what = "sphere's" if wall else "spheres'"
        raise ValueError(f"lammps needs the {what} radius: pass radius= (m)")
    radius = check_positive("radius", radius, "m")
    return {**parameters, "R_eff": radius if wall else radius / 2.0}


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


def cohesive_stepping(
    replica, stepping: dict, *, wall: bool, m: float, v0: float, e: float, T: float, timestep
):
    """`(stepping, h, es, Ts, warnings)` of a cohesive model's design (`jkr`, damped `jkr`,
    `dmt`): the replica's `stepping` parameters (with the wall's geometry) at the time step
    `h` (s) that realises `e` and `T` (s) at `v0` (m/s), or at the `timestep` given
    (`_stepping.step_and_response`), and the replica's `e` and `T` per start phase."""
    stepping = {**stepping, **({"geometry": "wall"} if wall else {})}
    h, es, Ts, warnings = _stepping.step_and_response(
        lambda h: replica({**stepping, "timestep": h}, m, v0),
        e,
        T,
        timestep,
        engine="LAMMPS",
        step="timestep",
    )
    return {**stepping, "timestep": h}, h, es, Ts, warnings
