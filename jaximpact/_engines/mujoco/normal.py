"""MuJoCo's normal model: solref, solimp and a step whose Euler step realises e and T."""

import math

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Stepping
from ..materials import check_positive
from .solref import (
    DEFAULT_TIMECONST,
    DEFAULT_TIMESTEP,
    SOLIMP,
    check_solref,
    continuous,
    dampratio_for,
    effective,
    replica,
)


def _corrected(e: float, T: float, v0: float, timestep) -> tuple[float, float, float]:
    """`(w0, zeta, h)`: natural frequency (1/s) and damping ratio that the Euler step at `h`
    (s: `timestep`, or the coarsest whose e spread is within tolerance, halved while the
    corrected contact misses) turns into `e`, `T` (s) at `v0` (m/s)."""
    if timestep is not None:
        return (*_at_step(e, T, v0, float(timestep))[:2], float(timestep))
    zeta = dampratio_for(e)
    w0 = continuous(zeta)[1] / T
    tol = _stepping.STEP_TOL - _CORRECTION_TOL
    h = _stepping.recommended_step(lambda h: replica(_solref_at(w0, zeta, h), h, v0), T, None, tol)
    while True:
        w0, zeta, es, Ts = _at_step(e, T, v0, h)
        if _stepping.realises(es, Ts, e, T) or T / h > _stepping.MAX_STEPS:
            return w0, zeta, h
        h = _stepping.nice_down(h / 2.0)


_CORRECTION_TOL = 2e-5  # how far the corrected phase means may stay from the target


def _at_step(e: float, T: float, v0: float, h: float):
    """`(w0, zeta, es, Ts)`: corrected (up to 8 rounds) for the Euler step at `h` (s)."""
    zeta = target = dampratio_for(e)
    w0 = continuous(zeta)[1] / T
    for _ in range(8):
        es, Ts = replica(_solref_at(w0, zeta, h), h, v0)
        e_mean, T_mean = float(es.mean()), float(Ts.mean())
        if abs(e_mean / e - 1) < _CORRECTION_TOL and abs(T_mean / T - 1) < _CORRECTION_TOL:
            break
        try:
            zeta_apparent = dampratio_for(min(e_mean, 1.0))
        except ValueError:
            break
        zeta = max(0.0, zeta + target - zeta_apparent)
        w0 *= T_mean / T
    else:
        es, Ts = replica(_solref_at(w0, zeta, h), h, v0)
    return w0, zeta, es, Ts


def _solref(w0: float, zeta: float):
    if zeta <= 0.0:
        return (-(w0**2), 0.0)  # e = 1: only the direct form has no damping
    return (1.0 / (w0 * zeta), zeta)


def _solref_at(w0: float, zeta: float, h: float):
    """`_solref`, direct where refsafe would raise the timeconst (below two steps `h`)."""
    solref = _solref(w0, zeta)
    if solref[0] > 0 and solref[0] < 2.0 * h:
        return (-(w0**2), -2.0 * zeta * w0)
    return solref


class Solref(AbstractNormalModel):
    """MuJoCo's soft contact at its Euler step (`solref.py`)."""

    NAME = "solref"
    LAW = "kelvin_voigt"
    KEYS = (
        Key("solref", "[timeconst s, dampratio], or the direct [-stiffness 1/s^2, -damping 1/s]"),
        Key("timestep", f"s, default {DEFAULT_TIMESTEP:g}, for its refsafe rule", needed=False),
    )
    STEPPING = (
        f"its Euler step at timestep (default {DEFAULT_TIMESTEP:g} s), semi-implicit in the "
        "contact force: replicated"
    )
    MASS_DEPENDS = None  # per unit mass
    ALLOWS_LIMIT_DAMPING = True
    NEAREST = "its kelvin_voigt law"
    SCENES = None

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        v0 = scene.v0
        warnings = []
        if T is None:
            zeta = dampratio_for(e)
            T = DEFAULT_TIMECONST * (continuous(zeta)[1] * zeta if zeta > 0 else math.pi)
            warnings.append(f"no T given: MuJoCo's default timeconst 0.02 s, T = {T:.4g} s")
        w0, zeta, h = _corrected(e, T, v0, timestep)
        solref = _solref(w0, zeta)
        es, Ts = replica(solref, h, v0)
        steps_per_contact = float(Ts.mean() / h)
        if solref[0] > 0 and solref[0] < 2.0 * h:
            warnings.append(
                f"timeconst {solref[0]:.4g} s is below two time steps ({2 * h:.4g} s): "
                "MuJoCo's refsafe raises it, so solref is given in its direct form, which is "
                "not raised"
            )
            solref = (-(w0**2), -2.0 * zeta * w0)
            es, Ts = replica(solref, h, v0)
        half_spread = float((es.max() - es.min()) / 2 / es.mean()) if es.mean() > 0 else 0.0
        if half_spread > _stepping.STEP_TOL:
            warnings.append(
                f"time step {h:.3g} s gives {steps_per_contact:.0f} steps per contact: e "
                f"ranges {es.min():.4g} to {es.max():.4g} with where contact starts inside a "
                f"step; use a step of {_stepping.describe_step(_corrected(e, T, v0, None)[2], T)}"
                " or less"
            )
        tol = _stepping.STEP_TOL
        if abs(es.mean() / e - 1) > tol or abs(Ts.mean() / T - 1) > tol:
            warnings.append(
                f"with time step {h:.3g} s MuJoCo realises e = {es.mean():.4g}, T = "
                f"{Ts.mean():.4g} s instead of e = {e:.4g}, T = {T:.4g} s"
            )
        parameters = {
            "solref": [float(solref[0]), float(solref[1])],
            "solref_direct": [-(w0**2), -2.0 * zeta * w0],
            "solimp": list(SOLIMP),
            "timestep": h,
            "integrator": "Euler",
            "natural_frequency": w0,
            "dampratio": zeta,
        }
        return Design.stepped(parameters, es, Ts, h, warnings, "force", parameters, target_T=T)

    def law_parameters(self, parameters, m):
        stiffness, damping = effective(parameters["solref"], parameters["timestep"])
        return {"c": m * stiffness, "b": m * damping}

    def response(self, parameters, *, m, radius=None):
        solref = check_solref(parameters["solref"])
        timestep = check_positive("timestep", parameters.get("timestep", DEFAULT_TIMESTEP), "s")
        return self.law({"solref": solref, "timestep": timestep}, m), "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping:
        h = check_positive("timestep", parameters.get("timestep", DEFAULT_TIMESTEP), "s")
        solref = check_solref(parameters["solref"])
        return Stepping(h, lambda v: replica(solref, h, v))
