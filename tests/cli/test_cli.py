"""The `jaximpact` command line, run in-process through `main(argv)`.

Each impact costs a trace of the solve (about 1-2 s), so the tests ask for as few as they can.
"""

import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import jax
import numpy as np
import pytest

jax.config.update("jax_enable_x64", True)

from helpers import assert_one_line_error, run_cli  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import _cli, _format  # noqa: E402
from jaximpact._cli import common, laws as cli_laws  # noqa: E402
from jaximpact._plotting import plot_impact  # noqa: E402

LAW = dict(c=2e6, b1=800.0)
SIMULATE = [
    "simulate",
    "--mass",
    "1",
    "--law",
    "hertz_rate",
    "--param",
    "c=2e6",
    "--param",
    "b1=800",
]
SIMULATE += ["--mass", "1", "--v0", "2.5"]


@pytest.fixture(autouse=True)
def _no_persistent_cache(monkeypatch):
    """Keep the CLI from writing JAX's compilation cache into the user's home."""
    monkeypatch.setenv("JAXIMPACT_CACHE_DIR", "")
    monkeypatch.delenv("JAXIMPACT_DEBUG", raising=False)


# ------------------------------------------------------------------------------ laws


def test_laws_table(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "200")  # the content, not its wrapping (test_assumptions)
    status, out, err = run_cli(capsys, ["laws"])
    assert status == 0 and err == ""
    for name in ji.LAW_NAMES:
        assert f"\n{name} " in out
    assert "c x^1.5 + b1 x^0.5 v" in out  # eq. 14
    assert "b1 [N s/m^1.5]" in out  # units with the law's exponents filled in
    assert "n [-] = 1.5" in out  # a default
    assert "Kuwabara" in out  # a reference
    # the tangential laws that --tangential takes, with their parameters and units
    tangential = out[out.index("Tangential laws (--tangential") :]
    for name in ji.TANGENTIAL_LAW_NAMES:
        assert f"\n{name} " in tangential
    assert "kt [N/m], mu [-], ct [N s/m] = 0" in tangential
    assert "G_star [Pa]" in tangential and "(or G, nu, G2, nu2)" in tangential


def test_laws_by_name(capsys, monkeypatch):
    """`jaximpact laws NAME ...`: the laws whose names begin with one of the names, normal
    or tangential (a user who typed `jaximpact laws hertz` got `unrecognized arguments`);
    a name that begins none is refused with the nearest names."""
    monkeypatch.setenv("COLUMNS", "200")
    status, out, err = run_cli(capsys, ["laws", "hertz", "Mindlin-Rescale"])
    assert status == 0 and err == ""
    shown = {line.split()[0] for line in out.splitlines() if line and line[0].isalpha()}
    wanted = {
        "hertz_viscous",
        "hertz_modified",
        "hertz_rate",
        "mindlin_rescale",
        "mindlin_rescale_force",
    }
    assert wanted <= shown and not shown & ({*ji.LAW_NAMES, *ji.TANGENTIAL_LAW_NAMES} - wanted)
    status, out, _ = run_cli(capsys, ["laws", "linear_history", "--json"])
    data = json.loads(out)
    assert data["laws"] == [] and [r["name"] for r in data["tangential_laws"]] == ["linear_history"]
    assert "Force laws" not in run_cli(capsys, ["laws", "linear_history"])[1]
    assert_one_line_error(*run_cli(capsys, ["laws", "hertzz"]), contains="did you mean hertz_rate?")


def test_laws_json(capsys):
    status, out, _ = run_cli(capsys, ["laws", "--json"])
    assert status == 0
    laws = json.loads(out)["laws"]
    assert [row["name"] for row in laws] == list(ji.LAW_NAMES)
    by_name = {row["name"]: row for row in laws}
    kv = by_name["kelvin_voigt"]
    assert kv["equation"] == "1" and kv["formula"] == "c x + b v"
    assert kv["parameters"] == [
        {"name": "c", "unit": "N/m", "default": None},
        {"name": "b", "unit": "N s/m", "default": None},
    ]
    for row in laws:
        assert row["reference"] and row["parameters"]
        assert [p["name"] for p in row["parameters"]] == list(ji.LAWS[row["name"]].parameters)
    tangential = {row["name"]: row for row in json.loads(out)["tangential_laws"]}
    assert list(tangential) == list(ji.TANGENTIAL_LAW_NAMES)
    assert tangential["linear_history"]["parameters"][0] == {
        "name": "kt",
        "unit": "N/m",
        "default": None,
    }
    assert tangential["mindlin"]["also"] == ["G", "nu", "G2", "nu2"]


# -------------------------------------------------------------------------- simulate


def test_simulate_text(capsys):
    status, out, err = run_cli(capsys, SIMULATE)
    assert status == 0 and err == ""
    values = dict(re.findall(r"^(\w+)\s+= (.*)$", out, flags=re.MULTILINE))
    assert values["e"].startswith("0.83")
    assert values["T"] == "7.845 ms"
    assert values["x_max"].endswith(" mm") and values["t_max"].endswith(" ms")
    assert values["F_max"].endswith(" kN") and values["dissipated"].endswith("J")
    assert values["status"] == "separated"
    assert "hertz_rate" in out and "b1 = 800 N s/m^1.5" in out


@pytest.mark.slow
def test_simulate_json_and_plot(capsys, tmp_path):
    # Kelvin-Voigt has a closed form (no solve), so only the plot's history costs a solve
    png = tmp_path / "impact.png"
    argv = [
        "simulate",
        "--mass",
        "1",
        "--law",
        "kelvin_voigt",
        "--param",
        "c=2e6",
        "b=400",
        "--v0",
        "2.5",
    ]
    argv += ["--separation", "penetration", "--json", "--plot", str(png)]
    status, out, err = run_cli(capsys, argv)
    assert status == 0 and err == ""
    data = json.loads(out)
    law = ji.law("kelvin_voigt", c=2e6, b=400.0)
    direct = ji.impact(law, m=1.0, v0=2.5, separation="penetration")
    for key in ("e", "T", "x_max", "F_max", "t_max", "dissipated", "v_out"):
        np.testing.assert_allclose(data[key], float(getattr(direct, key)), rtol=1e-12)
    assert data["status"] == "separated" and data["path"] == direct.path == "closed_form"
    assert data["law"] == "kelvin_voigt" and data["params"] == {"c": 2e6, "b": 400.0}
    assert data["m"] == 1.0 and data["separation"] == "penetration"
    assert data["units"]["T"] == "s" and data["plot"] == str(png)
    assert png.is_file() and png.stat().st_size > 10_000
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    "argv, contains",
    [
        (["--law", "no_such_law", "--param", "c=1", "--v0", "1"], "unknown law 'no_such_law'"),
        (["--law", "hertz_rate", "--param", "c=-2e6", "b1=800", "--v0", "2.5"], "stiffness c"),
        (
            ["--law", "hertz_rate", "--param", "c=2e6", "b1=800", "--v0", "2.5", "--mass", "-1"],
            "mass m",
        ),
        (["--law", "hertz_rate", "--param", "c=2e6", "b1=800", "--v0", "0"], "impact speed v0"),
        (["--law", "hertz_rate", "--param", "c=abc", "b1=800", "--v0", "2.5"], "not a number"),
        (["--law", "hertz_rate", "--param", "c", "--v0", "2.5"], "NAME=VALUE"),
        (
            ["--law", "hertz_rate", "--param", "c=2e6", "b1=800", "k=3", "--v0", "2.5"],
            "no parameter k",
        ),
        (["--law", "hertz_rate", "--param", "c=2e6", "--v0", "2.5"], "needs b1"),
        (["--law", "hertz_rate", "--param", "c=2e6", "c=3e6", "b1=800", "--v0", "2.5"], "twice"),
        (["--law", "hertz_rate", "--param", "c=2e6", "b1=800", "--v0", "fast"], "--v0"),
        (["--law", "hertz_rate", "--param", "c=2e6", "b1=800"], "--v0"),
        (
            ["--law", "hertz_rate", "--param", "c=2e6", "b1=800", "--v0", "2.5", "--plot", "a.xyz"],
            "format",
        ),
        (
            [
                "--law",
                "hertz_rate",
                "--param",
                "c=2e6",
                "b1=800",
                "--v0",
                "2.5",
                "--plot",
                "/no/such/dir/a.png",
            ],
            "does not exist",
        ),
    ],
)
def test_simulate_bad_input(capsys, argv, contains):
    assert_one_line_error(*run_cli(capsys, ["simulate", *argv]), contains=contains)


@pytest.mark.parametrize(
    "extra, contains",
    [
        (
            ["--mass", "10g"],
            "'10g': numbers are given without a unit, in the units --help gives "
            "(SI: kg, m, s, N, Pa): 10g is 0.01 (kg)",
        ),
        (["--mass", "250mg"], "250mg is 0.00025 (kg)"),
        (["--v0", "2.5m/s"], "give 2.5 if it is in that unit"),
        (["--mass", "10", "g"], "unrecognized arguments: g: numbers are given without a unit"),
        (["--param", "c=2MPa"], "'2MPa' is not a number: numbers are given without a unit"),
        (["--mass", "abc"], "invalid float value: 'abc' (see"),
    ],
)
def test_a_number_with_a_unit_is_told_what_to_give(capsys, extra, contains):
    """Found by using the command as a new user: `--radius 5mm` or `--mass 10 g` said only
    `invalid float value` or `unrecognized arguments: g`."""
    argv = [
        "simulate",
        "--mass",
        "1",
        "--law",
        "hertz_rate",
        "--param",
        "c=2e6",
        "b1=800",
        "--v0",
        "2.5",
    ]
    assert_one_line_error(*run_cli(capsys, [*argv, *extra]), contains=contains)


@pytest.mark.parametrize("argv", [[], ["frobnicate"], ["laws", "--bogus"]])
def test_usage_errors(capsys, argv):
    assert_one_line_error(*run_cli(capsys, argv))


def test_internal_error_is_one_line(capsys, monkeypatch):
    def broken(args):
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(cli_laws, "_run_laws", broken)
    assert_one_line_error(*run_cli(capsys, ["laws"]), expected_status=1, contains="boom")


@pytest.mark.parametrize("command", [[]] + [[name] for name, _ in _cli.COMMANDS])
def test_help_has_an_example(capsys, command):
    status, out, _ = run_cli(capsys, [*command, "--help"])
    assert status == 0
    assert "example:" in out and "jaximpact " in out.split("example:")[1]


def test_console_script_runs():
    script = Path(sys.executable).with_name("jaximpact")
    script = str(script) if script.exists() else shutil.which("jaximpact")
    if script is None:
        pytest.skip("the jaximpact console script is not installed (pip install -e .)")
    done = subprocess.run([script, "--help"], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "simulate" in done.stdout and "laws" in done.stdout


# ----------------------------------------------------------------- helpers, plotting


def test_parse_params_and_formatting():
    assert common.parse_params(["c=2e6", " b1 = 800 "]) == {"c": 2e6, "b1": 800.0}
    for bad in ["c", "=3", "c=", "c=x", "1c=3"]:
        with pytest.raises(common.CLIError):
            common.parse_params([bad])
    assert _format.format_quantity(7.844925e-3, "s") == "7.845 ms"
    assert _format.format_quantity(1033.45, "N") == "1.033 kN"
    assert _format.format_quantity(0.9999999, "m") == "1 m"
    assert _format.format_quantity(0.0, "J") == "0 J"
    assert _format.format_quantity(4e-3, "kg") == "4 g"  # not "4 mkg"
    assert _format.format_quantity(2.5, "kg") == "2.5 kg"
    assert _format.format_number(2e6) == "2e6" and _format.format_number(800.0) == "800"
    assert _format.jsonable({"a": np.float64(np.nan), "b": np.arange(2)}) == {
        "a": None,
        "b": [0, 1],
    }


def _synthetic_result(with_histories=True):
    """A made-up ImpactResult (a half sine), to test the drawing without a solve."""
    T, v0, e = 8e-3, 2.5, 0.8
    ts = np.linspace(0.0, 1.05 * T, 200)
    w = np.pi / T
    inside = ts <= T
    x = np.where(inside, v0 / w * np.sin(w * ts), 0.0)
    v = np.where(inside, v0 * np.cos(w * ts), -e * v0)
    force = np.where(inside, 2e6 * np.maximum(x, 0.0) ** 1.5, 0.0)
    histories = dict(ts=ts, x=x, v=v, F=force) if with_histories else {}
    return ji.ImpactResult(
        e=np.asarray(e),
        T=np.asarray(T),
        dissipated=np.asarray(1.0),
        v_out=np.asarray(-e * v0),
        status=np.asarray(0),
        num_steps=np.asarray(0),
        path="integrated",
        x_max=np.asarray(x.max()),
        F_max=np.asarray(force.max()),
        t_max=np.asarray(T / 2),
        **histories,
    )


def test_plot_impact_panels_and_units():
    matplotlib = pytest.importorskip("matplotlib")
    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    law = ji.law("hertz_rate", **LAW)
    fig = plot_impact(_synthetic_result(), law, fig=Figure())
    loop, force, speed = fig.axes
    assert "(mm)" in loop.get_xlabel() and "(N)" in loop.get_ylabel()
    assert "(ms)" in force.get_xlabel() and "(N)" in force.get_ylabel()
    assert "(ms)" in speed.get_xlabel() and "(m/s)" in speed.get_ylabel()
    assert any("elastic" in line.get_label() for line in loop.get_lines())
    assert "hertz_rate" in fig._suptitle.get_text()

    fig2 = Figure()
    axes = fig2.subplots(3, 1)
    assert plot_impact(_synthetic_result(), axes=axes, title="") is fig2  # no law: no elastic
    assert not any("elastic" in line.get_label() for line in axes[0].get_lines())

    with pytest.raises(ValueError, match="ts="):
        plot_impact(_synthetic_result(with_histories=False))
    with pytest.raises(ValueError, match="3 axes"):
        plot_impact(_synthetic_result(), axes=axes[:2])


def test_console_script_environment():
    """Run as the `jaximpact` console script (and only then), XLA's notes are hidden and
    equinox's run-time checks are NaN rather than host callbacks, so that JAX's persistent
    cache can keep the compiled fits; `main` sets them before JAX loads, and importing the
    library leaves both alone, whatever the process is called."""
    probe = (
        "import os, sys; sys.argv = [{!r}]; import jaximpact; "
        "imported = os.environ.get('EQX_ON_ERROR'); from jaximpact._cli import main\n"
        "try: main()\n"
        "except SystemExit: pass\n"  # no command: the usage error, on stderr
        "import equinox._config as c; print(imported, os.environ.get('EQX_ON_ERROR'), "
        "os.environ.get('TF_CPP_MIN_LOG_LEVEL'), c.EQX_ON_ERROR)"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("EQX_ON_ERROR", "TF_CPP_MIN_LOG_LEVEL")}

    def run_as(argv0):
        done = subprocess.run(
            [sys.executable, "-c", probe.format(argv0)],
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
        return done.stdout.split()

    assert run_as("/usr/bin/jaximpact") == ["None", "nan", "3", "nan"]
    _, eqx_env, _, eqx_mode = run_as("analysis.py")
    assert (eqx_env, eqx_mode) == ("None", "raise")


def test_simulate_asks_for_the_mass(capsys):
    """A mass is asked for, never assumed (it was 1 kg by default: a 10 g ball simulated
    without --mass gave a 1 kg body's contact without a word)."""
    argv = ["simulate", "--law", "hertz_rate", "--param", "c=2e6", "b1=800", "--v0", "2.5"]
    status, out, err = run_cli(capsys, argv)
    assert_one_line_error(status, out, err, contains="--mass is required: the body's mass in kg")


def test_several_numbers_for_one_option_point_to_the_data_file(capsys, monkeypatch):
    """Found as a new user: `calibrate --v0 1 2 3 --e ...` said only `unrecognized
    arguments: 2 3 ...`; a command that reads a CSV says where several impacts go."""
    argv = ["calibrate", "--law", "hertz_rate", "--mass", "0.05", "--v0", "1", "2", "--e", "0.9"]
    monkeypatch.setattr("sys.argv", ["jaximpact", *argv])
    status, out, err = run_cli(capsys, argv)
    assert_one_line_error(
        status, out, err, contains="unrecognized arguments: 2: an option takes one number"
    )
    assert "--data FILE.csv" in err
