"""`_tracing.anchors`: a loop's carry started as it leaves the body is traced once per
transformation, and the anchors change no value."""

import math

import jax
import jax.numpy as jnp
import numpy as np

from jaximpact._tracing import anchors


def _batchings_of_a_scan(anchored: bool) -> int:
    """How many times `vmap` of a scan batches its body (a `custom_vmap` in it counts),
    where the carry starts with a time at 0 and a flag that leave the body batched."""
    calls = []

    @jax.custom_batching.custom_vmap
    def counted(x):
        return x

    @counted.def_vmap
    def _(axis_size, in_batched, x):
        calls.append(1)
        return x, in_batched[0]

    def body(carry, _):
        x, t, alive = carry
        x = counted(x)
        return (x * 0.5, t + x, alive & (x > 0.1)), None

    def run(x):
        zero, no = anchors(x) if anchored else (0.0, False)
        t0 = zero + jnp.zeros(())
        (x, t, alive), _ = jax.lax.scan(body, (x, t0, ~no), None, length=4)
        return t + jnp.where(alive, 1.0, 0.0)

    out = jax.vmap(run)(jnp.array([1.0, 2.0, 3.0]))
    np.testing.assert_allclose(out, np.array([1.875, 3.75, 5.625]) + 1.0)
    return len(calls)


def test_an_anchored_carry_is_batched_once():
    assert _batchings_of_a_scan(anchored=False) == 2  # JAX's fixpoint: a second pass
    assert _batchings_of_a_scan(anchored=True) == 1


def test_the_anchors_are_an_exact_zero_and_false_whatever_the_leaves():
    tree = {"a": jnp.array([1e308, 1e308, math.inf]), "b": jnp.array(math.nan), "n": 3}
    zero, no = anchors(tree, 2.5)
    assert float(zero) == 0.0 and not math.copysign(1.0, float(zero)) < 0
    assert not bool(no)
    batched = jax.vmap(lambda x: anchors({"x": x}))(jnp.array([1.0, -math.inf]))
    assert batched[0].shape == (2,) and np.all(np.asarray(batched[0]) == 0.0)
    assert not np.any(np.asarray(batched[1]))
