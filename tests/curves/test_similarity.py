"""The universal curves (`impact(..., method="similarity")`) against closed forms, the
integrated path, finite differences; the cache of built shapes; refusals."""

import os
import subprocess
import sys
import textwrap
import zlib

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaximpact as ji
from jaximpact import closed_forms
from jaximpact._curves import build, store
from jaximpact._curves.check import scipy_impact
from jaximpact._curves.curve import Curves
from jaximpact._curves.shapes import curve_key
from jaximpact._curves.similarity import beta_for_restitution, curve_values
from jaximpact._laws import shape_of

M, V0 = 1.0, 2.5
# one law per shipped shape, with its damping parameter and a value giving beta ~ 1
SHAPES = {
    "kelvin_voigt_modified": ("b1", dict(c=2e6, b1=4e5)),
    "hertz_viscous": ("b", dict(c=2e6, b=900.0)),
    "hertz_modified": ("b", dict(c=2e6, b=2e5)),
    "hertz_rate": ("b1", dict(c=2e6, b1=8e3)),
    "hunt_crossley": ("a", dict(c=2e6, a=0.3)),
}


def _law(name, scale=1.0):
    damping, params = SHAPES[name]
    return ji.law(name, **{**params, damping: params[damping] * scale})


def _law_at(name, beta):
    """The law of `SHAPES[name]` with its damping set so that `beta` is as given."""
    base = _law(name).dynamics(m=M, v0=V0, g=0.0).beta
    return _law(name, beta / float(base))


def _rng(*words):
    return np.random.default_rng(zlib.crc32(" ".join(words).encode()))


def _checked_criteria():
    for name in SHAPES:
        for separation in ("force", "penetration"):
            if not (name == "hertz_viscous" and separation == "penetration"):
                yield name, separation


@pytest.mark.parametrize("name, separation", list(_checked_criteria()))
def test_curves_match_scipy(name, separation):
    """`impact` on the curves against scipy DOP853 at rtol 1e-13 at random damping, up to
    beta of about 10 (beyond, T under the force criterion is ill-conditioned: docs)."""
    for beta in np.exp(_rng(name, separation).uniform(np.log(1e-3), np.log(10.0), 3)):
        law = _law_at(name, beta)
        r = ji.impact(law, m=M, v0=V0, separation=separation)
        assert r.path == "similarity" and int(r.status) == ji.Status.separated
        d = law.dynamics(m=M, v0=V0, g=0.0)
        key = curve_key(*shape_of(law), separation)
        want = scipy_impact(float(d.beta), key.n, key.p, key.separation)
        got = (r.e, r.T / d.t_star, r.x_max / d.x_star, r.t_max / d.t_star, r.F_max / d.force_scale)
        for field, a, b in zip(("e", "T", "x_max", "t_max", "F_max"), got, want, strict=True):
            assert abs(float(a) - b) <= 1e-9 * b, (field, float(d.beta), float(a), b)


@pytest.mark.slow
@pytest.mark.parametrize("name, separation", list(_checked_criteria()))
def test_curves_match_the_integrated_path(name, separation):
    for beta in np.exp(_rng(name, separation).uniform(np.log(1e-3), np.log(10.0), 2)):
        law = _law_at(name, beta)
        fast = ji.impact(law, m=M, v0=V0, separation=separation)
        slow = ji.impact(law, m=M, v0=V0, separation=separation, method="integrate", rtol=1e-12)
        assert fast.path == "similarity" and slow.path == "integrated"
        assert int(fast.status) == int(slow.status) == ji.Status.separated
        for field in ("e", "T", "x_max", "t_max"):
            a, b = float(getattr(fast, field)), float(getattr(slow, field))
            assert abs(a - b) <= 2e-9 * abs(b), (field, beta, a, b)


def test_kelvin_voigt_curves_match_the_closed_form():
    key = curve_key(1.0, 0.0, "force")
    curves = store.curves_for(key)
    betas = np.exp(np.linspace(np.log(1e-9), np.log(10.0), 25))
    values = np.exp(curves.log_values(betas))  # the same series, evaluated in numpy
    for beta, got in zip(betas, values, strict=True):
        exact = closed_forms.kelvin_voigt(1.0, beta, 1.0, 1.0, "force")
        for index, field in enumerate(("e", "T", "x_max", "t_max", "F_max")):
            want = float(exact[field])
            assert abs(got[index] - want) <= 1e-10 * want, (beta, field, got[index], want)


def test_hunt_crossley_restitution_matches_lambert_w():
    mpmath = pytest.importorskip("mpmath")
    mpmath.mp.dps = 40
    curves = store.curves_for(curve_key(1.5, 1.5, "force"))
    for alpha in np.exp(np.linspace(np.log(1e-8), np.log(1e3), 30)):
        a = mpmath.mpf(alpha)
        want = float((1 + mpmath.lambertw(-(1 + a) * mpmath.exp(-(1 + a)), 0).real) / a)
        got = float(np.exp(curves.log_values([alpha])[0, 0]))
        assert abs(got - want) <= 1e-10 * want, (alpha, got, want)


@pytest.mark.parametrize("key", store.SHIPPED, ids=lambda k: k.name)
def test_elastic_limit_is_the_undamped_spring(key):
    spring = closed_forms.power_spring(1.0, key.n, 1.0, 1.0)
    got = np.asarray(curve_values(store.curves_for(key), jnp.asarray(0.0), (0, 1, 2, 3, 4)))
    # (through JAX: below BETA_MIN the curve is its elastic limit and slope)
    assert abs(got[0] - 1.0) <= 1e-10  # measured: 3.2e-11 at most (Kelvin-Voigt)
    for index, field in ((1, "T"), (2, "x_max"), (3, "t_max"), (4, "F_max")):
        assert abs(got[index] - float(spring[field])) <= 1e-10 * float(spring[field])


@pytest.mark.parametrize(
    "key", [k for k in store.SHIPPED if store.curves_for(k).capture is None], ids=lambda k: k.name
)
def test_restitution_falls_monotonically_with_damping(key):
    curves = store.curves_for(key)
    betas = np.exp(np.linspace(np.log(1e-6), np.log(curves.beta_max), 2000))
    e = np.exp(curves.log_values(betas)[:, 0])
    assert np.all(np.diff(e) < 0)


def test_calibrate_inversion_finds_the_damping_back():
    curves = store.curves_for(curve_key(1.5, 0.5, "force"))
    betas = np.exp(np.linspace(np.log(1e-5), np.log(1e3), 23))
    e = jnp.asarray(np.exp(curves.log_values(betas)[:, 0]))
    back = jax.vmap(lambda r: beta_for_restitution(curves, r))(e)
    assert np.allclose(np.asarray(back), betas, rtol=1e-8)


def test_capture_threshold_of_hertz_viscous_under_penetration():
    threshold = store.curves_for(curve_key(1.5, 0.0, "penetration")).capture
    assert threshold is not None and 1.1 < threshold < 1.2

    # at c = m = v0 = 1, beta = b: the integrated impact separates below, is captured above
    def status(beta):
        law = ji.law("hertz_viscous", c=1.0, b=beta)
        return int(ji.impact(law, m=1.0, v0=1.0, separation="penetration").status)

    assert status(0.97 * threshold) == ji.Status.separated
    assert status(1.03 * threshold) == ji.Status.captured
    law = ji.law("hertz_viscous", c=1.0, b=0.5)
    assert ji.impact(law, m=1.0, v0=1.0, separation="penetration").path == "integrated"


def _e_and_T(c, b1, method):
    r = ji.impact(ji.law("hertz_rate", c=c, b1=b1), m=M, v0=V0, method=method, peaks=False)
    return jnp.stack([r.e, r.T])


def test_gradients_match_finite_differences():
    c, b1 = 2e6, 800.0
    fast = jax.jacfwd(_e_and_T, argnums=(0, 1))(c, b1, "similarity")
    reverse = jax.jacrev(_e_and_T, argnums=(0, 1))(c, b1, "similarity")
    for k, h in ((0, 1e-4 * c), (1, 1e-4 * b1)):
        plus, minus = [c, b1], [c, b1]
        plus[k] += h
        minus[k] -= h
        central = (_e_and_T(*plus, "similarity") - _e_and_T(*minus, "similarity")) / (2 * h)
        np.testing.assert_allclose(fast[k], central, rtol=1e-6)
        np.testing.assert_allclose(reverse[k], fast[k], rtol=1e-12)


@pytest.mark.slow
def test_gradients_match_the_integrated_path():
    fast = jax.jacfwd(_e_and_T, argnums=(0, 1))(2e6, 800.0, "similarity")
    slow = jax.jacfwd(_e_and_T, argnums=(0, 1))(2e6, 800.0, "integrate")
    for k in (0, 1):
        np.testing.assert_allclose(slow[k], fast[k], rtol=1e-6)


def test_gradient_at_zero_damping_is_the_elastic_slope():
    # e = 1 - k beta + ...: the slope at b = 0 is finite and matches a small finite difference
    grad = jax.grad(lambda b: ji.impact(ji.law("hertz_rate", c=2e6, b1=b), m=M, v0=V0).e)(0.0)
    h = 1e-3
    e_h = ji.impact(ji.law("hertz_rate", c=2e6, b1=h), m=M, v0=V0).e
    assert np.isfinite(grad) and abs(float(grad) - float(e_h - 1.0) / h) <= 1e-5 * abs(float(grad))


def test_vmap_takes_the_curves():
    cs = jnp.array([1e6, 2e6, 4e6])
    one = jax.vmap(lambda c: ji.impact(ji.law("hertz_rate", c=c, b1=800.0), m=M, v0=V0).T)(cs)
    loop = [float(ji.impact(ji.law("hertz_rate", c=c, b1=800.0), m=M, v0=V0).T) for c in cs]
    np.testing.assert_allclose(one, loop, rtol=1e-14)


@pytest.mark.parametrize(
    "law, kwargs, words",
    [
        (ji.law("bingham", c=2e6, b=400.0, P=100.0), {}, "not one-group"),
        (ji.law("maxwell", c=2e6, b=4e3), {}, "not one-group"),
        (ji.custom_law(lambda x, v, p: p["k"] * x, k=1e6), {}, "not one-group"),
        (ji.law("kelvin_voigt_modified", c=2e6, b1=800.0), {"g": 9.81}, "gravity table"),
        (ji.law("hertz_rate", c=2e6, b1=800.0), {"ts": np.linspace(0, 1e-3, 5)}, "ts="),
        (ji.law("hertz_viscous", c=2e6, b=900.0), {"separation": "penetration"}, "captured"),
    ],
)
def test_similarity_is_refused_with_a_reason(law, kwargs, words):
    with pytest.raises(ValueError, match=words):
        ji.impact(law, m=M, v0=V0, method="similarity", **kwargs)


def test_auto_keeps_the_closed_form_and_integrates_what_the_curves_cannot_serve():
    assert ji.impact(ji.law("kelvin_voigt", c=2e6, b=400.0), m=M, v0=V0).path == "closed_form"
    law = ji.law("hertz_rate", c=2e6, b1=800.0)
    # with gravity: the two-group table (tests/curves/test_gravity_curves.py)
    assert ji.impact(law, m=M, v0=V0, g=9.81).path == "similarity"
    # the decisions that integrate, asked of `choose_path` itself (the impacts it sends to
    # the integrator are tested where they are integrated; compiling them here cost 10 s)
    from jaximpact._solve.options import choose_path

    def path(law, **kw):
        return choose_path(law, separation="force", method="auto", **kw).name

    assert path(law, g=9.81, rtol=1e-12) == "integrated"
    assert path(law, g=0.0, rtol=1e-12) == "integrated"
    # a shape without a gravity table integrates with gravity
    plain = ji.law("kelvin_voigt_modified", c=2e6, b1=800.0)
    assert path(plain, g=9.81, rtol=1e-11) == "integrated"
    assert path(plain, g=0.0, rtol=1e-11) == "similarity"


def _fake_curves(key):
    breaks = np.array([np.log(1e-18), np.log(1e4)])
    coefficients = np.zeros((1, 21, 5))
    coefficients[0, 0] = [-0.1, 1.0, 0.0, 0.5, 0.2]
    return Curves(key, breaks, coefficients, 1e4, None, np.zeros((1, 5)))


def test_a_corrupt_or_foreign_cache_file_is_rebuilt(tmp_path, monkeypatch):
    monkeypatch.setenv("JAXIMPACT_CURVES_DIR", str(tmp_path))
    key = curve_key(1.25, 0.75, "force")
    built = []
    monkeypatch.setattr(
        build, "build_curves", lambda k, progress=True: built.append(k) or _fake_curves(k)
    )
    path = store._cache_file(key)
    path.parent.mkdir(parents=True, exist_ok=True)
    for content in (b"not a zip file", None):
        store.curves_for.cache_clear()
        if content is None:  # a valid file, for another shape, under this shape's name
            store.save([_fake_curves(curve_key(1.5, 0.25, "force"))], path)
        else:
            path.write_bytes(content)
        curves = store.curves_for(key)
        assert curves.key == key and built[-1] == key
    # a tampered array fails its checksum
    with np.load(path) as data:
        arrays = dict(data)
    arrays[f"{key.name}/coefficients"][0, 0, 0] += 1e-9
    np.savez(path, **arrays)
    store.curves_for.cache_clear()
    before = len(built)
    store.curves_for(key)
    assert len(built) == before + 1
    # and a good file is trusted: no rebuild
    store.curves_for.cache_clear()
    store.curves_for(key)
    assert len(built) == before + 1
    store.curves_for.cache_clear()


@pytest.mark.slow
def test_a_custom_shape_is_built_once_and_reused_across_processes(tmp_path):
    # the build reports on stderr (the suite turns default meters off: on here)
    env = {**os.environ, "JAXIMPACT_CURVES_DIR": str(tmp_path), "JAXIMPACT_PROGRESS": "on"}
    script = textwrap.dedent(
        """
        import time, jax
        jax.config.update("jax_enable_x64", True)
        import jaximpact as ji
        t = time.perf_counter()
        r = ji.impact(ji.law("hunt_crossley", c=2e6, a=0.3, n=1.25), m=1.0, v0=2.5)
        s = ji.impact(ji.law("hunt_crossley", c=2e6, a=0.3, n=1.25), m=1.0, v0=2.5,
                      method="integrate", rtol=1e-12)
        print(r.path, float(r.e), float(s.e), float(r.T), float(s.T), time.perf_counter() - t)
        """
    )
    first = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True)
    assert first.returncode == 0, first.stderr[-2000:]
    assert "building curves" in first.stderr
    second = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True)
    assert second.returncode == 0 and "building curves" not in second.stderr
    path, e, e_ref, T, T_ref, _ = second.stdout.split()
    assert path == "similarity"
    assert abs(float(e) - float(e_ref)) <= 1e-9 and abs(float(T) - float(T_ref)) <= 1e-9 * float(
        T_ref
    )


def test_float32_takes_the_curves():
    script = textwrap.dedent(
        """
        import warnings
        warnings.simplefilter("ignore")
        import jaximpact as ji
        r = ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5)
        print(r.path, r.e.dtype, float(r.e), float(r.T))
        """
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr[-2000:]
    path, dtype, e, T = out.stdout.split()
    ref = ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=M, v0=V0)
    assert path == "similarity" and dtype == "float32"
    assert abs(float(e) - float(ref.e)) <= 1e-6 and abs(float(T) - float(ref.T)) <= 1e-6 * float(
        ref.T
    )


def test_calibrate_from_e_and_T_reads_the_curves():
    truth = ji.law("hertz_rate", c=2e6, b1=800.0)
    target = ji.impact(truth, m=M, v0=V0, method="integrate", rtol=1e-12)
    fit = ji.calibrate(ji.law("hertz_rate", c=1e6, b1=100.0), m=M, v0=V0, e=target.e, T=target.T)
    assert bool(fit.converged)
    np.testing.assert_allclose(fit.params["c"], 2e6, rtol=1e-8)
    np.testing.assert_allclose(fit.params["b1"], 800.0, rtol=1e-8)


def test_calibrate_at_several_speeds_on_the_curves_matches_the_integrated_fit():
    v0 = np.array([0.5, 1.0, 2.0, 4.0])
    truth = ji.law("hunt_crossley", c=5e7, a=0.2)
    e = [float(ji.impact(truth, m=0.01, v0=v).e) for v in v0]
    T = [float(ji.impact(truth, m=0.01, v0=v).T) for v in v0]
    start = ji.law("hunt_crossley", c=1e7, a=0.5)
    fit = ji.calibrate(start, m=0.01, v0=v0, e=e, T=T)
    assert bool(fit.converged)
    np.testing.assert_allclose([fit.params["c"], fit.params["a"]], [5e7, 0.2], rtol=1e-7)
    with pytest.raises(ValueError, match="not one-group"):
        ji.calibrate(ji.law("maxwell", c=1e6, b=1e3), m=1.0, v0=1.0, e=0.5, method="similarity")


def test_calibrate_of_a_nominal_law_runs_the_optimiser_on_the_curves():
    # the damping of a published variant is a formula of e_nominal: no closed-form start,
    # so the least squares runs (over the curves) from the given values
    truth = ji.law("lankarani_nikravesh", c=2e6, e_nominal=0.8)
    r = ji.impact(truth, m=M, v0=V0)
    assert r.path == "similarity"
    fit = ji.calibrate(
        ji.law("lankarani_nikravesh", c=2e7, e_nominal=0.5), m=M, v0=V0, e=r.e, T=r.T
    )
    assert bool(fit.converged) and int(fit.iterations) > 0
    np.testing.assert_allclose([fit.params["c"], fit.params["e_nominal"]], [2e6, 0.8], rtol=1e-7)


def test_hunt_crossley_built_inside_jit_still_takes_the_curves():
    def e_of(c):
        r = ji.impact(ji.law("hunt_crossley", c=c, a=0.1), m=M, v0=V0)
        assert r.path == "similarity"  # n = 1.5 stays a number under jit
        return r.e

    assert abs(float(jax.jit(e_of)(2e6)) - float(e_of(2e6))) <= 1e-15


@pytest.mark.parametrize(
    "option",
    [
        {"rtol": 0.0},
        {"rtol": -1e-8},
        {"atol": 2.0},
        {"rest_tol": float("nan")},
        {"max_steps": 0},
        {"max_steps": 1.5},
        {"tau_max": 0.0},
    ],
)
def test_options_outside_their_range_are_refused(option):
    with pytest.raises(ValueError, match=next(iter(option))):
        ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=M, v0=V0, **option)
