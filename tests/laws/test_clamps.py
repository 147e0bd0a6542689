"""A user's clamp at zero (`jnp.maximum(F, 0)` and its spellings) is data about the law:
integrated as written, with contact ending where the clamped force reaches zero (issue 34,
item 1: such a law once failed to solve, Newton's event step being 0/0 on its flat tail)."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaximpact as ji
from jaximpact._laws.clamps import unclamped


def _force(x, v, p):  # law 14 as a user writes it: F = c x^1.5 + b x^0.5 v
    return p["c"] * x**1.5 + p["b"] * x**0.5 * v


CLAMPS = {
    "maximum": lambda x, v, p: jnp.maximum(_force(x, v, p), 0.0),
    "maximum, zero first": lambda x, v, p: jnp.maximum(0.0, _force(x, v, p)),
    "clip": lambda x, v, p: jnp.clip(_force(x, v, p), 0, None),
    "relu": lambda x, v, p: jax.nn.relu(_force(x, v, p)),
    "where": lambda x, v, p: jnp.where(_force(x, v, p) > 0, _force(x, v, p), 0.0),
}
PARAMS = {"c": 2e6, "b": 800.0}
PULLING = (1e-3, -3.0)  # x (m), v (m/s) where F = c x^1.5 + b x^0.5 v < 0


@pytest.mark.parametrize("name", list(CLAMPS))
def test_the_force_before_the_clamp_is_read_off_the_law(name):
    """Each spelling of the clamp is found, and the function returned is the unclamped
    force: negative where the law pulls (the clamped law gives 0 there), equal to it where
    it pushes, with the same gradient, under vmap too."""
    fn = CLAMPS[name]
    peeled = unclamped(fn, PARAMS)
    assert peeled is not None
    x, v = PULLING
    assert float(fn(x, v, PARAMS)) == 0.0
    np.testing.assert_allclose(peeled(x, v, PARAMS), _force(x, v, PARAMS), rtol=1e-15)
    xs = jnp.array([1e-4, 1e-3, 5e-3])
    np.testing.assert_allclose(
        jax.vmap(peeled, in_axes=(0, None, None))(xs, 1.0, PARAMS), _force(xs, 1.0, PARAMS)
    )
    slope = jax.grad(peeled, argnums=1)(x, v, PARAMS)
    np.testing.assert_allclose(slope, PARAMS["b"] * x**0.5, rtol=1e-15)


@pytest.mark.parametrize(
    "fn",
    [
        _force,  # no clamp
        lambda x, v, p: jnp.maximum(_force(x, v, p), 1.0),  # a floor that is not zero
        lambda x, v, p: jnp.minimum(_force(x, v, p), 0.0),
        lambda x, v, p: jnp.where(v > 0, _force(x, v, p), p["c"] * x**1.5),  # no zero case
        lambda x, v, p: 2.0 * jnp.maximum(_force(x, v, p), 0.0),  # the clamp is not last
    ],
)
def test_a_law_that_does_not_end_in_a_clamp_at_zero_is_left_alone(fn):
    assert unclamped(fn, PARAMS) is None


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CLAMPS))
def test_a_clamped_law_is_the_unclamped_table_law(name):
    """`jnp.maximum(c x^1.5 + b x^0.5 v, 0)` and the other spellings give the table's
    law 14 (its universal curve): e, T and x_max within 1e-9, where they once raised 'the
    impact's solve failed'; under vmap too."""
    clamped = ji.custom_law(CLAMPS[name], **PARAMS)
    table = ji.law("hertz_rate", c=2e6, b1=800.0)
    r = ji.impact(clamped, m=1.0, v0=2.5)
    ref = ji.impact(table, m=1.0, v0=2.5)
    assert r.status_name == "separated"
    for key in ("e", "T", "x_max"):
        got, want = float(getattr(r, key)), float(getattr(ref, key))
        assert abs(got - want) <= 1e-9 * abs(want), (key, got, want)
    if name == "maximum":
        batch = jax.vmap(lambda v0: ji.impact(clamped, m=1.0, v0=v0).e)(jnp.array([1.0, 2.5]))
        want = [float(ji.impact(table, m=1.0, v0=v0).e) for v0 in (1.0, 2.5)]
        np.testing.assert_allclose(batch, want, rtol=1e-9)


@pytest.mark.slow
def test_gradients_through_a_clamped_law_are_the_table_laws():
    """d e / d c and d T / d c of the clamped law: the event is placed on the force before
    the clamp, so the contact's end moves with the parameters (a flat zero would give 0/0),
    equal to the table law's derivatives (its curve, analytic in the group): T's to 1e-6,
    e's to 3e-5, the integrated path's own derivative error (measured 8.8e-6 with the
    clamp, 1.9e-5 for the same law unclamped, at rtol 1e-10; issue 35's grid path is the
    cure)."""
    clamped = ji.custom_law(CLAMPS["maximum"], **PARAMS)
    table = ji.law("hertz_rate", c=2e6, b1=800.0)

    def e_and_T(law, c):
        r = ji.impact(law.replace(c=c), m=1.0, v0=2.5)
        return jnp.stack([r.e, r.T])

    got = jax.jacfwd(lambda c: e_and_T(clamped, c))(2e6)
    want = jax.jacfwd(lambda c: e_and_T(table, c))(2e6)
    np.testing.assert_allclose(got[1], want[1], rtol=1e-6)
    np.testing.assert_allclose(got[0], want[0], rtol=3e-5)


def test_a_law_closing_over_a_traced_value_is_read():
    """A law that closes over a traced value (as `jax.grad` through the forward Jacobian
    builds one) holds a tracer among its jaxpr's constants: it is not a known zero, and
    the clamp is still found (it raised TracerArrayConversionError)."""

    @jax.jit
    def pulling_force(c):
        def fn(x, v, p):  # c, traced, goes through a broadcast inside the law
            stiffness = jnp.broadcast_to(c, (1,))[0]
            return jnp.maximum(stiffness * x**1.5 + p["b"] * x**0.5 * v, 0.0)

        peeled = unclamped(fn, {"b": 800.0})
        return peeled(*PULLING, {"b": 800.0})

    np.testing.assert_allclose(pulling_force(2e6), _force(*PULLING, PARAMS), rtol=1e-15)
