"""Constant powers made cheap (issue 35, item 1): `x**1.5` as `x * sqrt(x)`, in the table's
laws (`contact_pow`, `safe_pow`) and in a user's law (`fast_powers`, read off its jaxpr),
with the values and gradients of `pow` to a few ulps and no NaN at the surface."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import assert_finite, primitive_names

import jaximpact as ji
from jaximpact._laws.fast_powers import fast_powers
from jaximpact._powers import contact_pow, half_power, safe_pow

XS = np.geomspace(1e-300, 1e3, 20_001)
TINY = float(np.finfo(float).tiny)
# the exponents laws use: within 4e-16 of pow (values and derivatives); others within 4 ulps
COMMON = (0.5, 1.5, 2.5, 2.0)
OTHERS = (3.5, 1.0, 3.0, 8.0, -0.5, -1.5, -2.0)


def _max_rel(actual, expected):
    """The largest relative difference where `expected` is a normal, finite number (below
    the normal range `pow` and the product round to the subnormal grid, not to 1 ulp)."""
    actual, expected = np.asarray(actual), np.asarray(expected)
    normal = np.isfinite(expected) & (np.abs(expected) >= TINY)
    assert np.all(np.isfinite(actual[normal]))
    assert np.all((actual == 0) == (expected == 0))
    return float(np.max(np.abs(actual[normal] - expected[normal]) / np.abs(expected[normal])))


def _on_grid(fn):
    return jax.jit(jax.vmap(fn))(jnp.asarray(XS)), jax.jit(jax.vmap(jax.grad(fn)))(jnp.asarray(XS))


@pytest.mark.parametrize("p", COMMON + OTHERS)
def test_half_power_is_pow_to_a_few_ulps(p):
    tol = 4e-16 if p in COMMON else 9e-16
    value, slope = _on_grid(lambda x: half_power(x, int(2 * p)))
    expected_value, expected_slope = _on_grid(lambda x: x**p)
    assert _max_rel(value, expected_value) <= tol
    assert _max_rel(slope, expected_slope) <= tol
    assert "pow" not in primitive_names(lambda x: half_power(x, int(2 * p)), 1.0)


@pytest.mark.parametrize("p", [0.5, 1.5, 2.5])
def test_a_static_half_power_is_guarded_as_before(p):
    """`safe_pow` and `contact_pow` with a static multiple of 1/2: sqrt and multiplies,
    zero with zero gradient and Hessian at and below the surface, finite elsewhere."""
    xs = jnp.array([-1.0, -1e-300, 0.0, 1e-300, TINY, 1e-8, 0.3, 4.0])
    for fn in (lambda x: safe_pow(x, p), lambda x: contact_pow(x, p)):
        assert "pow" not in primitive_names(fn, 1.0)
        value = jax.vmap(fn)(xs)
        slope = jax.vmap(jax.grad(fn))(xs)
        curvature = jax.vmap(jax.hessian(fn))(xs)
        # the curvature of x^0.5 at 1e-300 overflows, as pow's does
        assert_finite((value, slope, curvature[5:]), f"x^{p}")
        outside = np.asarray(xs) <= 0
        for result in (value, slope, curvature):
            assert np.all(np.asarray(result)[outside] == 0.0)
        np.testing.assert_allclose(value[3:], np.asarray(xs[3:]) ** p, rtol=4e-16, atol=0)


def test_a_traced_or_general_exponent_stays_pow():
    assert "pow" in primitive_names(lambda x, n: contact_pow(x, n), 1.0, 1.5)  # Hunt-Crossley's n
    for p in (0.25, 1.3, 17.5):
        assert "pow" in primitive_names(lambda x: contact_pow(x, p), 1.0)
    assert "pow" in primitive_names(lambda x: safe_pow(x, jnp.asarray(1.5)), 1.0)


def test_the_table_laws_with_half_powers_need_no_pow():
    law = ji.law("hertz_rate", c=2e6, b1=800.0)
    assert "pow" not in primitive_names(lambda x, v: law.force(x, v), 1e-3, 1.0)
    dynamics = law.dynamics(m=1.0, v0=2.5, g=0.0)
    y = jnp.array([0.3, 0.5])
    assert "pow" not in primitive_names(lambda y: dynamics.rhs(y, True), y)
    assert "pow" not in primitive_names(lambda y: dynamics.force_gap(y, True), y)
    traced = ji.law("hunt_crossley", c=2e6, a=0.1, n=1.5)  # n a parameter: pow, as before
    assert "pow" in primitive_names(lambda x, v: traced.force(x, v), 1e-3, 1.0)


# ---------------------------------------------------------------- a user's law, rewritten

USER_POWERS = {
    "x**1.5": (lambda x: x**1.5),
    "jnp.power(x, 2.5)": (lambda x: jnp.power(x, 2.5)),
    "x**0.5": (lambda x: x**0.5),
    "x**2": (lambda x: x**2),
    "x**2.0": (lambda x: x**2.0),
}


@pytest.mark.parametrize("name", list(USER_POWERS))
def test_a_users_power_is_rewritten_and_agrees_with_pow(name):
    fn = USER_POWERS[name]
    fast = fast_powers(fn)
    assert "pow" not in primitive_names(fast, 1.0)
    value, slope = _on_grid(fast)
    expected_value, expected_slope = _on_grid(fn)
    assert _max_rel(value, expected_value) <= 4e-16
    assert _max_rel(slope, expected_slope) <= 4e-16


def _hertz_rate(x, v, p):  # the law of the benchmark: c x^1.5 + b1 x^0.5 v (1 + 0.1 v)
    return p["c"] * x**1.5 + p["b1"] * jnp.power(x, 0.5) * v * (1 + 0.1 * v)


PARAMS = {"c": jnp.asarray(2e6), "b1": jnp.asarray(800.0)}


def test_a_rewritten_law_composes_with_jit_vmap_and_grad():
    fast = fast_powers(_hertz_rate)
    xs, vs = jnp.geomspace(1e-12, 1e-2, 7), jnp.linspace(-2.0, 2.0, 7)
    for transform in (
        lambda f: jax.jit(jax.vmap(f, in_axes=(0, 0, None))),
        lambda f: jax.vmap(jax.grad(f, argnums=(0, 1, 2)), in_axes=(0, 0, None)),
        lambda f: jax.vmap(jax.hessian(f), in_axes=(0, 0, None)),
        lambda f: jax.vmap(jax.jacfwd(f, argnums=2), in_axes=(0, 0, None)),
    ):
        got, expected = transform(fast)(xs, vs, PARAMS), transform(_hertz_rate)(xs, vs, PARAMS)
        for a, b in zip(jax.tree_util.tree_leaves(got), jax.tree_util.tree_leaves(expected)):
            # the terms of the curvature cancel: a few ulps of each, relative to the sum
            np.testing.assert_allclose(a, b, rtol=1e-13, atol=0)


def test_what_is_not_a_constant_half_power_is_left_as_written():
    def law(x, v, p):
        return jnp.power(x, p["n"]) + x**0.25 + x**2 + jnp.sqrt(x) + jax.lax.rsqrt(x) * v

    names = primitive_names(fast_powers(law), 0.3, 1.0, {"n": jnp.asarray(1.5)})
    assert names.count("pow") == 2  # the traced n and the general 0.25
    assert names.count("integer_pow") == 1 and "sqrt" in names and "rsqrt" in names
    x, v, p = 0.3, 1.0, {"n": jnp.asarray(1.5)}
    np.testing.assert_allclose(fast_powers(law)(x, v, p), law(x, v, p), rtol=1e-15)


def test_powers_inside_a_users_jitted_helper_and_a_clamp_are_rewritten():
    @jax.jit
    def hertz(x, c):
        return c * x**1.5

    @jax.jit
    def power(x, n):  # the exponent a literal of the call
        return x**n

    def law(x, v, p):
        return jnp.maximum(hertz(x, p["c"]) + p["b1"] * power(x, 0.5) * v, 0.0)

    fast = fast_powers(law)
    assert "pow" not in primitive_names(fast, 0.3, 1.0, PARAMS)
    for x, v in [(1e-3, 1.0), (1e-3, -3.0)]:
        np.testing.assert_allclose(fast(x, v, PARAMS), law(x, v, PARAMS), rtol=1e-15)


def test_a_law_that_reads_concrete_values_is_called_as_written():
    def law(x, v, p):
        return float(p["c"]) * x**1.5  # not traceable: eager calls only

    np.testing.assert_allclose(fast_powers(law)(0.01, 0.0, PARAMS), 2e6 * 0.01**1.5, rtol=1e-15)


def test_a_custom_law_evaluates_no_pow_and_no_nan_at_the_surface():
    """`CustomLaw.force` (and `edge_force` of a clamped law) go through `fast_powers`; the
    force and its gradients are finite at x = tiny, 0 and below, and 0 outside."""
    law = ji.custom_law(_hertz_rate, c=2e6, b1=800.0)
    clamped = ji.custom_law(lambda x, v, p: jnp.maximum(_hertz_rate(x, v, p), 0.0), c=2e6, b1=800.0)
    assert "pow" not in primitive_names(lambda x, v: law.force(x, v), 1e-3, 1.0)
    assert "pow" not in primitive_names(lambda x, v: clamped.edge_force(x, v), 1e-3, 1.0)
    xs = jnp.array([-1e-3, -1e-300, 0.0, TINY, 1e-300, 1e-12, 1e-3])
    vs = jnp.full_like(xs, 1.5)

    def force(law, x, v):
        return law.force(x, v)

    value = jax.vmap(force, in_axes=(None, 0, 0))(law, xs, vs)
    grads = jax.vmap(jax.grad(force, argnums=(0, 1, 2)), in_axes=(None, 0, 0))(law, xs, vs)
    assert_finite((value, grads), "a custom law's force and gradients near the surface")
    assert np.all(np.asarray(value)[:2] == 0.0)
    inside = np.asarray(xs) > 1e-300
    expected = jax.vmap(_hertz_rate, in_axes=(0, 0, None))(xs[inside], vs[inside], PARAMS)
    np.testing.assert_allclose(np.asarray(value)[inside], expected, rtol=1e-15)
    np.testing.assert_allclose(clamped.edge_force(1e-3, -3.0), _hertz_rate(1e-3, -3.0, PARAMS))
