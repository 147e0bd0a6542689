"""LAMMPS's `jkr` model with `damping viscoelastic` (`pair_coeff * * jkr E damp poisson
cohesion damping viscoelastic`) for a `jkr_viscoelastic` law: `jkr.py`'s neck plus
gran_sub_mod_damping.cpp's `Fdamp = -damp meff a v_n` (22Jul2025), the law's `b a / R^0.5 v`
with `b = damp meff Reff^0.5`. Only the neck breaks earlier, and no closed form says what
that keeps: LAMMPS's impact is a function of `(q, beta)`, `beta = b x*^1.5 / (meff v0)`; the
export keeps the law's `beta` at `v0`, sets `q` for its e and `E` for its T there
(`lammps_impact`); at other speeds its e(v) is measured, not promised."""

import math

import numpy as np

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Stepping
from . import jkr, script
from .jkr import ENERGY_RATIO, design_scales, pulloff_distance


def _radius(X: float, q: float) -> float:
    """`sigma` of `sigma^4 - q sigma = X` right of the least force: Newton from the right."""
    sigma = max(X, 0.0) ** 0.25 + q ** (1.0 / 3.0)
    for _ in range(100):
        step = (sigma**4 - q * sigma - X) / (4.0 * sigma**3 - q)
        sigma -= step
        if abs(step) <= 1e-16 * sigma:
            break
    return sigma


def lammps_impact(q: float, beta: float, rtol: float = 1e-11) -> tuple[float, float]:
    """`(e, tau)` (tau in `t*`, to the neck's breaking) of LAMMPS's continuous damped JKR
    impact at groups `q`, `beta` (DOP853 at `rtol`); `e = 0` where the neck holds the body."""
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
    """The `q` whose impact at `beta` has restitution `e` (a one-line ValueError where the
    damping alone leaves less)."""
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


def replica(parameters, m: float, v0: float, phases=_stepping.PHASES):
    """`jkr.replica` damped (`damp meff a v` at the half-step speed)."""
    return jkr.replica(parameters, m, v0, phases, damped=True)


def _check(parameters) -> tuple[float, float, float, float]:
    """`(E, poisson, cohesion, damp)`, checked."""
    return script.material(parameters, damped=True)


def model(E: float, damp: float, poisson: float, cohesion: float) -> str:
    """The damped `jkr` clause."""
    return f"jkr {E:.10g} {damp:.10g} {poisson:.10g} {cohesion:.10g} damping viscoelastic"


class JKRViscoelastic(AbstractNormalModel):
    """LAMMPS's damped `jkr` model, keeping the exported law's damping group (the module's
    docstring)."""

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
            (e, T, timestep),
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
        """`jkr.py`'s, with `b = damp meff Reff^0.5` (N s/m^1.5): its e and T at v0 within 0.3 %
        of the replica's (tests/engines; with `w = 2 cohesion`, e 2.7 % below)."""
        E, nu, cohesion, damp = _check(parameters)
        c, b, R_eff = script.hertz_groups(parameters, m, E, nu, damp)
        return {"c": c, "b": b, "R": R_eff, "w": 2.0 * cohesion * ENERGY_RATIO**0.6}

    def response(self, parameters, *, m, radius=None):
        return self.law(script.with_effective_radius(parameters, radius), m), "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        return script.cohesive_stepper(replica, _check, parameters, m=m, radius=radius)
