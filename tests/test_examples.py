"""Every script of examples/ runs from a fresh install and writes its plot (slow set).

Each runs in its own process, in a temporary directory, as a user would run it; the seconds
each took are printed (`pytest -m slow -s tests/test_examples.py`). Scripts that read the
shared measurements skip, saying so, when ../shared/data is not there.
"""

import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"
NEEDS_DATA = {"fit_microphone_impacts.py", "fit_video_trajectory.py", "pick_a_law.py"}
OUTPUTS = {  # script -> (arguments, files it must write)
    "batch_100k.py": ([], ["batch_100k.png", "impacts.csv"]),
    "bounce_paper_section7.py": ([], ["bounce_section7.png"]),
    "bumper_design.py": ([], ["bumper_design.png"]),
    "calibrate_e_and_T.py": ([], ["calibration.png"]),
    "drop_design.py": ([], ["drop_design.png"]),
    "fit_microphone_impacts.py": ([], ["microphone_impacts.png"]),
    "fit_video_trajectory.py": ([], ["video_trajectory.png"]),
    "maps.py": (["--out", "maps"], ["maps"]),
    "pick_a_law.py": ([], ["pick_a_law.png"]),
    "uncertainty_propagation.py": ([], ["uncertainty.png"]),
}


def test_every_example_is_listed():
    assert {p.name for p in (ROOT / "examples").glob("*.py")} == set(OUTPUTS)


@pytest.mark.slow
@pytest.mark.parametrize("script", sorted(OUTPUTS))
def test_example_runs(script, tmp_path):
    if script in NEEDS_DATA and not DATA.is_dir():
        pytest.skip(f"{script} reads ../shared/data, which is not here")
    arguments, outputs = OUTPUTS[script]
    start = time.perf_counter()
    done = subprocess.run(
        [sys.executable, str(ROOT / "examples" / script), *arguments],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=900,
    )
    seconds = time.perf_counter() - start
    print(f"\n{script}: {seconds:.1f} s")
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Traceback" not in done.stderr
    for name in outputs:
        path = tmp_path / name
        assert path.exists() and (path.is_dir() or path.stat().st_size > 5_000), name
