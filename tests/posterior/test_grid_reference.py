"""`posterior` against an independent reference: a dense grid posterior of a two-parameter
law (`hertz_rate`, on the universal curves), its likelihood computed from `impact` over
the prior's box, in `ln c` and `ln b1` (a loguniform prior is flat there).

The posterior is checked through the quantiles (5, 50, 95 %) of each parameter's marginal:
NUTS's within 0.15 posterior standard deviations of the grid's; Laplace's too where the
posterior is near Gaussian (ten speeds measured to 1 % in e and 2 % in T), and visibly
different where it is not (two speeds, e to 0.05: a skewed posterior).
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaximpact as ji
from posterior_data import M, synthetic

QUANTILES = np.array([0.05, 0.5, 0.95])


@jax.jit
def _grid_log_likelihood(log_c, log_b1, v0, e, T, s_e, s_T):
    """ln L on the grid (`log_c` x `log_b1`), every impact from `ji.impact`."""

    def one(lc, lb):
        law = ji.law("hertz_rate", c=jnp.exp(lc), b1=jnp.exp(lb))
        r = jax.vmap(lambda v: ji.impact(law, m=M, v0=v))(v0)
        return -0.5 * jnp.sum(((r.e - e) / s_e) ** 2) - 0.5 * jnp.sum(((r.T - T) / s_T) ** 2)

    rows = jax.vmap(lambda lc: jax.vmap(lambda lb: one(lc, lb))(log_b1))
    return rows(log_c)


def grid_quantiles(fit, e, T, s_e, s_T, box, n=161, width=8.0):
    """Marginal quantiles (in ln c, ln b1) and standard deviations of the grid posterior
    over `box` (the prior's, loguniform), restricted to `width` standard errors of the
    fit around it (outside, the posterior is negligible); trapezoid CDFs."""
    axes = []
    for k in ("c", "b1"):
        centre = np.log(float(fit.params[k]))
        half = width * float(fit.stderr[k]) / float(fit.params[k])
        lo, hi = np.log(box[k][0]), np.log(box[k][1])
        axes.append(np.linspace(max(centre - half, lo), min(centre + half, hi), n))
    log_l = np.asarray(
        _grid_log_likelihood(*(jnp.asarray(a) for a in axes), jnp.asarray(fit.v0), e, T, s_e, s_T)
    )
    p = np.exp(log_l - log_l.max())
    out = {}
    for i, k in enumerate(("c", "b1")):
        x = axes[i]
        marginal = np.trapezoid(p, axes[1 - i], axis=1 - i)
        cdf = np.concatenate([[0.0], np.cumsum(0.5 * (marginal[1:] + marginal[:-1]) * np.diff(x))])
        cdf /= cdf[-1]
        assert marginal[0] < 1e-6 * marginal.max() and marginal[-1] < 1e-6 * marginal.max()
        mean = np.trapezoid(x * marginal, x) / np.trapezoid(marginal, x)
        sd = np.sqrt(np.trapezoid((x - mean) ** 2 * marginal, x) / np.trapezoid(marginal, x))
        out[k] = (np.interp(QUANTILES, cdf, x), sd)
    return out


BOX = {"c": (1e5, 1e8), "b1": (10.0, 1e5)}


@pytest.fixture(scope="module")
def near_gaussian(weighted_fit):
    """Ten speeds, e to 0.01 and T to 2 % (the shared `weighted_fit`)."""
    fit = weighted_fit
    e, T = np.asarray(fit.e_target), np.asarray(fit.T_target)
    reference = grid_quantiles(fit, e, T, 0.01, np.asarray(fit.sigma_T), BOX)
    prior = {k: ("loguniform", *BOX[k]) for k in BOX}
    return fit, reference, prior


def _check(post, reference, tol):
    for k, (q_grid, sd) in reference.items():
        q = np.quantile(np.log(post.samples[k]), QUANTILES)
        off = np.abs(q - q_grid) / sd
        assert np.all(off < tol), (k, off)


def test_laplace_matches_the_grid_where_near_gaussian(near_gaussian):
    fit, reference, prior = near_gaussian
    post = ji.posterior(fit, prior=prior, method="laplace", key=jax.random.key(0))
    _check(post, reference, 0.15)


@pytest.mark.slow
def test_nuts_matches_the_grid(near_gaussian):
    fit, reference, prior = near_gaussian
    post = ji.posterior(fit, prior=prior, method="nuts", key=jax.random.key(1))
    assert post.diagnostics["r_hat"] < 1.01
    assert post.diagnostics["divergences"] == 0
    _check(post, reference, 0.15)


@pytest.fixture(scope="module")
def skewed():
    """Two speeds, e to 0.03 and T to 15 %: a posterior far from Gaussian in ln c."""
    v0 = np.array([1.0, 2.0])
    e, T, s_T = synthetic(v0, 0.03, 0.15, seed=1)
    start = ji.law("hertz_rate", c=1e6, b1=100.0)
    fit = ji.calibrate(start, m=M, v0=v0, e=e, T=T, sigma_e=0.03, sigma_T=s_T)
    reference = grid_quantiles(fit, e, T, 0.03, s_T, BOX, n=241, width=12.0)
    prior = {k: ("loguniform", *BOX[k]) for k in BOX}
    return fit, reference, prior


def test_laplace_is_honestly_different_where_skewed(skewed):
    """The Gaussian at the mode misplaces a tail quantile of a skewed posterior by more
    than 0.15 standard deviations (measured: 0.32 for c's 95 % quantile)."""
    fit, reference, prior = skewed
    post = ji.posterior(fit, prior=prior, method="laplace", key=jax.random.key(0))
    q = np.quantile(np.log(post.samples["c"]), QUANTILES)
    q_grid, sd = reference["c"]
    assert np.max(np.abs(q - q_grid) / sd) > 0.2


@pytest.mark.slow
def test_nuts_matches_the_grid_where_skewed(skewed):
    fit, reference, prior = skewed
    post = ji.posterior(fit, prior=prior, method="nuts", key=jax.random.key(2))
    _check(post, reference, 0.15)
