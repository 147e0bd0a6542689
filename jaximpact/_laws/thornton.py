"""Thornton's (1997) elastic-perfectly-plastic law: a law with a contact state (the largest
overlap so far), its row of the law table, its dynamics and its exact impact.

Loading is Hertz, `F = c x^1.5`, up to the yield overlap `x_y`, then the contact pressure is
limited: `F = c x_y^0.5 (1.5 x - 0.5 x_y)` (the slope stays `1.5 c x_y^0.5`). Unloading from
the largest overlap `x_m` (force `F_m`) is Hertzian about the plastic overlap `x_p`, with the
radius enlarged to `R_p = R c x_m^1.5 / F_m`: `F = c_p (x - x_p)^1.5`,
`c_p = c (c x_m^1.5 / F_m)^0.5`, `x_m - x_p = (F_m / c_p)^(2/3)`. Contact ends where the
body leaves the dent, `x = x_p` (`separation="force"`), or the original surface, `x = 0`
(`"penetration"`: a free flight from `x_p` to 0 added).

Without gravity the impact depends on `v0 / v_y` alone, with the yield speed
`v_y = (4 c x_y^2.5 / (5 m))^0.5` (the speed whose Hertz impact just reaches `x_y`), and it is
exact: `e` (Thornton's formula), `T`, `x_max`, `F_max` in closed form (`thornton_impact`).
C. Thornton, J. Appl. Mech. 64(2):383-386 (1997); shared/notes/contact-physics.md, 2.1.
"""

import math
from typing import ClassVar

import equinox as eqx
import jax.numpy as jnp
from jax.scipy.special import betainc
from jaxtyping import Array

from .._powers import safe_pow
from .._status import Status
from .base import AbstractLaw, LawSpec
from .dynamics import AbstractDynamics
from .parameters import checked_parameters

# (2/5) B(2/5, 1/2): the Hertz contact's time from first touch to maximum compression in
# units of x_max / v0, the integral of du / sqrt(1 - u^2.5) over (0, 1)
HERTZ_HALF_TIME = 0.4 * math.exp(math.lgamma(0.4) + math.lgamma(0.5) - math.lgamma(0.9))


def yield_speed(c, x_y, m):
    """The impact speed (m/s) whose Hertz impact just reaches the yield overlap:
    `v_y = (4 c x_y^2.5 / (5 m))^0.5` (c in N/m^1.5, x_y in m, m in kg)."""
    return jnp.sqrt(0.8 * c * x_y**2.5 / m)


def thornton_restitution(v0_over_vy):
    """Thornton's exact `e(v0 / v_y)` (1 below the yield speed):
    `e = (6 sqrt3 / 5)^0.5 (1 - r^2/6)^0.5 [r / (r + 2 (6/5 - r^2/5)^0.5)]^(1/4)`, r = v_y/v0;
    `1.185 r^(1/4)` at high speed."""
    ratio = jnp.asarray(v0_over_vy, dtype=float)
    plastic = ratio > 1.0
    r = 1.0 / jnp.where(plastic, ratio, 2.0)
    e = (
        jnp.sqrt(6.0 * math.sqrt(3.0) / 5.0)
        * jnp.sqrt(1.0 - r**2 / 6.0)
        * (r / (r + 2.0 * jnp.sqrt(1.2 - 0.2 * r**2))) ** 0.25
    )
    return jnp.where(plastic, e, 1.0)


def _unloading(c, x_m, F_m):
    """The Hertzian unloading about the plastic overlap: `(c_p, x_m - x_p)`."""
    c_p = c * jnp.sqrt(c * x_m**1.5 / F_m)
    return c_p, (F_m / c_p) ** (2.0 / 3.0)


def thornton_impact(c, x_y, m, v0, separation="force"):
    """The exact impact without gravity: a dict of `e`, `T` (s), `x_max` (m), `F_max` (N),
    `t_max` (s), `status`. The Hertz loading to `x_y` takes
    `(x_h/v0) (2/5) B(w_y; 2/5, 1/2)`, `x_h = (5 m v0^2 / (4 c))^0.4`, `w_y = (x_y/x_h)^2.5`;
    the linear loading after it is a quarter of an oscillation about `x_y/3` at
    `omega = (1.5 c x_y^0.5 / m)^0.5`; the unloading a Hertz half-contact of stiffness
    `c_p`, ending at `v_out^2 = 0.8 c_p (x_m - x_p)^2.5 / m`."""
    x_h = (1.25 * m * v0**2 / c) ** 0.4
    plastic = x_h > x_y
    # the elastic impact wherever it applies (double where: no NaN in a discarded branch)
    x_y_p = jnp.where(plastic, x_y, 0.5 * x_h)
    w_y = (x_y_p / x_h) ** 2.5
    t_hertz = x_h / v0 * HERTZ_HALF_TIME * betainc(0.4, 0.5, w_y)
    v_1 = v0 * jnp.sqrt(1.0 - w_y)
    k = 1.5 * c * jnp.sqrt(x_y_p)
    omega = jnp.sqrt(k / m)
    rise = 2.0 * x_y_p / 3.0  # x_y - x_y/3, the spring's stretch at yield
    amplitude = jnp.sqrt(rise**2 + (v_1 / omega) ** 2)
    t_linear = jnp.arctan2(v_1 / omega, rise) / omega
    x_m = jnp.where(plastic, x_y_p / 3.0 + amplitude, x_h)
    F_m = jnp.where(plastic, k * amplitude, c * x_h**1.5)
    c_p, depth = _unloading(c, x_m, F_m)
    v_out = jnp.sqrt(0.8 * c_p * depth**2.5 / m)
    t_max = jnp.where(plastic, t_hertz + t_linear, HERTZ_HALF_TIME * x_h / v0)
    T = t_max + HERTZ_HALF_TIME * depth / v_out
    if separation == "penetration":
        T = T + (x_m - depth) / v_out  # the free flight from the dent's bottom to x = 0
    zero = jnp.zeros_like(T)
    return dict(
        e=v_out / v0,
        T=T,
        x_max=x_m,
        F_max=F_m,
        t_max=t_max,
        status=zero.astype(jnp.int32) + Status.separated,
        x_end=(x_m - depth) if separation == "force" else zero,  # the dent's bottom, or 0
    )


def ratio_for_restitution(e):
    """`v0 / v_y` whose Thornton restitution is `e` (numpy; bisection in the logarithm of
    the ratio, over 1 to 1e12; 1 for `e >= 1`)."""
    lo, hi = 0.0, math.log(1e12)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if float(thornton_restitution(math.exp(mid))) > e else (lo, mid)
    return math.exp(0.5 * (lo + hi))


def thornton_start(*, m, v0, e, T):
    """Start values for a fit: `c` from `T` as if the contact were Hertz's
    (`T = 2.943 x_h / v0`), `x_y` from `e` through Thornton's formula at this `c`."""
    T = 1e-3 if T is None or not math.isfinite(T) else T
    x_h = v0 * T / (2.0 * HERTZ_HALF_TIME)
    c = 1.25 * m * v0**2 / x_h**2.5
    v_y = v0 / ratio_for_restitution(min(e, 1.0))
    return dict(c=c, x_y=(1.25 * m * v_y**2 / c) ** 0.4)


def thornton_closed_form(separation):
    """Thornton's law without gravity: `thornton_impact` (any `v0 / v_y`)."""

    def impact_fields(law, *, m, v0, g=0.0, rest_tol, tau_max=None, with_end=False):
        from .closed_forms import _finish

        fields = thornton_impact(law.params["c"], law.params["x_y"], m, v0, separation)
        return _finish(fields, m, v0, g, with_end)

    return impact_fields


class ThorntonDynamics(AbstractDynamics):
    """Thornton's contact in Hertz units: `x* = (m v0^2 / c)^0.4`, `t* = x*/v0`, force in
    `m v0^2 / x*`. State `(X, V, X_m)`, `X_m` the largest overlap (it follows `X` while
    compressing, and stays after); loading `X^1.5` up to `X_y`, `X_y^0.5 (1.5 X - 0.5 X_y)`
    beyond; unloading `C_p (X - X_p)^1.5`, zero inside the dent's free part (`X < X_p`).
    The force criterion ends contact at `X = X_p`, which the body crosses transversally."""

    x_yield: Array  # X_y = x_y / x*
    gamma: Array
    x_star: Array
    t_star: Array
    mass: Array
    has_dry: bool = eqx.field(static=True, default=False)
    split: bool = eqx.field(static=True, default=True)

    def y0(self):
        zero = jnp.zeros_like(self.x_yield)
        return jnp.stack([zero, zero + 1.0, zero])

    def position(self, y):
        return y[0]

    def velocity(self, y):
        return y[1]

    def _loading(self, x):
        yielded = x > self.x_yield
        hertz = safe_pow(jnp.where(yielded, self.x_yield, x), 1.5)
        limited = jnp.sqrt(self.x_yield) * (1.5 * x - 0.5 * self.x_yield)
        return jnp.where(yielded, limited, hertz)

    def _dent(self, x_m):
        """`(C_p, X_p)` of the unloading from the largest overlap `X_m`."""
        x_m = jnp.maximum(x_m, 1e-100)  # no 0/0 before contact
        c_p, depth = _unloading(1.0, x_m, self._loading(x_m))
        return c_p, x_m - depth

    def force(self, y, compressing):
        c_p, x_p = self._dent(y[2])
        return jnp.where(compressing, self._loading(y[0]), c_p * safe_pow(y[0] - x_p, 1.5))

    def rhs(self, y, compressing):
        v = y[1]
        return jnp.stack(
            [v, -self.force(y, compressing) + self.gamma, jnp.where(compressing, v, 0.0)]
        )

    def force_gap(self, y, compressing):
        _, x_p = self._dent(y[2])
        return jnp.where(compressing, self._loading(y[0]), y[0] - x_p)


class ThorntonLaw(AbstractLaw):
    """Thornton's elastic-perfectly-plastic law, built by
    `jaximpact.law("thornton", c=..., x_y=...)` (c in N/m^1.5, the Hertz stiffness
    `4/3 E* R^0.5`; x_y in m, the overlap where the contact pressure reaches its limit,
    `R (pi p_y / (2 E*))^2`: `jaximpact.yield_overlap`). Its force depends on the largest
    overlap so far, a state of the contact: `force(x, v, x_max=...)`.

    **Example**: `jaximpact.law("thornton", c=1.6e10, x_y=2e-7)`.
    """

    params: dict[str, Array]
    has_state: ClassVar[bool] = True

    @property
    def name(self) -> str:
        return THORNTON.name

    @property
    def spec(self) -> LawSpec:
        return THORNTON

    def replace(self, **params):
        self._refuse_unknown(params)
        return ThorntonLaw(checked_parameters(THORNTON, {**self.params, **params}))

    def yield_speed(self, m):
        """The yield speed (m/s) of a body of mass `m` (kg): `yield_speed`."""
        return yield_speed(self.params["c"], self.params["x_y"], m)

    def dynamics(self, *, m, v0, g):
        c, x_y = self.params["c"], self.params["x_y"]
        x_star = (m * v0**2 / c) ** 0.4
        t_star = x_star / v0
        return ThorntonDynamics(
            x_yield=x_y / x_star,
            gamma=g * x_star / v0**2 + jnp.zeros_like(x_star),
            x_star=x_star,
            t_star=t_star,
            mass=m + jnp.zeros_like(x_star),
        )

    def force(self, x, v, *, x_max=None, v0=None):
        """The force (N) at overlap `x` (m): on the loading curve where `x_max` (the largest
        overlap so far, m) is not given or `x >= x_max`, else on the unloading curve from
        `x_max` (zero below the plastic overlap). It depends on neither `v` nor the impact
        speed `v0` (accepted as every law's `force` takes it)."""
        c, x_y = self.params["c"], self.params["x_y"]
        unit = ThorntonDynamics(
            x_yield=x_y, gamma=0.0, x_star=1.0, t_star=1.0, mass=1.0
        )  # in SI: x* = 1 m, force per unit c
        x = jnp.asarray(x, dtype=float)
        x_max = x if x_max is None else jnp.maximum(jnp.asarray(x_max, dtype=float), x)
        y = jnp.stack([x, jnp.zeros_like(x), x_max + jnp.zeros_like(x)])
        return c * unit.force(y, x >= x_max)


THORNTON = LawSpec(
    name="thornton",
    equation="Thornton 1997",
    formula="c x^1.5 to x_y, then c x_y^0.5 (1.5 x - 0.5 x_y); Hertzian unloading about "
    "the plastic overlap",
    parameters=("c", "x_y"),
    units={"c": "N/m^1.5", "x_y": "m"},
    reference="C. Thornton, J. Appl. Mech. 64(2):383-386 (1997)",
    state=ThorntonLaw,
    positive=("c", "x_y"),
    damping="x_y",
    map_range=(1e-5, 5e-3),
    closed_form=thornton_closed_form,
    start=thornton_start,
    kind="plastic",
)
