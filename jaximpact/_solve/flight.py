"""Free flight of a ball between impacts, in closed form (never integrated).

Vertical motion of a point mass above a floor: height `y` (m, positive above the floor),
upward velocity `u = dy/dt` (m/s), gravity `g` (m/s^2) pulling down and, optionally, air drag
quadratic in speed, `du/dt = -g - k u |u|` with `k = rho C_d A / (2 m)` (1/m), whose terminal
speed is `v_t = sqrt(g / k)`.

Every flight is described by its apex `(t_apex, y_apex)`: the instant and height where `u = 0`.
A flight that starts moving down has a *virtual* apex earlier in time (the ball would have been
at rest there had it flown freely before); the formulas below hold on both sides of the apex.

- Without drag: `y = y_a - g s^2 / 2`, `u = -g s`, `s = t - t_a`.
- With drag, rising (`s < 0`): `y = y_a + (v_t^2/g) ln cos(g s / v_t)`, `u = -v_t tan(g s / v_t)`;
  falling (`s >= 0`): `y = y_a - (v_t^2/g) ln cosh(g s / v_t)`, `u = -v_t tanh(g s / v_t)`.
  From a state `(y0, u0)`: `t_a = t0 + (v_t/g) atan(u0/v_t)` and
  `y_a = y0 + (v_t^2 / 2g) ln(1 + u0^2/v_t^2)` going up; `atanh` and `ln(1 - u0^2/v_t^2)` going
  down (which needs `|u0| < v_t`).
- Landing (`y = 0`, falling): `t = t_a + (v_t/g) asinh(sqrt(exp(2 g y_a / v_t^2) - 1))`, at the
  speed `v_t sqrt(1 - exp(-2 g y_a / v_t^2))`; without drag `t_a + sqrt(2 y_a / g)` and
  `sqrt(2 g y_a)`.

All functions are differentiable, NaN-free in value and gradient (arguments outside a
branch's domain are replaced before the branch is evaluated: the double-`where` pattern), and
work on arrays of any shape.
"""

import equinox as eqx
import jax.numpy as jnp
from jaxtyping import Array, ArrayLike

_EDGE = 1e-12  # keeps tan, atanh and log cos away from their poles in unused branches


def _terminal_speed(g, drag):
    return jnp.sqrt(g / drag)


def _log_cosh(z):
    """`ln cosh z`, without overflow for large `|z|`."""
    return jnp.logaddexp(z, -z) - jnp.log(2.0)


class Flight(eqx.Module):
    """One free flight, known by its (possibly virtual) apex.

    - `t_apex` (s), `y_apex` (m): when and where the upward velocity is zero.
    - `g` (m/s^2), `drag` (1/m): gravity and the quadratic drag coefficient
      `k = rho C_d A / (2 m)`; `drag=None` is a parabola.

    **Example**: `Flight.from_state(0.0, 0.6, 0.0, g=9.81).landing()` is
    `(0.3497..., 3.4310...)`: a ball dropped from 0.6 m lands after 0.35 s at 3.43 m/s.
    """

    t_apex: Array
    y_apex: Array
    g: Array
    drag: Array | None = None

    @classmethod
    def from_state(cls, t0: ArrayLike, y0: ArrayLike, u0: ArrayLike, *, g, drag=None):
        """The flight through height `y0` (m) at time `t0` (s) with upward velocity `u0`
        (m/s). With drag, a downward `u0` must be slower than the terminal speed."""
        t0, y0, u0 = (jnp.asarray(a, dtype=float) for a in (t0, y0, u0))
        g = jnp.asarray(g, dtype=float)
        if drag is None:
            return cls(t0 + u0 / g, y0 + 0.5 * u0**2 / g, g, None)
        drag = jnp.asarray(drag, dtype=float)
        v_t = _terminal_speed(g, drag)
        r = u0 / v_t
        up = r > 0
        r_up = jnp.where(up, r, 0.0)
        r_down = jnp.clip(jnp.where(up, 0.0, r), -1.0 + _EDGE, 0.0)
        dt = jnp.where(up, jnp.arctan(r_up), -jnp.arctanh(-r_down))
        dy = jnp.where(up, jnp.log1p(r_up**2), -jnp.log1p(-(r_down**2)))
        return cls(t0 + (v_t / g) * dt, y0 + 0.5 * (v_t**2 / g) * dy, g, drag)

    def state(self, t: ArrayLike) -> tuple[Array, Array]:
        """Height (m) and upward velocity (m/s) at the times `t` (s)."""
        s = jnp.asarray(t, dtype=float) - self.t_apex
        if self.drag is None:
            return self.y_apex - 0.5 * self.g * s**2, -self.g * s
        v_t = _terminal_speed(self.g, self.drag)
        z = self.g * s / v_t
        rising = z < 0
        z_up = jnp.clip(jnp.where(rising, z, 0.0), -0.5 * jnp.pi + 1e-6, 0.0)
        z_down = jnp.where(rising, 0.0, z)
        scale = v_t**2 / self.g
        y = jnp.where(
            rising,
            self.y_apex + scale * jnp.log(jnp.cos(z_up)),
            self.y_apex - scale * _log_cosh(z_down),
        )
        u = jnp.where(rising, -v_t * jnp.tan(z_up), -v_t * jnp.tanh(z_down))
        return y, u

    def height(self, t: ArrayLike) -> Array:
        """Height (m) at the times `t` (s)."""
        return self.state(t)[0]

    def velocity(self, t: ArrayLike) -> Array:
        """Upward velocity (m/s) at the times `t` (s)."""
        return self.state(t)[1]

    def landing(self) -> tuple[Array, Array]:
        """`(t, v)`: the time (s) at which the falling ball reaches `y = 0` and its downward
        speed there (m/s). A flight whose apex is not above the floor lands at its apex,
        at speed 0."""
        above = self.y_apex > 0
        y_a = jnp.where(above, self.y_apex, 1.0)
        if self.drag is None:
            fall = jnp.sqrt(2.0 * y_a / self.g)
            speed = jnp.sqrt(2.0 * self.g * y_a)
        else:
            v_t = _terminal_speed(self.g, self.drag)
            w = 2.0 * self.g * y_a / v_t**2
            z = jnp.arcsinh(jnp.sqrt(jnp.expm1(w)))
            fall = v_t * z / self.g
            speed = v_t * jnp.sqrt(-jnp.expm1(-w))
        return (
            self.t_apex + jnp.where(above, fall, 0.0),
            jnp.where(above, speed, 0.0),
        )

    @property
    def apex_height(self) -> Array:
        """Height of the apex above the floor (m)."""
        return self.y_apex


def free_flight(t: ArrayLike, *, y0, u0, g=9.81, drag=None, t0=0.0) -> tuple[Array, Array]:
    """Height (m) and upward velocity (m/s) at times `t` (s) of a ball that was at height
    `y0` (m) with upward velocity `u0` (m/s) at time `t0`, under gravity `g` (m/s^2) and
    optional quadratic air drag `drag` = `k` (1/m) in `du/dt = -g - k u |u|`. Closed form
    (see the module's docstring); valid until the ball reaches the floor.

    **Example**: `free_flight(0.1, y0=0.0, u0=2.0)` is `(0.15095, 1.019)`.
    """
    return Flight.from_state(t0, y0, u0, g=g, drag=drag).state(t)
