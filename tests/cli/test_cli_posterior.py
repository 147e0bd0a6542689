"""`jaximpact calibrate --posterior`, `fit --posterior` and `export --from` a posterior's
JSON, run in-process through `main(argv)`. The fast tests check the bad input (one line,
exit status 2, before any compilation) and `export --from` a hand-written posterior (one
export per draw, LAMMPS: milliseconds); the slow ones sample a posterior."""

import json
import math

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

import jaximpact as ji

LAW14 = dict(c=2e6, b1=800.0)
ROWS = [  # hertz_rate at LAW14, m = 1 kg, e to 0.01 and T to 2 % (noise drawn once)
    (0.5, 0.88121, 0.0110902, 0.01, 0.0002182),
    (1.0, 0.86466, 0.0092218, 0.01, 0.0001894),
    (1.5, 0.85994, 0.00879099, 0.01, 0.0001743),
    (2.0, 0.83767, 0.00830876, 0.01, 0.0001643),
    (3.0, 0.83504, 0.00760039, 0.01, 0.0001511),
]


@pytest.fixture(autouse=True)
def _no_persistent_cache(monkeypatch):
    monkeypatch.setenv("JAXIMPACT_CACHE_DIR", "")
    monkeypatch.delenv("JAXIMPACT_DEBUG", raising=False)


@pytest.fixture
def drops(tmp_path):
    path = tmp_path / "drops.csv"
    lines = ["v0,e,T,sigma_e,sigma_T"] + [",".join(map(repr, row)) for row in ROWS]
    path.write_text("\n".join(lines) + "\n")
    return path


CALIBRATE = ["calibrate", "--law", "hertz_rate", "--mass", "1"]


@pytest.mark.parametrize(
    "extra, contains",
    [
        (["--law", "all", "--posterior"], "--posterior takes one law"),
        (["--prior", "c=loguniform:1e5:1e8"], "--prior need --posterior"),
        (["--posterior", "--prior", "c=loguniform:1e5"], "must be NAME=KIND:A:B"),
        (["--posterior", "--prior", "c=flat:1:2"], "unknown prior kind 'flat'"),
        (["--posterior", "--prior", "c=loguniform:1e8:1e5"], "lo must be < hi"),
        (["--posterior", "--draws", "0"], "--draws must be at least 1"),
    ],
)
def test_calibrate_posterior_bad_input(capsys, drops, extra, contains):
    argv = CALIBRATE + ["--data", str(drops)] + extra
    if "all" in extra:
        argv = ["calibrate", "--mass", "1", "--data", str(drops)] + extra
    assert_one_line_error(*run_cli(capsys, argv), contains=contains)


def _posterior_file(tmp_path, samples=True):
    """A fit's JSON with a posterior of three draws, as `calibrate --posterior --json`
    writes it (by hand: the draws are c and b1 about LAW14)."""
    draws = {"c": [1.9e6, 2.0e6, 2.1e6], "b1": [760.0, 800.0, 850.0]}
    posterior = {
        "method": "laplace",
        "law": "hertz_rate",
        "names": ["c", "b1"],
        "free": ["c", "b1"],
        "units": {"c": "N/m^1.5", "b1": "N s/m^1.5"},
        "priors": {"c": ["loguniform", 1e5, 1e8], "b1": ["loguniform", 10.0, 1e5]},
        "median": {"c": 2.0e6, "b1": 800.0},
        "map": {"c": 2.0e6, "b1": 800.0},
        "diagnostics": {"r_hat": None, "ess": 3.0, "divergences": 0},
        "log_evidence": 1.0,
        "noise": "normal",
        "nu": 4.0,
        "law_parameters": {"c": 1.5e6, "b1": 500.0},
    }
    if samples:
        posterior["samples"] = draws
        posterior["z"] = [[0.0, 0.0]] * 3
        posterior["thinned"] = {"draws": 3, "of": 8000}
    record = {
        "law": "hertz_rate",
        "params": {"c": 1.5e6, "b1": 500.0},
        "free": ["c", "b1"],
        "m": 1.0,
        "rows": [{"v0": 2.0}],
        "separation": "force",
        "g": 0.0,
        "posterior": posterior,
    }
    path = tmp_path / "post.json"
    path.write_text(json.dumps(record))
    return path, draws


def test_export_from_a_posterior_gives_the_band(capsys, tmp_path):
    """The law at the posterior medians (not the fit's `params`), and the band over the
    file's draws: the draws exported one by one, at the median export's step."""
    path, draws = _posterior_file(tmp_path)
    argv = ["export", "lammps", "--from", str(path), "--radius", "0.02", "--json"]
    status, out, err = run_cli(capsys, argv)
    assert status == 0, err
    data = json.loads(out)
    assert data["band_draws"] == 3  # (its "law" is the engine's own, tsuji for LAMMPS)
    median = ji.export(ji.law("hertz_rate", **LAW14), "lammps", m=1.0, v0=2.0, radius=0.02)
    assert data["e"] == pytest.approx(median.e, rel=1e-12)
    es, Ts = [], []
    for c, b1 in zip(draws["c"], draws["b1"], strict=True):
        one = ji.export(
            ji.law("hertz_rate", c=c, b1=b1),
            "lammps",
            m=1.0,
            v0=2.0,
            radius=0.02,
            timestep=median.timestep,
            curves=False,
            strict=False,
        )
        es.append(one.e)
        Ts.append(one.T)
    assert data["e_band"] == pytest.approx(list(np.quantile(es, [0.05, 0.95])), rel=1e-12)
    assert data["T_band"] == pytest.approx(list(np.quantile(Ts, [0.05, 0.95])), rel=1e-12)
    status, out, err = run_cli(capsys, argv[:-1])
    assert status == 0, err
    assert "at the posterior medians (band over 3 of its draws, of 8000)" in out
    assert "band     e " in out and "5-95 % over 3 posterior draws" in out


def test_export_from_a_posterior_without_draws_says_so(capsys, tmp_path):
    path, _ = _posterior_file(tmp_path, samples=False)
    argv = ["export", "lammps", "--from", str(path), "--radius", "0.02"]
    status, out, err = run_cli(capsys, argv)
    assert status == 0, err
    assert "warning: no engine band: the posterior in the file holds no draws" in out
    assert "band     e" not in out
    assert_one_line_error(
        *run_cli(capsys, argv + ["--band-draws", "0"]), contains="--band-draws must be at least 1"
    )


@pytest.mark.slow
def test_calibrate_posterior_then_export(capsys, drops, tmp_path):
    """Laplace: medians with 90 % intervals and the evidence in the text, the pairs plot,
    the JSON's summary and 200 draws, and `export --from` that JSON with its band."""
    plot = tmp_path / "post.png"
    argv = CALIBRATE + ["--data", str(drops), "--posterior", "laplace"]
    status, out, err = run_cli(capsys, argv + ["--plot", str(plot)])
    assert status == 0, err
    assert "Posterior of hertz_rate (laplace, 8000 draws; SI units)" in out
    assert "(90 %: " in out and "log_evidence" in out and "diagnostics" in out
    assert plot.stat().st_size > 10_000
    status, out, err = run_cli(capsys, argv + ["--json"])
    assert status == 0, err
    data = json.loads(out)
    post = data["posterior"]
    assert post["method"] == "laplace" and post["thinned"] == {"draws": 200, "of": 8000}
    assert len(post["samples"]["c"]) == 200 and len(post["z"]) == 200
    for k, v in LAW14.items():  # the truth inside the 90 % interval of these data
        lo, hi = post["interval90"][k]
        assert lo < v < hi
    assert math.isfinite(post["log_evidence"])
    path = tmp_path / "post.json"
    path.write_text(out)
    argv = [
        "export",
        "lammps",
        "--from",
        str(path),
        "--v0",
        "2",
        "--radius",
        "0.02",
        "--band-draws",
        "20",
        "--json",
    ]
    status, out, err = run_cli(capsys, argv)
    assert status == 0, err
    x = json.loads(out)
    again = ji.Posterior.from_dict(post)
    law = ji.law("hertz_rate", **{k: post["median"][k] for k in ("c", "b1")})
    median = ji.export(law, "lammps", m=1.0, v0=2.0, radius=0.02)
    assert x["e"] == pytest.approx(median.e, rel=1e-12)
    band = ji.export(again, "lammps", m=1.0, v0=2.0, radius=0.02, band_draws=20, progress=False)
    assert x["e_band"] == pytest.approx(list(band.e_band), rel=1e-12)
    assert x["e_band"][0] < median.e < x["e_band"][1]
