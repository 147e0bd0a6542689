"""The scales of one impact (energy, penetration, duration, force) checked against what
float64 carries, before a solve would under- or overflow: `check_contact_scales`."""

import math

from .._checks import check_scale
from .table import LAWS


def check_contact_scales(law_name: str, params: dict, m: float, v0: float):
    """The scales of an impact of the law `law_name` (parameters `params`), mass `m` (kg)
    and speed `v0` (m/s): the energy `m v0^2` (J) and, for the family `F = c x^n + ...`,
    the penetration `x* = (m v0^2 / c)^(1/(n+1))` (m), the duration `x*/v0` (s) and the
    force `c x*^n` (N) must each lie within [1e-150, 1e150] (`_checks.check_scale`), so
    that no result under- or overflows float64 (a one-line `ValueError` otherwise)."""
    energy = m * v0 * v0
    if not (math.isfinite(m) and math.isfinite(v0) and m > 0 and v0 > 0):
        return  # the library's own checks say what is wrong
    what = f"for m = {m:g} kg and v0 = {v0:g} m/s, the contact's"
    check_scale(f"{what} energy m v0^2", energy, "J")
    spec = LAWS.get(law_name)
    if not (spec and spec.shape):  # a user's law, or one outside the family (no x* scale)
        return
    try:
        c, n = (float(a) for a in spec.coefficients({**spec.defaults, **params}, v0)[:2])
    except (KeyError, TypeError, ValueError):
        return  # a parameter missing or wrong: the law's own checks say so
    if not (c > 0 and n > 0 and math.isfinite(c)):
        return
    log_x = (math.log(energy) - math.log(c)) / (n + 1)  # logs: no overflow on the way
    for name, log_value, unit in (
        ("penetration scale (m v0^2/c)^(1/(n+1))", log_x, "m"),
        ("duration scale x*/v0", log_x - math.log(v0), "s"),
        ("force scale c x*^n", math.log(c) + n * log_x, "N"),
    ):
        check_scale(f"{what} {name}", math.exp(max(min(log_value, 700.0), -700.0)), unit)
