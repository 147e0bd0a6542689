"""Yade's `ViscElMat(tc=, en=, et=)` (Yade 2025.2.0 and 2023.02a, `pkg/dem/ViscoelasticPM.cpp`).
`Calculate_ViscElMat_ViscElMat_ViscElPhys` (Pournin et al. 2001), two materials in series:
`kn = massR (pi^2 + ln^2 en) / tc^2` (N/m), `cn = -2 massR ln(en) / tc` (N s/m), `massR = m1
m2/(m1 + m2)`; `computeForceTorqueViscEl` zeroes a negative `F = kn x + cn v`: `kelvin_voigt`
under `separation="force"`, so e is above en (0.5 gives 0.552), never below exp(-2); the
export inverts that. `NewtonIntegrator` is a leapfrog (`_stepping.semi_implicit_euler`) with
Cundall's damping `a *= 1 - damping sign(a (v + dt a/2))`, 0.2 by default (0.5 becomes about
0.42): the snippet sets 0. A sphere on a wall of mass 0 gets `massR = m/2`, not m.
Tangential: the shear force grows by `ks dt v_s`, is tested alone against `tan(frictionAngle)
|F_n|` and rescaled to it while sliding, the damper `cs v_s` added only while sticking; the
contact point is halfway through the overlap: `linear_history` (`kt = ks`, `ct = 0`). `et`
ties `ks` to `tc`, so a tangential export gives each material explicit `kn`, `cn`, `ks`,
`cs`, twice the contact's."""

import math

import numpy as np

from . import _stepping
from .base import (
    AbstractEngine,
    AbstractNormalModel,
    AbstractTangentialModel,
    Design,
    Key,
    Stepping,
)
from .materials import check_positive, check_restitution
from .mujoco.solref import continuous, dampratio_for

CUNDALL_DEFAULT = 0.2  # NewtonIntegrator.damping's default (pkg/dem/NewtonIntegrator.hpp)


def stiffness_damping(tc: float, en: float, mass_r: float) -> tuple[float, float]:
    """`(kn, cn)` (N/m, N s/m) of `tc` (s), `en` and `mass_r` (kg)."""
    log_e = math.log(en)
    return mass_r * (math.pi**2 + log_e**2) / tc**2, -2.0 * mass_r * log_e / tc


def inputs_for(e: float, T: float, geometry: str = "spheres") -> tuple[float, float, float]:
    """`(en, tc, zeta)` whose clamped contact realises `e`, `T` (s), `zeta` its damping ratio
    (< 1). On a wall of mass 0, kn and cn from `massR = m/2` act on m: the damping ratio is
    `1/sqrt(2)` of the pair's, e not below 0.2079."""
    if e >= 1.0:
        return 1.0, T if geometry != "wall" else T / math.sqrt(2.0), 0.0
    wall = geometry == "wall"
    top = 1.0 / math.sqrt(2.0) if wall else 1.0  # the largest damping ratio en -> 0 gives
    floor = continuous(top)[0] if wall else math.exp(-2.0)
    if e <= floor:
        where = " on a wall of mass 0" if wall else ""
        value = f"{floor:.4f}" if wall else f"exp(-2) = {floor:.4f}"
        raise ValueError(
            f"Yade's ViscElMat cannot realise e = {e:g}{where}: its force is kept "
            f"non-attractive and en -> 0 gives e = {value} (use kn and cn directly for less)"
        )
    zeta = dampratio_for(e)
    omega0 = continuous(zeta)[1] / T
    z = zeta / top  # Pournin's damping ratio for massR: sqrt(2) zeta on a wall
    en = math.exp(-math.pi * z / math.sqrt(1.0 - z**2))
    tc = math.pi / (omega0 * math.sqrt(1.0 - z**2)) * top
    return en, tc, zeta


def acceleration(kn: float, cn: float, mass_r: float, damping: float = 0.0, h: float = 0.0):
    """`a(x, v) = -max(0, kn x + cn v)/massR` times Cundall's factor."""

    def accel(x, v):
        a = -np.maximum(0.0, kn * x + cn * v) / mass_r
        if damping:
            a = a * (1.0 - damping * np.sign(a * (v + 0.5 * h * a)))
        return a

    return accel


def replica(parameters, m: float, v0: float, phases=_stepping.PHASES):
    """`(e, T)` per start phase of NewtonIntegrator with `parameters` (`tc`, `en`, `timestep`,
    `damping` default 0, `geometry`) for spheres of mass `m` (kg) at `v0` (m/s)."""
    h = parameters["timestep"]
    kn, cn = stiffness_damping(parameters["tc"], parameters["en"], m / 2.0)
    m_eff = m if parameters.get("geometry", "spheres") == "wall" else m / 2.0
    accel = acceleration(kn, cn, m_eff, parameters.get("damping", 0.0), h)
    return _stepping.semi_implicit_euler(accel, h, v0, phases)


class ViscElMat(AbstractNormalModel):
    """Yade's `ViscElMat(tc=, en=)` at `NewtonIntegrator`'s leapfrog."""

    NAME = "ViscElMat"
    LAW = "kelvin_voigt"
    KEYS = (
        Key("tc", "s"),
        Key("en", "in (0, 1]"),
        Key("timestep", "s; without it, no stepping", needed=False),
        Key("damping", "NewtonIntegrator's, in [0, 1), default 0", needed=False),
    )
    STEPPING = (
        "with a timestep, NewtonIntegrator's leapfrog and its Cundall damping (default 0 "
        "here): replicated"
    )
    MASS_DEPENDS = "its density (and kn, cn) scale with the mass"
    ALLOWS_LIMIT_DAMPING = True
    NEAREST = "its kelvin_voigt law"
    SCENES = None

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        m, v0, radius, wall = scene.m, scene.v0, scene.radius, scene.wall
        en, tc, zeta = inputs_for(e, T, "wall" if wall else "spheres")
        start = {"tc": tc, "en": en, "damping": 0.0}
        params, es, Ts, warnings = _stepping.replicated(
            replica, start, scene, e, T, timestep, engine="Yade", step="O.dt ="
        )
        h = params["timestep"]
        cundall = float(replica({**params, "damping": CUNDALL_DEFAULT}, m, v0)[0].mean())
        warnings += [
            f"en = {en:.6g} is not the e Yade realises: its force is kept non-attractive, so "
            f"en = {en:.4g} and tc = {tc:.4g} s give e = {e:.4g}, T = {T:.4g} s",
            "keep NewtonIntegrator(damping=0): its default 0.2 damps every contact further "
            f"(measured on the replica: e = {cundall:.4g} instead of {es.mean():.4g})",
        ]
        kn, cn = stiffness_damping(tc, en, m / 2.0)
        rho = m / (4.0 / 3.0 * math.pi * radius**3)
        parameters = {
            "tc": tc,
            "en": en,
            "et": 1.0,
            "density": rho,
            "frictionAngle": 0.0,
            "NewtonIntegrator_damping": 0.0,
            "timestep": h,
            "kn": kn,
            "cn": cn,
            "damping_ratio": zeta,
            "material": (
                f"ViscElMat(tc={tc!r}, en={en!r}, et=1.0, density={rho!r}, frictionAngle=0.0)"
            ),
        }
        if wall:
            parameters["geometry"] = "wall"
            parameters["wall"] = "utils.wall(0.0, axis=2, sense=1, material=mat)"
        return Design.stepped(parameters, es, Ts, h, warnings, "force", parameters)

    def law_parameters(self, parameters, m):
        """kn and cn of `massR = m/2` (on a wall of mass 0 too)."""
        kn, cn = stiffness_damping(parameters["tc"], parameters["en"], m / 2.0)
        return {"c": kn, "b": cn}

    def response(self, parameters, *, m, radius=None):
        return self.law(_inputs(parameters), m), "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        if parameters.get("timestep") is None:
            return None
        h = check_positive("timestep", parameters["timestep"], "s")
        damping = float(parameters.get("damping", 0.0))
        if not 0.0 <= damping < 1.0:
            raise ValueError(f"NewtonIntegrator damping must lie in [0, 1), got {damping!r}")
        geometry = parameters.get("geometry", "spheres")
        stepping = {**_inputs(parameters), "timestep": h, "damping": damping, "geometry": geometry}
        return Stepping(h, lambda v: replica(stepping, m, v))


def _inputs(parameters) -> dict:
    """`tc` (s) and `en` of `parameters`, checked."""
    return {
        "tc": check_positive("tc", parameters["tc"], "s"),
        "en": check_restitution(parameters["en"], "en"),
    }


class ViscElShear(AbstractTangentialModel):
    """ViscElMat's shear for a `linear_history` law (the module's docstring)."""

    MODEL = "Yade's ViscElMat shear is a constant spring (ks)"
    FRICTION = None
    # ScGeom's contactPoint: halfway through the overlap between spheres
    # (Ig2_Sphere_Sphere_ScGeom), the sphere's centre projected on a wall (Ig2_Wall_Sphere)
    CONTACT_POINT = {"wall": 1.0, "spheres": 0.5}

    def check(self, tangential, *, timestep) -> None:
        ct = float(tangential.params.get("ct", 0.0))
        if ct != 0.0:
            raise ValueError(
                "Yade adds its shear damper cs outside Coulomb's test, not as "
                f"linear_history's ct = {ct:g} N s/m (inside it): export with ct=0"
            )

    def poisson(self, design: Design, tangential) -> None:
        return None

    def parameters(self, design: Design, tangential) -> dict:
        """Explicit `kn`, `cn`, `ks = kt`, `cs = 0` (each material's twice the contact's),
        `frictionAngle = atan(mu)`."""
        parameters = design.parameters
        kt, mu = float(tangential.params["kt"]), float(tangential.params["mu"])
        angle = math.atan(mu)
        material = (
            f"ViscElMat(kn={2.0 * parameters['kn']!r}, cn={2.0 * parameters['cn']!r}, "
            f"ks={2.0 * kt!r}, cs=0.0, density={parameters['density']!r}, "
            f"frictionAngle={angle!r})"
        )
        return dict(parameters, ks=kt, frictionAngle=angle, material=material)

    def realised(self, parameters, tangential):
        return tangential

    def notes(self, parameters, tangential) -> list[str]:
        return []

    def oblique(self, parameters, *, m, radius, v_n, v_t):
        return None


class Yade(AbstractEngine):
    """Yade's ViscElMat contact and its shear."""

    NAME = "yade"
    LABEL = "Yade"
    SCENES = {
        "spheres": "two equal spheres of ViscElMat, each of mass m and radius `radius`, "
        "colliding head-on at relative speed v0 (no gravity, NewtonIntegrator(damping=0))",
        "wall": "a sphere of ViscElMat, mass m and radius `radius`, hitting a fixed wall body "
        "(utils.wall, mass 0) head-on at speed v0 (no gravity, NewtonIntegrator(damping=0))",
    }
    TWO_SPHERES = True
    CONTINUOUS_PLANT = False
    NORMAL = {"kelvin_voigt": ViscElMat()}
    TANGENTIAL = {"linear_history": ViscElShear()}

    def snippet(self, parameters) -> str:
        wall = parameters.get("geometry") == "wall"  # the wall z = 0 (mass 0, fixed)
        return "\n".join(
            [
                f"mat = O.materials.append({parameters['material']})",
                *([f"O.bodies.append({parameters['wall']})"] if wall else []),
                "O.engines = [",
                "    ForceResetter(),",
                "    InsertionSortCollider([Bo1_Sphere_Aabb()"
                + (", Bo1_Wall_Aabb()" if wall else "")
                + "]),",
                "    InteractionLoop([Ig2_Sphere_Sphere_ScGeom()"
                + (", Ig2_Wall_Sphere_ScGeom()" if wall else "")
                + "], [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),",
                "    NewtonIntegrator(damping=0.0),  # its default 0.2 damps every contact",
                "]",
                f"O.dt = {parameters['timestep']!r}",
            ]
        )
