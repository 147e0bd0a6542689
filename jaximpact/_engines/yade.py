"""Yade: two equal spheres of `ViscElMat(tc=, en=, et=)` through
`Ip2_ViscElMat_ViscElMat_ViscElPhys` and `Law2_ScGeom_ViscElPhys_Basic`, by its source.

Yade 2025.2.0 (and 2023.02a, Debian's package), `pkg/dem/ViscoelasticPM.cpp`:
`Calculate_ViscElMat_ViscElMat_ViscElPhys` sets, from Pournin et al. (2001) with the reduced
mass `massR = m1 m2/(m1 + m2)`, `kn1 = kn2 = 2 massR (pi^2 + ln^2 en)/tc^2`,
`cn1 = cn2 = -4 massR ln(en)/tc`, combined in series (`contactParameterCalculation`):

    kn = massR (pi^2 + ln^2 en) / tc^2 (N/m),   cn = -2 massR ln(en) / tc (N s/m);

`computeForceTorqueViscEl` applies `F = kn x + cn v` and sets it to zero when negative
("Prevent appearing of attraction forces", after Schwager & Poschel 2007): a linear
spring-dashpot whose force never pulls, `kelvin_voigt` under `separation="force"`. Pournin's
formulas give `en` and `tc` for the contact that lasts while the spheres overlap; with the
force clamped the realised e is higher and T shorter (en = 0.5 gives e = 0.552), and no `en`
gives less than e = exp(-2) = 0.135 (the critically damped limit, `en -> 0`). The export
inverts the clamped law: it asks for the `en` and `tc` that realise the target.

Time stepping: `NewtonIntegrator` is a leapfrog, the contact force taken at `x_n` and the
half-step velocity `v_{n-1/2}` (`_stepping.semi_implicit_euler`), and it applies Cundall's
non-viscous damping `a *= 1 - damping sign(a (v + dt a/2))` (`cundallDamp2nd`), with
`damping = 0.2` by default: that alone turns a requested 0.5 into about 0.42 (the public
report in the issue). The snippet sets `damping=0`; `replica` models any value.
Pitfall: a sphere on a wall or facet of mass 0 gets `massR = m/2` (Yade copies the other
body's mass), not `m`: then `tc` is sqrt(2) too long and the damping ratio 1/sqrt(2) too low.

Tangential (`computeForceTorqueViscEl`): the elastic shear force grows by `ks dt v_s` (`v_s`
the slip of the contact point), is tested alone against `tan(frictionAngle) |F_n|` (the
clamped normal force) and rescaled to it while sliding; the damper `cs v_s` is added only
while sticking. The contact point is halfway through the overlap (ScGeom's `contactPoint`),
so the lever arm is `R - x/2`. With `ks` constant this is jaximpact's `linear_history`
(`kt = ks`, `ct = 0`; a damper outside Coulomb's test is not `linear_history`'s `ct`, so
`ct > 0` is refused), with `contact_point="midpoint"`. Pournin's `et` ties `ks` and `cs`
to `tc` (`ks = 2/7 massR (pi^2 + ln^2 et)/tc^2`), so a tangential export gives ViscElMat its
explicit `kn`, `cn`, `ks`, `cs` instead (`Calculate_ViscElMat_ViscElMat_ViscElPhys`: each
material's value, two equal ones in series: twice the contact's), `kn`, `cn` those `tc`,
`en` give: the normal contact is unchanged.
"""

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
    """`(kn, cn)` (N/m, N s/m) that Yade derives from `tc` (s), `en` and the reduced mass
    `mass_r` (kg): `kn = mass_r (pi^2 + ln^2 en)/tc^2`, `cn = -2 mass_r ln(en)/tc`."""
    log_e = math.log(en)
    return mass_r * (math.pi**2 + log_e**2) / tc**2, -2.0 * mass_r * log_e / tc


def inputs_for(e: float, T: float, geometry: str = "spheres") -> tuple[float, float, float]:
    """`(en, tc, zeta)`: the ViscElMat inputs whose clamped contact realises `e` and `T` (s),
    and its damping ratio `zeta = cn / (2 sqrt(kn m_eff))` (< 1: Pournin's form has no
    over-damped case). Two spheres: `m_eff = massR`. A sphere on a wall of mass 0
    (`geometry="wall"`): Yade forms kn and cn with `massR = m/2` (the wall takes the
    sphere's mass) but they act on the sphere's own mass m, so `kn/m = (pi^2 + ln^2 en)/(2
    tc^2)`, `cn/m = -ln(en)/tc`: the damping ratio is `1/sqrt(2)` of the pair's, no `en`
    gives more than `1/sqrt(2)`, and no e below 0.2079 is reached (the pair's: exp(-2))."""
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
    """The relative acceleration `a(x, v)` (x the overlap, v its rate) of the two spheres:
    `-max(0, kn x + cn v)/massR`, then Cundall's factor `1 - damping sign(a (v + h a/2))`."""

    def accel(x, v):
        a = -np.maximum(0.0, kn * x + cn * v) / mass_r
        if damping:
            a = a * (1.0 - damping * np.sign(a * (v + 0.5 * h * a)))
        return a

    return accel


def replica(parameters, m: float, v0: float, phases=_stepping.PHASES):
    """`(e, T)` per start phase that Yade's NewtonIntegrator realises for two spheres of mass
    `m` (kg) at relative speed `v0` (m/s), or with `parameters["geometry"] == "wall"` one
    such sphere on a wall of mass 0 at speed `v0` (kn, cn from `massR = m/2`, acting on m);
    `parameters`: `tc`, `en`, `timestep` and optionally `damping` (NewtonIntegrator's,
    default 0 here)."""
    h = parameters["timestep"]
    kn, cn = stiffness_damping(parameters["tc"], parameters["en"], m / 2.0)
    m_eff = m if parameters.get("geometry", "spheres") == "wall" else m / 2.0
    accel = acceleration(kn, cn, m_eff, parameters.get("damping", 0.0), h)
    return _stepping.semi_implicit_euler(accel, h, v0, phases)


def _with_cundall(params, m, v0) -> float:
    es, _ = replica({**params, "damping": CUNDALL_DEFAULT}, m, v0)
    return float(es.mean())


class ViscElMat(AbstractNormalModel):
    """Yade's `ViscElMat(tc=, en=)` between two spheres or a sphere and a fixed wall, at
    `NewtonIntegrator`'s leapfrog (the module's docstring has the formulas and sources)."""

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
        """ViscElMat inputs and O.dt for target `e` and `T` (s) in `scene` (a wall: of mass 0);
        its force is always kept non-attractive (`limit_damping` does not apply), and it
        takes no Poisson's ratio."""
        m, v0, radius, wall = scene.m, scene.v0, scene.radius, scene.wall
        en, tc, zeta = inputs_for(e, T, "wall" if wall else "spheres")
        params, es, Ts, warnings = _stepping.replicated(
            replica,
            {"tc": tc, "en": en, "damping": 0.0},
            scene,
            e,
            T,
            timestep,
            engine="Yade",
            step="O.dt =",
        )
        h = params["timestep"]
        warnings.append(
            f"en = {en:.6g} is not the e Yade realises: its force is kept non-attractive, so "
            f"en = {en:.4g} and tc = {tc:.4g} s give e = {e:.4g}, T = {T:.4g} s"
        )
        warnings.append(
            "keep NewtonIntegrator(damping=0): its default 0.2 damps every contact further "
            f"(measured on the replica: e = {_with_cundall(params, m, v0):.4g} instead of "
            f"{es.mean():.4g})"
        )
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
        """`kelvin_voigt`'s `c` = kn (N/m) and `b` = cn (N s/m) that Yade forms for two
        spheres of mass `m` (kg; reduced mass `m/2`, also on a wall of mass 0), under
        `separation="force"`."""
        kn, cn = stiffness_damping(parameters["tc"], parameters["en"], m / 2.0)
        return {"c": kn, "b": cn}

    def response(self, parameters, *, m, radius=None):
        """`(law, separation)` that `parameters` (`tc` s > 0, `en` in (0, 1]) give two
        spheres of mass `m` (kg)."""
        return self.law(_inputs(parameters), m), "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        """NewtonIntegrator's leapfrog at `parameters["timestep"]` (s) with its `damping`
        (default 0), or None without a timestep."""
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
    """`tc` (s, > 0) and `en` (in (0, 1]) of `parameters`, checked (one-line ValueErrors)."""
    return {
        "tc": check_positive("tc", parameters["tc"], "s"),
        "en": check_restitution(parameters["en"], "en"),
    }


class ViscElShear(AbstractTangentialModel):
    """ViscElMat's shear for a `linear_history` law: its constant spring `ks`, no damper in
    Coulomb's test (the module's docstring)."""

    MODEL = "Yade's ViscElMat shear is a constant spring (ks)"
    FRICTION = None
    # ScGeom's contactPoint: halfway through the overlap between spheres
    # (Ig2_Sphere_Sphere_ScGeom), the sphere's centre projected on a wall (Ig2_Wall_Sphere)
    CONTACT_POINT = {"wall": 1.0, "spheres": 0.5}

    def check(self, tangential, *, timestep) -> None:
        """Yade's ViscElMat shear is a constant spring without a damper in Coulomb's test."""
        ct = float(tangential.params.get("ct", 0.0))
        if ct != 0.0:
            raise ValueError(
                "Yade adds its shear damper cs outside Coulomb's test, not as "
                f"linear_history's ct = {ct:g} N s/m (inside it): export with ct=0"
            )

    def poisson(self, design: Design, tangential) -> None:
        return None

    def parameters(self, design: Design, tangential) -> dict:
        """The design's parameters with ViscElMat's explicit `kn`, `cn` (the design's) and
        `ks` = kt,
        `cs` = 0, `frictionAngle` = atan(mu), each material's value twice the contact's
        (two equal ones in series)."""
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
