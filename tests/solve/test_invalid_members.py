"""A bad member under `jit`, `vmap` or `grad` (DESIGN.md, "Off the curves"): NaN in every
result field and status `invalid`, the other members computed; an eager call raises the
same one-line `ValueError` as before (`_checks.MemberChecks`, issue 34 item 6).

Cheap: the fast tests use `hertz_rate` on the universal curves (the similarity path, which
compiles in about a second); the oblique impact and the fits under `vmap` compile programs
of their own and are marked slow.
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaximpact as ji
from jaximpact._oblique import oblique_impact, tangential_law
from jaximpact._solve.bounce import BounceStatus

LAW = ji.law("hertz_rate", c=2e6, b1=800.0)
FLOATS = ("e", "T", "x_max", "t_max", "F_max", "dissipated", "v_out")


def _assert_refused(result, index=None):
    """Every float field NaN and the status `invalid` (of member `index` of a batch)."""
    pick = (lambda a: np.asarray(a)) if index is None else (lambda a: np.asarray(a)[index])
    for name in FLOATS:
        assert np.isnan(pick(getattr(result, name))), name
    assert int(pick(result.status)) == ji.Status.invalid


def test_vmap_over_masses_computes_the_good_member_and_refuses_the_bad():
    batch = jax.vmap(lambda m: ji.impact(LAW, m=m, v0=2.5))(jnp.array([1.0, 0.0]))
    eager = ji.impact(LAW, m=1.0, v0=2.5)
    for name in FLOATS:
        assert float(getattr(batch, name)[0]) == pytest.approx(
            float(getattr(eager, name)), rel=1e-12
        )
    assert int(batch.status[0]) == ji.Status.separated
    _assert_refused(batch, 1)
    assert batch.to_dict()["status"] == ["separated", "invalid"]


@pytest.mark.slow  # three programs of their own (the vmap test above keeps the rule fast)
def test_jit_with_a_negative_mass_gives_nan_and_invalid():
    result = jax.jit(lambda m: ji.impact(LAW, m=m, v0=2.5))(-1.0)
    _assert_refused(result)
    assert result.status_name == "invalid"
    # a negative gravity and a NaN speed too
    _assert_refused(jax.jit(lambda g: ji.impact(LAW, m=1.0, v0=2.5, g=g))(-9.81))
    _assert_refused(jax.jit(lambda v: ji.impact(LAW, m=1.0, v0=v))(jnp.nan))


def test_grad_at_a_zero_speed_is_nan_and_elsewhere_unchanged():
    def e(v0):
        return ji.impact(LAW, m=1.0, v0=v0).e

    assert np.isnan(float(jax.grad(e)(0.0)))
    grads = jax.vmap(jax.grad(e))(jnp.array([2.5, 0.0]))
    h = 1e-4
    fd = (float(e(2.5 + h)) - float(e(2.5 - h))) / (2 * h)
    assert float(grads[0]) == pytest.approx(fd, rel=1e-5)
    assert np.isnan(float(grads[1]))


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(m=0.0, v0=2.5), "mass m must be a finite number > 0 kg, got 0.0"),
        (dict(m=-1.0, v0=2.5), "mass m must be a finite number > 0 kg, got -1.0"),
        (dict(m=1.0, v0=0.0), "impact speed v0 must be a finite number > 0 m/s, got 0.0"),
        (dict(m=1.0, v0=2.5, g=-1.0), "gravity g must be a finite number >= 0 m/s^2, got -1.0"),
    ],
)
def test_eager_calls_still_raise_one_line(kwargs, message):
    with pytest.raises(ValueError) as error:
        ji.impact(LAW, **kwargs)
    assert str(error.value) == message


def test_eager_bounce_and_calibrate_still_raise_one_line():
    with pytest.raises(ValueError, match=r"^mass m must be a finite number > 0 kg, got 0.0$"):
        ji.bounce(LAW, m=0.0, h0=0.5, t_end=1.0)
    with pytest.raises(ValueError, match=r"^h0 = 0 with v_drop = 0: the ball starts at rest"):
        ji.bounce(LAW, m=1.0, h0=0.0, t_end=1.0)
    with pytest.raises(ValueError, match=r"^mass m must be a finite number > 0 kg, got 0.0$"):
        ji.calibrate(LAW, m=0.0, v0=2.5, e=0.8, T=8e-3)
    with pytest.raises(ValueError, match=r"^restitution e must lie in \(0, 1\], got \[1.5\]$"):
        ji.calibrate(LAW, m=1.0, v0=2.5, e=1.5, T=8e-3)
    tl = tangential_law("mindlin", G_star=1e10, mu=0.3)
    with pytest.raises(ValueError, match=r"^normal speed v_n \(approaching\) must be a finite"):
        oblique_impact(LAW, tl, m=1.0, R=0.01, v_n=0.0, v_t=1.0)


# --------------------------------------------------------------------------- slow


@pytest.mark.slow
def test_vmap_of_bounce_refuses_a_bad_member():
    batch = jax.vmap(lambda m: ji.bounce(LAW, m=m, h0=0.5, t_end=1.0, max_impacts=4))(
        jnp.array([1.0, -1.0])
    )
    single = ji.bounce(LAW, m=1.0, h0=0.5, t_end=1.0, max_impacts=4)
    assert float(batch.e[0, 0]) == pytest.approx(float(single.e[0]), rel=1e-12)
    assert int(batch.status[1]) == BounceStatus.invalid
    assert int(batch.num_impacts[1]) == 0
    assert np.all(np.isnan(np.asarray(batch.e[1]))) and np.isnan(float(batch.t_rest[1]))


@pytest.mark.slow
def test_vmap_of_oblique_impact_refuses_a_zero_normal_speed():
    # Kharaz et al.'s alumina sphere at 40 degrees (tests/oblique/test_oblique_impact.py)
    E, nu, R = 380e9, 0.23, 2.5e-3
    m = 4000.0 * 4.0 / 3.0 * np.pi * R**3
    law = ji.law("hunt_crossley", c=4.0 / 3.0 * E / (1 - nu**2) * np.sqrt(R), a=0.0)
    tl = tangential_law("mindlin", G_star=E / (2 * (1 + nu)) / (2 - nu), mu=0.092)

    def one(v_n):
        return oblique_impact(law, tl, m=m, R=R, v_n=v_n, v_t=2.5)

    batch = jax.vmap(one)(jnp.array([3.0, 0.0]))
    single = one(3.0)
    for name in ("e", "e_t", "T", "v_t_out", "omega_out"):
        assert float(getattr(batch, name)[0]) == pytest.approx(
            float(getattr(single, name)), rel=1e-9
        )
        assert np.isnan(float(getattr(batch, name)[1])), name
    assert [int(s) for s in batch.status] == [ji.Status.separated, ji.Status.invalid]


@pytest.mark.slow
def test_vmap_of_calibrate_refuses_a_bad_member():
    start = ji.law("hertz_rate", c=1e6, b1=100.0)
    good = ji.impact(LAW, m=1.0, v0=2.5)
    e, T = float(good.e), float(good.T)

    def one(m, e):
        return ji.calibrate(start, m=m, v0=2.5, e=e, T=T)

    batch = jax.vmap(one)(jnp.array([1.0, 0.0, 1.0]), jnp.array([e, e, 1.5]))
    single = one(1.0, e)
    assert bool(batch.converged[0])
    for key in ("c", "b1"):
        assert float(batch.params[key][0]) == pytest.approx(float(single.params[key]), rel=1e-9)
    for i in (1, 2):  # a mass of 0, an e above 1
        assert not bool(batch.converged[i]) and not bool(batch.reproduces[i])
        for value in (
            batch.params["c"][i],
            batch.params["b1"][i],
            batch.e[i, 0],
            batch.T[i, 0],
            batch.loss[i],
            batch.law.params["c"][i],
        ):
            assert np.isnan(float(value))
