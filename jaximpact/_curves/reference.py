"""Reference impacts of the one-group power family at unit scales, for building curves.

`X'' = -X^n - beta X^p X'`, `X(0) = 0`, `X'(0) = 1`: the law `F = c x^n + b x^p v` in the
units `x* = (m v0^2/c)^(1/(n+1))`, `t* = x*/v0`, with `beta = b x*^(p+1)/(m v0)`. Written
in `(X, V)` itself, not in the Lienard variable that `impact` uses for its gradients: at
heavy damping `W = V + beta X^(p+1)/(p+1)` is much larger than `V`, and its rounding would
be all of a small `e`. Dopri8 with a pure relative tolerance; three event-terminated solves,
each with a single condition (two crossing in one step would mask each other): compression
to `V = 0` (`x_max`, `t_max`), compression to the first force peak `dF/dtau = 0` (light
damping puts it within a step of maximum compression), and restitution from maximum
compression to separation (`e`, `T`).
"""

from typing import NamedTuple

import diffrax as dfx
import jax.numpy as jnp
import optimistix as optx

from .._powers import contact_pow, safe_pow

SOLVER = dfx.Dopri8()


def _pow(x, q):
    """`x^q`: an integer power continued below 0 (a clipped one is flat there, and the
    event's Newton step from the far side of a crossing cannot come back), a fractional
    one zero below 0."""
    return contact_pow(x, q) if float(q).is_integer() else safe_pow(x, q)


def _force(y, beta, n, p):
    return _pow(y[0], n) + beta * _pow(y[0], p) * y[1]


def _separation_gap(y, beta, n, p, separation, dry=None):
    """Positive in contact, crossing zero at separation (a transversal crossing); with a
    dry force (restitution: `F = X^n + beta X^p V - dry`), the force itself under
    `"force"` (it crosses zero inside the surface, before `X` does)."""
    x, v = y[0], y[1]
    if dry is not None and separation == "force":
        return jnp.minimum(x, _force(y, beta, n, p) - dry)
    if separation == "penetration" or n == p:
        return x
    k = n - p  # F = x^p (x^k + beta v); with the smaller of it and x, whose slope below 0
    # keeps Newton's step sound where the bracket is flat
    if k >= 1:
        reduced = _pow(x, k) + beta * v
    else:  # x^k has an infinite slope at 0: the same sign and zero, C1
        reduced = x + jnp.sign(v) * _pow(beta * jnp.abs(v), 1.0 / k)
    return jnp.minimum(x, reduced)


def _peak_condition(y, beta, n, p, gamma=0.0):
    """The sign of `dF/dtau` in compression, times `X^(1-q)` where an exponent `q < 1` of
    the law would make it infinite at first touch."""
    x, v = y[0], y[1]
    acceleration = -_force(y, beta, n, p) + gamma
    q = min(n, 1.0) if p == 0 else min(n, p, 1.0)
    scale = lambda k: _pow(x, k + 1.0 - q)  # x^k times x^(1-q)
    elastic = n * scale(n - 1.0) * v
    damping = (
        beta * (p * scale(p - 1.0) * v**2 + scale(p) * acceleration)
        if p
        else beta * scale(0.0) * acceleration
    )
    return elastic + damping


class _Motion(NamedTuple):
    """`X'' = -X^n - beta X^p X' + gamma` (nondimensional): the damping group `beta`, the
    exponents `n`, `p` (numbers) and the constant push `gamma` (gravity in, minus a dry
    force against the motion)."""

    beta: object
    n: float
    p: float
    gamma: object = 0.0


def _solve(y0, t0, t1, condition, motion: _Motion, *, rtol, max_steps, direction=False):
    """`motion` from `y0` at `t0` up to `t1` or the crossing of `condition(y)` (in the
    sense `direction`); returns the state and instant at the end and whether the event
    fired."""
    beta, n, p, gamma = motion

    def rhs(t, y, args):
        return jnp.stack([y[1], -_force(y, beta, n, p) + gamma])

    sol = dfx.diffeqsolve(
        dfx.ODETerm(rhs),
        SOLVER,
        t0,
        t1,
        None,
        y0,
        stepsize_controller=dfx.PIDController(rtol=rtol, atol=1e-3 * rtol),
        event=dfx.Event(
            lambda t, y, args, **kw: condition(y),
            # bisection inside the step's bracket (diffrax passes it): Newton starts at the
            # step's end, beyond the crossing, where min(x, x^k + beta v) can be flat (T of
            # Hertz viscous at beta = 1e-12 was 4e-6 off)
            root_finder=optx.Bisection(rtol=1e-15, atol=1e-18),
            direction=direction,
        ),
        saveat=dfx.SaveAt(t1=True),
        max_steps=max_steps,
        throw=False,
    )
    return sol.ys[-1], sol.ts[-1], sol.event_mask


def reference_impact(
    beta,
    *,
    n: float,
    p: float,
    separation: str,
    rtol=1e-13,
    tau_max=1e7,
    max_steps=400_000,
    gamma=None,
    dry=None,
):
    """`dict` of the five `curve.OUTPUTS` (nondimensional), `separated` (bool) at `beta`.

    `gamma` (`g x*/v0^2`, gravity pushing in: `X'' = -X^n - beta X^p X' + gamma`): `None`
    for none; with it, a restitution in which `V` comes back up to 0 before separation
    (the body held in the surface: a second solve, up to the separation) is not
    `separated`. `dry` (`P/(c x*^n)`, `None` for none): a dry force against the motion; a
    body that comes to rest with `X^n <= dry` is held (stuck), not `separated`; `F_max`
    includes it."""
    y0 = jnp.stack([jnp.zeros_like(beta), jnp.ones_like(beta)])
    options = dict(rtol=rtol, max_steps=max_steps)
    # compression: gravity in, the dry force out
    constant = (0.0 if gamma is None else gamma) - (0.0 if dry is None else dry)
    compressing = _Motion(beta, n, p, constant)
    y_max, t_max, _ = _solve(y0, 0.0, tau_max, lambda y: y[1], compressing, **options)
    y_peak, _, peaked = _solve(
        y0,
        0.0,
        t_max,
        lambda y: _peak_condition(y, beta, n, p, constant),
        compressing,
        **options,
    )
    in_dry = 0.0 if dry is None else dry
    at_touch = _force(y0, beta, n, p) + in_dry
    later = (
        jnp.maximum(_force(y_max, beta, n, p), jnp.where(peaked, _force(y_peak, beta, n, p), 0.0))
        + in_dry
    )
    f_max = jnp.maximum(at_touch, later)
    restitution = y_max.at[1].set(0.0)
    end = tau_max
    restoring = compressing
    if dry is not None:  # restitution: gravity in, the dry force in (against V < 0)
        restoring = compressing._replace(gamma=(0.0 if gamma is None else gamma) + dry)
    if gamma is not None or dry is not None:
        # where V comes back up to 0 (upwards only): gravity holding the body, or, after
        # a separation, its fall back; the separation must come before it. (V - 1e-14:
        # negative at the start, where V = 0, so that the bracket is never [0, +])
        _, end, _ = _solve(
            restitution,
            t_max,
            tau_max,
            lambda y: y[1] - 1e-14,
            restoring,
            direction=True,
            **options,
        )
    y_end, tau_end, ended = _solve(
        restitution,
        t_max,
        end,
        lambda y: _separation_gap(y, beta, n, p, separation, dry),
        restoring,
        **options,
    )
    return dict(
        e=-y_end[1],
        tau=tau_end,
        x_max=y_max[0],
        t_max=t_max,
        F_max=f_max,
        # a dry force holds a body at rest at maximum compression where X^n <= dry
        separated=ended & (y_end[1] < 0) & (_pow(y_max[0], n) > in_dry),
        # where this flips, F_max switches from a later peak to the force at first touch
        # (p = 0: beta): a kink that no Chebyshev piece may straddle
        peak_at_touch=at_touch >= later,
    )
