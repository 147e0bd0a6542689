"""Residual functions whose derivative is a forward-mode Jacobian, in every AD mode."""

import jax
import jax.numpy as jnp


def with_forward_jacobian(residuals, value_and_jacobian_fn=None, *, held=False):
    """Wrap `residuals(theta, data) -> r` (1-D arrays) so that any differentiation of it,
    forward or reverse, goes through one `jax.jacfwd` of the impact solves.

    A fit has two to four parameters: forward mode through diffrax costs 2-4 solves, reverse
    mode 15-50 (shared/notes, section 0), and compiles in half the time. The `custom_jvp`
    rule returns `J @ dtheta`, which is linear in the tangent, so `jax.grad` (which
    transposes it) works too. `data` is not differentiated. `value_and_jacobian_fn(theta,
    data) -> ((r, aux), J)` may be given to share one compiled Jacobian between call sites.
    `held=True` holds `J` constant (`stop_gradient`): first derivatives stay exact, and a
    second one (`jax.hessian` of a function `f` of `r`) is Gauss-Newton's, `J^T (d^2 f /
    dr^2) J`, with no second derivative through the solves (the posterior's Laplace step).
    """
    if value_and_jacobian_fn is None:
        value_and_jacobian_fn = jax.jit(
            lambda theta, data: value_and_jacobian(
                lambda t, d: (residuals(t, d), None), theta, data
            )
        )

    @jax.custom_jvp
    def wrapped(theta, data):
        return residuals(theta, data)

    @wrapped.defjvp
    def _jvp(primals, tangents):
        theta, data = primals
        if held:
            fixed = jax.lax.stop_gradient(theta)
            (value, _), jacobian = value_and_jacobian_fn(fixed, jax.lax.stop_gradient(data))
            jacobian = jax.lax.stop_gradient(jacobian)
            # the value's own derivative J dtheta (J held), for a derivative of the rule's
            return value + jacobian @ (theta - fixed), jacobian @ tangents[0]
        (value, _), jacobian = value_and_jacobian_fn(theta, data)
        return value, jacobian @ tangents[0]

    return wrapped


def value_and_jacobian(residuals, theta, data):
    """`((r, aux), dr/dtheta)` of `residuals(theta, data) -> (r, aux)`, by forward mode."""

    def with_aux(t):
        r, aux = residuals(t, data)
        return r, (r, aux)

    jacobian, value = jax.jacfwd(with_aux, has_aux=True)(theta)
    return value, jnp.atleast_2d(jacobian)


def rows_value_and_jacobian(per_row, theta, rows):
    """`((out, aux), J)` of `per_row(theta, row) -> (out, aux)` for every row of `rows`
    (arrays along their first axis), `J` holding `d out / d theta` on a last axis: one
    `vmap` over the (row, direction) pairs of a `jax.jvp`.

    `jax.jacfwd` of a `vmap` over the rows batches the solve twice, once per transformation,
    and JAX's batching of diffrax's nested loops is most of a fit's tracing: batched once,
    a user's law's Jacobian program of 4 impacts traced in 2.8 s instead of 5.2 s (its
    solves run in the same time: the pairs' repeated primals are members of one batch).
    `out`: a tuple of float arrays; `aux` is not differentiated.
    """
    n = theta.shape[0]
    count = jax.tree.leaves(rows)[0].shape[0]
    repeated = jax.tree.map(lambda a: jnp.repeat(a, n, axis=0), rows)
    directions = jnp.tile(jnp.eye(n, dtype=theta.dtype), (count, 1))

    def pair(row, direction):
        return jax.jvp(lambda t: per_row(t, row), (theta,), (direction,), has_aux=True)

    out, d_out, aux = jax.vmap(pair)(repeated, directions)
    first = jax.tree.map(lambda a: a[::n], (out, aux))  # every direction's primal is the same
    jacobian = jax.tree.map(
        lambda a: jnp.moveaxis(jnp.reshape(a, (count, n, *a.shape[1:])), 1, -1), d_out
    )
    return first, jacobian
