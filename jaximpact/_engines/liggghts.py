"""LIGGGHTS: two equal spheres through `pair_style gran model hertz` with the material
properties as `fix property/global`, by its source; checked against LIGGGHTS 3.8.0 (Debian's
`liggghts` package) in tests/test_engines.py.

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

from . import lammps

NAME = "liggghts"
MIN_COEFFICIENT = 0.05  # createCoeffRest: "0.05 < coefficientRestitution <= 1 required"
SCENE = lammps.SCENE
GEOMETRIES = lammps.GEOMETRIES
SCENE_WALL = (
    "a sphere of mass m and radius `radius` hitting a fixed flat primitive wall (fix "
    "wall/gran, of the sphere's own material: atom type 1) head-on at speed v0 (no gravity, "
    "no friction effect)"
)
law = lammps.law
KEYS = lammps.KEYS
TWO_SPHERES = True
MASS_DEPENDS = "its youngsModulus scales with the mass"  # what m changes (export)
stepper = lammps.stepper  # fix nve/sphere: the same velocity Verlet


def response(parameters, *, m: float, radius=None):
    """`(law, separation)`: as LAMMPS's (`limit_damping` is `limitForce on`)."""
    clamped = bool(parameters.get("limit_damping", False))
    return lammps.tsuji_response(parameters, m=m, radius=radius, clamped=clamped, engine=NAME)


def design(e, T, *, m, v0, radius, poisson=0.3, timestep=None, limit_damping=False,
           geometry="spheres"):  # fmt: skip
    """LAMMPS's design in LIGGGHTS's names. `geometry="wall"`: a sphere on a primitive
    `fix wall/gran` of its own material (atom type 1). Its contact, `fix_wall_gran.cpp` and
    `normal_model_hertz.h`: the particle's own mass and radius (`reff = radi` on a wall),
    `Y*` from the sphere's type and the wall's (`createYeff`, type 1 with type 1:
    `Y/(2 (1 - nu^2))`), i.e. LAMMPS's `fix wall/gran` term for term (checked: the two
    engines give the same e and T to every digit printed)."""
    if poisson < 0:
        raise ValueError(f"LIGGGHTS requires 0 <= poissonsRatio <= 0.5, got {poisson:g}")
    wall = {"geometry": "wall"} if geometry == "wall" else {}
    out = lammps.design(
        e, T, m=m, v0=v0, radius=radius, poisson=poisson, timestep=timestep,
        limit_damping=limit_damping, **wall,
    )  # fmt: skip
    p = out["parameters"]
    if p["coeff_restitution"] <= MIN_COEFFICIENT:
        floor = lammps.impact_at_unit_scales(MIN_COEFFICIENT, "force" if limit_damping else
                                             "penetration")[0]  # fmt: skip
        raise ValueError(
            f"LIGGGHTS cannot realise e = {e:g}: it refuses coefficientRestitution <= 0.05 "
            f"(src/global_properties.cpp), whose e is {floor:.4g}"
            + (" with limitForce on" if limit_damping else "")
        )
    extra = particle_range_line(p["youngs_modulus"])
    if extra:
        out["warnings"].append(
            f"youngsModulus {p['youngs_modulus']:.4g} Pa is outside LIGGGHTS's SI sanity range "
            f"[5e6, 1e9] Pa: the snippet adds '{extra}'"
        )
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
        "particle_range": extra,
    }
    if wall:
        out["parameters"]["fix_wall"] = (
            "fix wall all wall/gran model hertz tangential history primitive type 1 zplane 0.0"
            + (" limitForce on" if limit_damping else "")  # after the wall, or it is refused
        )
        out["parameters"]["geometry"] = "wall"
    return out


def snippet(parameters) -> str:
    return "\n".join(
        [
            "units si",
            "atom_style granular",
            "communicate single vel yes",
            *([parameters["particle_range"]] if parameters.get("particle_range") else []),
            parameters["youngsModulus"],
            parameters["poissonsRatio"],
            parameters["coefficientRestitution"],
            parameters["coefficientFriction"],
            parameters["pair_style"],
            parameters["pair_coeff"],
            *([parameters["fix_wall"]] if parameters.get("fix_wall") else []),
            "fix integr all nve/sphere",
            parameters["timestep"],
        ]
    )


def particle_range_line(youngs_modulus: float) -> str | None:
    """The line LIGGGHTS needs for a modulus outside its SI sanity range [5e6, 1e9] Pa
    (`src/global_properties.cpp`, `createYoungsModulus`), or None."""
    if youngs_modulus > 1e9:
        return "hard_particles yes"
    if youngs_modulus < 5e6:
        return "soft_particles yes"
    return None


def simulate(parameters, *, m, v0, radius, phases=(0.5,), executable="liggghts"):
    """Run LIGGGHTS (`executable`) on two spheres (mass `m` kg, radius `radius` m each,
    head-on at relative speed `v0` m/s) with the exported `parameters`, or with
    `parameters["geometry"] == "wall"` on one such sphere hitting the exported primitive wall
    (the plane z = 0) at `v0`; returns arrays `(e, T)`, T the number of steps with a non-zero
    contact force times the step."""
    import math
    import os
    import subprocess
    import tempfile

    import numpy as np

    h = parameters["timestep_s"]
    rho = m / (4.0 / 3.0 * math.pi * radius**3)
    steps = int(20 * radius / v0 / h) + 10  # far longer than any contact the export makes
    wall = parameters.get("geometry", "spheres") == "wall"
    if wall:  # it rises by at most 4 R, inside the box (10 R), after any contact the export makes
        steps = int(4 * radius / v0 / h) + 10
    es, Ts = [], []
    for phase in map(float, phases):
        gap = v0 * h * phase
        box = 10 * radius
        extra = particle_range_line(parameters["youngs_modulus"])
        if wall:  # the sphere above the wall z = 0, first touch `gap` away
            atoms = f"""{parameters["fix_wall"]}
create_atoms 1 single 0 0 {radius + gap!r} units box
set atom 1 diameter {2 * radius!r} density {rho!r} vx 0 vy 0 vz {-v0!r}
fix integr all nve/sphere
variable f1 equal fz[1]
variable dv equal vz[1]"""
        else:
            atoms = f"""create_atoms 1 single {-radius - gap / 2!r} 0 0 units box
create_atoms 1 single {radius + gap / 2!r} 0 0 units box
set atom 1 diameter {2 * radius!r} density {rho!r} vx {v0 / 2!r} vy 0 vz 0
set atom 2 diameter {2 * radius!r} density {rho!r} vx {-v0 / 2!r} vy 0 vz 0
fix integr all nve/sphere
variable f1 equal fx[1]
variable dv equal vx[2]-vx[1]"""
        script = f"""atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
{extra or ""}
region box block {-box!r} {box!r} {-box!r} {box!r} {-box!r} {box!r} units box
create_box 1 box
neighbor {0.5 * radius!r} bin
neigh_modify delay 0
{parameters["youngsModulus"]}
{parameters["poissonsRatio"]}
{parameters["coefficientRestitution"]}
{parameters["coefficientFriction"]}
{parameters["pair_style"]}
{parameters["pair_coeff"]}
{parameters["timestep"]}
{atoms}
variable m1 equal mass[1]
fix out all print 1 "${{f1}} ${{dv}} ${{m1}}" file out.txt screen no
run {steps}
"""
        with tempfile.TemporaryDirectory() as folder:
            with open(os.path.join(folder, "in.impact"), "w") as handle:
                handle.write(script)
            run = subprocess.run(
                [executable, "-in", "in.impact", "-log", "none", "-screen", "none"],
                cwd=folder, capture_output=True, text=True, timeout=600,
            )  # fmt: skip
            path = os.path.join(folder, "out.txt")
            if not os.path.exists(path):
                raise RuntimeError(f"LIGGGHTS gave no output: {run.stdout[-400:]}{run.stderr}")
            rows = np.loadtxt(path, comments="#", ndmin=2)
        if abs(rows[0, 2] / m - 1) > 1e-9:
            raise RuntimeError(f"LIGGGHTS's sphere has mass {rows[0, 2]}, not {m}")
        pushing = rows[:, 0] != 0.0
        es.append(rows[-1, 1] / v0)
        Ts.append(pushing.sum() * h)
    return np.array(es), np.array(Ts)
