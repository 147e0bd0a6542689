"""`run_batch`, `impact_batch`, `write_table`: chunks, padding, cost ordering, devices.

Compilation dominates. Every impact batch here (and in test_maps.py and test_design.py) uses
one configuration, `ET` below: hertz_rate, e and T only, blocks of 64 rows, so it compiles
once per process. The sharded run is a subprocess with 4 forced host devices, started by the
first test and collected by the last, so that its compilations overlap with this file's.
"""

import json
import os
import subprocess
import sys

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import assert_rel
from reference import reference_impact

import jaximpact as ji
from jaximpact._batch import block_length, impact_batch, run_batch, write_table
from jaximpact._progress import TextMeter

BLOCK = 64  # rows per device per call in every impact batch of these tests
ET = dict(peaks=False, fields=("e", "T", "status"), chunk_size=BLOCK, progress=False)
N_SHARDED = 4 * BLOCK * 2 + 17  # two rounds over 4 devices, the last one partial


def wide_population(n, seed=1):
    """hertz_rate over decades, heavily damped members included (step counts 57 to 101)."""
    rng = np.random.default_rng(seed)
    lu = lambda a, b: np.exp(rng.uniform(np.log(a), np.log(b), n))  # noqa: E731
    return dict(c=lu(1e5, 1e8), b1=lu(1, 1e4)), lu(0.01, 10), lu(0.1, 10)


_CHILD = """
import sys
import jax
import numpy as np
jax.config.update("jax_enable_x64", True)
sys.path[:0] = [{tests!r}, {root!r}]
from test_batch import ET, N_SHARDED, wide_population
from jaximpact._batch import impact_batch
assert len(jax.local_devices()) == 4, jax.local_devices()
params, m, v0 = wide_population(N_SHARDED)
out = impact_batch("hertz_rate", params, m=m, v0=v0, exact={exact}, **ET)
single = impact_batch("hertz_rate", params, m=m, v0=v0, devices=1, **ET)
np.savez({path!r}, **out, **{{"single_" + k: v for k, v in single.items()}})
"""


def _start_sharded(tmp_path, exact):
    path = str(tmp_path / f"sharded_{exact}.npz")
    here = os.path.dirname(__file__)
    code = _CHILD.format(tests=here, root=os.path.dirname(here), exact=exact, path=path)
    # XLA's default optimisation (not conftest's level 0, under which the arithmetic of a
    # block depends on its shape), four host devices; the one-device run in the same child
    suite = ("--xla_backend_optimization_level=", "--xla_cpu_use_fusion_emitters=")
    flags = [f for f in os.environ.get("XLA_FLAGS", "").split() if not f.startswith(suite)]
    env = dict(os.environ, XLA_FLAGS=" ".join([*flags, "--xla_force_host_platform_device_count=4"]))
    env.pop("JAX_PLATFORMS", None)
    process = subprocess.Popen(
        [sys.executable, "-c", code], env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE
    )
    return process, path


@pytest.fixture(scope="module")
def sharded_exact(tmp_path_factory):
    """The 4-device run, started in the background at the first test that asks for it."""
    return _start_sharded(tmp_path_factory.mktemp("sharded"), exact=True)


def _finish(process, path):
    _, stderr = process.communicate(timeout=600)
    assert process.returncode == 0, stderr.decode()[-3000:]
    with np.load(path) as data:
        single = {k[7:]: data[k] for k in data.files if k.startswith("single_")}
        return {k: data[k] for k in data.files if not k.startswith("single_")}, single


# ----------------------------------------------------------------------------- run_batch


def test_run_batch_chunks_pads_and_restores_order(sharded_exact, capsys):
    f = lambda row: {"y": jnp.sin(row["x"]) * row["w"], "pair": jnp.stack([row["x"], -row["x"]])}  # noqa: E731
    x = np.linspace(0.0, 3.0, 37)
    inputs = {"x": x, "w": np.arange(37.0)}
    expected = np.sin(x) * np.arange(37.0)
    out = run_batch(f, inputs, chunk_size=8, progress=TextMeter())  # True: off in the tests
    assert out["y"].shape == (37,) and out["pair"].shape == (37, 2)
    np.testing.assert_array_equal(out["pair"][:, 1], -x)
    assert_rel(out["y"], expected, 1e-15, "chunked result", atol=1e-300)
    bar = capsys.readouterr().err
    assert "37/37 rows" in bar and "5/5" in bar  # 37 rows in 5 blocks of 8

    # in a cost order (reversed) and back: the same numbers, in the caller's order
    again = run_batch(f, inputs, chunk_size=8, progress=False, cost=-x)
    np.testing.assert_array_equal(again["y"], out["y"])
    two_keys = run_batch(f, inputs, chunk_size=8, progress=False, cost=(x > 1.5, -x))
    np.testing.assert_array_equal(two_keys["y"], out["y"])

    # batched=True: fn takes whole blocks
    blocks = run_batch(lambda r: r["x"] * 2, inputs, chunk_size=8, batched=True, progress=False)
    np.testing.assert_array_equal(blocks, 2 * x)

    empty = run_batch(f, {"x": x[:0], "w": x[:0]}, progress=False)
    assert empty["y"].shape == (0,) and empty["pair"].shape == (0, 2)


def test_block_length():
    assert block_length(1, 1024, 1) == 2  # never one row: see the test below
    assert block_length(1, 1, 1) == 1  # unless asked for
    assert block_length(10, 1024, 1) == 16
    assert block_length(1000, 1024, 1) == 1024
    assert block_length(10**6, 1024, 4) == 1024
    assert block_length(100, 1024, 4) == 32  # 4 blocks of 32 rows
    assert block_length(3, 1024, 4) == 2


_ONE_ROW_AMONG_OTHERS = """
import sys
import jax
jax.config.update("jax_enable_x64", True)
import numpy as np
import jaximpact as ji
rng = np.random.default_rng(11)
c, b1 = rng.uniform(1e6, 3e6, 6), rng.uniform(100.0, 900.0, 6)
m, v0 = rng.uniform(0.1, 1.0, 6), rng.uniform(0.5, 3.0, 6)
c[5], b1[5] = 1262456.058094433, 245.0116533850106  # e 9e-14 apart alone (a file's row)
m[5], v0[5] = 0.045217726877444055, 1.6432672801068597
bits = []
for rows in ([5], [0, 1, 5], [0, 1, 2, 3, 4, 5]):
    out = ji.impact_batch("hertz_rate", {"c": c[rows], "b1": b1[rows]}, m=m[rows],
                          v0=v0[rows], g=9.81, separation="penetration", progress=False,
                          fields=("e", "T"))
    bits.append((out["e"][-1].hex(), out["T"][-1].hex()))
print(bits)
sys.exit(len(set(bits)) != 1)
"""


@pytest.mark.slow
def test_a_row_gives_the_same_bits_alone_or_among_others():
    """An integrated impact (gravity on) of one row, alone and in batches of 3 and 6 rows
    (blocks of 2, 4 and 8), compiled as users compile (XLA's default optimisation, not the
    suite's level 0): bitwise the same e and T. XLA's vmap over a single row gave this row
    another last bit, so blocks hold at least 2 rows: a file's output must not depend on how
    its rows fall into groups, chunks or processes."""
    env = {k: v for k, v in os.environ.items() if k != "XLA_FLAGS"}
    done = subprocess.run(
        [sys.executable, "-c", _ONE_ROW_AMONG_OTHERS],
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stdout + done.stderr[-2000:]


def test_run_batch_rejects_bad_inputs():
    f = lambda row: row["x"]  # noqa: E731
    with pytest.raises(ValueError, match="same number of rows"):
        run_batch(f, {"x": np.ones(3), "y": np.ones(4)}, progress=False)
    with pytest.raises(ValueError, match="not a scalar"):
        run_batch(f, {"x": 1.0}, progress=False)
    with pytest.raises(ValueError, match="chunk_size"):
        run_batch(f, {"x": np.ones(3)}, chunk_size=0, progress=False)
    with pytest.raises(ValueError, match="one value per row"):
        run_batch(f, {"x": np.ones(3)}, cost=np.ones(2), progress=False)
    with pytest.raises(ValueError, match="local devices"):
        run_batch(f, {"x": np.ones(3)}, devices=len(jax.local_devices()) + 1, progress=False)


# ----------------------------------------------------------------------------- tables


def test_write_table_csv_and_json(tmp_path):
    columns = {
        "e": np.array([0.5, 1 / 3, np.nan]),
        "status": np.array([0, 2, 3], dtype=np.int32),
        "T": np.array([1e-3, 2.5e-3, np.inf]),
    }
    csv_path = write_table(tmp_path / "t.csv", columns)
    lines = open(csv_path).read().splitlines()
    assert lines[0] == "e,status,T"
    assert len(lines) == 4
    back = np.genfromtxt(csv_path, delimiter=",", names=True)
    np.testing.assert_array_equal(back["e"][:2], columns["e"][:2])  # exact round trip
    assert np.isnan(back["e"][2]) and np.isinf(back["T"][2])

    data = json.load(open(write_table(tmp_path / "t.json", columns)))
    assert data["columns"] == ["e", "status", "T"] and data["rows"] == 3
    assert data["data"]["e"][:2] == [0.5, 1 / 3] and data["data"]["e"][2] is None
    assert data["data"]["status"] == [0, 2, 3] and data["data"]["T"][2] is None

    with pytest.raises(ValueError, match="equal lengths"):
        write_table(tmp_path / "bad.csv", {"a": np.ones(2), "b": np.ones(3)})
    with pytest.raises(ValueError, match=".csv or .json"):
        write_table(tmp_path / "t.parquet", columns)
    with pytest.raises(ValueError, match="1-D"):
        write_table(tmp_path / "t.csv", {"a": np.ones((2, 2))})


# ----------------------------------------------------------------------------- impacts


def test_impact_batch_matches_scipy_and_any_order():
    params, m, v0 = wide_population(200)
    out = impact_batch("hertz_rate", params, m=m, v0=v0, **ET)
    assert set(out) == {"e", "T", "status"} and out["e"].shape == (200,)
    assert np.all(out["status"] == ji.Status.separated)
    for i in (0, 7, 61, 150, 199):  # an independent integrator, one row at a time
        ref = reference_impact(
            "hertz_rate", {k: v[i] for k, v in params.items()}, m=m[i], v0=v0[i], rtol=1e-12
        )
        assert_rel(out["e"][i], ref["e"], 1e-7, f"e[{i}]")
        assert_rel(out["T"][i], ref["T"], 1e-7, f"T[{i}]")
    # sorted by cost or not: every member's result is the same to the last bit
    given = impact_batch("hertz_rate", params, m=m, v0=v0, order="given", **ET)
    for key in out:
        np.testing.assert_array_equal(given[key], out[key])


def test_impact_batch_broadcasts_and_takes_a_law():
    law = ji.law("hertz_rate", c=2e6, b1=800.0)
    b1 = np.linspace(200.0, 2000.0, 70)
    a = impact_batch(law, {"b1": b1}, m=1.0, v0=2.5, **ET)
    b = impact_batch("hertz_rate", {"c": np.full(70, 2e6), "b1": b1}, m=np.ones(70), v0=2.5, **ET)
    for key in a:
        np.testing.assert_array_equal(a[key], b[key])
    assert np.all(np.diff(a["e"]) < 0)  # more damping, less restitution


def test_kelvin_voigt_batch_takes_the_closed_form():
    c, b = np.geomspace(2e6, 2e7, 300), np.linspace(200.0, 1000.0, 300)
    out = impact_batch("kelvin_voigt", {"c": c, "b": b}, m=1.0, v0=2.5, progress=False)
    exact = ji.closed_forms.kelvin_voigt(c, b, 1.0, 2.5)
    for key in ("e", "T", "x_max", "F_max"):
        assert_rel(out[key], exact[key], 1e-14, key)


def test_impact_batch_rejects_bad_inputs():
    with pytest.raises(ValueError, match="unknown law"):
        impact_batch("no_such_law", {"c": 1.0}, m=1.0, v0=1.0)
    with pytest.raises(ValueError, match="needs b1"):
        impact_batch("hertz_rate", {"c": 2e6}, m=1.0, v0=1.0)
    with pytest.raises(ValueError, match=r"mass m .* got -1.0 at index 1"):
        impact_batch(
            "hertz_rate", {"c": 2e6, "b1": 800.0}, m=np.array([1.0, -1.0]), v0=1.0, invalid="raise"
        )
    with pytest.raises(ValueError, match="impact speed v0"):  # no good row to run
        impact_batch("hertz_rate", {"c": 2e6, "b1": 800.0}, m=1.0, v0=np.array([np.nan, -1.0]))
    with pytest.raises(ValueError, match="invalid must be"):
        impact_batch("hertz_rate", {"c": 2e6, "b1": 800.0}, m=1.0, v0=1.0, invalid="skip")
    with pytest.raises(ValueError, match="broadcast"):
        impact_batch("hertz_rate", {"c": np.ones(3), "b1": np.ones(4)}, m=1.0, v0=1.0)
    with pytest.raises(ValueError, match="unknown fields"):
        impact_batch("hertz_rate", {"c": 2e6, "b1": 800.0}, m=1.0, v0=1.0, fields=("E",))
    with pytest.raises(TypeError, match="law name"):
        impact_batch(42, {}, m=1.0, v0=1.0)


def test_a_bad_row_gets_its_own_status_and_the_others_their_results():
    """A NaN speed, a negative mass and a zero stiffness among good rows: those rows are
    `Status.invalid` with NaN results (and a warning that names the first), the others
    equal a batch of the good rows alone."""
    n = 64
    v0 = np.linspace(1.0, 3.0, n)
    m = np.ones(n)
    c = np.full(n, 2e6)
    v0[5], m[17], c[40] = np.nan, -1.0, 0.0
    with pytest.warns(UserWarning, match="3 of 64 rows .* first at row 5"):
        out = impact_batch("hertz_rate", {"c": c, "b1": 800.0}, m=m, v0=v0, **ET)
    bad = np.isin(np.arange(n), [5, 17, 40])
    assert np.all(out["status"][bad] == ji.Status.invalid)
    assert np.all(np.isnan(out["e"][bad])) and np.all(np.isnan(out["T"][bad]))
    good = impact_batch("hertz_rate", {"c": c[~bad], "b1": 800.0}, m=m[~bad], v0=v0[~bad], **ET)
    for key in ("e", "T", "status"):
        np.testing.assert_array_equal(out[key][~bad], good[key], err_msg=key)


# ----------------------------------------------------------------------------- devices


def test_sharded_over_4_devices_equals_one_device_exactly(sharded_exact):
    """Last in the file: the subprocess has been compiling since the first test."""
    sharded, single = _finish(*sharded_exact)
    assert set(sharded) == set(single)
    for key in single:
        np.testing.assert_array_equal(sharded[key], single[key], err_msg=key)


@pytest.mark.slow
def test_spmd_over_4_devices_agrees_with_one_device(tmp_path):
    """`exact=False` (one SPMD program): equal up to the last bits (XLA partitions it)."""
    sharded, single = _finish(*_start_sharded(tmp_path, exact=False))
    np.testing.assert_array_equal(sharded["status"], single["status"])
    for key in ("e", "T"):
        assert_rel(sharded[key], single[key], 1e-12, key)


@pytest.mark.slow
def test_impact_batch_with_gravity_and_a_custom_law():
    """Gravity per row, and a user's own law, against single `impact` calls."""
    g = np.array([0.0, 9.81, 9.81, 30.0])
    b1 = np.array([200.0, 800.0, 1500.0, 800.0])
    out = impact_batch("hertz_rate", {"c": 2e6, "b1": b1}, m=1.0, v0=0.5, g=g, **ET)
    for i in range(4):
        law = ji.law("hertz_rate", c=2e6, b1=b1[i])
        # the batch reads every row off the gravity table (at g = 0 the one-group curve),
        # as single calls do; both within 1e-9 of the integration
        one = ji.impact(law, m=1.0, v0=0.5, g=g[i], peaks=False)
        assert_rel(out["e"][i], one.e, 1e-12, f"e[{i}]")
        assert_rel(out["T"][i], one.T, 1e-12, f"T[{i}]")
        solved = ji.impact(law, m=1.0, v0=0.5, g=g[i], peaks=False, method="integrate")
        assert_rel(out["e"][i], solved.e, 1e-9, f"e[{i}] against the integration")
        assert_rel(out["T"][i], solved.T, 1e-9, f"T[{i}] against the integration")

    def force(x, v, p):
        return p["k"] * ji.safe_pow(x, 1.5) + p["d"] * ji.safe_pow(x, 0.5) * v

    custom = ji.custom_law(force, k=2e6, d=800.0)
    mine = impact_batch(custom, {"d": b1}, m=1.0, v0=2.5, **ET)
    builtin = impact_batch("hertz_rate", {"c": 2e6, "b1": b1}, m=1.0, v0=2.5, **ET)
    assert_rel(mine["e"], builtin["e"], 1e-7, "custom e")
    assert_rel(mine["T"], builtin["T"], 1e-7, "custom T")
