"""A user's law on the command line (issue 34, item 2): `--law FILE.py:NAME` with `--param`
wherever `--law NAME` goes, named `FILE.py:NAME` in the output; a bad file, name or
parameter is one line, exit status 2, before any work.

Compilation: the law file is written once for the module (`law_file`) and imported once
(`_laws.custom.load_law_function` keeps it per content), so `simulate` compiles one program and
`batch` one more; calibrate, fit and export each compile their own (slow)."""

import json

import numpy as np
import pytest
from helpers import assert_one_line_error, assert_rel, run_cli

import jaximpact as ji

LAW_SOURCE = '''"""Law 14 as a user writes it."""
import jax.numpy as jnp


def hertz_rate(x, v, p):
    return p["c"] * x**1.5 + p["b1"] * jnp.sqrt(x) * v


def _helper():
    pass


class Kelvin:
    pass


STIFFNESS = 2e6
'''
PARAMS = ["--param", "c=2e6", "b1=800"]


@pytest.fixture(autouse=True)
def _no_persistent_cache(monkeypatch):
    monkeypatch.setenv("JAXIMPACT_CACHE_DIR", "")


@pytest.fixture(scope="module")
def law_file(tmp_path_factory):
    """The law file, and its `--law` text `FILE.py:hertz_rate`."""
    path = tmp_path_factory.mktemp("laws") / "mylaw.py"
    path.write_text(LAW_SOURCE)
    return path, f"{path}:hertz_rate"


def test_simulate_runs_a_users_law_and_names_it(capsys, law_file):
    _, law = law_file
    status, out, err = run_cli(
        capsys, ["simulate", "--mass", "1", "--law", law, *PARAMS, "--v0", "2.5", "--json"]
    )
    assert status == 0, err
    data = json.loads(out)
    assert data["law"] == law and data["params"] == {"c": 2e6, "b1": 800.0}
    assert data["status"] == "separated" and data["path"] == "integrated"
    want = ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5)
    for key in ("e", "T", "x_max", "F_max"):
        assert_rel(data[key], getattr(want, key), 1e-9, key)
    status, out, err = run_cli(
        capsys, ["simulate", "--mass", "1", "--law", law, *PARAMS, "--v0", "2.5"]
    )
    assert status == 0, err
    assert out.splitlines()[0] == f"law        {law}"


def test_batch_runs_a_users_law_with_parameters_from_the_columns(capsys, law_file, tmp_path):
    _, law = law_file
    c, m, v0 = np.linspace(1.5e6, 3e6, 6), np.linspace(0.5, 2.0, 6), np.linspace(0.5, 4.0, 6)
    (tmp_path / "in.csv").write_text(
        "c,m,v0\n" + "".join(f"{a},{b},{d}\n" for a, b, d in zip(c, m, v0, strict=True))
    )
    argv = [
        "batch",
        str(tmp_path / "in.csv"),
        "--law",
        law,
        "--param",
        "b1=800",
        "--out",
        str(tmp_path / "out.csv"),
        "--chunk-rows",
        "3",
    ]
    status, out, err = run_cli(capsys, argv)
    assert status == 0, err
    assert "6 impacts written" in out and "2 chunks computed" in out
    lines = (tmp_path / "out.csv").read_text().splitlines()
    header, rows = lines[0].split(","), [line.split(",") for line in lines[1:]]
    got = {k: np.array([float(r[header.index(k)]) for r in rows]) for k in ("e", "T", "x_max")}
    want = ji.impact_batch("hertz_rate", {"c": c, "b1": 800.0}, m=m, v0=v0, progress=False)
    for key in got:  # the table's law 14, the same force
        assert_rel(got[key], want[key], 1e-9, key)
    assert {r[header.index("path")] for r in rows} == {"grid"}
    result = run_cli(capsys, [*argv[:4], "--out", str(tmp_path / "o.csv")])  # no b1
    assert_one_line_error(*result, contains=f'{law} reads params["b1"]: give a column b1')
    assert not (tmp_path / "o.csv").exists()


# every case fails before anything is compiled: the file, the name, what the law reads
@pytest.mark.parametrize(
    "law, params, message",
    [
        (
            "{file}:hertz_rate",
            ["c=2e6"],
            '{file}:hertz_rate reads params["b1"]: give it with --param b1=...',
        ),
        ("{file}:hertz_rate", [], 'reads params["c"]: give it with --param c=...'),
        (
            "{file}:hertz_rate",
            ["c=2e6", "b1=800", "k=1"],
            '--param k: {file}:hertz_rate does not read params["k"] (it reads c, b1)',
        ),
        ("{dir}/none.py:f", ["c=1"], "no such file {dir}/none.py"),
        ("{dir}/law.txt:f", ["c=1"], "{dir}/law.txt is not a .py file"),
        ("{file}", ["c=1"], "--law {file}: a user's law is FILE.py:NAME"),
        ("{file}:", ["c=1"], "a user's law is FILE.py:NAME"),
        (
            "{file}:hertz",
            ["c=1"],
            "has no 'hertz' (did you mean hertz_rate?); its callables: hertz_rate, Kelvin",
        ),
        ("{file}:STIFFNESS", ["c=1"], "STIFFNESS in {file} is a float, not a function"),
        (
            "{dir}/raises.py:f",
            ["c=1"],
            "importing {dir}/raises.py raised ZeroDivisionError at line 3: division by zero",
        ),
        ("{dir}/syntax.py:f", ["c=1"], "importing {dir}/syntax.py raised SyntaxError at line 2"),
        (
            "{dir}/broken.py:f",
            ["c=1"],
            "{dir}/broken.py:f failed when called as NAME(x, v, "
            "params) with numbers (NameError at line 2: name 'undefined' is not defined)",
        ),
    ],
)
def test_a_bad_law_file_is_one_line(capsys, law_file, law, params, message):
    path, _ = law_file
    folder = path.parent
    (folder / "raises.py").write_text("import math\n\nSCALE = 1 / 0\n")
    (folder / "syntax.py").write_text("def f(x, v, p):\n    return p[c] +\n")
    (folder / "broken.py").write_text("def f(x, v, p):\n    return undefined * x\n")
    (folder / "law.txt").write_text("")
    fill = {"file": str(path), "dir": str(folder)}
    argv = [
        "simulate",
        "--mass",
        "1",
        "--law",
        law.format(**fill),
        *(["--param", *params] if params else []),
        "--v0",
        "1",
    ]
    assert_one_line_error(*run_cli(capsys, argv), contains=message.format(**fill))


def test_commands_that_need_the_law_table_refuse_a_users_law(capsys, law_file):
    _, law = law_file
    assert_one_line_error(*run_cli(capsys, ["laws", law]), contains=f"{law} is a user's law")
    result = run_cli(
        capsys,
        ["calibrate", "--mass", "1", "--law", law, "--param", "c=2e6", "--v0", "2", "--e", "0.8"],
    )
    assert_one_line_error(*result, contains='reads params["b1"]: give it with --param b1=...')


@pytest.mark.slow  # compiles its own fit
def test_calibrate_fits_a_users_law(capsys, law_file):
    _, law = law_file
    truth = ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5)
    status, out, err = run_cli(
        capsys,
        [
            "calibrate",
            "--mass",
            "1",
            "--law",
            law,
            "--param",
            "c=1.5e6",
            "b1=500",
            "--v0",
            "2.5",
            "--e",
            repr(float(truth.e)),
            "--T",
            repr(float(truth.T)),
            "--json",
        ],
    )
    assert status == 0, err
    data = json.loads(out)
    assert data["law"] == law and data["free"] == ["c", "b1"] and data["converged"]
    assert data["params"]["c"] == pytest.approx(2e6, rel=1e-6)
    assert data["params"]["b1"] == pytest.approx(800.0, rel=1e-6)
    status, out, err = run_cli(
        capsys,
        [
            "calibrate",
            "--mass",
            "1",
            "--law",
            law,
            "--param",
            "c=1.5e6",
            "b1=500",
            "--v0",
            "2.5",
            "--e",
            repr(float(truth.e)),
            "--T",
            repr(float(truth.T)),
        ],
    )
    assert status == 0, err
    assert f"law        {law}\n" in out


@pytest.mark.slow  # compiles its own export
def test_export_takes_a_users_law(capsys, law_file):
    _, law = law_file
    truth = ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5)
    status, out, err = run_cli(
        capsys, ["export", "mujoco", "--law", law, *PARAMS, "--mass", "1", "--v0", "2.5", "--json"]
    )
    assert status == 0, err
    data = json.loads(out)
    assert data["target_e"] == pytest.approx(float(truth.e), rel=1e-9)
    assert data["target_T"] == pytest.approx(float(truth.T), rel=1e-9)


@pytest.mark.slow  # compiles its own bounce fit
def test_fit_takes_a_users_law(capsys, law_file, tmp_path):
    _, law = law_file
    b = ji.bounce(
        ji.law("hertz_rate", c=5.5e7, b1=700.0), m=0.0415, h0=0.9, t_end=3.0, max_impacts=8
    )
    times = np.asarray(b.impact_times)
    (tmp_path / "times.csv").write_text(
        "impact_time\n" + "".join(f"{float(t)!r}\n" for t in times[np.isfinite(times)])
    )
    status, out, err = run_cli(
        capsys,
        [
            "fit",
            str(tmp_path / "times.csv"),
            "--law",
            law,
            "--param",
            "c=5.5e7",
            "b1=100",
            "--mass",
            "0.0415",
            "--json",
        ],
    )
    assert status == 0, err
    fit = json.loads(out)["fits"]["all"]
    assert fit["law"] == law and fit["params"]["b1"] == pytest.approx(700.0, rel=1e-3)
