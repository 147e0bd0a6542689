"""Synthetic calibration data for the posterior tests: `hertz_rate` with known truth."""

import jax
import jax.numpy as jnp
import numpy as np

import jaximpact as ji

M = 1.0
TRUTH = {"c": 2e6, "b1": 800.0}


def synthetic(v0, sigma_e, rel_T, seed, truth=TRUTH):
    """e and T of `hertz_rate` at `truth` and speeds `v0`, with Gaussian noise of
    `sigma_e` in e and `rel_T * T` in T; returns `(e, T, sigma_T)`."""
    law = ji.law("hertz_rate", **truth)
    r = jax.vmap(lambda v: ji.impact(law, m=M, v0=v))(jnp.asarray(v0, dtype=float))
    rng = np.random.default_rng(seed)
    T_true = np.asarray(r.T)
    e = np.asarray(r.e) + sigma_e * rng.normal(size=len(v0))
    T = T_true + rel_T * T_true * rng.normal(size=len(v0))
    return e, T, rel_T * T_true


START = ji.law("hertz_rate", c=1e6, b1=100.0)
