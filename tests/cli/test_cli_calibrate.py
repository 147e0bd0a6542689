"""`jaximpact calibrate`, run in-process through `main(argv)`.

A fit compiles once per (law, free parameters, number of rows, e / T / sigmas given), so the
runs below share three configurations with tests/test_calibrate.py: law 14 at one row and at
five rows, Kelvin-Voigt at five rows (the `--law all` test narrows the model choice to two
laws); the plot adds one impact solve. Every input error is caught before any compilation.
"""

import json
import re

import pytest
from helpers import assert_one_line_error, assert_rel, run_cli
from reference import reference_impact

from jaximpact._cli import common as _cli_common
from jaximpact._fit import model_choice as _model_choice

LAW14 = dict(c=2e6, b1=800.0)
SPEEDS = (0.5, 1.0, 2.5, 5.0, 10.0)
TARGET = reference_impact("hertz_rate", LAW14, m=1.0, v0=2.5)
ONE = ["calibrate", "--law", "hertz_rate", "--mass", "1", "--v0", "2.5"]
ONE += ["--e", repr(TARGET["e"]), "--T", repr(TARGET["T"])]


@pytest.fixture(autouse=True)
def _no_persistent_cache(monkeypatch):
    """Keep the CLI from writing JAX's compilation cache into the user's home."""
    monkeypatch.setenv("JAXIMPACT_CACHE_DIR", "")
    monkeypatch.delenv("JAXIMPACT_DEBUG", raising=False)


@pytest.fixture(scope="module")
def law14_csv(tmp_path_factory):
    """Law 14 at five speeds (scipy), the second row without T."""
    path = tmp_path_factory.mktemp("data") / "drops.csv"
    lines = ["# law 14, c = 2e6, b1 = 800, m = 1 kg", "v0,e,T"]
    for i, v in enumerate(SPEEDS):
        r = reference_impact("hertz_rate", LAW14, m=1.0, v0=v)
        lines.append(f"{v},{r['e']!r},{'' if i == 1 else repr(r['T'])}")
    path.write_text("\n".join(lines) + "\n")
    return path


# --------------------------------------------------------------------- one impact


def test_one_impact_text(capsys):
    status, out, err = run_cli(capsys, ONE)
    assert status == 0 and err == "", err
    assert "law        hertz_rate (eq. 14: F = c x^1.5 + b1 x^0.5 v)" in out
    assert re.search(r"^fitted     c  = 2e6 N/m\^1\.5$", out, flags=re.MULTILINE), out
    assert re.search(r"^           b1 = 800 N s/m\^1\.5$", out, flags=re.MULTILINE), out
    flat = " ".join(out.split())  # the long lines are wrapped to 100 columns
    assert "optimiser converged after" in flat and "start auto" in flat
    assert "7.845 ms" in out  # the T column: measured and fitted
    # one speed, e and T, two parameters: no degree of freedom, an exact fit expected
    assert "goodness   RMS of e_fit - e = " in out and "an exact fit is expected" in flat
    assert "reproduces the data: every residual within 1e-6" in flat
    assert max(len(line) for line in out.splitlines()) <= 100


def test_sanity_echo_shows_grams_typed_as_kilograms(capsys):
    """The fitted law's x_max, F_max and contact time at the measured speed, with the mass
    and the kinetic energy: the same e and T with the mass typed 1000 times too large give
    the same x_max and a force and energy 1000 times larger, in plain sight."""
    status, out, _ = run_cli(capsys, ONE)
    assert status == 0
    check = " ".join(out[out.index("check      ") :].split("\n\n")[0].split())
    assert check.startswith("check m = 1 kg, kinetic energy 3.125 J at v0 = 2.5 m/s")
    reference = reference_impact("hertz_rate", LAW14, m=1.0, v0=2.5)
    x_mm, force = reference["x_max"] * 1e3, reference["F_max"] / 1e3
    assert f"penetration x_max of {x_mm:.4g} mm" in check, check
    assert f"peak force F_max of {force:.4g} kN" in check, check
    assert "contact time of 7.845 ms" in check and "check the units (--mass in kg)" in check
    records = []
    for mass in ("1", "1000"):
        argv = [*ONE, "--json"]
        argv[argv.index("--mass") + 1] = mass
        status, out, _ = run_cli(capsys, argv)
        assert status == 0
        records.append(json.loads(out)["rows"][0])
    assert_rel(records[0]["x_max"], reference["x_max"], 1e-8, "x_max of the fitted law")
    assert_rel(records[0]["F_max"], reference["F_max"], 1e-8, "F_max of the fitted law")
    assert_rel(records[1]["x_max"], records[0]["x_max"], 1e-8, "x_max: set by v0 and T")
    assert_rel(records[1]["F_max"], 1000 * records[0]["F_max"], 1e-8, "F_max scales with m")


def test_one_impact_json_with_start_values(capsys):
    """--param values of fitted parameters are a start (init given); JSON carries the rest."""
    status, out, err = run_cli(capsys, [*ONE, "--param", "c=2e7", "b1=8e3", "--json"])
    assert status == 0 and err == ""
    data = json.loads(out)
    assert data["init"] == "given" and data["start"] == {"c": 2e7, "b1": 8e3}
    assert data["converged"] is True and data["free"] == ["c", "b1"]
    assert_rel(data["params"]["c"], LAW14["c"], 1e-6, "c")
    assert_rel(data["params"]["b1"], LAW14["b1"], 1e-6, "b1")
    (row,) = data["rows"]
    assert row["v0"] == 2.5 and row["e"] == TARGET["e"] and row["T"] == TARGET["T"]
    assert_rel(row["e_fit"], TARGET["e"], 1e-8, "e_fit")
    # an eager fit: Levenberg-Marquardt in Python around one compiled program
    assert data["stderr"] is None and data["optimizer"] == "lm"


def test_progress_bar(capsys, monkeypatch):
    monkeypatch.setenv("JAXIMPACT_PROGRESS", "on")
    monkeypatch.setattr(_cli_common.heartbeat_meter, "__defaults__", (0.0,))  # no delay
    status, _, err = run_cli(capsys, ONE)
    assert status == 0
    assert "calibrating hertz_rate [" in err and "1/1" in err and err.endswith("\n")


# ----------------------------------------------------------------- several speeds


def test_data_file_with_missing_T_and_plot(capsys, tmp_path, law14_csv):
    png = tmp_path / "fit.png"
    argv = ["calibrate", "--mass", "1", "--law", "hertz_rate", "--data", str(law14_csv), "--json"]
    status, out, err = run_cli(capsys, [*argv, "--plot", str(png)])
    assert status == 0 and err == ""
    data = json.loads(out)
    assert data["converged"] is True
    assert_rel(data["params"]["c"], LAW14["c"], 1e-6, "c")
    assert_rel(data["params"]["b1"], LAW14["b1"], 1e-6, "b1")
    assert [row["v0"] for row in data["rows"]] == list(SPEEDS)
    assert data["rows"][1]["T"] is None and data["rows"][1]["T_fit"] > 0
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert png.stat().st_size > 20_000


def test_model_choice(capsys, monkeypatch, law14_csv):
    """`--law all` (narrowed to two laws, plus one whose fit raises): the true law first, the
    failing one reported, not fatal."""
    monkeypatch.setattr(_model_choice, "PAPER_LAWS", ("kelvin_voigt", "maxwell", "hertz_rate"))
    calibrate = _model_choice.calibrate

    def failing_maxwell(start, **kwargs):
        if start.name == "maxwell":
            raise RuntimeError("boom\nsecond line")
        return calibrate(start, **kwargs)

    monkeypatch.setattr(_model_choice, "calibrate", failing_maxwell)
    status, out, err = run_cli(
        capsys, ["calibrate", "--mass", "1", "--law", "all", "--data", str(law14_csv)]
    )
    assert status == 0 and err == ""
    lines = out.splitlines()
    header = next(line.split() for line in lines if line.startswith("rank"))
    assert header == ["rank", "law", "k", "sum_sq", "rms_e", "rms_T", "converged", "parameters"]
    table = [line.split() for line in lines if re.match(r"^\d+\s+\w+", line)]
    assert [row[:2] for row in table] == [["1", "hertz_rate"], ["2", "kelvin_voigt"]]
    # both optimisers converged; only law 14 reproduces the data (RMS of e_fit - e ~ 0)
    assert table[0][6] == "yes" and table[1][6] == "yes"
    assert float(table[0][4]) < 1e-12 < 1e-3 < float(table[1][4])
    assert "ranked by sum_sq, the sum of squared residuals e_fit - e and (T_fit - T)/T" in out
    assert "best: hertz_rate" in out and "fits these data badly" not in out
    assert "failed: maxwell (RuntimeError: boom)" in out
    monkeypatch.setattr(_model_choice, "PAPER_LAWS", ("kelvin_voigt", "hertz_rate"))
    status, out, _ = run_cli(
        capsys, ["calibrate", "--mass", "1", "--law", "all", "--data", str(law14_csv), "--json"]
    )
    data = json.loads(out)
    assert data["best"] == "hertz_rate" and data["criterion"] == "sum_sq"
    assert data["bad_fit"] is None
    best, other = data["ranking"]
    assert best["sum_sq"] < 1e-12 < other["sum_sq"] and other["chi2"] == other["sum_sq"]
    assert best["reproduces"] and best["converged"]
    assert other["converged"] and not other["reproduces"] and other["rms_e"] > 0.01


def test_model_choice_warns_when_the_best_law_fits_badly(capsys, monkeypatch, law14_csv):
    """Kelvin-Voigt alone on law 14's falling e: its optimiser converges, it is the best
    of one, and it fits badly (RMS of e_fit - e above 0.01, no sigmas): a warning line."""
    monkeypatch.setattr(_model_choice, "PAPER_LAWS", ("kelvin_voigt",))
    status, out, err = run_cli(
        capsys, ["calibrate", "--mass", "1", "--law", "all", "--data", str(law14_csv)]
    )
    assert status == 0 and err == ""
    assert "best: kelvin_voigt" in out
    (line,) = [line for line in out.splitlines() if line.startswith("warning:")]
    assert line.startswith("warning: the best law, kelvin_voigt, fits these data badly: RMS")
    assert "badly means an RMS residual above 0.01 in e or 5 % in T" in line


@pytest.mark.slow  # the Laplace approximation of two laws' posteriors compiles
def test_model_choice_by_evidence(capsys, monkeypatch, law14_csv):
    """`--law all --by evidence`: the laws ranked by their evidence, with the Bayes factors'
    table (`compare_laws(by="evidence")`); the true law first, its Bayes factor 1."""
    monkeypatch.setattr(_model_choice, "PAPER_LAWS", ("kelvin_voigt", "hertz_rate"))
    argv = ["calibrate", "--mass", "1", "--law", "all", "--data", str(law14_csv), "--by"]
    status, out, err = run_cli(capsys, [*argv, "evidence"])
    assert status == 0 and err == "", err
    assert "ranked by the evidence" in out and "best: hertz_rate" in out
    header = next(line.split() for line in out.splitlines() if "bayes_factor" in line)
    assert header[:5] == ["rank", "law", "k", "log_evidence", "bayes_factor"]
    status, out, _ = run_cli(capsys, [*argv, "evidence", "--json"])
    data = json.loads(out)
    assert data["criterion"] == "evidence" and data["ranking"][0]["bayes_factor"] == 1.0
    assert data["ranking"][1]["bayes_factor"] > 1.0 and data["ranking"][1]["aic_rank"] == 2
    bad = ["calibrate", "--mass", "1", "--law", "hertz_rate", "--v0", "1", "--e", "0.8"]
    assert_one_line_error(*run_cli(capsys, [*bad, "--by", "evidence"]), contains="--law all")


def test_compare_laws_reports_each_law_to_its_callback(monkeypatch):
    """`compare_laws(callback=...)` is called after each law with its place, its name and its
    `Ranking` or the exception of its fit; `errors="skip"` ranks the others (the command
    line's `--law all` goes through it). The fits are stand-ins (no solve)."""
    from types import SimpleNamespace

    import jax.numpy as jnp

    def stand_in(start, **kwargs):
        if start.name == "maxwell":
            raise RuntimeError("boom")
        return SimpleNamespace(residuals=jnp.asarray([0.1 if start.name == "hertz_rate" else 0.2]))

    monkeypatch.setattr(_model_choice, "calibrate", stand_in)
    seen = []
    kwargs = dict(m=1.0, v0=[1.0, 2.0, 3.0], e=[0.9, 0.85, 0.8], progress=False, warn=False)
    kwargs.update(laws=("kelvin_voigt", "maxwell", "hertz_rate"))
    ranked = _model_choice.compare_laws(
        **kwargs, errors="skip", callback=lambda *call: seen.append(call)
    )
    assert [r.name for r in ranked] == ["hertz_rate", "kelvin_voigt"]
    assert sorted((i, name, type(r).__name__) for i, name, r in seen) == [
        (0, "kelvin_voigt", "Ranking"),
        (1, "maxwell", "RuntimeError"),
        (2, "hertz_rate", "Ranking"),
    ]
    with pytest.raises(RuntimeError, match="boom"):
        _model_choice.compare_laws(**kwargs)


# -------------------------------------------------------------------- bad input


def _csv(tmp_path, text):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    return str(path)


BAD = [
    (["--v0", "2.5", "--e", "1.5"], "restitution e must lie in (0, 1]"),
    (["--v0", "2.5", "--e", "0.8", "--T", "-0.001"], "contact durations T must be finite and > 0"),
    (["--v0", "0", "--e", "0.8"], "impact speed v0"),
    (["--v0", "2.5", "--e", "0.8", "--mass", "0"], "--mass must be a finite number > 0"),
    (["--v0", "2.5"], "give --v0 and --e"),
    (["--e", "0.8"], "give --v0 and --e"),
    (["--v0", "2.5", "--e", "0.8", "--free", "c,k"], "cannot fit k"),
    (["--v0", "2.5", "--e", "0.8", "--param", "q=3"], "no parameter q"),
    (["--v0", "2.5", "--e", "0.8", "--T", "8e-3", "--sigma-e", "0.01"], "sigma_e and sigma_T"),
    (["--v0", "2.5", "--e", "0.8", "--sigma-T", "1e-4"], "sigma_T is given without any T"),
    (["--v0", "2.5", "--e", "0.8", "--plot", "fit.xyz"], "unknown figure format"),
    (["--v0", "2.5", "--e", "0.8", "--max-iter", "0"], "--max-iter"),
    (["--v0", "2.5", "--e", "0.8"], "--mass is required: the body's mass in kg"),
]


@pytest.mark.parametrize("argv, contains", BAD, ids=[c for _, c in BAD])
def test_bad_input_is_one_line(capsys, argv, contains):
    """Each as one line; a mass is asked for, never assumed (it was 1 kg by default)."""
    law = ["--law", "hertz_rate"]
    if "--mass" not in [*argv, contains.split()[0]]:  # the mass is what the case is about
        argv = [*argv, "--mass", "1"]
    assert_one_line_error(*run_cli(capsys, ["calibrate", *law, *argv]), contains=contains)


BAD_FILES = [
    ("v0,e,T\n2.5,0.8,8e-3\n3,,7e-3\n", "line 3: no e"),
    ("v0,e,x\n2.5,0.8,1\n", "unknown column 'x'"),
    ("e,T\n0.8,8e-3\n", "no column 'v0'"),
    ("v0,e\n2.5,0.8,1\n", "line 2: 3 cells for 2 columns"),
    ("v0,e\n2.5,high\n", "line 2, column e: 'high' is not a number"),
    ("v0,e\n", "has a header but no rows"),
    ("v0,e,T,sigma_e,sigma_T\n1,0.8,8e-3,0.01,\n", "sigma_T is missing on a row with a T"),
    ("v0,e,sigma_e\n1,0.8,0.01\n2,0.7,\n", "sigma_e is missing on some rows"),
    ("v0,e\n1,0.8\n2,1.2\n", "restitution e must lie in (0, 1]"),
]


@pytest.mark.parametrize("text, contains", BAD_FILES, ids=[c for _, c in BAD_FILES])
def test_bad_data_file_is_one_line(capsys, tmp_path, text, contains):
    argv = ["calibrate", "--mass", "1", "--law", "hertz_rate", "--data", _csv(tmp_path, text)]
    assert_one_line_error(*run_cli(capsys, argv), contains=contains)


def test_conflicting_and_missing_sources(capsys, tmp_path):
    path = _csv(tmp_path, "v0,e\n1,0.8\n")
    argv = ["calibrate", "--mass", "1", "--law", "hertz_rate", "--data", path, "--e", "0.8"]
    assert_one_line_error(*run_cli(capsys, argv), contains="give either --data or --e, not both")
    argv = ["calibrate", "--mass", "1", "--law", "hertz_rate", "--data", str(tmp_path / "none.csv")]
    assert_one_line_error(*run_cli(capsys, argv), contains="cannot read --data")
    argv = ["calibrate", "--mass", "1", "--law", "all", "--data", path, "--free", "c"]
    assert_one_line_error(*run_cli(capsys, argv), contains="drop --free and --param")
    argv = ["calibrate", "--mass", "1", "--law", "no_such_law", "--v0", "1", "--e", "0.8"]
    assert_one_line_error(*run_cli(capsys, argv), contains="unknown law 'no_such_law'")


def test_free_accepts_commas_and_words():
    from jaximpact._cli.common import CLIError, free_names

    assert free_names(["c,b1"]) == ("c", "b1") == free_names(["c", "b1"])
    assert free_names(None) is None
    with pytest.raises(CLIError, match="twice"):
        free_names(["c,c"])


def test_model_choice_when_every_law_fails(capsys, monkeypatch, tmp_path):
    monkeypatch.setattr(_model_choice, "PAPER_LAWS", ("maxwell",))

    def failing(start, **kwargs):
        raise RuntimeError("boom")

    monkeypatch.setattr(_model_choice, "calibrate", failing)
    argv = [
        "calibrate",
        "--mass",
        "1",
        "--law",
        "all",
        "--data",
        _csv(tmp_path, "v0,e\n1,0.8\n2,0.7\n"),
    ]
    assert_one_line_error(*run_cli(capsys, argv), contains="no law could be fitted: maxwell")


@pytest.mark.parametrize("limits", [(0.3, 0.4), (0.7, 4.5), (0.05, 20.0)])
def test_the_speed_axis_is_labelled_with_plain_numbers(limits):
    """`calibrate --plot`'s log speed axis: plain numbers (0.3, 2), not `3x10^-1`, whose
    minor labels ran into each other over a short range (`3×10⁻¹4×10⁻¹`)."""
    from jaximpact._plotting import new_figure, plain_log_axis

    fig = new_figure()
    ax = fig.add_subplot()
    ax.set_xscale("log")
    plain_log_axis(ax.xaxis)
    ax.set_xlim(*limits)
    locs = [x for x in ax.xaxis.get_major_locator()() if limits[0] <= x <= limits[1]]
    labels = ax.xaxis.get_major_formatter().format_ticks(locs)
    assert labels, "no labelled tick"
    for where, text in zip(locs, labels, strict=True):  # each the plain number at its tick
        assert float(text) == pytest.approx(where), labels
    minor = ax.xaxis.get_minor_formatter().format_ticks(list(ax.xaxis.get_minor_locator()()))
    assert not any(minor)  # no minor labels to run into the major ones
