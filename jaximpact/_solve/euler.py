"""The seed paper's own scheme for a bouncing ball: explicit Euler at a fixed step.

Polukoshko et al. 2007, section 7, integrate system (17) (a ball falling under gravity onto a
floor, `m y'' = m g + N`, `y` downward, `y >= 0` inside the floor, contact force `N` active
while `y >= 0`) with the explicit Euler method at the step `s = 2e-5 s` (Mathcad):

    y_{n+1}  = y_n + y'_n dt
    y'_{n+1} = y'_n + g dt + N_n dt / m
    N_{n+1}  = -F(y_n, y'_n) if y_n >= 0 else 0

As printed, the force used in the velocity update lags one step behind the state
(`N_n` is computed from `y_{n-1}`); `scheme="paper"` follows the print, `scheme="euler"` is
textbook explicit Euler (`N` from `y_n`, `y'_n`). Contact lasts while `y >= 0`, so a tensile
force pulls (the `"penetration"` separation criterion of `jaximpact.impact`).

This module exists as a baseline: `jaximpact.bounce` solves the same motion with closed-form
flights and converged contacts, and `docs/bounces.md` shows how far the Euler restitutions
(the paper prints e = 0.64, 0.64, 0.54 for laws 14, 1 and 6) are from the converged ones.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._checks import check_nonnegative, check_positive
from .._compiling import quick_jit
from .._laws import AbstractLaw

SCHEMES = ("paper", "euler")


class EulerResult(eqx.Module):
    """A fixed-step Euler bounce (numpy arrays; SI units; height above the floor and
    velocity and force upward, as in `jaximpact.BounceResult`).

    - `t`, `height`, `velocity`, `force`: every `stride`-th step.
    - `impact_times`, `release_times` (s), `impact_speeds` (m/s, downward), `e`, `T` (s): per
      contact, from the crossings of `y = 0` (linear interpolation between steps), where
      `e = -v_out / v_in` with the velocities interpolated at those crossings. A contact
      still going on at `t_end` is left out.
    """

    t: np.ndarray
    height: np.ndarray
    velocity: np.ndarray
    force: np.ndarray
    impact_times: np.ndarray
    release_times: np.ndarray
    impact_speeds: np.ndarray
    e: np.ndarray
    T: np.ndarray
    dt: float = eqx.field(static=True)
    scheme: str = eqx.field(static=True)


def _euler_steps(law, m, g, h0, v_drop, dt, *, steps: int, scheme: str):
    """`y`, `v` and `N` (downward, SI) at the `steps + 1` grid points of system (17)."""

    def contact_force(y, v):
        # N of system (17): minus the law's force (which pushes the body out) while y >= 0
        safe = jnp.where(y >= 0, y, 0.0)
        return jnp.where(y >= 0, -law.force(safe, v), 0.0)

    def step(state, _):
        y, v, force = state
        if scheme == "paper":
            v_next = v + g * dt + force * dt / m
            force_next = contact_force(y, v)
        else:
            force_now = contact_force(y, v)
            v_next = v + g * dt + force_now * dt / m
            force_next = contact_force(y + v * dt, v_next)
        state = (y + v * dt, v_next, force_next)
        return state, state

    start = (-h0, v_drop, jnp.zeros_like(h0))
    _, (y, v, force) = jax.lax.scan(step, start, None, length=steps)
    return (
        jnp.concatenate([start[0][None], y]),
        jnp.concatenate([start[1][None], v]),
        jnp.concatenate([start[2][None], force]),
    )


# compiled quickly and briefly (`_compiling`): a scan of simple steps, whose compile at XLA's
# defaults took 0.6 s of each of the 24 programs of a first `jaximpact paper` (14 s)
_integrate = quick_jit(_euler_steps, brief=True)


def _crossings(t, y, v):
    """Times and velocities where `y` (downward) crosses 0: entering (`y < 0 <= y_next`)
    and leaving (`y >= 0 > y_next`), by linear interpolation."""

    def at(index):
        y0, y1 = y[index], y[index + 1]
        w = np.where(y1 != y0, -y0 / np.where(y1 != y0, y1 - y0, 1.0), 0.0)
        return t[index] + w * (t[index + 1] - t[index]), v[index] + w * (v[index + 1] - v[index])

    inside = y >= 0
    enter = np.flatnonzero(~inside[:-1] & inside[1:])
    leave = np.flatnonzero(inside[:-1] & ~inside[1:])
    t_in, v_in = at(enter)
    if inside[0]:  # dropped from the surface itself (h0 = 0): the contact starts at t[0]
        t_in, v_in = np.concatenate([t[:1], t_in]), np.concatenate([v[:1], v_in])
    return (t_in, v_in), at(leave)


def euler_bounce(
    law: AbstractLaw,
    *,
    m,
    h0,
    t_end,
    g=9.81,
    v_drop=0.0,
    dt=2e-5,
    scheme: str = "paper",
    stride: int = 1,
) -> EulerResult:
    """The seed paper's explicit Euler solution of system (17) (section 7): a ball of mass `m`
    (kg) dropped from height `h0` (m) with downward speed `v_drop` (m/s), integrated at the
    fixed step `dt` (s; the paper's 2e-5) until `t_end` (s). `scheme`: `"paper"` (as
    printed, the force lagging one step) or `"euler"` (textbook explicit Euler). Keeps
    every `stride`-th step in the returned histories. Not differentiable in any useful sense
    (the contact switches at grid points); a baseline, not a solver to use. `h0 = 0` and
    `g = 0` give one impact at speed `v_drop` from first touch, as the paper's figures 2-11.

    **Example**:
    `euler_bounce(law("hertz_rate", c=1e6, b1=1350.0), m=1.0, h0=0.6, t_end=2.0).e[:4]`.
    """
    if not isinstance(law, AbstractLaw):
        raise TypeError("euler_bounce needs a law from jaximpact.law(...) or custom_law(...)")
    if scheme not in SCHEMES:
        raise ValueError(f"scheme must be one of {SCHEMES}, got {scheme!r}")
    for name, value, unit in (("mass m", m, "kg"), ("t_end", t_end, "s"), ("dt", dt, "s")):
        check_positive(name, value, unit)
    check_nonnegative("gravity g", g, "m/s^2")
    check_nonnegative("drop height h0", h0, "m")
    steps = int(np.ceil(float(t_end) / float(dt)))
    y, v, force = _integrate(
        law,
        jnp.asarray(m, float),
        jnp.asarray(g, float),
        jnp.asarray(h0, float),
        jnp.asarray(v_drop, float),
        jnp.asarray(dt, float),
        steps=steps,
        scheme=scheme,
    )
    y, v, force = np.asarray(y), np.asarray(v), np.asarray(force)
    t = np.arange(steps + 1) * float(dt)
    (t_in, v_in), (t_out, v_out) = _crossings(t, y, v)
    # pair each entry with the first exit after it
    pairs = np.searchsorted(t_out, t_in)
    complete = pairs < len(t_out)
    t_in, v_in, pairs = t_in[complete], v_in[complete], pairs[complete]
    t_rel, v_rel = t_out[pairs], v_out[pairs]
    keep = slice(None, None, int(stride))
    return EulerResult(
        t=t[keep],
        height=-y[keep],
        velocity=-v[keep],
        force=-force[keep],
        impact_times=t_in,
        release_times=t_rel,
        impact_speeds=v_in,
        e=-v_rel / v_in,
        T=t_rel - t_in,
        dt=float(dt),
        scheme=scheme,
    )
