"""MuJoCo: a body on a plane through its soft contact (solref, solimp), and the e and T that
MuJoCo's time stepping realises.

MuJoCo (src/engine/engine_core_constraint.c, `getsolparam`, `getimpedance`, `mj_makeImpedance`;
docs: Modeling > Solver parameters) gives a contact row the reference acceleration
`aref = -B v - K d r` with impedance `d` from solimp; the solved acceleration of one
frictionless row is `(1 - d) a0 + d aref`. Standard solref `(timeconst, dampratio)`:
`K = 1/(dmax^2 timeconst^2 dampratio^2)`, `B = 2/(dmax timeconst)`. With a constant impedance
(`solimp` with `dmin = dmax`) the penetration `x` obeys, for any mass,

    x'' = -max(0, 2/timeconst x' + x/(timeconst dampratio)^2)

a linear spring-dashpot per unit mass with natural frequency `1/(timeconst dampratio)` and
damping ratio `dampratio` whose force never pulls: `kelvin_voigt` under
`separation="force"`. `refsafe` (on by default) raises `timeconst` to at least two time
steps; the direct form `(-stiffness, -damping)` (`x'' = -stiffness x - damping x'`) is never
raised. The default integrator (Euler) is semi-implicit in the contact force:
`_stepping.semi_implicit_euler` replicates it to round-off (checked against MuJoCo in
tests/engines).
"""

import math

import numpy as np

from . import _stepping
from .base import AbstractEngine, Design, Key, Stepping
from .materials import check_positive

DEFAULT_TIMECONST = 0.02  # s, MuJoCo's solref default
DEFAULT_TIMESTEP = 0.002  # s, MuJoCo's option timestep default
SOLIMP = (0.99, 0.99, 0.001, 0.5, 2.0)  # constant impedance: the contact is linear
_MAX_DAMPRATIO = 1e3


def continuous(dampratio: float) -> tuple[float, float]:
    """`(e, tau)` of the continuous contact: restitution and duration in units of
    `timeconst * dampratio` (= 1/natural frequency), from jaximpact's exact Kelvin-Voigt
    under the force criterion."""
    from ..closed_forms import kelvin_voigt

    out = kelvin_voigt(1.0, 2.0 * dampratio, 1.0, 1.0, "force")
    return float(out["e"]), float(out["T"])


def dampratio_for(e: float) -> float:
    """The damping ratio whose force-criterion restitution is `e` (0 for `e = 1`)."""
    if e >= 1.0:
        return 0.0
    from scipy.optimize import brentq

    if continuous(_MAX_DAMPRATIO)[0] > e:
        raise ValueError(
            f"e = {e:g} needs a MuJoCo dampratio above {_MAX_DAMPRATIO:g}; not realisable"
        )
    return brentq(lambda z: continuous(z)[0] - e, 0.0, _MAX_DAMPRATIO, xtol=1e-14, rtol=1e-13)


def acceleration(stiffness: float, damping: float):
    """The contact acceleration `a(x, v)` along the penetration (per unit mass, never
    pulling) of stiffness `stiffness` (1/s^2) and damping `damping` (1/s)."""
    return lambda x, v: -np.maximum(0.0, damping * v + stiffness * x)


def check_solref(solref) -> tuple[float, float]:
    """`solref` as two floats, or a one-line ValueError: the standard form `[timeconst > 0,
    dampratio > 0]` or the direct form `[-stiffness < 0, -damping <= 0]`."""
    try:
        a, b = (float(value) for value in solref)
    except (TypeError, ValueError):
        message = f"solref must be two numbers, [timeconst, dampratio]; got {solref!r}"
        raise ValueError(message) from None
    standard = a > 0 and b > 0 and math.isfinite(a) and math.isfinite(b)
    direct = a < 0 and b <= 0 and math.isfinite(a) and math.isfinite(b)
    if not (standard or direct):
        raise ValueError(
            "solref must be [timeconst > 0, dampratio > 0] (standard) or [-stiffness < 0, "
            f"-damping <= 0] (direct), finite; got {list(solref)!r}"
        )
    return a, b


def effective(solref, timestep: float) -> tuple[float, float]:
    """`(stiffness, damping)` per unit mass that MuJoCo applies for `solref` (standard form
    `(timeconst, dampratio)`, raised to `timeconst >= 2 timestep` as refsafe does, or direct
    form `(-stiffness, -damping)`)."""
    a, b = float(solref[0]), float(solref[1])
    if a < 0:
        return -a, -b
    timeconst = max(a, 2.0 * timestep)
    return 1.0 / (timeconst * b) ** 2, 2.0 / timeconst


def replica(solref, timestep: float, v0: float, phases=_stepping.PHASES):
    """`(e, T)` per start phase that MuJoCo's Euler step realises (see `_stepping`)."""
    stiffness, damping = effective(solref, timestep)
    return _stepping.semi_implicit_euler(acceleration(stiffness, damping), timestep, v0, phases)


def _corrected(e: float, T: float, v0: float, timestep) -> tuple[float, float, float]:
    """`(w0, zeta, h)`: the natural frequency (1/s) and damping ratio that MuJoCo's Euler
    step at `h` (s: `timestep`, or the recommended step) turns into `e` and `T` (s) at `v0`
    (m/s), the continuous contact's corrected for the step's own bias (phase means). The
    recommended step is the coarsest at which e's spread over start phases stays within the
    export's tolerance (`_stepping.recommended_step`; the correction then moves the mean onto
    the target, within `_CORRECTION_TOL`), halved where the corrected contact still misses
    it."""
    if timestep is not None:
        return (*_at_step(e, T, v0, float(timestep))[:2], float(timestep))
    zeta = dampratio_for(e)
    w0 = continuous(zeta)[1] / T
    tol = _stepping.STEP_TOL - _CORRECTION_TOL
    h = _stepping.recommended_step(lambda h: replica(_solref_at(w0, zeta, h), h, v0), T, None,
                                   tol)  # fmt: skip
    while True:
        w0, zeta, es, Ts = _at_step(e, T, v0, h)
        if _stepping.realises(es, Ts, e, T) or T / h > _stepping.MAX_STEPS:
            return w0, zeta, h
        h = _stepping.nice_down(h / 2.0)


# how far (relative) the corrected contact's phase-mean e and T may stay from the target
_CORRECTION_TOL = 2e-5


def _at_step(e: float, T: float, v0: float, h: float):
    """`(w0, zeta, es, Ts)`: the continuous contact's natural frequency (1/s) and damping
    ratio corrected (phase means, up to 8 rounds) so that MuJoCo's Euler step at `h` (s)
    realises `e` and `T` (s) at `v0` (m/s), and what it realises per start phase."""
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
    """`_solref`, in the direct form where refsafe would raise the standard form's
    timeconst (below two steps `h`, s): the solref the design gives MuJoCo."""
    solref = _solref(w0, zeta)
    if solref[0] > 0 and solref[0] < 2.0 * h:
        return (-(w0**2), -2.0 * zeta * w0)
    return solref


class Mujoco(AbstractEngine):
    """MuJoCo's soft contact (solref, solimp) for a body on a plane, at its Euler step (the
    module's docstring has the formulas and sources)."""

    NAME = "mujoco"
    LABEL = "MuJoCo"
    SCENES = {
        "wall": "a free body of mass m on a fixed plane (MuJoCo scales the contact per unit "
        "mass: the promise holds for any mass), no gravity, approaching along the normal at v0"
    }
    TWO_SPHERES = False
    # solref scales the contact per unit mass: from targets e and T no mass is needed (from
    # a law, its e and T at v0 depend on the mass)
    MASS_DEPENDS = None
    KEYS = (
        Key("solref", "[timeconst s, dampratio], or the direct [-stiffness 1/s^2, -damping 1/s]"),
        Key("timestep", f"s, default {DEFAULT_TIMESTEP:g}, for its refsafe rule", needed=False),
    )
    LAW = "kelvin_voigt"
    STEPPING = (
        f"its Euler step at timestep (default {DEFAULT_TIMESTEP:g} s), semi-implicit in the "
        "contact force: replicated"
    )
    CONTINUOUS_PLANT = False
    FRICTION = (
        "MuJoCo has no tangential spring: a tangential law goes as its Coulomb mu alone, in "
        "MuJoCo's soft pyramidal friction cone (condim 3), solref corrected for the cone's "
        "stiffening head-on; the cone acts on the slip at the rate of the contact's damping, "
        "so a nearly elastic contact (low dampratio) barely slows it"
    )

    def check_tangential(self, tangential, *, radius, timestep):
        """MuJoCo takes any tangential law's `mu`."""

    def with_tangential(self, parameters, tangential):
        """`parameters` with friction `mu` (the tangential law's) on the pyramidal cone, and
        solref in its direct form divided by `head_on_factor(mu)`, so that head-on MuJoCo
        realises the frictionless design (mujoco_friction.py). `mu = 0`: no friction
        (condim 1), unchanged."""
        from .mujoco_friction import frictional_solref, head_on_factor

        mu = float(tangential.params["mu"])
        out = dict(parameters, friction=[mu, 0.0, 0.0], condim=3 if mu > 0 else 1,
                   cone="pyramidal", impratio=1.0)  # fmt: skip
        if mu > 0:
            out["solref"] = frictional_solref(parameters["solref"], parameters["timestep"], mu)
            out["cone_factor"] = head_on_factor(mu)
        return out

    def tangential_changes(self, parameters, tangential):
        """How strongly MuJoCo's friction can act: its cone slows the slip at the rate of
        the contact's damping `B` (1/s), over the contact's duration `T`; `B T` well below
        1 leaves the slip almost as it came."""
        if "cone_factor" not in parameters:
            return []
        stiffness, damping = effective(parameters["solref"], parameters["timestep"])
        zeta = damping / (2.0 * math.sqrt(stiffness))
        duration = continuous(zeta)[1] / math.sqrt(stiffness)
        return [
            f"MuJoCo's friction slows the slip at the rate of its contact damping, "
            f"{damping:.3g} /s, over a contact of {duration:.3g} s: B T = "
            f"{damping * duration:.2g} (it acts fully only where B T is several, a damping "
            "ratio near 1)"
        ]

    def oblique(self, parameters, *, m, radius, v_n, v_t):
        """MuJoCo's Euler step on the sphere with the exported friction (mujoco_friction.py);
        without friction the normal replica, the tangential speed and spin unchanged."""
        from .mujoco_friction import oblique_replica

        mu = float(parameters.get("friction", [0.0])[0])
        if mu > 0:
            return oblique_replica(parameters["solref"], parameters["timestep"], mu=mu,
                                   radius=radius, v_n=v_n, v_t=v_t)  # fmt: skip
        v_n = np.atleast_1d(np.asarray(v_n, float))
        e = np.stack([replica(parameters["solref"], parameters["timestep"], v)[0] for v in v_n])
        return e, np.ones_like(e), np.zeros_like(e)

    def design(self, e, T, *, m, v0, timestep=None, radius=None, poisson=0.3,
               limit_damping=False, geometry=None) -> Design:  # fmt: skip
        """solref, solimp and time step that realise `e` and `T` (s; None: MuJoCo's default
        timeconst) at `v0` (m/s) in MuJoCo, and what MuJoCo realises with them. The contact
        per unit mass does not depend on the mass `m`; the other options do not apply."""
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
        return Design(
            parameters=parameters,
            **_stepping.realised(es, Ts, h),
            warnings=tuple(warnings),
            separation="force",
            target_T=T,
            stepping=parameters,
        )

    def law_parameters(self, parameters, m):
        """`kelvin_voigt`'s `c` (N/m) and `b` (N s/m) for a body of mass `m` (kg), to be
        read with `separation="force"`."""
        stiffness, damping = effective(parameters["solref"], parameters["timestep"])
        return {"c": m * stiffness, "b": m * damping}

    def response(self, parameters, *, m, radius=None):
        """`(law, separation)`: the continuous law of `parameters` (`solref`, `timestep`,
        default 0.002 s, for refsafe) for a body of mass `m` (kg), each value checked."""
        solref = check_solref(parameters["solref"])
        timestep = check_positive("timestep", parameters.get("timestep", DEFAULT_TIMESTEP), "s")
        return self.law({"solref": solref, "timestep": timestep}, m), "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping:
        """MuJoCo's Euler step at `parameters["timestep"]` (default 0.002 s)."""
        h = check_positive("timestep", parameters.get("timestep", DEFAULT_TIMESTEP), "s")
        solref = check_solref(parameters["solref"])
        return Stepping(h, lambda v: replica(solref, h, v))

    def snippet(self, parameters) -> str:
        solref = " ".join(f"{v:.10g}" for v in parameters["solref"])
        solimp = " ".join(f"{v:g}" for v in parameters["solimp"])
        option, geom, note = "", "", ""
        if "friction" in parameters:
            friction = " ".join(f"{v:.10g}" for v in parameters["friction"])
            option = ' cone="pyramidal" impratio="1"'
            geom = f' friction="{friction}" condim="{parameters["condim"]}"'
            note = "; it takes the larger friction of the two"
        return (
            f'<option timestep="{parameters["timestep"]:.6g}" integrator="Euler"{option}/>\n'
            "<default>\n"
            f'  <geom solref="{solref}" solimp="{solimp}"{geom}/>\n'
            "</default>\n"
            "<!-- MuJoCo mixes the solref/solimp of the two geoms in contact: give both these\n"
            f"     values (the default class above does), or use a <pair>{note} -->"
        )
