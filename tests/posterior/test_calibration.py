"""Simulation-based calibration: over synthetic data sets whose truth is drawn from the
prior, the 90 % intervals of NUTS hold the truth about 90 % of the time (within binomial
bounds), and the truth's rank among the draws is uniform."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from posterior_data import M, START
from scipy import stats

import jaximpact as ji

PRIOR = {"c": ("loguniform", 1e6, 4e6), "b1": ("loguniform", 300.0, 2000.0)}
DATASETS = 60


@pytest.mark.slow
def test_intervals_cover_the_truth():
    rng = np.random.default_rng(2024)
    v0 = np.linspace(0.5, 3.0, 6)

    def one(c, b1, v):
        return ji.impact(ji.law("hertz_rate", c=c, b1=b1), m=M, v0=v)

    simulate = jax.jit(jax.vmap(one, (None, None, 0)))
    held, ranks = [], []
    for i in range(DATASETS):
        truth = {
            k: float(np.exp(rng.uniform(np.log(lo), np.log(hi))))
            for k, (_, lo, hi) in PRIOR.items()
        }
        r = simulate(truth["c"], truth["b1"], jnp.asarray(v0))
        e = np.asarray(r.e) + 0.01 * rng.normal(size=v0.size)
        T = np.asarray(r.T) * (1.0 + 0.03 * rng.normal(size=v0.size))
        s_T = 0.03 * np.asarray(r.T)
        fit = ji.calibrate(START, m=M, v0=v0, e=e, T=T, sigma_e=0.01, sigma_T=s_T)
        post = ji.posterior(
            fit,
            prior=PRIOR,
            method="nuts",
            num_samples=250,
            num_warmup=300,
            chains=2,
            key=jax.random.key(i),
        )
        for k, value in truth.items():
            lo, hi = post.interval(0.9)[k]
            held.append(lo <= value <= hi)
            ranks.append(np.mean(post.samples[k] < value))
    n = len(held)
    lo, hi = stats.binom.ppf([0.0005, 0.9995], n, 0.9)  # a 99.9 % band of the count
    p_ranks = stats.kstest(ranks, "uniform").pvalue
    print(f"90 % intervals held the truth {sum(held)} times of {n}; ranks' KS p = {p_ranks:.3g}")
    assert lo <= sum(held) <= hi, (sum(held), n)
    assert p_ranks > 1e-3
