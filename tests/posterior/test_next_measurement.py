"""`next_measurement`: the best-ranked candidate shrinks the posterior more than the
median-ranked one does, once measured."""

import jax
import numpy as np
import pytest
from posterior_data import M, START, TRUTH, synthetic

import jaximpact as ji


def _spread(post):
    """The posterior's generalised variance in ln c, ln b1: det of their covariance."""
    z = np.log(np.stack([post.samples["c"], post.samples["b1"]]))
    return np.linalg.det(np.cov(z))


@pytest.fixture(scope="module")
def narrow():
    """Five speeds between 0.5 and 1 m/s: the candidates far from them teach more
    (measured: gains from 0.16 nats at 0.3 m/s to 0.26 at 8 m/s, realised 0.16 to 0.27)."""
    v0 = np.linspace(0.5, 1.0, 5)
    e, T, s_T = synthetic(v0, 0.01, 0.02, seed=11)
    fit = ji.calibrate(START, m=M, v0=v0, e=e, T=T, sigma_e=0.01, sigma_T=s_T)
    return fit, ji.posterior(fit, method="laplace", key=jax.random.key(0))


@pytest.mark.slow
def test_the_best_candidate_shrinks_the_posterior_most(narrow):
    fit, post = narrow
    candidates = np.linspace(0.3, 8.0, 9)
    nm = ji.next_measurement(post, v0=candidates)
    assert sorted(nm.v0) == sorted(candidates)
    assert np.all(np.diff(nm.gain) <= 0) and nm.gain[0] > 0
    assert nm.measure == ("e", "T")
    truth = ji.law("hertz_rate", **TRUTH)
    spread = {}
    for which, speed in (("best", nm.v0[0]), ("median", nm.v0[len(candidates) // 2])):
        r = ji.impact(truth, m=M, v0=float(speed))
        v0 = np.append(fit.v0, speed)
        e = np.append(fit.e_target, float(r.e))
        T = np.append(fit.T_target, float(r.T))
        s_T = np.append(fit.sigma_T, 0.02 * float(r.T))
        more = ji.calibrate(START, m=M, v0=v0, e=e, T=T, sigma_e=0.01, sigma_T=s_T)
        spread[which] = _spread(ji.posterior(more, method="laplace", key=jax.random.key(1)))
    before = _spread(post)
    assert spread["best"] < spread["median"] < before
    # the gain predicted is the shrinkage realised, 1/2 ln(det before / det after)
    realised = 0.5 * np.log(before / spread["best"])
    assert realised == pytest.approx(nm.gain[0], rel=0.15)
    assert "gain" in nm.summary() and nm.to_dict()["v0"][0] == nm.v0[0]


def test_ranking_and_bad_candidates(laplace_post):
    post = laplace_post
    nm = ji.next_measurement(post, v0=[0.2, 1.0, 6.0], measure=("e",))
    assert np.all(np.diff(nm.gain) <= 0) and nm.measure == ("e",)
    with pytest.raises(ValueError, match="candidate speeds > 0"):
        ji.next_measurement(post, v0=[1.0, -2.0])
    with pytest.raises(ValueError, match="measure takes"):
        ji.next_measurement(post, v0=[1.0], measure=("x_max",))
