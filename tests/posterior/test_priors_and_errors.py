"""Priors: each kind's coordinate map and normalised density; bad input to `posterior`
refused with one clear line."""

import jax.numpy as jnp
import numpy as np
import pytest

import jaximpact as ji
from jaximpact._posterior.priors import default_prior, parse_prior

KINDS = [
    ("loguniform", 1e3, 1e7),
    ("uniform", 0.2, 0.9),
    ("normal", 5.0, 2.0),
    ("lognormal", 1.0, 0.5),
]


@pytest.mark.parametrize("spec", KINDS, ids=lambda s: s[0])
def test_density_of_z_is_normalised_and_maps_back(spec):
    prior = parse_prior("c", spec)
    z = np.linspace(-40.0, 40.0, 200_001)
    density = np.exp(np.asarray(prior.log_density(jnp.asarray(z))))
    assert np.trapezoid(density, z) == pytest.approx(1.0, abs=1e-9)
    x = np.asarray(prior.value(jnp.asarray([-1.3, 0.0, 2.1])))
    np.testing.assert_allclose(prior.coordinate(x), [-1.3, 0.0, 2.1], atol=1e-9)


@pytest.mark.parametrize("spec", KINDS[:2], ids=lambda s: s[0])
def test_bounded_priors_stay_inside_their_range(spec):
    prior = parse_prior("c", spec)
    x = np.asarray(prior.value(jnp.asarray([-30.0, 30.0])))
    assert spec[1] <= x[0] <= x[1] <= spec[2]


def test_loguniform_is_uniform_in_the_logarithm():
    """`u = sigmoid(z)` is the prior's CDF: x = lo (hi/lo)^u."""
    prior = parse_prior("c", ("loguniform", 1e2, 1e6))
    u = np.linspace(0.01, 0.99, 9)
    x = np.asarray(prior.value(jnp.asarray(np.log(u) - np.log1p(-u))))
    np.testing.assert_allclose(x, 1e2 * 1e4**u, rtol=1e-12)


def test_default_prior():
    assert default_prior("b1", 800.0).as_tuple() == ("loguniform", 0.8, 800_000.0)
    assert default_prior("e_nominal", 0.7).as_tuple() == ("uniform", 0.0, 1.0)


@pytest.mark.parametrize(
    "prior, message",
    [
        ({"c": ("gaussian", 1.0, 2.0)}, "unknown prior kind 'gaussian' for 'c'"),
        ({"c": ("loguniform", 1e8, 1e5)}, "lo must be < hi"),
        ({"c": ("uniform", 3.0, 3.0)}, "lo must be < hi"),
        ({"c": ("loguniform", 0.0, 1e5)}, "loguniform needs 0 < lo"),
        ({"c": ("normal", 1.0, -1.0)}, "spread of a normal must be > 0"),
        ({"c": ("loguniform", 1e5)}, "must be (kind, a, b)"),
        ({"zeta": ("loguniform", 1.0, 2.0)}, "has no parameter 'zeta'"),
        ({"sigma_e": ("loguniform", 1e-3, 1.0)}, "sigma_e was given to calibrate"),
    ],
)
def test_bad_priors_raise_one_line(weighted_fit, prior, message):
    with pytest.raises(ValueError) as error:
        ji.posterior(weighted_fit, prior=prior, method="laplace")
    assert message in str(error.value) and "\n" not in str(error.value)


def test_bad_options_raise_one_line(weighted_fit):
    for kwargs, message in [
        ({"method": "mcmc"}, "method must be 'nuts' or 'laplace'"),
        ({"noise": "cauchy"}, "noise must be 'normal' or 'student_t'"),
        ({"num_samples": 0}, "num_samples must be an integer >= 1"),
        ({"prior": [("c", 1)]}, "prior takes a dict"),
    ]:
        with pytest.raises((ValueError, TypeError), match=message):
            ji.posterior(weighted_fit, **kwargs)


def test_a_prior_on_a_held_parameter_is_refused():
    law = ji.law("hunt_crossley", c=2e6, a=0.2)
    fit = ji.calibrate(law, m=1.0, v0=[1.0, 2.0], e=[0.8, 0.7], free=("a",))
    with pytest.raises(ValueError, match="'c' is held fixed|c is held fixed by this fit"):
        ji.posterior(fit, prior={"c": ("loguniform", 1e5, 1e7)}, method="laplace")


def test_unsupported_fits_are_a_type_error():
    with pytest.raises(TypeError, match="posterior takes the result of calibrate"):
        ji.posterior(ji.law("hertz_rate", c=2e6, b1=800.0))
