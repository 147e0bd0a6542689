"""`rows_value_and_jacobian`: one `vmap` over (row, direction) pairs of a `jax.jvp` gives what
`jax.jacfwd` of a `vmap` over the rows gives, for an analytic function with an aux output."""

import jax
import jax.numpy as jnp
import numpy as np

from jaximpact._fit.forward_jacobian import rows_value_and_jacobian


def _per_row(theta, row):
    """Two outputs of three parameters and a row `{"v": speed, "k": scale}`, and an integer
    aux that depends on the row only."""
    a, b, c = theta[0], theta[1], theta[2]
    first = jnp.exp(a * row["v"]) * jnp.sin(b) + c**2 * row["k"]
    second = jnp.log1p(a**2 + row["v"] * b * c)
    return (first, second), jnp.asarray(row["v"] > 1.0, jnp.int32)


def test_pairs_of_jvps_are_jacfwd_of_the_rows():
    theta = jnp.array([0.3, -1.2, 0.7])
    rows = {"v": jnp.array([0.5, 1.5, 2.5, 4.0]), "k": jnp.array([1.0, -2.0, 3.0, 0.5])}
    (out, aux), jacobian = rows_value_and_jacobian(_per_row, theta, rows)

    def stacked(t):
        return jax.vmap(lambda r: _per_row(t, r)[0])(rows)

    expected_out = stacked(theta)
    expected_jacobian = jax.jacfwd(stacked)(theta)
    for k in range(2):
        np.testing.assert_allclose(out[k], expected_out[k], rtol=1e-15)
        assert jacobian[k].shape == (4, 3)
        np.testing.assert_allclose(jacobian[k], expected_jacobian[k], rtol=1e-14, atol=1e-15)
    np.testing.assert_array_equal(aux, [0, 1, 1, 1])
    # and against central differences, independent of JAX's forward mode
    h = 1e-6
    for j in range(3):
        step = jnp.zeros(3).at[j].set(h)
        difference = (stacked(theta + step)[0] - stacked(theta - step)[0]) / (2 * h)
        np.testing.assert_allclose(jacobian[0][:, j], difference, rtol=1e-8)
