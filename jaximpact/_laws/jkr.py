"""The JKR adhesive elastic contact (Johnson, Kendall & Roberts 1971), a law with a contact
state (the neck: attached or not), its row of the law table, its dynamics and its exact
impact.

With the contact radius `a`, `E* = 3 c / (4 R^0.5)` and the work of adhesion `w` (J/m^2):
`x = a^2/R - (2 pi w a / E*)^0.5`, `F = 4 E* a^3 / (3 R) - (8 pi w E* a^3)^0.5`. The neck
forms when the surfaces touch (`x = 0`: the force snaps to `-8/9 F_c`, `F_c = 1.5 pi w R`)
and breaks where `x` is least, at pull-off: `x_f = -3/4 (pi^2 w^2 R / E*^2)^(1/3)`,
`F = -5/9 F_c`. Contact ends there under either separation criterion (the body is held
until the neck breaks); below the sticking speed it never breaks: `e = 0`, `captured`.

In Hertz units (`x* = (m v0^2/c)^0.4`, `t* = x*/v0`) and `sigma = (a^2 / (R x*))^(1/4)`,
`X = sigma^4 - q sigma` and `F = sigma^6 - 1.5 q sigma^3` with the one group
`q = (2 pi w / E*)^0.5 R^0.25 / x*^0.75`, so without gravity the impact depends on `q`
(equivalently `v0 / V_s`) alone, and it is exact: the energy `U(sigma) = 0.4 sigma^10 -
q sigma^7 + 0.375 q^2 sigma^4` gives `e = (1 - 2 (U(sigma_f) - U(sigma_0)))^0.5`, and
`T` is a quadrature of `dX / V` (`jkr_impact`). Sticking speed:
`V_s = 1.0348 (F_c^5 / (m^3 E*^2 R))^(1/6)` (shared/notes/contact-physics.md, 3.1, prints
`R^3`: with `W = 7.092 (w^5 R^4 / E*^2)^(1/3)` and `V_s = (2 W / m)^0.5` it is `R`).
"""

from typing import ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._status import Status
from .base import AbstractLaw, LawSpec
from .dynamics import AbstractDynamics
from .parameters import checked_parameters
from .thornton import HERTZ_HALF_TIME

_NEWTON_STEPS = 60  # monotone Newton from the right; linear only at pull-off's double root
_NODES, _WEIGHTS = (np.asarray(a) for a in np.polynomial.legendre.leggauss(64))


def adhesion_group(c, R, w, m, v0):
    """The group `q = (2 pi w / E*)^0.5 R^0.25 / x*^0.75` (E* = 3 c / (4 R^0.5),
    x* = (m v0^2 / c)^0.4)."""
    E_star = 0.75 * c / jnp.sqrt(R)
    x_star = (m * v0**2 / c) ** 0.4
    return jnp.sqrt(2.0 * jnp.pi * w / E_star) * R**0.25 / x_star**0.75


def sticking_speed(c, R, w, m):
    """The speed (m/s) below which a JKR impact sticks:
    `V_s = 1.0348 (F_c^5 / (m^3 E*^2 R))^(1/6)`, `F_c = 1.5 pi w R` (c in N/m^1.5,
    R in m, w in J/m^2, m in kg); computed exactly as `(2 W / m)^0.5`, W the energy the
    neck takes."""
    # the energy taken, W = m v0^2 (U(sigma_f) - U(sigma_0)), does not depend on v0 (each
    # term of U goes as q^(10/3), q as v0^-0.6): read it at v0 = 1 m/s
    loss = _energy_loss(adhesion_group(c, R, w, m, 1.0))
    return jnp.sqrt(2.0 * loss)


def _potential(sigma, q):
    """`U(sigma)`, the work of the JKR force from `sigma = 0` (units of m v0^2)."""
    return 0.4 * sigma**10 - q * sigma**7 + 0.375 * q**2 * sigma**4


def _snap(q):
    """`sigma` where the neck forms (`X = 0`) and where it breaks (least `X`)."""
    return q ** (1.0 / 3.0), (q / 4.0) ** (1.0 / 3.0)


def _energy_loss(q):
    """`U(sigma_f) - U(sigma_0)`: the energy (units of m v0^2) the neck takes."""
    s0, sf = _snap(q)
    return _potential(sf, q) - _potential(s0, q)


def radius_at(X, q):
    """`sigma` on the attached branch (`sigma >= sigma_f`) where `sigma^4 - q sigma = X`;
    `sigma_f` below pull-off. Newton from the right (`X^(1/4) + q^(1/3)` lies right of
    the root; the function is convex and increasing there, so the iterates fall
    monotonically), then one step with gradients: the implicit function's derivative."""
    _, sf = _snap(q)
    X_f = sf**4 - q * sf
    X = jnp.maximum(X, X_f)

    def newton(sigma):
        return sigma - (sigma**4 - q * sigma - X) / (4.0 * sigma**3 - q)

    start = jnp.maximum(X, 0.0) ** 0.25 + q ** (1.0 / 3.0)
    sigma = jax.lax.fori_loop(
        0, _NEWTON_STEPS, lambda _, s: newton(s), jax.lax.stop_gradient(start)
    )
    sigma = jnp.maximum(jax.lax.stop_gradient(sigma), sf)
    slope = 4.0 * sigma**3 - q
    safe = slope > 1e-12 * q
    step = (sigma**4 - q * sigma - X) / jnp.where(safe, slope, 1.0)
    return jnp.where(safe, sigma - step, sf)


def _descend(f, df, start, steps=80):
    """A root of `f` by Newton from `start`, monotone where `f` is convex and increasing
    (to the right), then one step with gradients."""
    root = jax.lax.fori_loop(0, steps, lambda _, s: s - f(s) / df(s), jax.lax.stop_gradient(start))
    root = jax.lax.stop_gradient(root)
    return root - f(root) / df(root)


def _bisect(f, lo, hi, steps=110):
    """The root of `f`, which falls from `lo` to `hi` (or rises), by bisection of the
    bracket, then one Newton step with gradients (`jax.grad` of `f` in its argument)."""
    f_lo = f(jax.lax.stop_gradient(lo))

    def halve(_, bracket):
        a, b = bracket
        mid = 0.5 * (a + b)
        same = jnp.sign(f(mid)) == jnp.sign(f_lo)
        return jnp.where(same, mid, a), jnp.where(same, b, mid)

    a, b = jax.lax.fori_loop(0, steps, halve, jax.lax.stop_gradient((lo, hi)))
    root = jax.lax.stop_gradient(0.5 * (a + b))
    slope = jax.grad(lambda s: jnp.sum(f(s)))(root)
    return root - f(root) / jnp.where(slope != 0, slope, 1.0)


def _travel_time(lo, hi, singular_at, q, energy):
    """`integral of (4 sigma^3 - q) / V dsigma` over `[lo, hi]`, `V^2 = 1 - 2 (U - U_0)`,
    with `sigma = p + (other - p) u^2` about the end `p` (`singular_at`: `lo` or `hi`)
    where `V` may vanish as a square root, so the integrand is smooth in `u`."""
    u = 0.5 * (_NODES + 1.0)
    p, other = (lo, hi) if singular_at == "lo" else (hi, lo)
    sigma = p + (other - p) * u[:, None] ** 2 if jnp.ndim(p) else p + (other - p) * u**2
    speed2 = jnp.maximum(1.0 - 2.0 * (_potential(sigma, q) - energy), 1e-300)
    integrand = (4.0 * sigma**3 - q) / jnp.sqrt(speed2) * 2.0 * (other - p) * u
    return jnp.abs(0.5 * jnp.sum(_WEIGHTS * integrand, axis=0))


def jkr_impact(c, R, w, m, v0):
    """The exact impact without gravity: a dict of `e`, `T` (s), `x_max` (m), `F_max` (N),
    `t_max` (s), `status` (`captured` below the sticking speed, with `T` the time the body
    turns back, held by the neck)."""
    q = adhesion_group(c, R, w, m, v0)
    x_star = (m * v0**2 / c) ** 0.4
    t_star = x_star / v0
    s0, sf = _snap(q)
    U0 = _potential(s0, q)

    def excess(s):  # U - U0 - 1/2: zero at maximum compression (right of U's minimum)
        return _potential(s, q) - U0 - 0.5

    def excess_slope(s):
        return 4.0 * s**9 - 7.0 * q * s**6 + 1.5 * q**2 * s**3

    s_m = _descend(excess, excess_slope, 1.0 + 2.0 * q ** (1.0 / 3.0))
    loss = _potential(sf, q) - U0
    separated = 2.0 * loss < 1.0
    # captured: the body turns back at U - U0 = 1/2 inside the well, between sigma_f and
    # sigma_0 (where U falls as sigma grows)
    s_turn = _bisect(excess, sf, s0)  # excess falls from sf to s0 (> 0 at sf if captured)
    s_end = jnp.where(separated, sf, jnp.clip(s_turn, sf, s0))
    t_in = _travel_time(s0, s_m, "hi", q, U0)
    t_out = _travel_time(s_end, s0, "lo", q, U0)
    # the square root sees 1 where the body is held, so that its derivative stays finite
    e = jnp.where(separated, jnp.sqrt(jnp.where(separated, 1.0 - 2.0 * loss, 1.0)), 0.0)
    status = jnp.where(separated, Status.separated, Status.captured).astype(jnp.int32)
    return dict(
        e=e,
        T=(2.0 * t_in + t_out) * t_star,
        x_max=(s_m**4 - q * s_m) * x_star,
        F_max=(s_m**6 - 1.5 * q * s_m**3) * m * v0**2 / x_star,
        t_max=t_in * t_star,
        status=status,
        x_end=(s_end**4 - q * s_end) * x_star,
    )


def jkr_start(*, m, v0, e, T, R):
    """Start values for a fit at radius `R` (m): `c` from `T` as if the contact were
    Hertz's (`T = 2.943 x_h / v0`), `w` from `e` through `e = (1 - (V_s/v0)^2)^0.5`
    (`V_s` grows as `w^(5/6)`); a stuck impact (`e = 0`) starts at `V_s = 1.5 v0`."""
    import math

    T = 1e-3 if T is None or not math.isfinite(T) else T
    x_h = v0 * T / (2.0 * HERTZ_HALF_TIME)
    c = 1.25 * m * v0**2 / x_h**2.5
    v_s = v0 * math.sqrt(max(1.0 - e**2, 1e-6)) if e > 0 else 1.5 * v0
    unit = float(sticking_speed(c, R, 1.0, m))  # V_s at w = 1 J/m^2
    return dict(c=c, R=R, w=(v_s / unit) ** 1.2)


def jkr_closed_form(separation):
    """JKR without gravity: `jkr_impact`, either criterion (contact ends at pull-off)."""

    def impact_fields(law, *, m, v0, g=0.0, rest_tol, tau_max=None, with_end=False):
        from .closed_forms import _finish

        p = law.params
        return _finish(jkr_impact(p["c"], p["R"], p["w"], m, v0), m, v0, g, with_end)

    return impact_fields


class JKRDynamics(AbstractDynamics):
    """The JKR contact in Hertz units: state `(X, V)`, force `sigma^6 - 1.5 q sigma^3
    + beta sigma^2 V` at `sigma = radius_at(X, q)` from first touch (the snap-in force
    `-q^2/2` at `X = 0`) until pull-off `X_f = -3/4 q (q/4)^(1/3)`, where contact ends under
    either criterion. `beta = b x*^1.5 / (m v0)`: LAMMPS's viscoelastic damping
    `b a / R^0.5 v` (`jkr_viscoelastic`; 0 for `jkr`)."""

    q: Array
    beta: Array
    gamma: Array
    x_star: Array
    t_star: Array
    mass: Array
    has_dry: bool = eqx.field(static=True, default=False)
    split: bool = eqx.field(static=True, default=False)

    def y0(self):
        zero = jnp.zeros_like(self.q)
        return jnp.stack([zero, zero + 1.0])

    def position(self, y):
        return y[0]

    def velocity(self, y):
        return y[1]

    def _pull_off(self):
        _, sf = _snap(self.q)
        return sf**4 - self.q * sf

    def force(self, y, compressing):
        sigma = radius_at(y[0], self.q)
        return sigma**6 - 1.5 * self.q * sigma**3 + self.beta * sigma**2 * y[1]

    def rhs(self, y, compressing):
        return jnp.stack([y[1], -self.force(y, compressing) + self.gamma])

    def force_gap(self, y, compressing):
        return y[0] - self._pull_off()

    def penetration_gap(self, y):
        return y[0] - self._pull_off()


class _NeckLaw(AbstractLaw):
    """What the JKR rows share: the parameters `c` (N/m^1.5, the Hertz stiffness
    `4/3 E* R^0.5`), `R` (m, the effective radius), `w` (J/m^2, the work of adhesion,
    twice a surface energy for like surfaces: `jaximpact.work_of_adhesion`), and with
    `jkr_viscoelastic` the damping `b` (N s/m^1.5). Its force depends on whether the neck
    has formed, a state of the contact: `force(x, v, attached=...)`."""

    params: dict[str, Array]
    has_state: ClassVar[bool] = True
    ROW: ClassVar[LawSpec]

    @property
    def name(self) -> str:
        return self.ROW.name

    @property
    def spec(self) -> LawSpec:
        return self.ROW

    def replace(self, **params):
        self._refuse_unknown(params)
        return type(self)(checked_parameters(self.ROW, {**self.params, **params}))

    def dynamics(self, *, m, v0, g):
        p = self.params
        x_star = (m * v0**2 / p["c"]) ** 0.4
        return JKRDynamics(
            q=adhesion_group(p["c"], p["R"], p["w"], m, v0),
            beta=p.get("b", 0.0) * x_star**1.5 / (m * v0) + jnp.zeros_like(x_star),
            gamma=g * x_star / v0**2 + jnp.zeros_like(x_star),
            x_star=x_star,
            t_star=x_star / v0,
            mass=m + jnp.zeros_like(x_star),
        )

    def force(self, x, v, *, attached=True, v0=None):
        """The force (N) at overlap `x` (m) and speed `v` (m/s, into the surface) with the
        neck formed (`attached`, from first touch until pull-off, down to `x_f < 0`), or 0
        where it is not (`x < 0`). It does not depend on the impact speed `v0` (accepted as
        every law's `force` takes it)."""
        p = self.params
        E_star = 0.75 * p["c"] / jnp.sqrt(p["R"])
        k = jnp.sqrt(2.0 * jnp.pi * p["w"] / E_star)
        q = k * p["R"] ** 0.25  # the group and the units at x* = 1 m (force unit: c)
        x = jnp.asarray(x, dtype=float)
        sigma = radius_at(x, q)  # sigma^2 = a / R^0.5 at x* = 1 m
        force = p["c"] * (sigma**6 - 1.5 * q * sigma**3) + p.get("b", 0.0) * sigma**2 * v
        return jnp.where(attached | (x >= 0), force, 0.0)


class JKRLaw(_NeckLaw):
    """The JKR adhesive elastic contact, built by `jaximpact.law("jkr", c=..., R=..., w=...)`
    (c in N/m^1.5, the Hertz stiffness `4/3 E* R^0.5`; R in m, the effective radius; w in
    J/m^2, the work of adhesion, twice a surface energy for like surfaces:
    `jaximpact.work_of_adhesion`). Its force depends on whether the neck has formed, a state
    of the contact: `force(x, v, attached=...)`.

    **Example**: `jaximpact.law("jkr", c=2.8e3, R=2.45e-6, w=0.4)`.
    """

    def sticking_speed(self, m):
        """The speed (m/s) below which a body of mass `m` (kg) sticks: `sticking_speed`."""
        p = self.params
        return sticking_speed(p["c"], p["R"], p["w"], m)


class JKRViscoelasticLaw(_NeckLaw):
    """JKR with LAMMPS's viscoelastic damping (`pair_style granular ... jkr ... damping
    viscoelastic`): `F = F_JKR(a) + b a / R^0.5 v`, `a` the JKR contact radius (so that
    without adhesion it is `c x^1.5 + b x^0.5 v`, the `dmt` law's damping), built by
    `jaximpact.law("jkr_viscoelastic", c=..., b=..., R=..., w=...)` (b in N s/m^1.5; the
    others as `jkr`'s). Integrated: the damping takes energy in both phases, so `e(v)`
    has no closed form; below a speed that the damping raises the neck holds the body
    (`captured`, `e = 0`).

    **Example**: `jaximpact.law("jkr_viscoelastic", c=2.8e3, b=1e-4, R=2.45e-6, w=0.4)`.
    """


JKR = LawSpec(
    name="jkr",
    equation="JKR 1971",
    formula="4 E* a^3 / (3 R) - (8 pi w E* a^3)^0.5 at x = a^2/R - (2 pi w a / E*)^0.5, "
    "E* = 3 c / (4 R^0.5); snap-in at x = 0, pull-off at least x",
    parameters=("c", "R", "w"),
    units={"c": "N/m^1.5", "R": "m", "w": "J/m^2"},
    reference="Johnson, Kendall & Roberts, Proc. R. Soc. A 324:301 (1971); Thornton & Ning, "
    "Powder Technol. 99:154 (1998)",
    state=JKRLaw,
    positive=("c", "R"),
    damping="w",
    map_range=(1e-3, 1.0),
    closed_form=jkr_closed_form,
    captures=True,  # below the sticking speed: e = 0, captured
    geometry=("R",),  # the radius is the user's, never fitted nor guessed
    start=jkr_start,
    kind="adhesive",
)


def jkr_viscoelastic_start(*, m, v0, e, T, R):
    """Start values for a fit at radius `R` (m): the loss `1 - e^2` split evenly between
    the neck (`w`, as `jkr_start` for the `e` that half the loss gives) and the damping
    (`b` from the damping ratio of that `e`, `b = 2 zeta m v0 / x_h^1.5`)."""
    import math

    e_half = math.sqrt(1.0 - 0.5 * (1.0 - e**2)) if e > 0 else 0.0
    start = jkr_start(m=m, v0=v0, e=e_half, T=T, R=R)
    x_h = (m * v0**2 / start["c"]) ** 0.4
    log_e = math.log(min(max(e_half, 0.05), 0.999999))
    zeta = -log_e / math.sqrt(math.pi**2 + log_e**2)
    return dict(start, b=2.0 * zeta * m * v0 / x_h**1.5)


JKR_VISCOELASTIC = LawSpec(
    name="jkr_viscoelastic",
    equation="JKR + LAMMPS",
    formula="4 E* a^3 / (3 R) - (8 pi w E* a^3)^0.5 + b a / R^0.5 v at x = a^2/R - "
    "(2 pi w a / E*)^0.5, E* = 3 c / (4 R^0.5); snap-in at x = 0, pull-off at least x",
    parameters=("c", "b", "R", "w"),
    units={"c": "N/m^1.5", "b": "N s/m^1.5", "R": "m", "w": "J/m^2"},
    reference="Johnson, Kendall & Roberts, Proc. R. Soc. A 324:301 (1971); LAMMPS pair "
    "granular jkr with damping viscoelastic (eta = damp m_eff a)",
    state=JKRViscoelasticLaw,
    positive=("c", "R"),
    damping="b",
    map_range=(0.0, 2000.0),
    map_fixed={"w": 0.1},  # a surface energy of 0.1 J/m^2, as dmt's map
    captures=True,  # below a sticking speed: e = 0, captured
    geometry=("R",),
    start=jkr_viscoelastic_start,
    kind="adhesive",
)
JKRViscoelasticLaw.ROW = JKR_VISCOELASTIC
JKRLaw.ROW = JKR
