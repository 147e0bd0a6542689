"""Force laws: construction, errors, values at special points, NaN-free powers."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import PAPER_IDS, PAPER_SETS, assert_finite, assert_rel
from reference import reference_force

import jaximpact as ji

PAPER_LAWS = (
    "kelvin_voigt",
    "kelvin_voigt_modified",
    "bingham",
    "bingham_modified",
    "bingham_compression",
    "maxwell",
    "hertz_viscous",
    "hertz_modified",
    "hertz_rate",
    "hunt_crossley",
)
# the Hunt-Crossley family with damping from a nominal restitution
NOMINAL_LAWS = tuple(
    name for name in ji.LAW_NAMES if ji.LAWS[name].parameters == ("c", "e_nominal", "n")
)
# laws beyond the paper and the nominal family, with parameters to try them with
OTHER_LAWS = {
    "power": dict(c=2e6, n=1.5, b=800.0, p=0.5),
    # the engines' own laws (jaximpact._engines)
    "tsuji": dict(c=2e6, b=800.0),
    "tsuji_restitution": dict(c=2e6, e_nominal=0.8, m_eff=1.0),
    "spring_dashpot_restitution": dict(c=2e6, e_nominal=0.8, m_eff=1.0),
    "point_contact": dict(c=2e6, d=0.2),
    # laws with a contact state: plastic, adhesive
    "thornton": dict(c=2e6, x_y=1e-3),
    "jkr": dict(c=2e6, R=0.01, w=200.0),
    "jkr_viscoelastic": dict(c=2e6, b=800.0, R=0.01, w=200.0),
    "dmt": dict(c=2e6, b=800.0, R=0.01, w=200.0),
}
# laws whose every term carries a fractional power of x: no force at all outside contact
FRACTIONAL = ("hertz_rate", "hunt_crossley") + NOMINAL_LAWS


def sample_params(name):
    """Valid parameters for any law of `LAW_NAMES`."""
    for row_name, params, _, _ in PAPER_SETS:
        if row_name == name:
            return dict(params)
    if name in OTHER_LAWS:
        return dict(OTHER_LAWS[name])
    return dict(c=2e6, e_nominal=0.8)


def test_law_names_cover_the_paper_and_the_nominal_family():
    assert set(PAPER_LAWS) <= set(ji.LAW_NAMES)
    assert len(set(ji.LAW_NAMES)) == len(ji.LAW_NAMES)
    assert set(ji.LAWS) == set(ji.LAW_NAMES)
    # the Hunt-Crossley family with damping from a nominal restitution (Lankarani-Nikravesh, ...)
    assert {"lankarani_nikravesh", "flores", "gonthier", "hu_guo"} <= set(NOMINAL_LAWS)
    assert set(ji.LAW_NAMES) == set(PAPER_LAWS) | set(NOMINAL_LAWS) | set(OTHER_LAWS)


@pytest.mark.parametrize("name", ji.LAW_NAMES)
def test_law_builds_with_array_fields(name):
    params = sample_params(name)
    law = ji.law(name, **params)
    assert isinstance(law, ji.AbstractLaw)
    assert law.name == name
    assert set(law.parameters) == set(ji.LAWS[name].parameters)
    for key, value in params.items():
        # shape exponents given as numbers stay numpy arrays (still numbers under jax.jit,
        # where the curves need them); every other parameter is a JAX array
        kinds = (jax.Array, np.ndarray) if key in ji.LAWS[name].shape else jax.Array
        assert isinstance(law.parameters[key], kinds)
        assert float(law.parameters[key]) == value
        assert float(getattr(law, key)) == value  # attribute access by the paper's name
    # every parameter is an inexact array leaf, i.e. something optax can update
    leaves = jax.tree_util.tree_leaves(eqx.filter(law, eqx.is_inexact_array))
    assert len(leaves) == len(ji.LAWS[name].parameters)


def test_defaults_and_replace():
    law = ji.law("hunt_crossley", c=2e6, a=0.1)
    assert float(law.n) == 1.5
    other = law.replace(a=0.2)
    assert float(other.a) == 0.2 and float(other.c) == 2e6 and float(law.a) == 0.1
    with pytest.raises(ValueError, match="has no parameter b.*c, a, n"):
        law.replace(b=1.0)


def test_law_is_a_pytree_that_jit_and_vmap_accept():
    law = ji.law("hertz_rate", c=2e6, b1=800.0)
    force = jax.jit(lambda law_, x, v: law_.force(x, v))(law, 1e-3, 1.0)
    assert_rel(force, 2e6 * 1e-3**1.5 + 800.0 * 1e-3**0.5, 1e-14, "jit force")
    batch = jax.vmap(lambda c: ji.law("hertz_rate", c=c, b1=800.0).force(1e-3, 0.0))(
        jnp.array([1e6, 2e6])
    )
    assert_rel(batch, np.array([1e6, 2e6]) * 1e-3**1.5, 1e-14, "vmap force")


# ----------------------------------------------------------------------------- errors


def _one_line(excinfo):
    message = str(excinfo.value)
    assert "\n" not in message, message
    return message


def test_unknown_law_lists_the_names():
    with pytest.raises(ValueError) as excinfo:
        ji.law("kelvin_vogt", c=1.0, b=1.0)
    message = _one_line(excinfo)
    assert "kelvin_vogt" in message
    for name in ji.LAW_NAMES:
        assert name in message


def test_unknown_parameter_lists_the_accepted_ones():
    with pytest.raises(ValueError) as excinfo:
        ji.law("hertz_rate", c=2e6, b=800.0)
    message = _one_line(excinfo)
    assert "'b'" in message or " b;" in message or " b " in message, message
    assert "c, b1" in message


def test_missing_parameter_lists_the_accepted_ones():
    with pytest.raises(ValueError) as excinfo:
        ji.law("bingham", c=2e6, b=200.0)
    message = _one_line(excinfo)
    assert "needs P" in message and "c, b, P" in message


@pytest.mark.parametrize(
    "name, params, needle",
    [
        ("kelvin_voigt", dict(c=-2e6, b=400.0), "stiffness c must be a finite number > 0"),
        ("kelvin_voigt", dict(c=0.0, b=400.0), "stiffness c must be a finite number > 0"),
        ("hertz_rate", dict(c=float("nan"), b1=800.0), "stiffness c must be a finite number"),
        ("kelvin_voigt", dict(c=2e6, b=-1.0), "b must be a finite number >= 0"),
        ("bingham", dict(c=2e6, b=200.0, P=-1.0), "P must be a finite number >= 0"),
        ("hunt_crossley", dict(c=2e6, a=0.1, n=0.0), "exponent n must be a finite number > 0"),
        ("lankarani_nikravesh", dict(c=2e6, e_nominal=1.5), "e_nominal must lie in (0, 1]"),
        ("lankarani_nikravesh", dict(c=2e6, e_nominal=0.0), "e_nominal must lie in (0, 1]"),
    ],
)
def test_bad_values_are_a_clear_value_error(name, params, needle):
    with pytest.raises(ValueError) as excinfo:
        ji.law(name, **params)
    message = _one_line(excinfo)
    assert needle in message, message
    assert name in message


@pytest.mark.parametrize("c", [[1e6, 2e6], np.array([1e6, 2e6]), jnp.array([1e6, 2e6])])
def test_an_array_of_several_values_is_refused_at_once(c):
    """A parameter is one number: an array was accepted, then failed inside `impact`
    ("mul got incompatible shapes for broadcasting"); issue 34 item 7."""
    with pytest.raises(ValueError) as excinfo:
        ji.law("hertz_rate", c=c, b1=800.0)
    assert _one_line(excinfo) == (
        "law 'hertz_rate': c must be one number, got an array of shape (2,); "
        "for many values use jax.vmap or jaximpact.impact_batch"
    )
    with pytest.raises(ValueError, match="b1 must be one number, got an array of shape"):
        ji.law("hertz_rate", c=2e6, b1=800.0).replace(b1=[1.0, 2.0])


def test_a_bool_is_not_a_number():
    """`c=True` was taken as 1."""
    with pytest.raises(TypeError) as excinfo:
        ji.law("hertz_rate", c=True, b1=800.0)
    assert _one_line(excinfo) == "law 'hertz_rate': c must be a number, got True"
    with pytest.raises(TypeError, match="b1 must be a number, got"):
        ji.law("hertz_rate", c=2e6, b1=np.array(False))


def test_many_values_through_vmap_and_the_batches():
    """What the refusal points to: `jax.vmap` builds the law from traced scalars, and
    `impact_batch` takes the arrays as rows."""
    cs = jnp.array([1e6, 2e6])
    law_e = jax.vmap(lambda c: ji.impact(ji.law("hertz_rate", c=c, b1=800.0), m=1.0, v0=2.5).e)
    batch = ji.impact_batch("hertz_rate", {"c": cs, "b1": 800.0}, m=1.0, v0=2.5, progress=False)
    assert_rel(law_e(cs), batch["e"], 1e-12, "vmap vs impact_batch")


def test_bad_values_survive_jit():
    build = jax.jit(lambda c: ji.law("kelvin_voigt", c=c, b=400.0).force(1e-3, 0.0))
    assert_rel(build(2e6), 2e3, 1e-14, "jit-built law")
    with pytest.raises(Exception, match="stiffness c must be a finite number > 0"):
        jax.block_until_ready(build(-2e6))


def test_custom_law_errors():
    with pytest.raises(ValueError, match="function"):
        ji.custom_law(2.0, k=1.0)
    with pytest.raises(ValueError, match="parameters as keywords"):
        ji.custom_law(lambda x, v, p: x)
    law = ji.custom_law(lambda x, v, p: p["k"] * x, k=3.0)
    with pytest.raises(ValueError, match="no parameter d.*it has k"):
        law.replace(d=1.0)
    assert float(law.replace(k=4.0).force(2.0, 0.0)) == 8.0


def test_force_needs_what_it_needs():
    with pytest.raises(ValueError, match="Maxwell force is a state"):
        ji.law("maxwell", c=2e6, b=2000.0).force(1e-3, 1.0)
    with pytest.raises(ValueError, match="needs the impact speed"):
        ji.law("flores", c=2e6, e_nominal=0.8).force(1e-3, 1.0)


# ---------------------------------------------------------------- force values


XS = np.array([1e-9, 1e-6, 3e-4, 2e-3])
VS = np.array([-2.0, -1e-3, 1e-3, 2.5])


@pytest.mark.parametrize(
    "row",
    [row for row in PAPER_SETS if row[0] != "maxwell"],
    ids=[i for i, row in zip(PAPER_IDS, PAPER_SETS, strict=True) if row[0] != "maxwell"],
)
def test_force_matches_the_equation(row):
    name, params, _, _ = row
    law = ji.law(name, **params)
    for x in XS:
        for v in VS:
            expected = reference_force(name, params, x, v, 1 if v > 0 else -1)
            scale = abs(expected) + 1e-12 * float(params["c"])
            got = float(law.force(x, v))
            assert abs(got - expected) <= 1e-13 * scale, (name, x, v, got, expected)


def test_dry_force_follows_the_phase():
    law = ji.law("bingham", c=2e6, b=200.0, P=400.0)
    assert float(law.force(1e-3, 1.0)) == pytest.approx(2e3 + 200.0 + 400.0, rel=1e-14)
    assert float(law.force(1e-3, -1.0)) == pytest.approx(2e3 - 200.0 - 400.0, rel=1e-14)
    # at v = 0 the phase decides the sign of the dry force
    assert float(law.force(1e-3, 0.0, compressing=True)) == pytest.approx(2400.0, rel=1e-14)
    assert float(law.force(1e-3, 0.0, compressing=False)) == pytest.approx(1600.0, rel=1e-14)
    law9 = ji.law("bingham_compression", c=2e6, P=800.0)
    assert float(law9.force(1e-3, 1.0)) == pytest.approx(2800.0, rel=1e-14)
    assert float(law9.force(1e-3, -1.0)) == pytest.approx(2000.0, rel=1e-14)


def test_nominal_laws_damping_and_value():
    # Lankarani-Nikravesh: D = 3 (1 - e^2) / (4 v0)
    law = ji.law("lankarani_nikravesh", c=2e6, e_nominal=0.8, n=1.5)
    x, v, v0 = 1e-3, 1.2, 2.5
    damping = 3 * (1 - 0.8**2) / (4 * v0)
    assert_rel(law.force(x, v, v0=v0), 2e6 * x**1.5 * (1 + damping * v), 1e-14, "LN force")


def _force_and_gradient(law, x, v, **kwargs):
    value = law.force(x, v, **kwargs)
    dx, dv = jax.grad(lambda x_, v_: law.force(x_, v_, **kwargs), argnums=(0, 1))(x, v)
    dlaw = jax.grad(lambda law_: law_.force(x, v, **kwargs))(law)
    return value, dx, dv, dlaw


OUTSIDE = [0.0, -1e-300, -1e-12, -1e-3]


@pytest.mark.parametrize("name", FRACTIONAL)
@pytest.mark.parametrize("x", OUTSIDE)
def test_fractional_laws_vanish_outside_contact(name, x):
    """Zero force and zero gradient (in x, v and every parameter) for x <= 0, no NaN."""
    law = ji.law(name, **sample_params(name))
    for v in (-1.0, 0.0, 2.5):
        value, dx, dv, dlaw = _force_and_gradient(law, x, v, v0=2.5)
        assert float(value) == 0.0
        assert float(dx) == 0.0 and float(dv) == 0.0
        for key, grad in dlaw.parameters.items():
            assert float(grad) == 0.0, (name, key, x, v)


@pytest.mark.parametrize("name", ["hertz_viscous", "hertz_modified"])
@pytest.mark.parametrize("x", OUTSIDE)
def test_hertz_elastic_part_vanishes_outside_contact(name, x):
    """`c x^1.5` has zero value and slope for x <= 0; the integer-power damping of these
    laws is continued smoothly (`b v`, `b x v`), so only v = 0 gives zero force."""
    law = ji.law(name, **sample_params(name))
    value, dx, dv, dlaw = _force_and_gradient(law, x, 0.0)
    assert float(value) == 0.0 and float(dx) == 0.0
    assert float(dlaw.c) == 0.0
    assert_finite((dv, dlaw), name)


@pytest.mark.parametrize("name", [n for n in ji.LAW_NAMES if n != "maxwell"])
def test_gradients_are_finite_at_first_touch(name):
    """At x = 0 (where every contact starts and ends) no NaN reaches a gradient, even
    with zero damping, where `x^0.5` would have an infinite slope."""
    params = sample_params(name)
    for key in ("b", "b1", "a"):
        if key in params:
            params[key] = 0.0
    law = ji.law(name, **params)
    for x in (0.0, 1e-30, 1e-6):
        assert_finite(_force_and_gradient(law, x, 1.0, v0=2.5), f"{name} at x={x}")


def test_fractional_force_slope_at_small_penetration():
    law = ji.law("hertz_rate", c=2e6, b1=800.0)
    x, v = 1e-6, 0.5
    dx = jax.grad(lambda x_: law.force(x_, v))(x)
    assert_rel(dx, 1.5 * 2e6 * x**0.5 + 0.5 * 800.0 * x**-0.5 * v, 1e-13, "dF/dx")


# ------------------------------------------------------------------------- safe_pow


@pytest.mark.parametrize("p", [0.5, 1.5, 2.5, 1.0, 0.25])
def test_safe_pow_values_and_gradients(p):
    xs = jnp.array([-1.0, -1e-300, 0.0, 1e-300, 1e-8, 0.3, 4.0])
    values = ji.safe_pow(xs, p)
    expected = np.where(np.asarray(xs) > 0, np.maximum(np.asarray(xs), 0) ** p, 0.0)
    np.testing.assert_allclose(values, expected, rtol=1e-14, atol=0)
    grad_x = jax.vmap(jax.grad(lambda x: ji.safe_pow(x, p)))(xs)
    grad_p = jax.vmap(jax.grad(lambda q, x: ji.safe_pow(x, q)), in_axes=(None, 0))(p, xs)
    hess = jax.vmap(jax.hessian(lambda x: ji.safe_pow(x, p)))(xs)
    assert_finite((grad_x, grad_p), f"safe_pow gradient, p={p}")
    outside = np.asarray(xs) <= 0
    assert np.all(np.asarray(grad_x)[outside] == 0.0)
    assert np.all(np.asarray(grad_p)[outside] == 0.0)
    assert np.all(np.asarray(hess)[outside] == 0.0)
    inside = np.asarray(xs) >= 1e-8
    x_in = np.asarray(xs)[inside]
    np.testing.assert_allclose(np.asarray(grad_x)[inside], p * x_in ** (p - 1), rtol=1e-13)
    np.testing.assert_allclose(
        np.asarray(grad_p)[inside], x_in**p * np.log(x_in), rtol=1e-13, atol=1e-300
    )


def test_safe_pow_under_jit_and_forward_mode():
    f = jax.jit(jax.jacfwd(lambda x: ji.safe_pow(x, 0.5)))
    assert float(f(0.0)) == 0.0 and float(f(-2.0)) == 0.0
    assert_rel(f(4.0), 0.25, 1e-15, "d sqrt(x)/dx at 4")
