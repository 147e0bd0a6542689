"""Shared synthetic calibrations for the posterior tests (compiled once per session)."""

import jax
import numpy as np
import pytest
from posterior_data import M, START, synthetic

import jaximpact as ji


@pytest.fixture(scope="session")
def weighted_fit():
    """Ten speeds, e to 0.01 and T to 2 %, sigmas given."""
    v0 = np.linspace(0.5, 3.0, 10)
    e, T, s_T = synthetic(v0, 0.01, 0.02, seed=3)
    return ji.calibrate(START, m=M, v0=v0, e=e, T=T, sigma_e=0.01, sigma_T=s_T)


@pytest.fixture(scope="session")
def laplace_post(weighted_fit):
    return ji.posterior(weighted_fit, method="laplace", key=jax.random.key(0))
