"""`SolveOptions`: the solve options as one record, accepted whole by `impact`,
`impact_batch`, `bounce`, `calibrate` and `fit_bounces` beside their keywords (issue 36,
item 3); the path of `calibrate` and `bounce` asked of `choose_path` alone; curves loaded
before a fit is compiled."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaximpact as ji
import jaximpact._curves.build as build
import jaximpact._curves.store as store
import jaximpact._fit.calibrate as _calibrate
from jaximpact._solve.options import choose_path

LAW = ji.law("hertz_rate", c=2e6, b1=800.0)
OPTIONS = ji.SolveOptions(rtol=1e-10, atol=1e-11, max_steps=2048, tau_max=1e3, rest_tol=1e-8)
KEYWORDS = dict(rtol=1e-10, atol=1e-11, max_steps=2048, tau_max=1e3, rest_tol=1e-8)
FIELDS = ("e", "T", "x_max", "F_max", "t_max", "dissipated", "v_out", "status", "num_steps")


def _same(a, b, fields=FIELDS):
    for name in fields:
        assert np.array_equal(np.asarray(getattr(a, name)), np.asarray(getattr(b, name))), name


@pytest.mark.parametrize("method", ["auto", "integrate"])
def test_impact_takes_the_record_whole(method):
    """The record gives bit for bit what its fields as keywords give, on the curves and
    integrated; a record of defaults is no record."""
    whole = ji.impact(LAW, m=1.0, v0=2.5, method=method, options=OPTIONS)
    _same(whole, ji.impact(LAW, m=1.0, v0=2.5, method=method, **KEYWORDS))
    assert whole.path == ("similarity" if method == "auto" else "integrated")
    _same(ji.impact(LAW, m=1.0, v0=2.5, options=ji.SolveOptions()), ji.impact(LAW, m=1.0, v0=2.5))
    # a keyword beside the record: at its default or the record's value, accepted
    same = ji.impact(LAW, m=1.0, v0=2.5, method=method, max_steps=2048, options=OPTIONS)
    _same(same, whole)
    # a field the record leaves None is the keyword's
    part = ji.impact(
        LAW, m=1.0, v0=2.5, method="integrate", rtol=1e-10, options=ji.SolveOptions(max_steps=2048)
    )
    _same(part, ji.impact(LAW, m=1.0, v0=2.5, method="integrate", rtol=1e-10, max_steps=2048))


def test_a_conflicting_keyword_is_refused_in_one_line():
    with pytest.raises(ValueError, match=r"^impact got rtol=1e-12 and options.rtol=1e-10") as e:
        ji.impact(LAW, m=1.0, v0=2.5, rtol=1e-12, options=OPTIONS)
    assert "\n" not in str(e.value)
    with pytest.raises(ValueError, match="bounce got throw=True and options.throw=False"):
        ji.bounce(LAW, m=1.0, h0=0.1, t_end=0.2, throw=True, options=ji.SolveOptions(throw=False))
    with pytest.raises(ValueError, match="calibrate got rtol=1e-09 and options.rtol=1e-10"):
        ji.calibrate(LAW, m=1.0, v0=2.5, e=0.8, rtol=1e-9, options=OPTIONS)
    with pytest.raises(ValueError, match="impact_batch got max_steps=100"):
        ji.impact_batch(
            "hertz_rate",
            {"c": 2e6, "b1": 800.0},
            m=1.0,
            v0=2.5,
            max_steps=100,
            options=OPTIONS,
            progress=False,
        )
    with pytest.raises(TypeError, match="must be a jaximpact.SolveOptions, got dict"):
        ji.impact(LAW, m=1.0, v0=2.5, options=KEYWORDS)


def test_options_an_entry_point_decides_itself_are_refused():
    with pytest.raises(ValueError, match=r"calibrate takes no adjoint .*forward mode"):
        ji.calibrate(LAW, m=1.0, v0=2.5, e=0.8, options=ji.SolveOptions(adjoint=object()))
    with pytest.raises(ValueError, match=r"fit_bounces takes no peaks"):
        ji.fit_bounces(
            LAW, m=1.0, impact_times=np.linspace(0.0, 1.0, 6), options=ji.SolveOptions(peaks=True)
        )
    with pytest.raises(ValueError, match=r"impact_batch takes no throw .*each row's status"):
        ji.impact_batch(
            "hertz_rate",
            {"c": 2e6, "b1": 800.0},
            m=1.0,
            v0=2.5,
            options=ji.SolveOptions(throw=True),
            progress=False,
        )


def test_the_record_under_jit_and_vmap():
    """Closed over by a `vmap`ped function, or passed through `jit` as an argument (a pytree
    with no leaves: static configuration), the record gives the keywords' numbers."""
    speeds = jnp.array([1.0, 2.5, 4.0])
    want = jax.vmap(lambda v: ji.impact(LAW, m=1.0, v0=v, method="integrate", **KEYWORDS).e)(speeds)
    closed = jax.vmap(lambda v: ji.impact(LAW, m=1.0, v0=v, method="integrate", options=OPTIONS).e)(
        speeds
    )
    passed = jax.jit(lambda o, v: ji.impact(LAW, m=1.0, v0=v, method="integrate", options=o).e)
    assert np.array_equal(closed, want)
    assert np.array_equal(passed(OPTIONS, speeds[1]), want[1])
    assert jax.tree_util.tree_leaves(OPTIONS) == []


def test_impact_batch_takes_the_record_whole():
    params = {"c": 2e6, "b1": np.linspace(100.0, 2000.0, 8)}
    run = dict(m=1.0, v0=2.5, method="integrate", progress=False)
    whole = ji.impact_batch("hertz_rate", params, options=OPTIONS, **run)
    keywords = ji.impact_batch("hertz_rate", params, **KEYWORDS, **run)
    for name in keywords:
        assert np.array_equal(whole[name], keywords[name]), name


def test_bounce_takes_the_record_whole_and_asks_choose_path():
    run = dict(m=1.0, h0=0.05, t_end=0.3, max_impacts=4)
    whole = ji.bounce(LAW, **run, options=ji.SolveOptions(rtol=1e-10, rest_tol=1e-8))
    keywords = ji.bounce(LAW, **run, rtol=1e-10, rest_tol=1e-8)
    for name in ("impact_times", "e", "T", "status", "num_impacts"):
        assert np.array_equal(getattr(whole, name), getattr(keywords, name), equal_nan=True)
    # its contacts' path is choose_path's with gravity: the gravity table for this law
    path = choose_path(LAW, separation="force", g=9.81, rtol=1e-10)
    assert path.name == "gravity_table"
    assert whole.options.impact.similarity == path.key
    assert not whole.options.impact.closed_form
    kv = ji.law("kelvin_voigt", c=2e6, b=400.0)
    assert ji.bounce(kv, **run).options.impact.closed_form
    integrated = ji.bounce(LAW, **run, method="integrate").options.impact
    assert integrated.similarity is None and not integrated.closed_form


@pytest.mark.parametrize(
    "law, g, method, path",
    [
        (LAW, 0.0, "auto", "similarity"),  # the curves before a closed form: the start too
        (ji.law("kelvin_voigt", c=2e6, b=400.0), 0.0, "auto", "similarity"),
        (ji.law("kelvin_voigt", c=2e6, b=400.0), 9.81, "auto", "closed_form"),
        (LAW, 9.81, "auto", "integrated"),  # no gravity table for a one-group law in a fit
        (LAW, 0.0, "integrate", "integrated"),
    ],
)
def test_calibrate_asks_choose_path_for_its_path(monkeypatch, law, g, method, path):
    """calibrate's route is `choose_path(..., fit=True)`, asked once, and what it compiles
    follows it (the fit itself is not run)."""
    asked = []
    real = _calibrate.choose_path
    monkeypatch.setattr(_calibrate, "choose_path", lambda *a, **k: asked.append(k) or real(*a, **k))

    class Reached(Exception):
        pass

    def fit(law, data, m, g, target_tol, options):
        asked.append(options)
        raise Reached

    for fitter in ("_fit", "_fit_on_host"):
        monkeypatch.setattr(_calibrate, fitter, fit)
    with pytest.raises(Reached):
        ji.calibrate(law, m=1.0, v0=2.5, e=0.8, T=5e-3, g=g, method=method)
    (question, setup) = asked
    assert question["fit"] is True
    assert real(law, **question).name == path
    assert setup.closed_form == (path == "closed_form")
    assert (setup.curves is not None) == (path == "similarity")
    assert setup.start_on_curves == (path == "similarity")


def test_a_fit_never_builds_curves_once_compiling(monkeypatch, tmp_path):
    """A shape without shipped curves: `choose_path` loads (here: would build) them, before
    the compiled fit is reached; nothing inside the fit builds."""
    monkeypatch.setenv("JAXIMPACT_CURVES_DIR", str(tmp_path))  # an empty cache
    built = []

    def refuse(key, progress=True):
        built.append(key)
        raise RuntimeError("a build")

    monkeypatch.setattr(build, "build_curves", refuse)
    reached = []
    for fitter in ("_fit", "_fit_on_host"):
        monkeypatch.setattr(_calibrate, fitter, lambda *a: reached.append(a))
    store.curves_for.cache_clear()
    try:
        law = ji.law("hunt_crossley", c=2e6, a=0.1, n=1.37)  # not a shipped shape
        with pytest.raises(RuntimeError, match="a build"):
            ji.calibrate(law, m=1.0, v0=2.5, e=0.8, T=5e-3)
    finally:
        store.curves_for.cache_clear()
    assert len(built) == 1 and built[0].n == 1.37
    assert not reached  # the build came from the path decision, before the fit
