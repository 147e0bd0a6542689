"""Drake's point contact, `f = k x (1 + d v)` clamped non-negative (multibody "Contact
Modeling", `geometry::AddContactMaterial`: `point_contact_stiffness` k N/m,
`hunt_crossley_dissipation` d s/m): Hunt & Crossley with n = 1 (law `point_contact`), e a
function of `d v0` (exact at the export's v0). Two geometries combine in series (`k = k1 k2 /
(k1 + k2)`, `d = (k2 d1 + k1 d2) / (k1 + k2)`): both get `2k` and `d`. A discrete plant (TAMSI,
Lagged, Similar; Castro et al. 2019, 2022) steps a contact found at a step's start by `m (v1 -
v) = -h k (x + h v1)_+ (1 + d v1)_+` (`replica`, equal to Drake 1.51.1 to 5 digits per
phase), which damps (e = 0.9 gave 0.59 at 10 steps): the export corrects k and d for it.
kSap ignores `hunt_crossley_dissipation`."""

import math

import numpy as np

from .. import _stepping
from ..base import AbstractNormalModel, Design, Key, Stepping
from ..materials import check_positive


def _tau(alpha: float) -> float:
    """The duration (in `sqrt(m/k)`) of `m x'' = -k x (1 + alpha v)` at `k = m = v0 = 1`."""
    from ..._laws import law
    from ..._solve.impact import impact

    return float(impact(law("point_contact", c=1.0, d=alpha), m=1.0, v0=1.0).T)


def alpha_for(e: float) -> float:
    """The `alpha = d v0` whose restitution is `e` (closed form, force criterion)."""
    from scipy.optimize import brentq

    from ...closed_forms import hunt_crossley_restitution

    if e >= 1.0:
        return 0.0
    f = lambda a: float(hunt_crossley_restitution(a)) - e  # noqa: E731
    hi = 1.0
    while f(hi) > 0:
        hi *= 4.0
        if hi > 1e12:
            raise ValueError(f"Drake's point contact cannot realise e = {e:g}")
    return brentq(f, 0.0, hi, xtol=1e-15, rtol=1e-13)


def _parameters(k: float, d: float, time_step: float) -> dict:
    out = {
        "point_contact_stiffness": k,
        "hunt_crossley_dissipation": d,
        "time_step": time_step,
        "per_geometry": {"point_contact_stiffness": 2.0 * k, "hunt_crossley_dissipation": d},
        "contact_model": "point",
    }
    if time_step:
        out["discrete_contact_approximation"] = "lagged"
    return out


def discrete_step(x, v, k, d, m, h):
    """`(x1, v1, pushing)` of one implicit step (the module's docstring), `x1 = x + h v1`."""
    A = h * h * k * d
    B = m + h * h * k + h * k * d * x
    C = h * k * x - m * v
    with np.errstate(invalid="ignore", divide="ignore"):
        root = np.where(
            A > 0,
            (-B + np.sqrt(np.maximum(B * B - 4 * A * C, 0.0))) / (2 * np.where(A > 0, A, 1.0)),
            -C / B,
        )
    active = (x > 0) & (x + h * v > 0) & (1 + d * v > 0)
    v1 = np.where(active, root, v)
    return x + h * v1, v1, active


def replica(parameters, m: float, v0: float, timestep: float, phases=None):
    """`(e, T)` per start phase of a discrete plant at `timestep` (s) with `parameters`, for
    mass `m` (kg) at `v0` (m/s)."""
    phases = _stepping.PHASES if phases is None else phases
    k = parameters["point_contact_stiffness"]
    d = parameters["hunt_crossley_dissipation"]
    h = float(timestep)
    return _stepping.step_until_separated(
        lambda x, v: discrete_step(x, v, k, d, m, h), h, v0, phases
    )


def _discrete(e: float, T: float, k: float, alpha: float, m: float, v0: float, h: float):
    """`(parameters, es, Ts, reachable)`: `k` (N/m), `alpha` corrected until the plant at `h`
    (s) realises `e`, `T` (s) on the phase mean, and whether some `d >= 0` reaches `e`."""
    params = _parameters(k, alpha / v0, h)
    reachable = True
    for _ in range(40):
        es, Ts = replica(params, m, v0, h)
        e_mean, T_mean = float(es.mean()), float(Ts.mean())
        if abs(e_mean / e - 1) < 1e-5 and abs(T_mean / T - 1) < 1e-4:
            break
        k *= (T_mean / T) ** 2
        if e_mean > 0 and e < 1:
            alpha = max(0.0, alpha + alpha_for(e) - alpha_for(min(e_mean, 1.0)))
        if alpha == 0.0 and e_mean < e * (1 - 1e-5):
            reachable = False
        params = _parameters(k, alpha / v0, h)
    es, Ts = replica(params, m, v0, h)
    return params, es, Ts, reachable


class PointContact(AbstractNormalModel):
    """Drake's point contact (the module's docstring)."""

    NAME = "point"
    LAW = "point_contact"
    KEYS = (
        Key("point_contact_stiffness", "N/m"),
        Key("hunt_crossley_dissipation", "s/m"),
        Key("time_step", "s; 0 or none: its continuous plant", needed=False),
    )
    STEPPING = (
        "with time_step > 0 its discrete plant's implicit step (Lagged, Similar, TAMSI): "
        "replicated; the continuous plant (time_step = 0) has no step error"
    )
    MASS_DEPENDS = "its point_contact_stiffness scales with the mass"
    ALLOWS_LIMIT_DAMPING = True
    NEAREST = "its point_contact law"
    SCENES = None

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        """k and d: exact on the continuous plant (`timestep` None or 0), corrected through
        `replica` on a discrete one (a warning where no d >= 0 gives `e`)."""
        from ...closed_forms import hunt_crossley_restitution

        m, v0 = scene.m, scene.v0
        if T is None:
            raise ValueError("Drake needs a contact duration: pass T= (s) or a law")
        alpha = alpha_for(e)
        tau = _tau(alpha)
        k = m * (tau / T) ** 2
        if not timestep:  # the continuous plant: exact
            e_c, T_c = float(hunt_crossley_restitution(alpha)), float(tau * math.sqrt(m / k))
            return Design(_parameters(k, alpha / v0, 0.0), e_c, T_c, 0.0, "force")
        h = float(timestep)
        params, es, Ts, reachable = _discrete(e, T, k, alpha, m, v0, h)
        steps = float(Ts.mean() / h)
        warnings = []
        if not reachable or abs(es.mean() / e - 1) > 0.005:
            warnings.append(
                f"a discrete plant at time_step {h:.3g} s ({steps:.0f} steps per contact) "
                f"damps more than e = {e:.4g} allows: even with hunt_crossley_dissipation = 0 "
                f"it realises e = {es.mean():.4g} (its implicit step; TAMSI, Lagged and "
                "Similar alike, measured); use time_step = 0 or a smaller step"
            )
        if (es.max() - es.min()) / 2 > 0.005 * es.mean():
            warnings.append(
                f"time_step {h:.3g} s: e ranges {es.min():.4g} to {es.max():.4g} with where "
                "first touch falls inside a step"
            )
        warnings.append(
            "the promise is for the Lagged (Drake's default), Similar or TAMSI discrete "
            "approximation; kSap ignores hunt_crossley_dissipation (e near 0)"
        )
        return Design.stepped(params, es, Ts, h, warnings, "force", params)

    def law_parameters(self, parameters, m):
        return {
            "c": parameters["point_contact_stiffness"],
            "d": parameters["hunt_crossley_dissipation"],
        }

    def response(self, parameters, *, m, radius=None):
        k = check_positive("point_contact_stiffness", parameters["point_contact_stiffness"], "N/m")
        d = float(parameters["hunt_crossley_dissipation"])
        if not (math.isfinite(d) and d >= 0):
            raise ValueError(f"hunt_crossley_dissipation must be >= 0 s/m, got {d:g}")
        law = self.law({"point_contact_stiffness": k, "hunt_crossley_dissipation": d}, m)
        return law, "force"

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        if not parameters.get("time_step"):
            return None
        h = check_positive("time_step", parameters["time_step"], "s")
        self.response(parameters, m=m)  # the values checked
        return Stepping(h, lambda v: replica(parameters, m, v, h))
