"""The Laplace approximation: the posterior's mode (MAP) in the unbounded coordinates `z`
and the Gaussian `N(z_map, H^-1)` there, `H = -d^2 ln p(y, z) / dz^2` (`jax.hessian`),
with the evidence it implies:

    ln Z = ln p(y, z_map) + (d/2) ln(2 pi) - (1/2) ln det H.

`ln p(y, z)` is the likelihood times the normalised prior density of `z` (Jacobian
included), so `Z` is the marginal likelihood of the data whatever the coordinates.
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np


class Laplace(eqx.Module):
    """The mode `z` (unbounded coordinates), `covariance` (`H^-1`), `log_density` there
    (unnormalised log posterior), `log_evidence`, Newton `iterations`, and whether the
    mode was found (`converged`: gradient below tolerance, `H` positive definite)."""

    z: jax.Array
    covariance: jax.Array
    log_density: jax.Array
    log_evidence: jax.Array
    iterations: jax.Array
    converged: jax.Array


@eqx.filter_jit
def laplace(model, z0, max_iter: int = 100, gtol: float = 1e-8) -> Laplace:
    """Newton's method on `model.log_posterior` from `z0` (a damped, saddle-free step:
    the Hessian's eigenvalues taken in absolute value, floored, with a backtracking line
    search), then the Gaussian at the mode."""
    f = model.log_posterior
    d = z0.shape[0]

    def derivatives(z):
        """`(f, g, -H)` at `z` from one trace (the Hessian's, the value and gradient its
        by-products): each copy of the forward model costs its compile time."""

        def gradient(zz):
            value, g = jax.value_and_grad(f)(zz)
            return g, (value, g)

        H, (value, g) = jax.jacfwd(gradient, has_aux=True)(z)
        return value, g, -0.5 * (H + H.T)

    def step(carry):
        z, value, g, H, k, _ = carry
        w, v = jnp.linalg.eigh(H)
        w = jnp.maximum(jnp.abs(w), 1e-8 * jnp.maximum(jnp.max(jnp.abs(w)), 1.0))
        direction = v @ ((v.T @ g) / w)

        # backtracking: the full step, then halve until the log density rises (down to
        # 1e-12 of the step); one call of `f` in the program
        def shorter(c):
            alpha, _, _, _ = c
            alpha = 0.5 * alpha
            trial = z + alpha * direction
            return alpha, trial, f(trial), jnp.asarray(True)

        def not_better(c):
            alpha, _, new, tried = c
            return ~tried | ((~(new >= value)) & (alpha > 1e-12))

        start = (jnp.asarray(2.0, z.dtype), z, value, jnp.asarray(False))
        _, trial, new, _ = jax.lax.while_loop(not_better, shorter, start)
        better = new >= value
        z_next = jnp.where(better, trial, z)
        _, g_next, H_next = derivatives(z_next)
        # the Newton decrement g^T H^-1 g: twice the rise a full step would bring
        done = (jnp.abs(g @ direction) < gtol) | ~better
        return z_next, jnp.where(better, new, value), g_next, H_next, k + 1, done

    def keep_going(carry):
        *_, k, done = carry
        return (k < max_iter) & ~done

    value0, g0, H0 = derivatives(z0)
    carry = (z0, value0, g0, H0, jnp.asarray(0), jnp.asarray(False))
    z, value, g, H, k, _ = jax.lax.while_loop(keep_going, step, carry)
    w = jnp.linalg.eigvalsh(H)
    positive = jnp.all(w > 0)
    covariance = jnp.linalg.inv(H)
    log_det = jnp.sum(jnp.log(jnp.where(positive, w, 1.0)))
    log_evidence = value + 0.5 * d * jnp.log(2.0 * jnp.pi) - 0.5 * log_det
    log_evidence = jnp.where(positive, log_evidence, jnp.nan)
    # the gradient in the metric of H: small where the mode is found
    converged = positive & (jnp.abs(g @ covariance @ g) < 1e-6) & jnp.isfinite(value)
    return Laplace(z, covariance, value, log_evidence, k, converged)


def gaussian_draws(result: Laplace, key, num: int) -> np.ndarray:
    """`num` draws of `z` from `N(z_map, H^-1)`, shape `(num, d)`."""
    d = result.z.shape[0]
    L = jnp.linalg.cholesky(result.covariance)
    eps = jax.random.normal(key, (num, d), dtype=result.z.dtype)
    return np.asarray(result.z[None, :] + eps @ L.T)
