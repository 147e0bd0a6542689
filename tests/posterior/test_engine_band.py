"""The engine's band: `export(post, engine, ...)` exports the law at the posterior medians,
and `e_band`, `T_band` are the 5-95 % band of what the engine realises over the draws; the
same numbers as exporting those draws one by one."""

import json

import numpy as np
import pytest
from posterior_data import M

import jaximpact as ji


def _one_by_one(post, engine, x, draws, **kwargs):
    """Each of the band's draws exported on its own, at the median export's step."""
    es, Ts = [], []
    for law in post.draw_laws(draws):
        one = ji.export(
            law,
            engine,
            m=M,
            v0=2.0,
            timestep=x.timestep or None,
            curves=False,
            strict=False,
            **kwargs,
        )
        es.append(one.e)
        Ts.append(one.T)
    return np.asarray(es), np.asarray(Ts)


@pytest.mark.parametrize(
    "engine, kwargs, draws",
    [("lammps", dict(radius=0.02), 12), ("mujoco", {}, 3), ("drake", {}, 4)],
)
def test_the_band_is_the_draws_exported_one_by_one(laplace_post, engine, kwargs, draws):
    post = laplace_post
    x = ji.export(post, engine, m=M, v0=2.0, band_draws=draws, progress=False, **kwargs)
    median = ji.export(post.median_law, engine, m=M, v0=2.0, **kwargs)
    assert (x.e, x.T, x.timestep, x.parameters) == (
        median.e,
        median.T,
        median.timestep,
        median.parameters,
    )
    es, Ts = _one_by_one(post, engine, x, draws, **kwargs)
    assert x.band_draws == draws
    assert x.e_band == pytest.approx(tuple(np.quantile(es, [0.05, 0.95])), rel=1e-12)
    assert x.T_band == pytest.approx(tuple(np.quantile(Ts, [0.05, 0.95])), rel=1e-12)
    assert x.e_band[0] < x.e_band[1] and x.T_band[0] < x.T_band[1]


def test_the_band_holds_the_posterior_of_the_law(laplace_post):
    """Over 60 draws the LAMMPS band lies about the law's own band at v0 (what the engine
    adds is its stepping, 0.5 % at the recommended step)."""
    post = laplace_post
    x = ji.export(post, "lammps", m=M, v0=2.0, radius=0.02, band_draws=60, progress=False)
    law = post.predict(v0=[2.0], max_draws=60)
    assert x.e_band[0] == pytest.approx(float(law.e_lo[0]), abs=0.005)
    assert x.e_band[1] == pytest.approx(float(law.e_hi[0]), abs=0.005)
    assert x.T_band[0] == pytest.approx(float(law.T_lo[0]), rel=0.01)
    assert x.T_band[1] == pytest.approx(float(law.T_hi[0]), rel=0.01)
    data = json.loads(json.dumps(x.to_dict()))
    assert data["e_band"] == list(x.e_band) and data["band_draws"] == 60


def test_a_law_has_no_band(laplace_post):
    x = ji.export(laplace_post.median_law, "lammps", m=M, v0=2.0, radius=0.02)
    assert x.e_band is None and x.T_band is None
    assert not {"e_band", "T_band", "band_draws"} & set(x.to_dict())
    with pytest.raises(ValueError, match="either a posterior or the targets"):
        ji.export(laplace_post, "mujoco", m=M, v0=2.0, e=0.8)


def test_a_posterior_from_its_dict_exports_alike(laplace_post):
    """A posterior read back from `to_dict()` rebuilds its law by name (`law_parameters`)."""
    post = laplace_post
    again = ji.Posterior.from_dict(json.loads(json.dumps(post.to_dict())))
    assert again.median_law.parameters.keys() == post.median_law.parameters.keys()
    for k, v in post.median_law.parameters.items():
        assert float(again.median_law.parameters[k]) == pytest.approx(float(v), rel=1e-12)
    a = ji.export(post, "lammps", m=M, v0=2.0, radius=0.02, band_draws=5, progress=False)
    b = ji.export(again, "lammps", m=M, v0=2.0, radius=0.02, band_draws=5, progress=False)
    assert (a.e, *a.e_band, *a.T_band) == pytest.approx((b.e, *b.e_band, *b.T_band), rel=1e-12)
    with pytest.raises(ValueError, match="integer >= 1"):
        post.draw_laws(0)
