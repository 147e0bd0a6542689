"""Nondimensional equations of motion of one contact.

Every law is integrated in its own natural units: length `x*`, time `t*` and force
`m v0^2 / x*`, so that the solver sees an O(1) problem whatever the stiffness, mass and
impact speed (shared/notes, section 3). The state starts at `X = 0`, `V = 1`.
A dynamics object knows its state layout; the impact solve only calls the methods below.
"""

import abc
from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
from jaxtyping import Array

from .._powers import contact_pow


class AbstractDynamics(eqx.Module):
    """Equations of motion of one contact in nondimensional form.

    `compressing` is a boolean (traced) that selects the phase: the compression phase
    (`v > 0`) or the restitution phase (`v < 0`); laws with a dry force differ between them.
    """

    x_star: eqx.AbstractVar[Array]  # length scale, m
    t_star: eqx.AbstractVar[Array]  # time scale, s
    gamma: eqx.AbstractVar[Array]  # gravity g x* / v0^2, pushing into the surface
    has_dry: eqx.AbstractVar[bool]  # a dry force can hold the body at rest (static)
    split: eqx.AbstractVar[bool]  # the force jumps at maximum compression (static)

    @abc.abstractmethod
    def y0(self) -> Array:
        """State at first touch: `X = 0`, `V = 1`."""

    @abc.abstractmethod
    def rhs(self, y: Array, compressing) -> Array:
        """`dy/dtau`."""

    @abc.abstractmethod
    def position(self, y: Array) -> Array:
        """`X = x / x*`."""

    @abc.abstractmethod
    def velocity(self, y: Array) -> Array:
        """`V = v / v0`."""

    @abc.abstractmethod
    def force(self, y: Array, compressing) -> Array:
        """Contact force in units of `m v0^2 / x*`, positive pushing the body out."""

    @abc.abstractmethod
    def force_gap(self, y: Array, compressing) -> Array:
        """Positive while the contact pushes; crosses zero transversally where it stops
        pushing (the `"force"` separation criterion)."""

    def penetration_gap(self, y: Array) -> Array:
        """Positive while in contact under the `"penetration"` criterion: `X` (the body
        leaves the surface at `X = 0`), unless the contact holds beyond it (an adhesive
        neck, which breaks at pull-off)."""
        return self.position(y)

    def surface_gap(self, y: Array) -> Array | None:
        """`None`, or a condition that crosses zero where the body leaves the surface
        (`X = 0`) and that ends contact under the force criterion besides `force_gap` (a
        user's law whose force may vanish only at `X = 0`, degenerately)."""
        return None

    def force_rate(self, y: Array, compressing) -> Array:
        """`dF/dtau` along the motion (zero at a force peak)."""
        return jax.jvp(lambda z: self.force(z, compressing), (y,), (self.rhs(y, compressing),))[1]

    def creeping(self, rest_tol):
        """`None`, or a dict for a law that can be known, before integrating, never to
        reach maximum compression: `captured` (bool), and the closed-form rest instant
        `tau`, position `x` there, and force peak `tau_peak`, `force_peak` (nondimensional),
        valid where `captured`. `impact` then skips the (stiff, endless) integration."""
        return None

    @property
    def force_scale(self) -> Array:
        """`m v0^2 / x*` in N, given through the scales: `x* / t*^2` times the mass."""
        return self.mass * self.x_star / self.t_star**2

    mass: eqx.AbstractVar[Array]


class PowerDynamics(AbstractDynamics):
    """`F = c x^n + b x^p v + P_phase`, in the Lienard variable `W`.

    With `X = x/x*`, `x* = (m v0^2/c)^(1/(n+1))`, `t* = x*/v0`, `beta = b x*^(p+1)/(m v0)`:
    `X' = W - beta X^(p+1)/(p+1)`, `W' = -X^n - P_phase + gamma`, and `V = X'`.
    The damping term is absorbed into `W` (since `x^p x' = d/dt x^(p+1)/(p+1)`), so no
    `x^(p-1)` appears in the Jacobian: AD derivatives converge for the `x^0.5` laws
    (shared/notes, section 2.4).
    """

    n: Array | float
    p: Array | float
    beta: Array
    dry_in: Array  # dry force in compression, units of m v0^2/x*
    dry_out: Array  # dry force in restitution
    gamma: Array
    x_star: Array
    t_star: Array
    mass: Array
    # where the force criterion ends contact: at the first zero of x or of the "reduced"
    # force, which is F itself ("force", dry laws), or F / x^p = x^(n-p) + beta V (a number:
    # n - p); "x": the force only vanishes at x = 0 (Hunt-Crossley)
    gap: str | float = eqx.field(static=True)
    has_dry: bool = eqx.field(static=True, default=False)
    split: bool = eqx.field(static=True, default=False)

    def y0(self):
        zero = jnp.zeros_like(self.beta)
        return jnp.stack([zero, zero + 1.0])

    def _damping_potential(self, x):
        return self.beta * contact_pow(x, self.p + 1) / (self.p + 1)

    def position(self, y):
        return y[0]

    def velocity(self, y):
        return y[1] - self._damping_potential(y[0])

    def _dry(self, compressing):
        return jnp.where(compressing, self.dry_in, self.dry_out)

    def rhs(self, y, compressing):
        x = y[0]
        return jnp.stack(
            [self.velocity(y), -contact_pow(x, self.n) - self._dry(compressing) + self.gamma]
        )

    def force(self, y, compressing):
        x, v = y[0], self.velocity(y)
        elastic = contact_pow(x, self.n)
        damping = self.beta * contact_pow(x, self.p) * v
        return elastic + damping + self._dry(compressing)

    def force_gap(self, y, compressing):
        x = y[0]
        if self.gap == "x" or (not isinstance(self.gap, str) and self.gap == 0):
            # n = p (Kelvin-Voigt modified, F = x (c + b1 v)): the reduced force
            # G = 1 + beta V obeys G' = -beta X G + beta gamma, so it cannot reach 0 while
            # X > 0; it only decays towards 0 (heavy damping) where its sign is rounding
            # noise, and a noise crossing ended contact early (T off by up to 3x). The force
            # vanishes at X = 0 only, as for the Hunt-Crossley family.
            return x
        if self.gap == "force":
            reduced = self.force(y, compressing)
        elif 0 < self.gap < 1:
            # x^k + beta V with k < 1 (Hertz modified, k = 1/2) has an infinite slope at
            # X = 0, where light damping puts its zero, and the root finder placed the
            # event early (T 1.1e-4 low). Same sign, same zero, and C1:
            # X + sign(V) (beta |V|)^(1/k)
            velocity = self.velocity(y)
            push = contact_pow(self.beta * jnp.abs(velocity), 1.0 / self.gap)
            reduced = x + jnp.sign(velocity) * push
        else:
            reduced = contact_pow(x, self.gap) + self.beta * self.velocity(y)
        # at a tie (no damping: x^(n-p) + beta V = x) take the force, whose derivative in
        # the damping is the right one (jnp.minimum would split it between the branches)
        return jnp.where(x < reduced, x, reduced)


class MaxwellDynamics(AbstractDynamics):
    """Spring `c` in series with dashpot `b`; the force is a state (eqs. 10-11).

    With `t* = sqrt(m/c)`, `x* = v0 t*` and `Phi = F/(c x*)`:
    `X' = V`, `V' = -Phi + gamma`, `Phi' = V - mu Phi`, `mu = sqrt(m c)/b`.
    """

    mu: Array
    gamma: Array
    x_star: Array
    t_star: Array
    mass: Array
    has_dry: bool = eqx.field(static=True, default=False)
    split: bool = eqx.field(static=True, default=False)

    def y0(self):
        zero = jnp.zeros_like(self.mu)
        return jnp.stack([zero, zero + 1.0, zero])

    def position(self, y):
        return y[0]

    def velocity(self, y):
        return y[1]

    def rhs(self, y, compressing):
        return jnp.stack([y[1], -y[2] + self.gamma, y[1] - self.mu * y[2]])

    def force(self, y, compressing):
        return y[2]

    def force_gap(self, y, compressing):
        return y[2]

    def creeping(self, rest_tol):
        """Over-damped (`mu >= 2`) and no gravity: `V'' + mu V' + V = 0` keeps `V > 0`, the
        body sinks in for ever while the force relaxes (`closed_forms.maxwell_creep`)."""
        from .closed_forms import maxwell_creep  # only for Maxwell

        captured = (self.mu >= 2.0) & (self.gamma == 0)
        # a harmless over-damped value elsewhere, so no NaN reaches a discarded gradient;
        # the closed form (a Newton root) only runs where it is used (both branches run
        # under vmap, where `cond` becomes a select): under-damped impacts pay nothing
        mu = jnp.where(captured, self.mu, 3.0)
        tau, x, tau_peak, force_peak = jax.lax.cond(
            captured,
            lambda mu: maxwell_creep(mu, rest_tol),
            lambda mu: (jnp.zeros_like(mu),) * 4,
            mu,
        )
        return dict(captured=captured, tau=tau, x=x, tau_peak=tau_peak, force_peak=force_peak)


class ScaledDynamics(AbstractDynamics):
    """A user's force law, rescaled: `X'' = -F(x* X, v0 V)/(m v0^2/x*) + gamma`.

    The scale `x*` solves `x* F(x*, v0) = m v0^2` (work of the contact force over `x*`
    equals the kinetic energy), found by bisection. The law is evaluated through
    `law.force`, which is 0 outside the surface, so a trial step below `X = 0` never
    meets a NaN. Under the force criterion contact ends at the first zero of `F` inside
    the surface (`force_gap`) or at `X = 0` (`surface_gap`): a force that vanishes only
    at `X = 0`, like `x^1.5`, has a degenerate zero there that no root finder places
    well, while `X` crosses 0 transversally.
    """

    law: eqx.Module
    v0: Array
    gamma: Array
    x_star: Array
    t_star: Array
    mass: Array
    has_dry: bool = eqx.field(static=True, default=False)
    split: bool = eqx.field(static=True, default=False)

    def y0(self):
        zero = jnp.zeros_like(self.v0)
        return jnp.stack([zero, zero + 1.0])

    def position(self, y):
        return y[0]

    def velocity(self, y):
        return y[1]

    def force(self, y, compressing):
        return self.law.force(self.x_star * y[0], self.v0 * y[1]) / self.force_scale

    def rhs(self, y, compressing):
        return jnp.stack([y[1], -self.force(y, compressing) + self.gamma])

    def force_gap(self, y, compressing):
        # inside: the force itself (its zeros inside the surface are transversal for the
        # laws that go tensile there, e.g. c x + b v); at and below X = 0 the force's limit
        # at the surface where that pulls (so a zero crossed within the step that also
        # crosses X = 0 is still seen), else +1: the surface event ends those contacts
        # (the force before a clamp at zero where the law clamps it: `CustomLaw.edge_force`)
        at_surface = self._edge_force(jnp.stack([jnp.zeros_like(y[0]), y[1]]))
        below = jnp.where(at_surface < 0, at_surface, 1.0)
        return jnp.where(y[0] > 0, self._edge_force(y), below)

    def _edge_force(self, y):
        return self.law.edge_force(self.x_star * y[0], self.v0 * y[1]) / self.force_scale

    def surface_gap(self, y):
        return y[0]


class PowerCoefficients(NamedTuple):
    """The coefficients of `F = c x^n + b x^p v + P_phase` at one impact speed, as
    `LawSpec.coefficients` gives them: `c` (N/m^n), `n`, `b` (N s/m^(p+1)), `p`, and the
    dry force `dry_in` in compression and `dry_out` in restitution (N)."""

    c: Array | float
    n: Array | float
    b: Array | float
    p: Array | float
    dry_in: Array | float
    dry_out: Array | float


def power_dynamics(
    coefficients: PowerCoefficients, *, m, v0, g, gap, split=False, can_stick=False
) -> PowerDynamics:
    """Build `PowerDynamics` from the law's `coefficients` (SI units), the mass `m` (kg),
    the impact speed `v0` (m/s) and gravity `g` (m/s^2); `gap` as `PowerDynamics.gap`;
    `split`: the dry force differs between compression and restitution; `can_stick`: it
    can hold the body."""
    c, n, b, p, dry_in, dry_out = coefficients
    x_star = (m * v0**2 / c) ** (1.0 / (n + 1.0))
    force_scale = m * v0**2 / x_star
    return PowerDynamics(
        n=n,
        p=p,
        beta=jnp.asarray(b * x_star ** (p + 1.0) / (m * v0), dtype=float),
        dry_in=jnp.asarray(dry_in / force_scale, dtype=float),
        dry_out=jnp.asarray(dry_out / force_scale, dtype=float),
        gamma=jnp.asarray(g * x_star / v0**2, dtype=float),
        x_star=jnp.asarray(x_star, dtype=float),
        t_star=jnp.asarray(x_star / v0, dtype=float),
        mass=jnp.asarray(m, dtype=float),
        gap=gap,
        has_dry=can_stick,
        split=split,
    )


def maxwell_dynamics(c, b, *, m, v0, g) -> MaxwellDynamics:
    """Build `MaxwellDynamics` from the spring `c` (N/m) and dashpot `b` (N s/m)."""
    t_star = jnp.sqrt(m / c)
    x_star = v0 * t_star
    return MaxwellDynamics(
        mu=jnp.asarray(jnp.sqrt(m * c) / b, dtype=float),
        gamma=jnp.asarray(g * x_star / v0**2, dtype=float),
        x_star=jnp.asarray(x_star, dtype=float),
        t_star=jnp.asarray(t_star, dtype=float),
        mass=jnp.asarray(m, dtype=float),
    )


def _energy_length(law, m, v0):
    """`x*` with `x* F(x*, v0) = m v0^2`, by bisection on `log10 x*` in [-30, 10]."""
    target = jnp.log(m * v0**2)

    def excess(log10_x):
        x = 10.0**log10_x
        return jnp.log(jnp.maximum(x * law.force(x, v0), 1e-300)) - target

    def step(_, bounds):
        lo, hi = bounds
        mid = 0.5 * (lo + hi)
        above = excess(mid) > 0
        return jnp.where(above, lo, mid), jnp.where(above, mid, hi)

    lo, hi = jax.lax.fori_loop(0, 80, step, (jnp.asarray(-30.0), jnp.asarray(10.0)))
    return jax.lax.stop_gradient(10.0 ** (0.5 * (lo + hi)))


def scaled_dynamics(law, *, m, v0, g) -> ScaledDynamics:
    """Build `ScaledDynamics` for a user's law (`law.force(x, v)` in SI units)."""
    x_star = _energy_length(jax.lax.stop_gradient(law), m, v0)
    return ScaledDynamics(
        law=law,
        v0=jnp.asarray(v0, dtype=float),
        gamma=jnp.asarray(g * x_star / v0**2, dtype=float),
        x_star=x_star,
        t_star=x_star / v0,
        mass=jnp.asarray(m, dtype=float),
    )
