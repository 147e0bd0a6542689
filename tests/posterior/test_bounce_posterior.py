"""`posterior` of a `fit_bounces` fit (impact times): the Laplace approximation against the
fit's own estimates and standard errors, bands of single impacts, refusals, the command
line (`jaximpact fit --posterior`); slow: NUTS against Laplace, the noise scale sampled.

One module-scope fit and Laplace posterior serve the fast tests: a golf ball's eight
impact times (hertz_rate, b1 free) with 1 ms timing noise, sigma given."""

import json
import warnings

import jax
import numpy as np
import pytest
from helpers import run_cli

import jaximpact as ji
from jaximpact._posterior.posterior import PosteriorWarning
from jaximpact._solve.bounce import bounce

GOLF_M = 0.0415  # kg
NOISE = 1e-3  # s
START = ji.law("hertz_rate", c=5.5e7, b1=100.0)


def golf_times(seed=0):
    b = bounce(ji.law("hertz_rate", c=5.5e7, b1=700.0), m=GOLF_M, h0=0.9, t_end=6.0, max_impacts=16)
    times = np.asarray(b.impact_times[:8]) + 1.234
    return times + np.random.default_rng(seed).normal(0.0, NOISE, times.size)


@pytest.fixture(scope="module")
def times():
    return golf_times()


@pytest.fixture(scope="module")
def golf_fit(times):
    return ji.fit_bounces(START, m=GOLF_M, impact_times=times, sigma=NOISE)


@pytest.fixture(scope="module")
def golf_post(golf_fit):
    return ji.posterior(golf_fit, method="laplace", key=jax.random.key(0))


def test_laplace_agrees_with_the_fit(golf_fit, golf_post):
    """The mode is the fit and the spread its Jacobian standard errors: b1 as a Gaussian
    in ln b1, the nuisance (first impact's time and speed) in its own units."""
    post = golf_post
    assert post.names == ("b1", "t_impact", "v_impact")  # sigma was given: not sampled
    assert post.free == ("b1",)
    value, se = golf_fit.params["b1"], golf_fit.stderr["b1"]
    assert post.map["b1"] == pytest.approx(value, abs=0.01 * se)
    assert np.std(np.log(post.samples["b1"])) == pytest.approx(se / value, rel=0.05)
    for k in ("t_impact", "v_impact"):
        value, se = golf_fit.nuisance[k], golf_fit.stderr[k]
        assert post.map[k] == pytest.approx(value, abs=0.01 * se)
        assert np.std(post.samples[k]) == pytest.approx(se, rel=0.05)
    lo, hi = post.interval(0.999)["b1"]
    assert lo < 700.0 < hi  # the truth
    assert np.isfinite(post.log_evidence)


def test_record_text_and_dict(golf_post):
    post = golf_post
    text = post.summary()
    assert "t_impact" in text and "v_impact" in text and "90 %" in text
    assert post.units["t_impact"] == "s" and post.units["v_impact"] == "m/s"
    data = json.loads(json.dumps(post.to_dict()))
    again = ji.Posterior.from_dict(data)
    assert again.interval(0.9)["b1"] == pytest.approx(post.interval(0.9)["b1"])
    assert post.median_law.params["b1"] == pytest.approx(post.median["b1"])


def test_bands_of_single_impacts(golf_post):
    """The law's e and T at new speeds: a narrow band about the true law's."""
    bands = golf_post.predict(v0=[1.0, 4.0])
    assert np.all(bands.e_lo <= bands.e) and np.all(bands.e <= bands.e_hi)
    truth = ji.law("hertz_rate", c=5.5e7, b1=700.0)
    for k, v in enumerate((1.0, 4.0)):
        r = ji.impact(truth, m=GOLF_M, v0=v, g=9.81)
        assert abs(float(r.e) - bands.e[k]) < 0.01
    with pytest.raises(ValueError, match="measured neither"):
        golf_post.predict(v0=1.0, observed=True)
    with pytest.raises(ValueError, match="not of a bounce fit"):
        ji.next_measurement(golf_post, v0=[1.0, 2.0])


def test_bad_priors_and_unsupported_fits(golf_fit):
    with pytest.raises(ValueError, match="sigma was given to fit_bounces"):
        ji.posterior(golf_fit, prior={"sigma": ("loguniform", 1e-5, 1e-2)})
    with pytest.raises(ValueError, match="'c' is held fixed|c is held fixed by this fit"):
        ji.posterior(golf_fit, prior={"c": ("loguniform", 1e6, 1e9)})
    with pytest.raises(ValueError, match="not a parameter of this bounce fit"):
        ji.posterior(golf_fit, prior={"floor": ("uniform", 0.0, 1.0)})
    with pytest.raises(TypeError, match=r"posterior takes one fit.*one fit per drop"):
        ji.posterior([golf_fit, golf_fit])
    with pytest.raises(TypeError, match="calibrate .* or of fit_bounces"):
        ji.posterior({"b1": 1.0})


def test_oblique_fits_are_a_one_line_type_error():
    from jaximpact._oblique.fit import ObliqueFit

    fit = object.__new__(ObliqueFit)  # the type alone decides
    with pytest.raises(TypeError, match="fit_oblique results are not supported") as info:
        ji.posterior(fit)
    assert "\n" not in str(info.value)


def test_cli_fit_posterior(capsys, tmp_path, times, golf_post):
    """`jaximpact fit --posterior laplace --json`: the posterior's record per drop, the
    same as the library's (the same fit, so the same compiled model)."""
    path = tmp_path / "impacts.csv"
    path.write_text("t\n" + "\n".join(repr(float(t)) for t in times) + "\n")
    argv = [
        "fit",
        str(path),
        "--law",
        "hertz_rate",
        "--param",
        "c=5.5e7",
        "b1=100",
        "--mass",
        str(GOLF_M),
        "--sigma",
        str(NOISE),
        "--posterior",
        "laplace",
    ]
    code, out, _ = run_cli(capsys, argv + ["--json"])
    assert code == 0
    data = json.loads(out)
    (record,) = data["fits"].values()
    post = record["posterior"]
    assert post["method"] == "laplace" and set(post["names"]) == {"b1", "t_impact", "v_impact"}
    assert post["median"]["b1"] == pytest.approx(golf_post.median["b1"], rel=1e-3)
    assert len(post["samples"]["b1"]) == 200
    code, out, _ = run_cli(capsys, argv)
    assert code == 0 and "Posterior of hertz_rate (laplace" in out and "90 %" in out


def test_cli_fit_posterior_bad_input_is_one_line(capsys, tmp_path):
    path = tmp_path / "impacts.csv"
    path.write_text("t\n0.0\n0.5\n0.9\n1.2\n")
    argv = [
        "fit",
        str(path),
        "--law",
        "hertz_rate",
        "--param",
        "c=2e6",
        "b1=800",
        "--mass",
        "1",
        "--prior",
        "b1=loguniform:1:1e4",
    ]
    code, out, err = run_cli(capsys, argv)
    assert code == 2 and "--prior need --posterior" in err and len(err.strip().splitlines()) == 1


# ---------------------------------------------------------------------- slow


@pytest.mark.slow
@pytest.mark.very_slow  # 3 minutes of NUTS (run with -m very_slow); NUTS against an exact
# posterior stays in the slow group (test_grid_reference.py, test_calibration.py)
def test_nuts_agrees_with_laplace(golf_fit, golf_post):
    """Near Gaussian here: NUTS's median and 5 / 95 % quantiles within a quarter of a
    posterior standard deviation of Laplace's (Monte Carlo error of a few hundred
    effective draws included)."""
    with warnings.catch_warnings():  # an ess a little under 100 warns; the check is below
        warnings.simplefilter("ignore", PosteriorWarning)
        post = ji.posterior(
            golf_fit,
            method="nuts",
            num_samples=500,
            num_warmup=300,
            chains=2,
            key=jax.random.key(1),
        )
    assert post.diagnostics["divergences"] == 0
    assert post.diagnostics["r_hat"] < 1.05
    for k in post.names:
        a, b = np.asarray(post.samples[k]), np.asarray(golf_post.samples[k])
        if k == "b1":
            a, b = np.log(a), np.log(b)
        sd = np.std(b)
        for q in (0.05, 0.5, 0.95):
            assert abs(np.quantile(a, q) - np.quantile(b, q)) < 0.25 * sd, (k, q)


@pytest.mark.slow
def test_noise_scale_sampled_where_not_given(times):
    """Without sigma, the noise is sampled: its posterior holds the fit's estimate (eight
    detections: the realised scatter, 0.5 ms here, not the 1 ms drawn from) and b1's
    spread is near the fit's (which plugs in the estimated noise)."""
    fit = ji.fit_bounces(START, m=GOLF_M, impact_times=times)
    post = ji.posterior(fit, method="laplace", key=jax.random.key(0))
    assert post.names[-1] == "sigma" and post.units["sigma"] == "s"
    lo, hi = post.interval(0.9)["sigma"]
    assert lo < fit.sigma < hi
    assert post.map["b1"] == pytest.approx(fit.params["b1"], rel=1e-3)
    assert np.std(np.log(post.samples["b1"])) > 0.7 * fit.stderr["b1"] / fit.params["b1"]
