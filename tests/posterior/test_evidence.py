"""`compare_laws(..., by="evidence")`: the laws ranked by their Laplace evidence, with Bayes
factors beside the AIC ranking. On e(v) and T(v) of a steel ball (Thornton's plastic law)
and of a viscoelastic ball (Kuwabara-Kono, `hertz_rate`), sigmas given, the generating law
ranks first. The default `by` is the AIC ranking of `_fit.model_choice`, unchanged."""

import math
import subprocess
import sys

import jax
import numpy as np
import pytest

import jaximpact as ji
from jaximpact._fit import model_choice

R = 5e-3
STEEL_M = 4.0 / 3.0 * math.pi * R**3 * 7800.0
SPEEDS = np.array([0.1, 0.3, 0.6, 1.0, 2.0, 3.0])
NOISE = np.array([1.0, -1.0, 0.5, -0.5, 1.0, -1.0])
REL = 0.003  # the noise, relative, in e and in T; the sigmas given are these
LAWS = ("thornton", "hertz_rate", "kelvin_voigt")


def _measured(law, m):
    r = jax.vmap(lambda v: ji.impact(law, m=m, v0=v))(SPEEDS)
    e = np.asarray(r.e) * (1 + REL * NOISE)
    T = np.asarray(r.T) * (1 + REL * NOISE[::-1])
    return dict(m=m, v0=SPEEDS, e=e, T=T, sigma_e=REL * e, sigma_T=REL * T)


def _check(ranks, generator):
    assert isinstance(ranks, list) and ranks[0].name == generator
    assert ranks[0].bayes_factor == 1.0
    assert all(r.bayes_factor > 1.0 for r in ranks[1:])
    assert sorted(r.aic_rank for r in ranks) == list(range(1, len(ranks) + 1))
    assert all(np.isfinite(r.log_evidence) for r in ranks[:1])
    text = ranks.table()
    assert "bayes_factor" in text and "AIC" in text and generator in text
    data = ranks[0].to_dict()
    assert data["log_evidence"] == pytest.approx(ranks[0].log_evidence)
    assert data["aic_rank"] == ranks[0].aic_rank


@pytest.mark.slow
def test_evidence_picks_thornton_for_a_steel_ball():
    steel = ji.law(
        "thornton",
        c=ji.hertz_stiffness(E=2.1e11, nu=0.3, R=R, E2=math.inf),
        x_y=ji.yield_overlap(E=2.1e11, nu=0.3, R=R, Y=1e9, E2=math.inf),
    )
    ranks = ji.compare_laws(**_measured(steel, STEEL_M), laws=LAWS, by="evidence", progress=False)
    _check(ranks, "thornton")
    assert ranks[1].log_bayes_factor > math.log(100.0)  # decisive


@pytest.mark.slow
def test_evidence_picks_the_viscoelastic_law_for_a_rubber_ball():
    rubber = ji.law("hertz_rate", c=2e6, b1=800.0)
    ranks = ji.compare_laws(**_measured(rubber, 1.0), laws=LAWS, by="evidence", progress=False)
    _check(ranks, "hertz_rate")
    assert [r.name for r in ranks].index("thornton") > 0


def test_the_default_is_the_aic_ranking():
    """`by="aic"` (the default) is `_fit.model_choice.compare_laws` itself."""
    rubber = ji.law("hertz_rate", c=2e6, b1=800.0)
    data = _measured(rubber, 1.0)
    ours = ji.compare_laws(**data, laws=("hertz_rate",), progress=False)
    theirs = model_choice.compare_laws(**data, laws=("hertz_rate",), progress=False)
    assert type(ours[0]) is model_choice.Ranking
    assert ours[0].aic == pytest.approx(theirs[0].aic, rel=1e-12)
    with pytest.raises(ValueError, match="by must be 'aic' or 'evidence'"):
        ji.compare_laws(**data, laws=("hertz_rate",), by="bic")
    with pytest.raises(ValueError, match="prior= is for by='evidence'"):
        ji.compare_laws(**data, laws=("hertz_rate",), prior={"hertz_rate": {}})


def test_the_aic_ranking_loads_no_sampler():
    """`jaximpact.compare_laws` (by AIC) imports neither blackjax nor the posterior's
    modules: they cost 0.8 s of its first call, and only `by="evidence"` uses them."""
    code = (
        "import sys, jaximpact as ji; ji.compare_laws; "
        "print(sorted(m for m in sys.modules if m.startswith(('blackjax', "
        "'jaximpact._posterior.posterior', 'jaximpact._posterior.nuts'))))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[]"


@pytest.mark.slow
def test_evidence_of_a_law_whose_impacts_are_searched_for_events():
    """Bingham-modified's impacts come off its dry-force table or out of diffrax's event
    search, which has no second derivative (`nextafter`): its Laplace step takes the
    Gauss-Newton Hessian of the held forward Jacobian, and the evidence is a number (it
    raised NotImplementedError before)."""
    rubber = ji.law("hertz_rate", c=2e6, b1=800.0)
    data = _measured(rubber, 1.0)
    del data["T"], data["sigma_T"]
    ranks = ji.compare_laws(**data, laws=("bingham_modified",), by="evidence", progress=False)
    assert np.isfinite(ranks[0].log_evidence)
