"""How a loop's initial carry is made so that JAX traces the loop's body once per
transformation.

`jax.vmap` and `jax.jvp` of a `lax.scan` or `lax.while_loop` find which entries of the
carry are batched, or carry a tangent, by a fixpoint: they transform the body with the
initial carry's answer, see an entry come out batched (or with a tangent) that went in
without, and transform the body again. A carry that starts with constants (a time at 0,
a counter, a flag) and leaves a solve depending on the inputs costs one more pass per
transformation; for a body that holds a diffrax solve, that is seconds of tracing
(`fit_oblique`'s program: 15.4 -> 8.9 CPU s). `anchors` gives a zero and a False that
depend on the inputs, to start those entries as they leave the body.
"""

import jax
import jax.numpy as jnp
from jaxtyping import Array


def anchors(*trees) -> tuple[Array, Array]:
    """`(0.0, False)` that depend on every floating-point leaf of `trees`: batched under
    `vmap` where any leaf is, with a (zero) tangent under `jvp` where any leaf has one.
    Add the zero to a float entry of a loop's initial carry (an exact 0.0 or -0.0, which
    leave every entry that is not -0.0 as it is), or `|` the False into a boolean (or an
    integer, as `astype`) one. Non-finite values are read as 0, so the zero is exact."""
    total = jnp.zeros(())
    for leaf in jax.tree_util.tree_leaves(trees):
        if isinstance(leaf, jax.Array) and jnp.issubdtype(leaf.dtype, jnp.floating):
            total = total + jnp.sum(jnp.where(jnp.isfinite(leaf), leaf, 0.0))
    zero = 0.0 * jnp.where(jnp.isfinite(total), total, 0.0)
    return zero, zero != 0.0
