"""MuJoCo's soft contact per unit mass (shared by `normal.py`, `friction.py` and Yade).
src/engine/engine_core_constraint.c (`getsolparam`, `getimpedance`, `mj_makeImpedance`): a
row's `aref = -B v - K d r`, solved `(1 - d) a0 + d aref`; standard solref `(timeconst,
dampratio)` gives `K = 1/(dmax^2 timeconst^2 dampratio^2)`, `B = 2/(dmax timeconst)`, so with
constant impedance `x'' = -max(0, 2/timeconst x' + x/(timeconst dampratio)^2)`: `kelvin_voigt`
per unit mass under `separation="force"`. `refsafe` raises timeconst to two steps; the direct
form `(-stiffness, -damping)` is never raised. Euler is semi-implicit in the contact force
(`_stepping.semi_implicit_euler`, equal to MuJoCo to round-off)."""

import functools
import math

import numpy as np

from .. import _stepping

DEFAULT_TIMECONST = 0.02  # s, MuJoCo's solref default
DEFAULT_TIMESTEP = 0.002  # s, MuJoCo's option timestep default
SOLIMP = (0.99, 0.99, 0.001, 0.5, 2.0)  # constant impedance: the contact is linear
_MAX_DAMPRATIO = 1e3


@functools.cache
def _unit_kelvin_voigt():
    """`b -> (e, T)` of `kelvin_voigt` at `c = m = v0 = 1` (force criterion), compiled: run op
    by op, each call took 7-8 ms, and `dampratio_for`'s root search 0.15-0.6 s per export."""
    import jax

    from ...closed_forms import kelvin_voigt

    def e_and_T(b):
        out = kelvin_voigt(1.0, b, 1.0, 1.0, "force")
        return out["e"], out["T"]

    return jax.jit(e_and_T)


def continuous(dampratio: float) -> tuple[float, float]:
    """`(e, tau)` of the continuous contact, tau in `timeconst dampratio` (1/natural frequency)."""
    e, T = _unit_kelvin_voigt()(2.0 * dampratio)
    return float(e), float(T)


def dampratio_for(e: float) -> float:
    """The damping ratio whose restitution is `e` (force criterion)."""
    if e >= 1.0:
        return 0.0
    from scipy.optimize import brentq

    if continuous(_MAX_DAMPRATIO)[0] > e:
        raise ValueError(
            f"e = {e:g} needs a MuJoCo dampratio above {_MAX_DAMPRATIO:g}; not realisable"
        )
    return brentq(lambda z: continuous(z)[0] - e, 0.0, _MAX_DAMPRATIO, xtol=1e-14, rtol=1e-13)


def acceleration(stiffness: float, damping: float):
    """`a(x, v)` per unit mass, never pulling: stiffness (1/s^2), damping (1/s)."""
    return lambda x, v: -np.maximum(0.0, damping * v + stiffness * x)


def check_solref(solref) -> tuple[float, float]:
    """`solref` as two floats, standard or direct, or a one-line ValueError."""
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
    """`(stiffness, damping)` per unit mass MuJoCo applies for `solref` (refsafe included)."""
    a, b = float(solref[0]), float(solref[1])
    if a < 0:
        return -a, -b
    timeconst = max(a, 2.0 * timestep)
    return 1.0 / (timeconst * b) ** 2, 2.0 / timeconst


def replica(solref, timestep: float, v0: float, phases=_stepping.PHASES):
    """`(e, T)` per start phase of MuJoCo's Euler step."""
    stiffness, damping = effective(solref, timestep)
    return _stepping.semi_implicit_euler(acceleration(stiffness, damping), timestep, v0, phases)
