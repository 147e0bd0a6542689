"""Every script of examples/ runs from a fresh install and writes its plot (slow set).

Each runs in its own process, in a temporary directory, as a user would run it; the seconds
each took are printed (`pytest -m slow -s tests/test_examples.py`). The scripts that read
measurements use ../shared/data when it is there and the synthetic samples of examples/data
otherwise: `test_example_runs_on_the_samples` runs them from a copy of examples/ with no
shared data next to it, as from a fresh clone.
"""

import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
NEEDS_DATA = {"fit_microphone_impacts.py", "fit_video_trajectory.py", "pick_a_law.py"}
OUTPUTS = {  # script -> (arguments, files it must write)
    "batch_100k.py": ([], ["batch_100k.png", "batch_100k.csv"]),
    "batch_from_file.py": ([], ["batch_from_file.png", "impacts.csv", "streamed_impacts.csv"]),
    "bounce_paper_section7.py": ([], ["bounce_section7.png"]),
    "bumper_design.py": ([], ["bumper_design.png"]),
    "calibrate_e_and_T.py": ([], ["calibration.png"]),
    "drop_design.py": ([], ["drop_design.png"]),
    "export_to_engines.py": ([], ["export_to_engines.png"]),
    "fit_microphone_impacts.py": ([], ["microphone_impacts.png"]),
    "fit_video_trajectory.py": ([], ["video_trajectory.png"]),
    "maps.py": (["--out", "maps"], ["maps"]),
    "oblique_rebounds.py": ([], ["oblique_rebounds.png"]),
    "pick_a_law.py": ([], ["pick_a_law.png"]),
    "plastic_and_sticky.py": ([], ["plastic_and_sticky.png"]),
    "posterior_to_engine.py": ([], ["posterior.png"]),
    "uncertainty_propagation.py": ([], ["uncertainty.png"]),
}


def test_every_example_is_listed():
    assert {p.name for p in (ROOT / "examples").glob("*.py")} == set(OUTPUTS)


def test_samples_are_small():
    sizes = [p.stat().st_size for p in (ROOT / "examples" / "data").rglob("*.csv")]
    assert len(sizes) == 5 and all(0 < size < 20_000 for size in sizes)


@pytest.mark.slow
def test_make_samples_writes_the_shipped_samples(tmp_path):
    """examples/data/make_samples.py writes the shipped samples again byte for byte (fixed
    seeds; it compiles one impact solve per ball)."""
    data = ROOT / "examples" / "data"
    shipped = {p.relative_to(data): p.read_bytes() for p in data.rglob("*.csv")}
    assert len(shipped) == 5 and all(0 < len(b) < 20_000 for b in shipped.values())
    copy = tmp_path / "data"
    copy.mkdir()
    shutil.copy(data / "make_samples.py", copy)
    subprocess.run([sys.executable, str(copy / "make_samples.py")], check=True, capture_output=True)
    assert {p.relative_to(copy): p.read_bytes() for p in copy.rglob("*.csv")} == shipped


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(OUTPUTS))
def test_example_runs(script, tmp_path):
    run_example(ROOT / "examples" / script, tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(NEEDS_DATA))
def test_example_runs_on_the_samples(script, tmp_path):
    """From a copy of examples/ with no ../shared/data beside it (a fresh clone)."""
    clone = tmp_path / "clone"
    shutil.copytree(ROOT / "examples", clone / "examples")
    assert not (clone.parent / "shared").exists()
    out = tmp_path / "out"
    out.mkdir()
    stdout = run_example(clone / "examples" / script, out)
    assert "examples/data" in stdout
    # the output says the data are made up (and by what), and judges the fits
    data_line = next(line for line in stdout.splitlines() if line.startswith("data: "))
    assert data_line.startswith("data: SYNTHETIC") and "make_samples.py" in data_line
    assert "measured" not in data_line and "verdict" in stdout
    if script == "pick_a_law.py":  # e falling linearly with v0: no law fits within the errors
        assert "pingpong ball (synthetic data)" in stdout
        assert "does NOT fit these data: reduced chi-square" in stdout


def test_examples_give_law_14_its_units():
    """b1 of law 14 (F = c x^1.5 + b1 x^0.5 v) is in N s/m^1.5 wherever an example names
    its unit, and no example calls its made-up targets measured."""
    import re

    for path in (ROOT / "examples").glob("*.py"):
        text = path.read_text()
        for exponent in re.findall(r"b1[^\n]{0,40}?N s/m\^([\d.]+)", text):
            assert exponent == "1.5", f"{path.name}: b1 in N s/m^{exponent}"
        assert "we measured" not in text, path.name


def run_example(path, cwd):
    script = path.name
    arguments, outputs = OUTPUTS[script]
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, str(path), *arguments],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=900,
    )
    seconds = time.perf_counter() - start
    print(f"\n{script}: {seconds:.1f} s")
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Traceback" not in done.stderr
    for name in outputs:
        written = cwd / name
        assert written.exists() and (written.is_dir() or written.stat().st_size > 5_000), name
    return done.stdout
