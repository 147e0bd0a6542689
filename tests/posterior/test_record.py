"""The `Posterior` record: statistics, text, dicts, bands and the figure; the noise scale
as a parameter where no sigma was given; Student-t noise."""

import json

import jax
import numpy as np
import pytest
from posterior_data import M, START, TRUTH, synthetic

import jaximpact as ji


def test_laplace_agrees_with_the_fit(weighted_fit, laplace_post):
    """The mode is the fit (a flat prior in ln c, ln b1 up to its Jacobian, small here)
    and the spread its Jacobian standard errors (a Gaussian in ln theta)."""
    post = laplace_post
    for k in ("c", "b1"):
        value, se = float(weighted_fit.params[k]), float(weighted_fit.stderr[k])
        assert post.map[k] == pytest.approx(value, abs=0.01 * se)
        assert np.std(np.log(post.samples[k])) == pytest.approx(se / value, rel=0.05)
    assert np.isfinite(post.log_evidence)


def test_statistics(laplace_post):
    post = laplace_post
    assert set(post.samples) == {"c", "b1"}
    assert post.samples["c"].shape == (8000,)
    lo, hi = post.interval(0.9)["c"]
    assert lo < post.median["c"] < hi
    inside = (post.samples["c"] > lo) & (post.samples["c"] < hi)
    assert np.mean(inside) == pytest.approx(0.9, abs=0.01)
    for k, v in TRUTH.items():  # the truth inside the 99.9 % interval
        lo, hi = post.interval(0.999)[k]
        assert lo < v < hi
    with pytest.raises(ValueError, match="level must lie in"):
        post.interval(90)


def test_text_and_dicts(laplace_post):
    post = laplace_post
    text = post.summary()
    assert "N/m^1.5" in text and "90 %" in text and "log_evidence" in text
    assert repr(post) == text
    data = json.loads(json.dumps(post.to_dict()))
    assert data["median"]["c"] == pytest.approx(post.median["c"])
    again = ji.Posterior.from_dict(data)
    for k, (lo, hi) in post.interval(0.9).items():
        assert again.interval(0.9)[k] == pytest.approx((lo, hi))
    assert again.log_evidence == pytest.approx(post.log_evidence)
    with pytest.raises(ValueError, match="no forward model"):
        again.predict(v0=1.0)
    assert "samples" not in post.to_dict(samples=False)


def test_bands(weighted_fit, laplace_post):
    post = laplace_post
    v0 = np.asarray(weighted_fit.v0)
    law = post.predict(v0=v0)
    assert np.all(law.e_lo < law.e) and np.all(law.e < law.e_hi)
    truth = ji.law("hertz_rate", **TRUTH)
    r = jax.vmap(lambda v: ji.impact(truth, m=M, v0=v))(v0)
    # the law's band holds the true law at most speeds (a 90 % band, correlated)
    inside = (law.e_lo <= np.asarray(r.e)) & (np.asarray(r.e) <= law.e_hi)
    assert np.mean(inside) >= 0.5
    new = post.predict(v0=v0, observed=True)  # a new measurement's band: wider, noise added
    assert np.all(new.e_hi - new.e_lo > law.e_hi - law.e_lo)
    # the observed band holds about 90 % of new measurements of the true law
    fresh = np.asarray(r.e) + 0.01 * np.random.default_rng(7).normal(size=(2000, v0.size))
    held = (new.e_lo <= fresh) & (fresh <= new.e_hi)
    assert 0.85 <= np.mean(held) <= 0.95
    assert json.dumps(law.to_dict()) and "v0" in law.summary()
    with pytest.raises(ValueError, match="v0 must be finite speeds"):
        post.predict(v0=-1.0)


def test_plot(laplace_post, tmp_path):
    path = tmp_path / "post.png"
    fig = laplace_post.plot(path)
    assert path.stat().st_size > 10_000
    assert len(fig.axes) == 5  # 3 pairs panels, the e and T bands


@pytest.fixture(scope="module")
def unweighted_fit():
    """No sigmas: e scattered by 0.01 and T by 2 % of about 10 ms (0.2 ms)."""
    v0 = np.linspace(0.5, 3.0, 12)
    e, T, _ = synthetic(v0, 0.01, 0.02, seed=5)
    return ji.calibrate(START, m=M, v0=v0, e=e, T=T)


def test_noise_scale_is_a_parameter_without_sigmas(unweighted_fit):
    post = ji.posterior(unweighted_fit, method="laplace", key=jax.random.key(3))
    assert post.names == ("c", "b1", "sigma_e", "sigma_T")
    assert post.units["sigma_T"] == "s"
    lo, hi = post.interval(0.99)["sigma_e"]
    assert lo < 0.01 < hi
    lo, hi = post.interval(0.99)["sigma_T"]
    assert lo < 0.02 * np.median(unweighted_fit.T_target) < hi
    assert post.priors["sigma_e"] == ("loguniform", 1e-4, 0.5)


@pytest.mark.slow
def test_student_t_is_robust_to_an_outlier():
    """One e off by 0.2 (20 sigma): the normal likelihood's median of b1 moves by several
    of its standard deviations, Student-t's much less."""
    v0 = np.linspace(0.5, 3.0, 10)
    e, T, s_T = synthetic(v0, 0.01, 0.02, seed=3)
    e_bad = e.copy()
    e_bad[4] -= 0.2
    clean = ji.calibrate(START, m=M, v0=v0, e=e, T=T, sigma_e=0.01, sigma_T=s_T)
    bad = ji.calibrate(START, m=M, v0=v0, e=e_bad, T=T, sigma_e=0.01, sigma_T=s_T)
    ref = ji.posterior(clean, method="laplace")
    shift = {}
    for noise in ("normal", "student_t"):
        post = ji.posterior(bad, method="laplace", noise=noise, nu=3.0)
        shift[noise] = abs(np.log(post.median["b1"] / ref.median["b1"])) / np.std(
            np.log(ref.samples["b1"])
        )
    assert shift["normal"] > 3.0 and shift["student_t"] < 0.5 * shift["normal"]


@pytest.mark.parametrize("d", [1, 2])
def test_diagnostics_per_parameter_with_one_parameter_too(d):
    """NUTS's diagnostics, one r_hat and ESS per parameter, also for a single free
    parameter (blackjax returns a 0-d array there: a fit of b1 alone raised IndexError)."""
    from jaximpact._posterior.nuts import Chains, diagnostics

    z = jax.random.normal(jax.random.key(0), (4, 400, d))
    names = ["b1", "c"][:d]
    diag = diagnostics(Chains(z, np.zeros((4, 400), bool), np.ones((4, 400))), names)
    assert set(diag["r_hat_by_parameter"]) == set(names)
    assert all(0.98 < r < 1.02 for r in diag["r_hat_by_parameter"].values())
    assert all(e > 800 for e in diag["ess_by_parameter"].values())  # 1,600 independent draws
