"""`jaximpact bench`, run in-process through `main(argv)`.

One `--quick` run of Kelvin-Voigt (its closed form and `method="integrate"`: two compiled
solves, about 25 s on 2 cores) is shared by the tests below; every input error is caught
before any computation.
"""

import contextlib
import io
import json
import math

import pytest

from jaximpact._cli import bench as _cli_bench, main


def run(argv):
    """`main(argv)` with its stdout and stderr captured: (status, out, err)."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            status = main(argv)
        except SystemExit as exit:
            status = exit.code
    return status, out.getvalue(), err.getvalue()


@pytest.fixture(autouse=True)
def _no_persistent_cache(monkeypatch):
    """Keep the CLI from writing JAX's compilation cache into the user's home."""
    monkeypatch.setenv("JAXIMPACT_CACHE_DIR", "")


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """One `jaximpact bench --quick --laws kelvin_voigt --json --plot FILE` run."""
    plot = tmp_path_factory.mktemp("bench") / "ratios.png"
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("JAXIMPACT_CACHE_DIR", "")
        argv = ["bench", "--quick", "--laws", "kelvin_voigt", "--json", "--plot", str(plot)]
        status, out, err = run(argv)
    return status, out, err, plot


@pytest.mark.slow
def test_json_has_the_ratio_rows(quick):
    status, out, err, _ = quick
    assert status == 0, err
    data = json.loads(out)  # one JSON object
    cases = [row["case"] for row in data["rows"]]
    assert cases == ["kelvin_voigt", "kelvin_voigt (integrate)"]
    assert [row["path"] for row in data["rows"]] == ["closed_form", "integrated"]
    for row in data["rows"]:
        for key in ("single_s", "batch_s", "scipy_s", "ratio_single", "ratio_batch"):
            assert isinstance(row[key], float) and math.isfinite(row[key]) and row[key] > 0, key
        assert row["compile_s"] > 0 and row["batch_compile_s"] > 0
        assert row["target_single"] == 50 and row["target_batch"] == 1000
        assert isinstance(row["target_single_met"], bool)
        assert row["ratio_single"] == pytest.approx(row["scipy_s"] / row["single_s"], rel=1.0)
        # scipy was run at the loosest rtol reaching the target error in e
        assert row["scipy_err_e"] <= 1e-9
    machine = data["machine"]
    assert machine["cpu_count"] >= 1 and machine["backend"] and machine["load_average"]


@pytest.mark.slow
def test_default_impact_is_accurate(quick):
    data = json.loads(quick[1])
    for row in data["rows"]:
        assert row["reference"] == "closed form"
        assert row["err_e"] <= 1e-9 and row["batch_err_e"] <= 1e-9
        assert row["err_T"] <= 1e-8
    euler = data["euler"]  # the seed paper's Euler at 2e-5 s is far from converged
    assert euler["law"] == "hertz_rate" and euler["dt"] == 2e-5
    assert 1e-4 < euler["err_e"] < 0.5


@pytest.mark.slow
def test_plot_is_a_png(quick):
    plot = quick[3]
    assert plot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert json.loads(quick[1])["plot"] == str(plot)


@pytest.mark.slow
def test_text_table(quick):
    data = json.loads(quick[1])
    text = _cli_bench._text(data, width=400)  # unwrapped (wrapping: test_assumptions.py)
    assert "load average" in text and "CPUs" in text and "backend" in text
    assert "single (>= 50x)" in text and "batch (>= 1000x)" in text
    assert "kelvin_voigt (integrate)" in text and "explicit Euler" in text


def test_bad_law_is_one_line():
    status, out, err = run(["bench", "--quick", "--laws", "kelvin"])
    assert status == 2 and not out
    assert len(err.strip().splitlines()) == 1 and "kelvin" in err


def test_missing_scipy_says_how_to_install(monkeypatch):
    def missing():
        raise ImportError("no scipy")

    monkeypatch.setattr(_cli_bench, "require_scipy", missing)
    status, out, err = run(["bench", "--quick", "--laws", "maxwell"])
    assert status == 2 and not out
    assert err.strip().splitlines() == [
        "jaximpact: error: jaximpact bench compares against scipy: pip install scipy"
    ]
