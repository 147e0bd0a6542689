"""The equations of one oblique contact: a normal law's own nondimensional dynamics with
the tangential spring, the sliding of the contact point and the sphere's spin appended.

Units are the normal contact's (`AbstractDynamics`): length `x*`, time `t*`, force
`m v_n^2 / x*`, velocity `v_n`. The state is the normal law's state followed by
`(Q, U_c, W)`: the spring state `Q` (`TangentialDynamics`), the centre's tangential
velocity `U_c = v_t / v_n` and the spin `W = R omega / v_n`; the contact point slips at
`U = U_c - W`. With the tangential force `F_t` on the sphere,

    U_c' = F_t,    W' = -(m R^2 / I) F_t,    so    U' = (1 + m R^2 / I) F_t,

(`m v_t' = F_t`, `I omega' = -R F_t` in the sign convention of DESIGN.md). With the
contact point inside the overlap (`oblique_impact(contact_point=)`: LIGGGHTS, MuJoCo and
Drake place it halfway) the lever arm is `R - f x`: `U = U_c - (1 - h X) W` and
`W' = -(m R^2 / I) (1 - h X) F_t`, `h = f x* / R` (`lever_loss`). While the
contact sticks, `F_t` is the spring's trial force and `Q` follows the slip; while it
slides in the sense `s` (+1: the contact point moves forward), `F_t = -s mu |F_n|` and the
spring is held at the limit (`Q` is not integrated: it is set from the limit where sliding
stops, `TangentialDynamics.held`).
"""

import equinox as eqx
import jax
import jax.numpy as jnp

from .._laws.dynamics import AbstractDynamics
from .tangential import TangentialDynamics

STICK = 0
SLIP = 1


class ObliqueDynamics(eqx.Module):
    """One oblique contact in the normal law's units (module docstring)."""

    normal: AbstractDynamics
    tangential: TangentialDynamics
    size: int = eqx.field(static=True)  # the normal state's length
    lever_loss: object = None  # `f x* / R`: the lever arm `R - f x` (None: R)

    def parts(self, y):
        """`(normal state, Q, U_c, W)`."""
        return y[: self.size], y[self.size], y[self.size + 1], y[self.size + 2]

    def lever(self, y):
        """The lever arm of the tangential force about the centre, in units of `R`: 1, or
        `1 - f x / R` with the contact point inside the overlap."""
        if self.lever_loss is None:
            return 1.0
        overlap = jnp.maximum(self.normal.position(y[: self.size]), 0.0)
        return 1.0 - self.lever_loss * overlap

    def slip(self, y):
        """`U = U_c - lever W`, the contact point's velocity over the surface (units of
        `v_n`)."""
        return y[self.size + 1] - self.lever(y) * y[self.size + 2]

    def cap(self, y, compressing, sign=None):
        """Coulomb's limit `mu |F_n|`; `mu sign F_n` with a given `sign` (smooth where the
        normal force crosses zero: `_segments` judges a segment's end with it)."""
        force = self.normal.force(y[: self.size], compressing)
        return self.tangential.mu * (jnp.abs(force) if sign is None else sign * force)

    def trial(self, y):
        """The force a sticking contact carries at `y`."""
        y_n, q, _, _ = self.parts(y)
        return self.tangential.trial(q, self.normal.position(y_n), self.slip(y))

    def tested(self, y):
        """The force Coulomb's limit caps at `y` (the trial force, or the spring's alone:
        `TangentialDynamics.tested`)."""
        y_n, q, _, _ = self.parts(y)
        return self.tangential.tested(q, self.normal.position(y_n), self.slip(y))

    def tangential_force(self, y, mode, sense, compressing):
        return jnp.where(mode == STICK, self.trial(y), -sense * self.cap(y, compressing))

    def rhs(self, y, mode, sense, compressing):
        y_n, q, _, _ = self.parts(y)
        force = self.tangential_force(y, mode, sense, compressing)
        x, v = self.normal.position(y_n), self.normal.velocity(y_n)
        stick_rate = self.tangential.stick_rate(q, x, self.slip(y), v)
        return jnp.concatenate(
            [
                self.normal.rhs(y_n, compressing),
                jnp.stack(
                    [
                        jnp.where(mode == STICK, stick_rate, 0.0),
                        force,
                        -self.tangential.inv_inertia * self.lever(y) * force,
                    ]
                ),
            ]
        )

    def held(self, y, sense, compressing, sign=None):
        """`y` with the spring at the limit in the sense `sense` (where sliding stops)."""
        y_n = y[: self.size]
        q = self.tangential.held(
            sense, self.cap(y, compressing, sign), self.normal.position(y_n), self.slip(y)
        )
        return y.at[self.size].set(q)

    def stick_margin(self, y, compressing, sign=None):
        """`mu |F_n| - |F_tested|`: positive while the contact can stick."""
        return self.cap(y, compressing, sign) - jnp.abs(self.tested(y))

    def slide_excess(self, y, sense, compressing, sign=None):
        """The rate at which a sticking contact held at the limit would leave it,
        `d/dtau (|F_trial| - mu |F_n|)` along the sticking motion: positive while the
        contact slides (it equals `s K` times the sliding speed of a spring held at the
        limit); sliding stops where it reaches 0."""
        y_held = self.held(y, sense, compressing, sign)

        def excess(z):
            return -sense * self.tested(z) - self.cap(z, compressing, sign)

        direction = self.rhs(y_held, STICK, sense, compressing)
        return jax.jvp(excess, (y_held,), (direction,))[1]

    def switch(self, y, mode, sense, compressing, sign=None):
        """The condition that ends the present tangential mode (positive before)."""
        return jnp.where(
            mode == STICK,
            self.stick_margin(y, compressing, sign),
            self.slide_excess(y, sense, compressing, sign),
        )
