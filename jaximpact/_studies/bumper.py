"""`bumper_design`: the stiffness `c` and damping `b1` of law 14 (`c x^1.5 + b1 x^0.5 v`)
that minimise the peak force over a range of impact speeds while the maximum compression
stays under a bound and the restitution under a target (optax, constraints by penalty).
Several (bound, target) pairs run at once (vmapped): trade-off curves in one compilation.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import optax
from jaxtyping import Array

from .._format import PrintedFields
from .._laws import law as make_law
from .._solve.impact import impact


class BumperDesign(PrintedFields, eqx.Module):
    """The result of `bumper_design` (SI units). With several bounds, every array has a
    leading axis over the pairs `(x_max_bound, e_target)`.

    - `c` (N/m^1.5), `b1` (N s/m^1.5): the design; `law(i)` builds the i-th one.
    - `speeds` (m/s), `m` (kg), `x_max_bound` (m), `e_target`: the specification.
    - `F_max` (N), `x_max` (m), `e`: at each speed (last axis), for the design.
    - `F_peak` (N): the largest `F_max` over the speeds (what was minimised).
    - `feasible`: every `x_max <= x_max_bound (1 + tol)` and `e <= e_target + tol`.
    - `history`: the penalised objective at each iteration.
    - `F_ideal` (N): the lower bound `m v_max^2 / (2 x_max_bound)` of any force law with
      that stroke (a constant force over the whole stroke).
    """

    _TITLE = "BumperDesign (SI units; the hertz_rate law that meets the bounds)"
    _SHOWN = (
        ("c", "N/m^1.5"),
        ("b1", "N s/m^1.5"),
        ("feasible", None),
        ("F_peak", "N"),
        ("F_ideal", "N"),
        ("speeds", "m/s"),
        ("m", "kg"),
        ("x_max_bound", "m"),
        ("x_max", "m"),
        ("e_target", ""),
        ("e", ""),
    )

    c: Array
    b1: Array
    speeds: Array
    m: Array
    x_max_bound: Array
    e_target: Array
    F_max: Array
    x_max: Array
    e: Array
    F_peak: Array
    feasible: Array
    history: Array
    F_ideal: Array

    def law(self, index: int | None = None):
        """The designed law (`index`: which bound, when there are several)."""
        c, b1 = (self.c, self.b1) if index is None else (self.c[index], self.b1[index])
        return make_law("hertz_rate", c=float(c), b1=float(b1))


def _bumper_response(theta, scales, m, speeds, rtol):
    """`F_max`, `x_max`, `e` of law 14 with `(c, b1) = scales exp(theta)` at each speed."""
    c, b1 = scales[0] * jnp.exp(theta[0]), scales[1] * jnp.exp(theta[1])
    law = make_law("hertz_rate", c=c, b1=b1)

    def one(v0):
        r = impact(law, m=m, v0=v0, rtol=rtol)
        return jnp.stack([r.F_max, r.x_max, r.e])

    return jax.vmap(one)(speeds)


class _Run(eqx.Module):
    """How `_optimise_bumper` iterates: the constraints' tolerance `tol` (relative in
    `x_max`, absolute in `e`), the initial learning rate `lr`, the penalty weights
    `mu = (first, last)`, the number of `steps` and the `rtol` of each impact solve
    (`steps` and `rtol` static: one compilation per value)."""

    tol: Array | float
    lr: Array | float
    mu: Array
    steps: int = eqx.field(static=True)
    rtol: float = eqx.field(static=True)


@jax.jit
def _optimise_bumper(scales, m, speeds, bound, e_target, run: _Run):
    """Adam on `log(c / scales[0]), log(b1 / scales[1])` from 0, for a body of `m` (kg)
    at `speeds` (m/s) under the bounds `bound` (m) on `x_max` and `e_target` on `e`, the
    penalty weight growing geometrically from `mu[0]` to `mu[1]` (a continuation: first
    find the region, then sharpen the constraints) while the learning rate decays to 1%
    (to settle on the constraint boundary). Returns the parameters of the last
    evaluation, its response (`F_max, x_max, e` per speed) and the objective's history."""
    theta0 = jnp.zeros(2)
    tol, mu, steps = run.tol, run.mu, run.steps
    schedule = optax.cosine_decay_schedule(run.lr, steps, alpha=0.01)
    # clipped: the first (penalty-dominated) gradients must not freeze Adam's step size
    optimiser = optax.chain(optax.clip_by_global_norm(1.0), optax.adam(schedule, b2=0.99))

    def objective(theta, weight):
        response = _bumper_response(theta, scales, m, speeds, run.rtol)
        F, x, e = response.T
        peak = 0.01 * jax.nn.logsumexp(jnp.log(F) / 0.01)  # smooth max of log F_max
        over_x = jax.nn.relu(jnp.log(x / bound) + 0.5 * tol)
        over_e = jax.nn.relu((e - e_target + 0.5 * tol) / 0.01)
        value = peak + weight * (jnp.sum(over_x**2) + jnp.sum(over_e**2))
        return value, (value, response)

    def step(carry, k):
        theta, state = carry
        weight = mu[0] * (mu[1] / mu[0]) ** (k / (steps - 1))
        # forward mode (2 parameters), value and response from the same pass
        grad, (value, response) = jax.jacfwd(objective, has_aux=True)(theta, weight)
        updates, state = optimiser.update(grad, state, theta)
        return (optax.apply_updates(theta, updates), state), (value, theta, response)

    carry = (theta0, optimiser.init(theta0))
    _, (history, thetas, responses) = jax.lax.scan(step, carry, jnp.arange(steps))
    return thetas[-1], responses[-1], history


def bumper_design(
    *,
    m,
    speeds,
    x_max_bound,
    e_target,
    c0=None,
    b1_0=None,
    steps: int = 250,
    learning_rate: float = 0.05,
    penalty=(1.0, 1e4),
    tol: float = 1e-3,
    rtol: float = 1e-8,
) -> BumperDesign:
    """Choose `c` and `b1` of law 14 (`F = c x^1.5 + b1 x^0.5 v`, seed paper eq. 14) for a
    body of mass `m` (kg) hitting at every speed in `speeds` (m/s): minimise the peak
    contact force over the speeds, subject to `x_max <= x_max_bound` (m) and
    `e <= e_target` at every speed.

    Adam (optax) on `log c, log b1`, with gradients by forward mode through the solves; the
    constraints enter as quadratic penalties whose weight grows from `penalty[0]` to
    `penalty[1]` over the `steps` iterations (a continuation), with a margin of `tol/2` so
    that the final design meets them to `tol` (relative in `x_max`, absolute in `e`).
    `x_max_bound` and `e_target` may be 1-D arrays (broadcast together): all pairs are
    optimised at once (vmapped, one compilation), which gives trade-off curves such as the
    peak force against the stroke.
    `c0`, `b1_0`: starting point (default: the undamped spring that just reaches the bound
    at the highest speed, and a damping group of 0.5 at the mean speed).

    **Example**:
    `d = bumper_design(m=1.0, speeds=[1, 2, 3], x_max_bound=0.01, e_target=0.5)`;
    `d.c, d.b1, d.F_peak, d.feasible`.
    """
    speeds = jnp.asarray(speeds, dtype=float)
    if speeds.ndim != 1 or speeds.size < 1:
        raise ValueError("speeds must be a 1-D array of impact speeds (m/s)")
    if not np.all(np.asarray(speeds) > 0):
        raise ValueError("every impact speed must be > 0 m/s")
    bounds, targets = np.broadcast_arrays(
        np.asarray(x_max_bound, dtype=float), np.asarray(e_target, dtype=float)
    )
    if bounds.ndim > 1 or not np.all(bounds > 0):
        raise ValueError("x_max_bound must be a positive number or 1-D array (m)")
    if np.any(targets <= 0) or np.any(targets > 1):
        raise ValueError(f"e_target must lie in (0, 1], got {e_target}")
    if not float(m) > 0:
        raise ValueError(f"mass m must be > 0 kg, got {m}")
    m = jnp.asarray(m, dtype=float)
    v_max, v_mean = jnp.max(speeds), jnp.mean(speeds)

    def start(bound):
        c = 1.25 * m * v_max**2 / bound**2.5 if c0 is None else jnp.asarray(c0, dtype=float)
        x_star = (m * v_mean**2 / c) ** 0.4
        b1 = 0.5 * m * v_mean / x_star**1.5 if b1_0 is None else jnp.asarray(b1_0, dtype=float)
        return jnp.stack([c, b1])

    def solve(bound, target):
        scales = start(bound)
        run = _Run(
            tol=tol, lr=learning_rate, mu=jnp.asarray(penalty, dtype=float), steps=steps, rtol=rtol
        )
        theta, response, history = _optimise_bumper(scales, m, speeds, bound, target, run)
        F, x, e = response.T
        design = scales * jnp.exp(theta)
        feasible = jnp.all(x <= bound * (1 + tol)) & jnp.all(e <= target + tol)
        return design, F, x, e, feasible, history

    solver = jax.vmap(solve) if bounds.ndim else solve
    design, F, x, e, feasible, history = solver(jnp.asarray(bounds), jnp.asarray(targets))
    return BumperDesign(
        c=design[..., 0],
        b1=design[..., 1],
        speeds=speeds,
        m=m,
        x_max_bound=jnp.asarray(bounds),
        e_target=jnp.asarray(targets),
        F_max=F,
        x_max=x,
        e=e,
        F_peak=jnp.max(F, axis=-1),
        feasible=feasible,
        history=history,
        F_ideal=m * v_max**2 / (2 * jnp.asarray(bounds)),
    )
