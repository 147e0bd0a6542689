"""LAMMPS's `hertz/material` with `damping coeff_restitution`, its default normal model.
gran_sub_mod_normal.cpp and gran_sub_mod_damping.cpp (22Jul2025): `F_n = k delta^1.5 - eta_n
v_n`, `k = 4/3 E_eff sqrt(R_eff)`, `E_eff = E / (2 (1 - nu^2))`, `eta_n = damp sqrt(m_eff k)
delta^0.25`, `damp = sqrt(5) (-ln e) / sqrt(pi^2 + ln^2 e)`: the Tsuji form `c x^1.5 + b
x^0.25 v` (law `tsuji_restitution`), e the same at every speed and exact while the contact
lasts the overlap (`"penetration"`). `limit_damping` zeroes an attractive force (`"force"`):
e is then above the coefficient, never below about 0.14; the export inverts that."""

import math
from typing import NamedTuple

import numpy as np

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Stepping, sphere_radius
from ..materials import check_poisson, check_positive, check_restitution, hertz_stiffness
from . import script
from .script import effective


def impact_at_unit_scales(e_coefficient: float, separation: str):
    """`(e, tau)` of the Tsuji form at `c = m_eff = v0 = 1` (tau in `(m_eff v0^2/c)^0.4 / v0`)."""
    from ..._laws import law
    from ..._solve.impact import impact

    result = impact(
        law("tsuji_restitution", c=1.0, e_nominal=e_coefficient, m_eff=1.0),
        m=1.0,
        v0=1.0,
        separation=separation,
    )
    return float(result.e), float(result.T)


def coefficient_for(e: float, limit_damping: bool) -> float:
    """The `coeff_restitution` value that realises `e`."""
    if not limit_damping or e >= 1.0:
        return e
    from scipy.optimize import brentq

    floor = impact_at_unit_scales(1e-12, "force")[0]
    if e <= floor:
        raise ValueError(
            f"LAMMPS with limit_damping cannot realise e = {e:g}: coeff_restitution -> 0 gives "
            f"e = {floor:.4g} (drop limit_damping to reach lower values)"
        )
    return brentq(
        lambda q: impact_at_unit_scales(q, "force")[0] - e, 1e-12, 1.0, xtol=1e-13, rtol=1e-12
    )


def acceleration(c: float, b: float, m_eff: float, limit_damping: bool):
    def accel(x, v):
        force = c * x**1.5 + b * x**0.25 * v
        return -(np.maximum(force, 0.0) if limit_damping else force) / m_eff

    return accel


def damp_coefficient(e: float) -> float:
    log_e = math.log(e)
    return math.sqrt(5.0) * -log_e / math.sqrt(math.pi**2 + log_e**2)


def replica(parameters, m: float, v0: float, phases=_stepping.PHASES):
    """`(e, T)` per start phase of `fix nve/sphere` on `parameters` (`k`, `b`, `limit_damping`,
    `timestep`, `geometry`) for spheres of mass `m` (kg) at `v0` (m/s)."""
    m_eff = script.contact_mass(parameters, m)
    accel = acceleration(parameters["k"], parameters["b"], m_eff, parameters["limit_damping"])
    return _stepping.velocity_verlet(accel, parameters["timestep"], v0, phases)


class Tsuji(NamedTuple):
    """A Tsuji-form contact: coeff_restitution, its law's e and `tau` (as
    `impact_at_unit_scales`), `c` (N/m^1.5), `E` (Pa), `b` (N s/m^1.25), `m_eff` (kg),
    `R_eff` (m)."""

    coefficient: float
    e: float
    tau: float
    c: float
    E: float
    b: float
    m_eff: float
    R_eff: float


def tsuji_design(e: float, T: float, scene, poisson: float, clamped: bool) -> Tsuji:
    """The Tsuji-form contact (LAMMPS's, LIGGGHTS's, Chrono's) whose continuous impact in
    `scene` has `e` and `T` (s), `clamped` or not."""
    coefficient = coefficient_for(e, clamped)
    e_law, tau = impact_at_unit_scales(coefficient, "force" if clamped else "penetration")
    m_eff, R_eff = effective(scene.m, scene.radius, scene.geometry)
    c = m_eff * scene.v0**2 * (tau / (T * scene.v0)) ** 2.5
    E = c * 3.0 / (4.0 * math.sqrt(R_eff)) * 2.0 * (1.0 - poisson**2)
    R2 = None if scene.wall else scene.radius
    assert abs(hertz_stiffness(E, poisson, scene.radius, R2=R2) / c - 1) < 1e-12
    b = damp_coefficient(coefficient) * math.sqrt(m_eff * c) if coefficient < 1 else 0.0
    return Tsuji(coefficient, e_law, tau, c, E, b, m_eff, R_eff)


def tsuji_response(engine: str, parameters, *, m: float, radius, clamped: bool):
    """`(law, separation)` of a Tsuji-form `engine` from `E` (Pa), `coeff_restitution`,
    `poisson` (default 0.3) for spheres of mass `m` (kg) and `radius` (m)."""
    wall = parameters.get("geometry", "spheres") == "wall"
    radius = sphere_radius(engine, radius, parameters.get("geometry"))
    E = check_positive("E", parameters["E"], "Pa")
    nu = check_poisson("poisson", parameters.get("poisson", 0.3))
    coefficient = check_restitution(parameters["coeff_restitution"], "coeff_restitution")
    c = hertz_stiffness(E, nu, radius, R2=None if wall else radius)
    m_eff = m if wall else m / 2.0
    b = damp_coefficient(coefficient) * math.sqrt(m_eff * c) if coefficient < 1 else 0.0
    from ..._laws import law

    return law("tsuji", c=c, b=b), "force" if clamped else "penetration"


def clause(E: float, coefficient: float, poisson: float) -> str:
    """The `hertz/material ... damping coeff_restitution` clause."""
    return f"hertz/material {E:.10g} {coefficient:.10g} {poisson:.10g} damping coeff_restitution"


class HertzMaterial(AbstractNormalModel):
    """LAMMPS's `hertz/material` with `damping coeff_restitution`, the Tsuji form at `fix
    nve/sphere`'s velocity Verlet (the module's docstring)."""

    NAME = "hertz/material"
    LAW = "tsuji"
    KEYS = (
        Key("E", "Pa"),
        Key("coeff_restitution", "in (0, 1]"),
        script.POISSON,
        Key("limit_damping", "true or false", needed=False),
        script.TIMESTEP,
    )
    STEPPING = "with a timestep, fix nve/sphere's velocity Verlet: replicated"
    MASS_DEPENDS = "its Young's modulus scales with the mass"
    ALLOWS_LIMIT_DAMPING = True
    SCENES = None  # the engine's
    NEAREST = (
        "hertz/material with damping coeff_restitution (law tsuji, e the same at every "
        "speed; LAMMPS's mdr normal model is elastic-plastic, but another law, not exported)"
    )

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        wall, separation = scene.wall, "force" if limit_damping else "penetration"
        contact = tsuji_design(e, T, scene, poisson, limit_damping)
        coefficient, c, E, b = contact.coefficient, contact.c, contact.E, contact.b
        params = dict(k=c, b=b, limit_damping=limit_damping)
        params, es, Ts, warnings = _stepping.replicated(
            replica, params, scene, e, T, timestep, engine="LAMMPS", step="timestep"
        )
        h, text = params["timestep"], clause(E, coefficient, poisson)
        shown = dict(coeff_restitution=coefficient, k=c, b=b, limit_damping=limit_damping)
        parameters = script.granular_parameters(text, h, E=E, poisson=poisson, wall=wall, **shown)
        # `stepper`'s parameters: the pair's model (one material), or the wall at z = 0
        stepping = dict(E=E, coeff_restitution=coefficient, poisson=poisson, **params)
        return Design.stepped(parameters, es, Ts, h, warnings, separation, stepping, clause=text)

    def law_parameters(self, parameters, m):
        return {"c": parameters["k"], "b": parameters["b"]}

    def response(self, parameters, *, m, radius=None):
        clamped = bool(parameters.get("limit_damping", False))
        return tsuji_response("lammps", parameters, m=m, radius=radius, clamped=clamped)

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        if parameters.get("timestep") is None:
            return None
        h = check_positive("timestep", parameters["timestep"], "s")
        pair = self.response(parameters, m=m, radius=radius)[0]
        c, b = (float(pair.parameters[k]) for k in ("c", "b"))
        clamped = bool(parameters.get("limit_damping", False))
        geometry = parameters.get("geometry", "spheres")
        stepping = dict(k=c, b=b, limit_damping=clamped, timestep=h, geometry=geometry)
        return Stepping(h, lambda v: replica(stepping, m, v))
