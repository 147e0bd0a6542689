"""`posterior` of a `fit_oblique` fit: the Laplace approximation against the fit's own
standard errors, NUTS against Laplace, the truth inside the 90 % intervals, bands of e_t
and the spin at new incidence angles that hold the noiseless curves, the next angle to
measure, the noise scales sampled without sigmas, and one-line refusals.

Synthetic rebounds: a 5 mm alumina sphere (Hertz with a little damping) at 3.9 m/s and six
incidence angles from 5 to 50 degrees, its tangential law `linear_history` with kt = 5e7
N/m and mu = 0.15 (sticking, micro-slip and sliding among the rows), e_t with noise 0.01
and the spin with noise 15 rad/s. One module fit and its posteriors serve every slow test
(compiling the oblique solve and its derivatives dominates: a minute per program on two
cores); the fast tests need no fit."""

import json
import warnings

import jax
import numpy as np
import pytest

import jaximpact as ji
from jaximpact._oblique.fit import ObliqueFit
from jaximpact._posterior.posterior import PosteriorWarning

E, NU, RHO, R = 380e9, 0.23, 4000.0, 2.5e-3
M = RHO * 4.0 / 3.0 * np.pi * R**3
LAW = ji.law("hunt_crossley", c=4.0 / 3.0 * E / (1 - NU**2) * np.sqrt(R), a=0.01)
TRUTH = {"kt": 5e7, "mu": 0.15}
SPEED = 3.9  # m/s
ANGLES = np.deg2rad([5.0, 10.0, 16.0, 24.0, 35.0, 50.0])
SIGMA_E_T, SIGMA_OMEGA = 0.01, 15.0  # e_t, rad/s
NEW = np.deg2rad([7.0, 20.0, 42.0])  # angles of the bands


def rebounds(angles):
    """e_t and the spin after (rad/s) of the true law at `angles` (rad), noiseless."""
    law = ji.tangential_law("linear_history", **TRUTH)
    v_n, v_t = (np.asarray(v) for v in ji.incidence(SPEED, angles))
    r = jax.vmap(lambda a, b: ji.oblique_impact(LAW, law, m=M, R=R, v_n=a, v_t=b))(v_n, v_t)
    return v_n, v_t, np.asarray(r.e_t), np.asarray(r.omega_out)


@pytest.fixture(scope="module")
def data():
    v_n, v_t, e_t, omega = rebounds(ANGLES)
    rng = np.random.default_rng(9)
    e_t = e_t + SIGMA_E_T * rng.normal(size=e_t.size)
    omega = omega + SIGMA_OMEGA * rng.normal(size=omega.size)
    return dict(m=M, R=R, v_n=v_n, v_t=v_t, e_t=e_t, omega_out=omega)


def fit_of(data, **sigmas):
    start = ji.tangential_law("linear_history", kt=3e7, mu=0.2)
    return ji.fit_oblique(LAW, start, **data, **sigmas, start_scan=0, max_starts=1)


@pytest.fixture(scope="module")
def fit(data):
    return fit_of(data, sigma_e_t=SIGMA_E_T, sigma_omega=SIGMA_OMEGA)


@pytest.fixture(scope="module")
def oblique_laplace(fit):
    return ji.posterior(fit, method="laplace", key=jax.random.key(0))


@pytest.fixture(scope="module")
def oblique_nuts(fit, oblique_laplace):  # after Laplace: its compiled mode search is reused
    with warnings.catch_warnings():  # short chains: judged by the test, not the warning
        warnings.simplefilter("ignore", PosteriorWarning)
        return ji.posterior(
            fit, method="nuts", num_warmup=100, num_samples=150, chains=2, key=jax.random.key(1)
        )


# ---------------------------------------------------------------------- fast


def test_a_fit_without_its_rebounds_is_a_one_line_type_error():
    fit = object.__new__(ObliqueFit)  # an ObliqueFit that keeps no data
    with pytest.raises(TypeError, match="keeps no rebounds") as info:
        ji.posterior(fit)
    assert "fit_oblique" in str(info.value) and "\n" not in str(info.value)


def test_a_calibration_posterior_takes_speeds_not_angles(laplace_post):
    post = laplace_post  # conftest's: a calibration's
    for call in (
        lambda: post.predict(angle=NEW),
        lambda: post.predict(v0=[1.0], speed=2.0),
        lambda: ji.next_measurement(post, angle=NEW),
    ):
        with pytest.raises(ValueError, match="for the posterior of an oblique fit") as info:
            call()
        assert "\n" not in str(info.value)
    with pytest.raises(ValueError, match=r"predict needs the impact speeds"):
        post.predict()


# ---------------------------------------------------------------------- slow


@pytest.mark.slow
def test_the_fit_keeps_what_it_was_made_of(fit, data):
    problem = fit.problem
    np.testing.assert_array_equal(np.asarray(problem.v_n), data["v_n"])
    np.testing.assert_array_equal(np.asarray(problem.e_t), data["e_t"])
    np.testing.assert_array_equal(np.asarray(problem.omega_out), data["omega_out"])
    assert problem.law is LAW and problem.free == ("kt", "mu")
    assert np.all(np.asarray(fit.sigma_e_t) == SIGMA_E_T)
    assert np.all(np.asarray(fit.sigma_omega) == SIGMA_OMEGA)
    assert bool(fit.converged)


@pytest.mark.slow
def test_laplace_is_the_fit_and_its_standard_errors(fit, oblique_laplace):
    """With the sigmas given, the mode is the fit and the Gauss-Newton spread in ln kt,
    ln mu is the fit's Jacobian standard errors (relative)."""
    post = oblique_laplace
    assert post.names == ("kt", "mu") and post.free == ("kt", "mu")
    assert post.law_name == "linear_history" and post.units == {"kt": "N/m", "mu": ""}
    for k in ("kt", "mu"):
        value, se = float(fit.params[k]), float(fit.stderr[k])
        assert post.map[k] == pytest.approx(value, abs=0.01 * se)
        assert np.std(np.log(post.samples[k])) == pytest.approx(se / value, rel=0.05)
    assert np.isfinite(post.log_evidence)


@pytest.mark.slow
@pytest.mark.very_slow  # NUTS through oblique solves: 7.6 minutes (run with -m very_slow)
def test_nuts_agrees_with_laplace_and_holds_the_truth(oblique_laplace, oblique_nuts):
    """Near-Gaussian (in ln kt, ln mu): the medians agree within 0.25 posterior standard
    deviations (measured: within 0.05), the 90 % intervals of both hold the truth."""
    d = oblique_nuts.diagnostics
    assert d["divergences"] == 0 and d["r_hat"] < 1.1 and d["ess"] > 50
    for k, truth in TRUTH.items():
        sd = np.std(np.log(oblique_laplace.samples[k]))
        off = abs(np.log(oblique_nuts.median[k]) - np.log(oblique_laplace.median[k])) / sd
        assert off < 0.25, (k, off)
        for post in (oblique_laplace, oblique_nuts):
            lo, hi = post.interval(0.9)[k]
            assert lo < truth < hi, (post.method, k, lo, truth, hi)


@pytest.mark.slow
@pytest.mark.very_slow  # NUTS through oblique solves: 7.6 minutes (run with -m very_slow)
def test_bands_at_new_angles_hold_the_noiseless_curves(oblique_nuts):
    bands = oblique_nuts.predict(angle=NEW, max_draws=200)
    _, _, e_t, omega = rebounds(NEW)
    assert bands.speed == pytest.approx(SPEED) and bands.omega == 0.0 and bands.draws == 200
    assert np.all(bands.e_t_lo < e_t) and np.all(e_t < bands.e_t_hi)
    assert np.all(bands.omega_out_lo < omega) and np.all(omega < bands.omega_out_hi)
    assert np.all(bands.e_t_hi - bands.e_t_lo < 4 * SIGMA_E_T)  # the law is known better
    assert np.all((bands.angle_out_lo <= bands.angle_out) & (bands.angle_out < NEW))
    seen = oblique_nuts.predict(angle=NEW, max_draws=200, observed=True)
    assert np.all(seen.e_t_hi - seen.e_t_lo > bands.e_t_hi - bands.e_t_lo)
    assert np.all(seen.e_t_hi - seen.e_t_lo > 3 * SIGMA_E_T)  # a new measurement's noise
    assert "deg" in bands.summary() and json.dumps(bands.to_dict())


@pytest.mark.slow
def test_next_measurement_ranks_angles(oblique_laplace):
    candidates = np.deg2rad([3.0, 12.0, 30.0, 60.0, 75.0])
    nm = ji.next_measurement(oblique_laplace, angle=candidates)
    assert sorted(nm.angle) == sorted(candidates) and nm.over == "angle"
    assert np.all(np.diff(nm.gain) <= 0) and nm.gain[-1] > 0
    assert nm.measure == ("e_t", "omega_out")
    alone = ji.next_measurement(oblique_laplace, angle=candidates, measure=("e_t",))
    assert alone.measure == ("e_t",)
    by_angle = dict(zip(nm.angle, nm.gain, strict=True))
    for a, g in zip(alone.angle, alone.gain, strict=True):
        assert g <= by_angle[a] + 1e-12  # e_t alone teaches no more than e_t and the spin
    assert "deg" in nm.summary() and nm.to_dict()["angle"][0] == nm.angle[0]


@pytest.mark.slow
def test_wrong_keywords_and_priors_are_one_line_errors(fit, oblique_laplace):
    post = oblique_laplace
    for call, message in (
        (lambda: post.predict(v0=[1.0]), "predicts at incidence angles"),
        (lambda: post.predict(), "takes incidence angles: angle="),
        (lambda: post.predict(angle=[30.0]), r"radians in \(0, pi/2\)"),
        (lambda: post.predict(angle=NEW, speed=-1.0), "speed must be > 0"),
        (lambda: ji.next_measurement(post, v0=[1.0]), "ranks incidence angles"),
        (lambda: ji.next_measurement(post, angle=NEW, measure=("e",)), "measure takes 'e_t'"),
        (
            lambda: ji.posterior(fit, prior={"ct": ("uniform", 0.0, 1.0)}),
            "ct is held fixed by this fit",
        ),
        (
            lambda: ji.posterior(fit, prior={"sigma_e_t": ("uniform", 0.0, 1.0)}),
            "sigma_e_t was given to fit_oblique",
        ),
        (lambda: ji.posterior(fit, prior={"kn": ("uniform", 0.0, 1.0)}), "sampled: kt, mu"),
    ):
        with pytest.raises(ValueError, match=message) as info:
            call()
        assert "\n" not in str(info.value)


@pytest.mark.slow
def test_record_dict_and_plot(oblique_laplace, tmp_path):
    post = oblique_laplace
    text = post.summary()
    assert "linear_history" in text and "kt" in text and "90 %" in text
    again = ji.Posterior.from_dict(json.loads(json.dumps(post.to_dict())))
    law = again.law_at()  # the tangential law, rebuilt by name
    assert law.name == "linear_history"
    assert float(law.params["kt"]) == pytest.approx(post.median["kt"])
    assert post.median_law.params["mu"] == pytest.approx(post.median["mu"])
    path = tmp_path / "oblique_posterior.png"
    post.plot(path, angle=NEW)
    assert path.stat().st_size > 5_000


@pytest.mark.slow
def test_the_noise_scales_are_sampled_without_sigmas(data):
    """Without sigmas, `sigma_e_t` and `sigma_omega` are sampled beside kt and mu; the
    truth of all four inside their 90 % intervals (Laplace)."""
    fit = fit_of(data)
    post = ji.posterior(fit, method="laplace", key=jax.random.key(2))
    assert post.names == ("kt", "mu", "sigma_e_t", "sigma_omega")
    assert post.units["sigma_omega"] == "rad/s" and post.units["sigma_e_t"] == ""
    lo, hi = post.priors["sigma_omega"][1:]
    assert hi == pytest.approx(0.5 * np.max(np.abs(data["omega_out"])))
    truth = {**TRUTH, "sigma_e_t": SIGMA_E_T, "sigma_omega": SIGMA_OMEGA}
    for k, value in truth.items():
        lo, hi = post.interval(0.9)[k]
        assert lo < value < hi, (k, lo, value, hi)
