"""MuJoCo's soft contact (solref, solimp) per unit mass, and its Euler step replicated: what
its normal model (`normal.py`), its friction (`friction.py`) and Yade's design share.

MuJoCo: a body on a plane through its soft contact (solref, solimp), and the e and T that
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

from .. import _stepping

DEFAULT_TIMECONST = 0.02  # s, MuJoCo's solref default
DEFAULT_TIMESTEP = 0.002  # s, MuJoCo's option timestep default
SOLIMP = (0.99, 0.99, 0.001, 0.5, 2.0)  # constant impedance: the contact is linear
_MAX_DAMPRATIO = 1e3


def continuous(dampratio: float) -> tuple[float, float]:
    """`(e, tau)` of the continuous contact: restitution and duration in units of
    `timeconst * dampratio` (= 1/natural frequency), from jaximpact's exact Kelvin-Voigt
    under the force criterion."""
    from ...closed_forms import kelvin_voigt

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
