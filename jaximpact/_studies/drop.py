"""`drop_design`: the drop height and mass that give a wanted sequence of bounce apexes
(Levenberg-Marquardt through `jaximpact.bounce`, forward mode).
"""

import functools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._format import PrintedFields
from .._least_squares import levenberg_marquardt


class DropDesign(PrintedFields, eqx.Module):
    """The result of `drop_design` (SI units).

    - `h0` (m), `m` (kg): the drop height and mass found.
    - `target`, `apexes` (m): the wanted and the achieved apex heights after each contact.
    - `residuals`: `ln(apexes / target)`; `loss`: half their sum of squares.
    - `converged`: the scaled gradient, the relative decrease or the step fell below `tol`
      (`_least_squares`).
    - `iterations`; `history`: the loss at each accepted iterate.
    """

    _TITLE = "DropDesign (SI units)"
    _SHOWN = (
        ("h0", "m"),
        ("m", "kg"),
        ("target", "m"),
        ("apexes", "m"),
        ("loss", ""),
        ("converged", None),
        ("iterations", None),
    )

    h0: float
    m: float
    target: np.ndarray
    apexes: np.ndarray
    residuals: np.ndarray
    loss: float
    converged: bool
    iterations: int
    history: np.ndarray


@functools.partial(jax.jit, static_argnames=("count", "rtol"))
def _apex_residuals(theta, law, target, g, count, rtol):
    """`ln(apex_k / target_k)` for `theta = (ln h0, ln m)` and its Jacobian (forward mode),
    from `bounce`: the first `count` contacts, flights in closed form."""
    from .._solve.bounce import bounce

    def residuals(theta):
        h0, m = jnp.exp(theta[0]), jnp.exp(theta[1])
        # long enough for `count` flights, each shorter than the drop's own duration
        t_end = jax.lax.stop_gradient((2.0 * count + 2.0) * jnp.sqrt(2.0 * h0 / g))
        b = bounce(law, m=m, h0=h0, t_end=t_end, g=g, max_impacts=count, peaks=False, rtol=rtol)
        apexes = b.apex_heights[:count]
        r = jnp.log(apexes) - jnp.log(target)
        return r, (r, apexes)

    jac, (r, apexes) = jax.jacfwd(residuals, has_aux=True)(theta)
    return r, jac, apexes


def drop_design(
    law,
    *,
    apexes,
    h0_guess: float,
    m_guess: float,
    g: float = 9.81,
    max_iterations: int = 40,
    tol: float = 1e-10,
    rtol: float = 1e-10,
) -> DropDesign:
    """The drop height `h0` (m) and mass `m` (kg) of a ball released from rest on a floor
    with contact law `law` whose first bounces reach the wanted apex heights `apexes` (m,
    above the floor, one per contact, in order).

    Least squares in `ln(apex / target)` over `(ln h0, ln m)` by Levenberg-Marquardt, with
    the Jacobian by forward mode through `jaximpact.bounce` (closed-form flights, one impact
    solve with gravity per contact). The mass matters because the restitution of a law with
    a length scale depends on it (law 14: `e` is a function of `b1 (m v^2/c)^0.6 / (m v)`,
    so heavier balls bounce higher), the height because `e` depends on the impact speed.
    A sequence no `(h0, m)` can give returns the best fit, `converged` true and nonzero
    residuals: read `residuals`.

    **Example**: `drop_design(law("hertz_rate", c=1e6, b1=1350.0),
    apexes=[0.24, 0.10, 0.043], h0_guess=1.0, m_guess=0.3)`.
    """
    target = np.asarray(apexes, dtype=float)
    if target.ndim != 1 or target.size < 2 or np.any(target <= 0):
        raise ValueError("apexes must be at least two positive heights (m), one per bounce")
    if np.any(np.diff(target) >= 0):
        raise ValueError("apex heights must decrease from bounce to bounce")
    if not (h0_guess > target[0] and m_guess > 0):
        raise ValueError("h0_guess must be above the first apex and m_guess > 0")
    count = int(target.size)
    apex_residuals = functools.partial(
        _apex_residuals, law=law, target=jnp.asarray(target), g=float(g), count=count, rtol=rtol
    )

    def evaluate(theta):
        return tuple(np.asarray(out) for out in apex_residuals(jnp.asarray(theta)))

    theta0 = np.log([h0_guess, m_guess])
    fit = levenberg_marquardt(evaluate, theta0, max_iter=max_iterations, tol=tol)
    if not np.all(np.isfinite(fit.residuals)):
        raise ValueError(
            f"the starting guess (h0 = {h0_guess} m, m = {m_guess} kg) does not give {count} "
            "bounces: start higher or heavier"
        )
    return DropDesign(
        h0=float(np.exp(fit.theta[0])),
        m=float(np.exp(fit.theta[1])),
        target=target,
        apexes=np.asarray(fit.extra),
        residuals=fit.residuals,
        loss=float(fit.history[-1]),
        converged=bool(fit.converged),
        iterations=fit.iterations,
        history=fit.history,
    )
