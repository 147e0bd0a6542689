"""Programs kept on disk as traced (`jaximpact/_stored.py`): a second process (here: a new
wrapper of the same function, its memory empty) loads the program instead of tracing it,
gets the same values bit for bit, and anything the key cannot tell apart by value is never
stored."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaximpact as ji
from jaximpact import _compiling, _stored

TRACES = []


def _solve_like(law, x, *, scale, name):
    """A library-shaped program: a law (a Module with a static name), arrays, a static
    float and a static string; its output a Module and a non-array leaf."""
    TRACES.append(name)
    c = law.params["c"]
    scaled = eqx.tree_at(lambda item: item.params, law, {**law.params, "c": c * scale})
    return {"force": scaled, "y": x * c, "name": name}


def _fresh():
    """A wrapper of `_solve_like` as a new process has it: nothing in memory. The function
    poses as this package's (only its own functions are stored)."""
    _solve_like.__module__ = "jaximpact._stored_test_fixture"
    return _stored.stored_jit(_solve_like)


@pytest.fixture
def folder(tmp_path, monkeypatch):
    """A cache of its own (the suite's is shared between its processes)."""
    path = tmp_path / _stored._FOLDER

    def _folder():
        path.mkdir(exist_ok=True)
        return path

    monkeypatch.setattr(_stored, "_folder", _folder)
    TRACES.clear()
    return path


def _leaves(tree):
    return [np.asarray(x) for x in jax.tree_util.tree_leaves(tree)]


def test_a_second_process_loads_the_program_and_gets_the_same_bits(folder):
    law = ji.law("hunt_crossley", c=2e6, a=0.1)
    x = jnp.linspace(0.1, 1.0, 5)
    first = _fresh()(law, x, scale=2.0, name="first")
    assert TRACES == ["first"] and len(list(folder.glob("*.program"))) == 1
    second = _fresh()(law, x, scale=2.0, name="first")
    assert TRACES == ["first"]  # loaded, not traced
    plain = _solve_like(law, x, scale=2.0, name="plain")
    for a, b in zip(_leaves(second), _leaves(first), strict=True):
        assert np.array_equal(a, b)
    for part in ("force", "y"):
        for a, b in zip(_leaves(second[part]), _leaves(plain[part]), strict=True):
            np.testing.assert_array_equal(a, b)
    assert type(second["force"]) is type(law) and second["force"].name == "hunt_crossley"
    assert second["name"] == "first"  # a leaf that is not an array comes back as it was
    # new numbers, the same program
    again = _fresh()(law.replace(c=3e6), x + 1.0, scale=2.0, name="first")
    assert TRACES == ["first", "plain"]
    np.testing.assert_array_equal(np.asarray(again["y"]), np.asarray(x + 1.0) * 3e6)


@pytest.mark.parametrize(
    "change",
    ["shape", "dtype", "static float", "static string", "law", "equinox's checks"],
)
def test_whatever_changes_the_trace_changes_the_key(folder, change, monkeypatch):
    law, x = ji.law("hunt_crossley", c=2e6, a=0.1), jnp.ones(3)
    kwargs = dict(scale=2.0, name="a")
    _fresh()(law, x, **kwargs)
    if change == "shape":
        x = jnp.ones(4)
    elif change == "dtype":
        x = jnp.ones(3, dtype=jnp.float32)
    elif change == "static float":
        kwargs["scale"] = 2.0000000000000004
    elif change == "static string":
        kwargs["name"] = "b"
    elif change == "law":
        law = ji.law("hertz_rate", c=2e6, b1=10.0)
    else:  # the command line's NaN in place of a Python session's raise
        monkeypatch.setattr(_stored, "_equinox_on_error", lambda: "nan")
    _fresh()(law, x, **kwargs)
    assert len(TRACES) == 2 and len(list(folder.glob("*.program"))) == 2


def test_a_users_function_is_never_stored(folder):
    """A user's law holds a function the key cannot tell apart by value (its code may
    change under the same name): traced in memory, as `eqx.filter_jit` does."""
    law = ji.custom_law(lambda x, v, p: p["c"] * x**1.5, c=2e6)
    out = _fresh()(law, jnp.ones(2), scale=1.0, name="user")
    assert not folder.exists() or not list(folder.iterdir())
    np.testing.assert_array_equal(np.asarray(out["y"]), np.full(2, 2e6))
    # nor is a function outside this package, whatever its arguments
    outside = _stored.stored_jit(lambda x: x + 1)
    assert float(outside(jnp.asarray(1.0))) == 2.0
    assert not folder.exists() or not list(folder.iterdir())


def _with_callback(x):
    TRACES.append("callback")
    return jax.pure_callback(np.sin, jax.ShapeDtypeStruct(x.shape, x.dtype), x)


def test_a_program_export_refuses_is_marked_and_runs_in_memory(folder):
    _with_callback.__module__ = "jaximpact._stored_test_fixture"
    with_callback = _with_callback
    for _ in range(2):  # two processes
        out = _stored.stored_jit(with_callback)(jnp.asarray([0.5, 1.0]))
        np.testing.assert_array_equal(np.asarray(out), np.sin([0.5, 1.0]))
    assert len(list(folder.glob("*.refused"))) == 1 and not list(folder.glob("*.program"))
    # the refused export's trace and the plain one; the second process tries no export (the
    # plain trace is JAX's own, shared in this process)
    assert TRACES == ["callback", "callback"]


def test_a_damaged_file_is_traced_again(folder):
    law, x = ji.law("hunt_crossley", c=2e6, a=0.1), jnp.ones(3)
    _fresh()(law, x, scale=1.0, name="a")
    (path,) = folder.glob("*.program")
    path.write_bytes(path.read_bytes()[:100])
    out = _fresh()(law, x, scale=1.0, name="a")
    assert TRACES == ["a", "a"]
    np.testing.assert_array_equal(np.asarray(out["y"]), np.full(3, 2e6))
    assert _fresh()(law, x, scale=1.0, name="a") and TRACES == ["a", "a"]  # stored again


def test_without_the_cache_or_under_a_transform_nothing_is_stored(folder, monkeypatch):
    law = ji.law("hunt_crossley", c=2e6, a=0.1)
    stored = _fresh()
    y = jax.jit(lambda x: stored(law, x, scale=1.0, name="a")["y"])(jnp.ones(2))
    g = jax.grad(lambda x: stored(law, x, scale=1.0, name="a")["y"].sum())(jnp.ones(2))
    np.testing.assert_array_equal(np.asarray(y), np.full(2, 2e6))
    np.testing.assert_array_equal(np.asarray(g), np.full(2, 2e6))
    monkeypatch.setattr(_stored, "_folder", lambda: None)  # JAX's cache off
    stored(law, jnp.ones(2), scale=1.0, name="a")
    assert not folder.exists() or not list(folder.iterdir())


def test_a_call_on_its_own_takes_its_options_and_under_a_jit_the_jits(folder):
    """`eager_options` serve a call with no trace around it (its key holds them); a call
    inside a `jit` that closes over concrete arrays passes none (JAX refuses options on a
    nested `jit`): the same values. The library's solves take the quick options so."""
    asked = []

    def quick():
        asked.append(1)
        return _compiling.quick_options()

    _solve_like.__module__ = "jaximpact._stored_test_fixture"
    stored = _stored.stored_jit(_solve_like, eager_options=quick)
    law = ji.law("hunt_crossley", c=2e6, a=0.1)
    x = jnp.ones(2)
    alone = stored(law, x, scale=1.0, name="a")["y"]
    inside = jax.jit(lambda: stored(law, x, scale=1.0, name="a")["y"])()
    assert len(asked) == 1
    np.testing.assert_array_equal(np.asarray(alone), np.asarray(inside))
    # the library's solve (`solve_jit`), here on the universal curve (a cheap compile; the
    # integrated path under jit and eagerly: tests/solve/test_solve_options.py, slow)
    hertz = ji.law("hertz_rate", c=2e6, b1=800.0)
    eager = float(ji.impact(hertz, m=1.0, v0=2.5).e)
    jitted = float(jax.jit(lambda: ji.impact(hertz, m=1.0, v0=2.5).e)())
    assert jitted == pytest.approx(eager, rel=1e-12)


@pytest.mark.slow
def test_a_second_command_traces_no_fit_program_and_prints_the_same(tmp_path):
    """End to end, two processes of `jaximpact calibrate --law all` (a closed form, the
    curves and a two-group table among the fits): the second loads every fit program
    (JAX's log shows no trace of one) and prints the same report."""
    import os
    import subprocess
    import sys

    drops = os.path.join(os.path.dirname(__file__), "..", "examples", "data", "drops.csv")
    argv = ["calibrate", "--law", "all", "--mass", "0.0027", "--data", drops]
    env = {**os.environ, "JAXIMPACT_CACHE_DIR": str(tmp_path), "JAX_LOG_COMPILES": "1"}
    script = os.path.join(os.path.dirname(sys.executable), "jaximpact")  # the console script
    runs = [
        subprocess.run([script, *argv], capture_output=True, text=True, env=env) for _ in range(2)
    ]
    for run in runs:
        assert run.returncode == 0, run.stderr[-2000:]
    assert runs[0].stdout == runs[1].stdout
    assert "Finished tracing flat" in runs[0].stderr  # stored by the first
    assert "Finished tracing flat" not in runs[1].stderr
    assert "Finished tracing _evaluated" not in runs[1].stderr
    assert len(list((tmp_path / _stored._FOLDER).glob("*.program"))) >= 11
