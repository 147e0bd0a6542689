"""LAMMPS's `dmt` model with `damping viscoelastic` (`pair_coeff * * dmt E damp poisson
cohesion damping viscoelastic`) for a `dmt` law. gran_sub_mod_normal.cpp, `GranSubModNormalDMT`,
and gran_sub_mod_damping.cpp (22Jul2025): `Fne = 4/3 Emix a^3/Reff - 4 pi cohesion Reff`,
`a = (delta Reff)^0.5`, `Emix = E / (2 (1 - nu^2))`: Hertz's `c delta^1.5` less DMT's pull-off
`2 pi w Reff` (`w = 2 cohesion`); `Fdamp = -damp meff a v_n`, the law's `b delta^0.5 v` with
`b = damp meff Reff^0.5`; the contact holds while `delta > 0`. So LAMMPS's contact is a
`dmt` law: the export scales every force of the law by `meff/m` (the pair moves `meff` where
the law moves `m`), keeping its e(v) and T(v) at every speed."""

import math

import numpy as np

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Stepping
from . import script


def normal_force(delta, v, *, c: float, b: float, pull: float):
    """`c delta^1.5 + b delta^0.5 v - pull` (N, pushing apart)."""
    root = np.sqrt(np.maximum(delta, 0.0))
    return c * delta * root + b * root * v - pull


def replica(parameters, m: float, v0: float, phases=_stepping.PHASES):
    """`(e, T)` per start phase of `fix nve/sphere` on the dmt contact `parameters` (as
    `jkr.replica`'s, with `damp`) for spheres of mass `m` (kg) at `v0` (m/s)."""
    c, b, pull = _contact(parameters, m)
    return _stepping.cohesive_verlet(
        lambda x, v: normal_force(x, v, c=c, b=b, pull=pull),
        lambda x, attached: x > 0.0,  # the contact holds while the spheres overlap
        float(parameters["timestep"]),
        script.contact_mass(parameters, m),
        v0,
        phases,
    )


def _contact(parameters, m: float) -> tuple[float, float, float]:
    """`(c, b, pull)` (N/m^1.5, N s/m^1.5, N) for spheres of mass `m` (kg)."""
    E, nu, cohesion, damp = script.material(parameters, damped=True, adhesive=False)
    c, b, R_eff = script.hertz_groups(parameters, m, E, nu, damp)
    return c, b, 4.0 * math.pi * cohesion * R_eff


def model(E: float, damp: float, poisson: float, cohesion: float) -> str:
    """The `dmt` clause."""
    return f"dmt {E:.10g} {damp:.10g} {poisson:.10g} {cohesion:.10g} damping viscoelastic"


class DMT(AbstractNormalModel):
    """LAMMPS's `dmt` model, mapping the exported law's parameters (the module's docstring)."""

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
            (e, T, timestep),
            separation="penetration",
            **shown,
            normal="dmt",
        )

    def law_parameters(self, parameters, m):
        """`c = 4/3 Emix Reff^0.5`, `b = damp meff Reff^0.5`, `R = Reff`, `w = 2 cohesion`."""
        c, b, pull = _contact(parameters, m)
        R_eff = float(parameters["R_eff"])
        return {"c": c, "b": b, "R": R_eff, "w": pull / (2.0 * math.pi * R_eff)}

    def response(self, parameters, *, m, radius=None):
        return self.law(script.with_effective_radius(parameters, radius), m), "penetration"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        return script.cohesive_stepper(
            replica, lambda p: _contact(p, m), parameters, m=m, radius=radius
        )
