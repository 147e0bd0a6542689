"""Nothing assumed silently (issue 24): a physical input with no natural default is asked
for, a column and an option that disagree are refused, an export the engine cannot realise
is refused with the step that would work; and what a user reads fits a terminal (wide
tables), sweeps several speeds (`simulate --v0 1 2 3`) and hands a fit to an engine without
copying numbers (`export --from fit.json`).

Most tests here fail before any solve (fast); those that export or simulate share the
few compiled programs of the rest of the suite (hertz_rate, the Tsuji law of LAMMPS).
"""

import functools
import json
import math
import textwrap

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli
from hypothesis import HealthCheck, example, given, settings, strategies as st

import jaximpact as ji
from jaximpact._cli import bench as cli_bench, laws as cli_laws
from jaximpact._engines import _stepping
from jaximpact._engines.export import ENGINES, UnrealisedExport, UnrealisedWarning
from jaximpact._format import KEEP_TOGETHER, format_table
from jaximpact._jobs.job_law import job_law
from jaximpact._jobs.row_checks import check_rows

FEW = settings(max_examples=12, deadline=None, suppress_health_check=[HealthCheck.too_slow])
MASS_ENGINES = [name for name, module in ENGINES.items() if module.MASS_DEPENDS is not None]
RADIUS = {"radius": 0.01}


@pytest.fixture(autouse=True)
def _no_persistent_cache(monkeypatch):
    """Keep the CLI from writing JAX's compilation cache into the user's home."""
    monkeypatch.setenv("JAXIMPACT_CACHE_DIR", "")
    monkeypatch.delenv("JAXIMPACT_DEBUG", raising=False)


def _kwargs(engine):
    return RADIUS if ENGINES[engine].TWO_SPHERES else {}


# ------------------------------------------------------------ 1. the mass is asked for


def test_the_engines_that_need_the_mass_are_all_but_mujoco():
    assert sorted(MASS_ENGINES) == ["chrono", "drake", "lammps", "liggghts", "yade"]


@pytest.mark.parametrize("engine", MASS_ENGINES)
def test_export_without_mass_is_refused_in_python(engine):
    with pytest.raises(ValueError, match=f"{engine} needs the mass") as info:
        ji.export(None, engine, v0=1.0, e=0.5, T=1e-3, curves=False, **_kwargs(engine))
    assert "\n" not in str(info.value) and "m=" in str(info.value)


@pytest.mark.parametrize("engine", list(ENGINES))
def test_export_of_a_law_without_mass_is_refused_for_every_engine(engine):
    """A law's e and T at v0 depend on the mass: even MuJoCo needs it then."""
    law = ji.law("hertz_rate", c=2e6, b1=800.0)
    with pytest.raises(ValueError, match="the law's e and T at v0 depend on it"):
        ji.export(law, engine, v0=2.5, curves=False, **_kwargs(engine))


@pytest.mark.parametrize("engine", MASS_ENGINES)
def test_cli_export_without_mass_is_one_line_naming_the_option(engine, capsys):
    argv = ["export", engine, "--e", "0.5", "--T", "1e-3", "--v0", "1"]
    assert_one_line_error(*run_cli(capsys, [*argv, *("--radius", "0.01")]), contains="--mass")
    if ENGINES[engine].TWO_SPHERES:  # both missing: one line names both
        status, out, err = run_cli(capsys, argv)
        assert_one_line_error(status, out, err, contains="--mass (kg) and --radius (m)")


@pytest.mark.parametrize("engine", MASS_ENGINES)
def test_cli_engine_e_without_mass_is_refused(engine, capsys):
    params = {
        "lammps": {"E": 1e7, "coeff_restitution": 0.5},
        "liggghts": {"E": 1e7, "coeff_restitution": 0.5},
        "chrono": {"E": 1e7, "coeff_restitution": 0.5},
        "yade": {"tc": 1e-3, "en": 0.5},
        "drake": {"point_contact_stiffness": 1e5, "hunt_crossley_dissipation": 0.2},
    }[engine]
    argv = ["engine-e", "--engine", engine, "--params", json.dumps(params), "--speed", "1"]
    assert_one_line_error(*run_cli(capsys, [*argv, "--radius", "0.01"]), contains="--mass")


@functools.cache
def _mujoco_without_mass():
    return ji.export(None, "mujoco", v0=1.0, e=0.6, T=5e-3, timestep=5e-5, curves=False)


@settings(max_examples=4, deadline=None)
@given(m=st.floats(1e-4, 1e3))
def test_mujoco_from_targets_needs_no_mass_because_solref_is_per_unit_mass(m):
    """Where no mass is needed none is asked for: solref for any m is solref without one."""
    without = _mujoco_without_mass()
    with_m = ji.export(None, "mujoco", m=m, v0=1.0, e=0.6, T=5e-3, timestep=5e-5, curves=False)
    assert without.m is None and with_m.m == m
    assert without.parameters["solref"] == with_m.parameters["solref"]
    assert without.e == with_m.e and without.T == with_m.T


def test_the_mass_changes_what_the_engines_are_given():
    """Why it is asked for: Chrono's and Yade's inputs scale with m (E and density)."""
    a, b = (
        ji.export(None, "chrono", m=m, v0=1.0, e=0.5, T=1e-3, radius=0.01, curves=False)
        for m in (0.05, 0.1)
    )
    assert b.parameters["SetYoungModulus"] == pytest.approx(2 * a.parameters["SetYoungModulus"])
    a, b = (
        ji.export(None, "yade", m=m, v0=1.0, e=0.5, T=1e-3, radius=0.01, curves=False)
        for m in (0.05, 0.1)
    )
    assert b.parameters["density"] == pytest.approx(2 * a.parameters["density"])


# -------------------------------------------------- 2. a column and an option disagree


def _where(i):
    return f"in.csv, line {i + 2}"


@settings(max_examples=200, deadline=None)
@given(
    column=st.lists(st.sampled_from([0.5, 1.0, 2.0]), min_size=1, max_size=8),
    option=st.sampled_from([0.5, 1.0, 2.0]),
    key=st.sampled_from(["m", "v0", "c", "b1", "g"]),
)
def test_check_rows_refuses_the_first_row_where_a_column_and_an_option_disagree(
    column, option, key
):
    values = {key: np.array(column)}
    fixed = {k: 1.0 for k in ("c", "b1", "m", "v0") if k != key}
    differ = [i for i, v in enumerate(column) if v != option]
    if not differ:
        check_rows(job_law("hertz_rate"), values, fixed, _where, {key: option})
        return
    with pytest.raises(ValueError) as info:
        check_rows(job_law("hertz_rate"), values, fixed, _where, {key: option})
    message = str(info.value)
    assert message.startswith(f"{_where(differ[0])}, column {key}: ") and "\n" not in message
    option = f"--param {key}=" if key in ("c", "b1") else {"m": "--mass"}.get(key, f"--{key}")
    assert "disagrees with " + option in message


def test_check_rows_separation_column_against_its_option():
    values = {"separation": np.array(["force", "penetration"], object)}
    with pytest.raises(ValueError, match="line 3, column separation: .*--separation"):
        check_rows(
            job_law("hertz_rate"),
            values,
            {"c": 1.0, "b1": 1.0, "m": 1.0, "v0": 1.0},
            _where,
            {"separation": "force"},
        )


@pytest.fixture
def bodies(tmp_path):
    path = tmp_path / "bodies.csv"
    path.write_text("c,m,v0\n2e6,1,2.5\n2e6,2,2.5\n")
    return path


@pytest.mark.parametrize(
    "option, contains",
    [
        (["--mass", "1"], "line 3, column m: m = 2.0 disagrees with --mass"),
        (["--mass", "3"], "line 2, column m: m = 1.0 disagrees with --mass"),
        (["--param", "c=1e6"], "line 2, column c: c = 2000000.0 disagrees with --param c="),
        (["--v0", "1"], "column v0"),
    ],
)
def test_cli_batch_refuses_a_column_that_disagrees_with_an_option(bodies, option, contains, capsys):
    out = bodies.parent / "out.csv"
    argv = ["batch", str(bodies), "--law", "hertz_rate", "--param", "b1=800", *option]
    assert_one_line_error(*run_cli(capsys, [*argv, "--out", str(out)]), contains=contains)
    assert not out.exists()


def test_batch_file_refuses_the_same_from_python(bodies):
    with pytest.raises(ValueError, match="column m: m = 2.0 disagrees with --mass \\(m=\\) 1"):
        ji.batch_file(
            bodies,
            bodies.parent / "o.csv",
            "hertz_rate",
            params={"b1": 800.0},
            m=1.0,
            progress=False,
        )


def test_batch_file_takes_a_column_that_agrees_with_its_option(bodies):
    out = bodies.parent / "o.csv"
    result = ji.batch_file(
        bodies,
        out,
        "hertz_rate",
        params={"b1": 800.0, "c": 2e6},
        progress=False,
        separation="force",
    )
    assert result.rows == 2 and out.exists()


# ------------------------------------------- 3. what an engine cannot realise is refused


@settings(max_examples=300, deadline=None)
@given(
    e=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.floats(0, 1.2)),
    T=st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.floats(1e-4, 2e-3)),
    steps=st.one_of(st.none(), st.floats(0.1, 1e4)),
)
@example(e=9.678e5, T=0.002, steps=0.5)  # issue 24: MuJoCo at a step longer than the contact
def test_unrealised_says_why_exactly_when_a_criterion_fails(e, T, steps):
    target_e, target_T = 0.5, 1e-3
    why = _stepping.unrealised(
        e,
        T,
        target_e=target_e,
        target_T=target_T,
        steps_per_contact=steps,
        parameters={"k": 1.0, "solref": [0.1, 1.0]},
    )
    impact = math.isfinite(e) and math.isfinite(T) and 0 <= e <= 1.005 and T > 0
    resolved = steps is None or steps >= _stepping.RESOLVED_STEPS
    near = impact and abs(e / target_e - 1) <= 0.05 and abs(T / target_T - 1) <= 0.05
    assert (why is None) == (impact and resolved and near), why
    assert why is None or "\n" not in why


def test_unrealised_refuses_a_parameter_that_is_not_finite():
    why = _stepping.unrealised(
        0.5,
        1e-3,
        target_e=0.5,
        target_T=1e-3,
        steps_per_contact=100,
        parameters={"solref": [float("nan"), 1.0]},
    )
    assert "solref is not a finite number" in why


@settings(max_examples=8, deadline=None)
@given(engine=st.sampled_from(["yade", "chrono"]), steps=st.floats(0.2, 4.9))
def test_export_at_a_step_that_does_not_resolve_the_contact_is_refused(engine, steps):
    """Fewer than 5 steps per contact: a one-line ValueError naming a step that works,
    and that step is accepted; strict=False gives a warning and the export."""
    T = 1e-3
    kwargs = dict(m=0.05, v0=1.0, e=0.5, T=T, radius=0.01, curves=False)
    with pytest.raises(UnrealisedExport) as info:
        ji.export(None, engine, timestep=T / steps, **kwargs)
    refusal = info.value
    assert isinstance(refusal, ValueError) and "\n" not in str(refusal)
    assert "cannot realise" in str(refusal) and "strict=False" in str(refusal)
    assert 0 < refusal.working < T / 5 and f"{refusal.working:.3g} s or less" in str(refusal)
    ok = ji.export(None, engine, timestep=refusal.working, **kwargs)
    assert abs(ok.e / 0.5 - 1) < 0.05
    with pytest.warns(UnrealisedWarning, match="cannot realise"):
        anyway = ji.export(None, engine, timestep=T / steps, strict=False, **kwargs)
    assert "cannot realise" in anyway.warnings[0]


def test_issue_example_mujoco_step_longer_than_the_contact(capsys):
    """`realised e = 1.7e14` and a negative solref with exit 0, before: now exit 2 with
    the step that works; --no-strict exports it with a warning on stderr."""
    argv = ["export", "mujoco", "--e", "0.5", "--T", "1e-3", "--v0", "1", "--timestep", "0.002"]
    status, out, err = run_cli(capsys, argv)
    assert_one_line_error(status, out, err, contains="use a time step of 7.4e-06 s or less (T/135)")
    assert "--no-strict" in err and "not an impact" in err
    status, out, err = run_cli(capsys, [*argv, "--no-strict", "--json"])
    assert status == 0 and "jaximpact: warning: mujoco cannot realise" in err
    assert json.loads(out)["warnings"][0].startswith("mujoco cannot realise")


def test_drake_discrete_step_too_coarse_is_refused_and_names_a_discrete_step():
    """e = 0.9 at 10 steps per contact: Drake's implicit step gives 0.66 whatever d."""
    with pytest.raises(UnrealisedExport, match="more than 5% off") as info:
        ji.export(None, "drake", m=1.0, v0=1.0, e=0.9, T=0.01, timestep=0.001, curves=False)
    assert 0 < info.value.working < 0.001 and "time_step = 0" in str(info.value)


@FEW
@given(e=st.floats(0.3, 0.95), T=st.floats(1e-4, 1e-2))
def test_a_recommended_step_is_always_realised(e, T):
    """Without a timestep the export picks one, and never refuses its own choice."""
    x = ji.export(None, "yade", m=0.01, v0=1.0, e=e, T=T, radius=0.01, curves=False)
    assert abs(x.e / e - 1) < 0.005 and abs(x.T / T - 1) < 0.005


# ------------------------------------------------------------------ 4. wide tables


def _words(lines):
    return " ".join(lines).replace(KEEP_TOGETHER, " ").split()


@settings(max_examples=60, deadline=None)
@given(width=st.integers(60, 220))
@example(width=80)
def test_laws_table_fits_any_width_and_keeps_every_word(width):
    rows = cli_laws._law_rows()
    text = cli_laws._laws_text(rows, width=width)
    assert max(map(len, text.splitlines())) <= width
    words = text.split()
    for row in rows:
        assert row["name"] in words
        for word in row["formula"].split():
            assert word in words
    assert "b1 [N s/m^1.5]" in text  # a parameter and its unit stay on one line


def test_cli_laws_fits_the_terminal_and_json_stays_full(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    status, out, _ = run_cli(capsys, ["laws"])
    assert status == 0 and max(map(len, out.splitlines())) <= 80
    status, out, _ = run_cli(capsys, ["laws", "--json"])
    assert json.loads(out)["laws"][0]["formula"] == "c x + b v"


def _bench_data(n, cache="/root/.cache/jaximpact/jax-xla"):
    names = ["kelvin_voigt", "kelvin_voigt (integrate)", "maxwell", "hertz_rate", "hunt_crossley"]
    row = dict(
        path="integrated",
        err_e=1.2e-12,
        err_T=3.4e-11,
        single_s=2.3e-5,
        compile_s=1.5,
        batch_s=1.1e-6,
        batch_compile_s=2.2,
        scipy_rtol=1e-9,
        scipy_err_e=5e-10,
        scipy_s=3.5e-3,
        ratio_single=152.0,
        ratio_batch=3181.0,
        target_single_met=True,
        target_batch_met=False,
        batch_size=1000,
        rounds=7,
    )
    machine = dict(
        cpu_count=2,
        processor="x86_64",
        jax="0.10.2",
        backend="cpu",
        scipy="1.16",
        python="3.12.3",
        load_average="1.2, 1.0, 0.9",
        load_average_end="1.5, 1.1",
        compilation_cache=cache,
    )
    euler = dict(
        dt=2e-5, law="hertz_rate", e=0.83, e_ref=0.84, err_e=1e-2, err_T=1e-3, single_s=0.2
    )
    return dict(
        machine=machine,
        conditions=dict(quick=False, m=1.0, v0=2.5),
        rows=[dict(row, case=names[i % 5]) for i in range(n)],
        targets=dict(error_e=1e-13),
        euler=euler,
    )


@settings(max_examples=60, deadline=None)
@given(width=st.integers(60, 400), n=st.integers(1, 5))
@example(width=80, n=5)
def test_bench_report_fits_any_width_and_keeps_every_number(width, n):
    text = cli_bench._text(_bench_data(n), width=width)
    assert max(map(len, text.splitlines())) <= width
    for word in ("3181x", "152x", "MISSED", "3500", "1.0e-09", "kelvin_voigt", "explicit"):
        assert word in text


_WORD = st.text("abcdefgh0123456789.-", min_size=1, max_size=10)


@settings(max_examples=200, deadline=None)
@given(
    data=st.data(),
    columns=st.integers(1, 9),
    n_rows=st.integers(1, 6),
    width=st.integers(60, 160),
)
def test_format_table_fits_where_it_can_and_loses_no_word(data, columns, n_rows, width):
    cell = st.lists(_WORD, min_size=1, max_size=4).map(" ".join)
    header = data.draw(st.lists(cell, min_size=columns, max_size=columns))
    rows = data.draw(
        st.lists(
            st.lists(cell, min_size=columns, max_size=columns), min_size=n_rows, max_size=n_rows
        )
    )
    wrap = data.draw(st.lists(st.integers(0, columns - 1), unique=True, max_size=columns))
    lines = format_table(header, rows, width=width, wrap=wrap)
    dashes = {"-" * k for k in range(1, 200)}
    given_words = set(_words(header) + [w for r in rows for w in _words(r)]) - dashes
    assert given_words <= set(_words(lines))
    # fits wherever the first column beside any other one, each narrowed as far as it
    # goes (a cell of free text to its longest word, a header to its longest word), does
    least = [
        max(
            [max(map(len, r[i].split())) if i in wrap else len(r[i]) for r in rows]
            + [max(map(len, header[i].split()))]
        )
        for i in range(columns)
    ]
    if all(least[0] + 2 + least[i] <= width for i in range(1, columns)) and least[0] <= width:
        assert max(map(len, lines)) <= width


# ------------------------------------------------------------- 5. simulate sweeps v0


def test_simulate_sweeps_several_speeds(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "88")
    argv = ["simulate", "--law", "hertz_rate", "--param", "c=2e6", "b1=800", "--mass", "1"]
    status, out, err = run_cli(capsys, [*argv, "--v0", "0.5", "1", "2", "--json"])
    assert status == 0, err
    runs = json.loads(out)
    assert isinstance(runs, list) and [r["v0"] for r in runs] == [0.5, 1.0, 2.0]
    assert runs[0]["e"] > runs[1]["e"] > runs[2]["e"]  # law 14: e falls with speed
    status, one, _ = run_cli(capsys, [*argv, "--v0", "1", "--json"])
    assert json.loads(one) == runs[1]  # each member is the one-speed answer
    status, text, _ = run_cli(capsys, [*argv, "--v0", "0.5", "1", "2"])
    assert status == 0
    header = text.splitlines()[4]
    for column in ("v0 (m/s)", "e", "T (s)", "x_max (m)", "F_max (N)"):
        assert column in header
    assert "at every speed: status separated" in text
    assert max(map(len, text.splitlines())) <= 88


def test_simulate_sweep_checks_every_speed_first(capsys):
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
        "1",
        "-2",
    ]
    assert_one_line_error(*run_cli(capsys, argv), contains="--v0 -2: the impact speed v0")


# ------------------------------------------------- 6. export --from a calibrate fit


def _fit(tmp_path, **changes):
    fit = {
        "law": "hertz_rate",
        "params": {"c": 102116.27312860748, "b1": 36.8145403998733},
        "free": ["c", "b1"],
        "converged": True,
        "rows": [{"v0": 2.5, "e": 0.85, "e_fit": 0.85, "T": 0.0078, "T_fit": 0.0078}],
        "m": 0.05,
        "separation": "force",
        "g": 0.0,
    }
    fit.update(changes)
    path = tmp_path / "fit.json"
    path.write_text(json.dumps({k: v for k, v in fit.items() if v is not None}))
    return str(path)


@pytest.mark.slow
def test_calibrate_json_then_export_from_it(tmp_path, capsys):
    """The round trip of the issue, on calibrate's own JSON: the export's target is the
    fitted law's e and T at the fit's mass and speed, and equals the same export typed
    out by hand."""
    argv = [
        "calibrate",
        "--law",
        "hertz_rate",
        "--mass",
        "0.05",
        "--v0",
        "2.5",
        "--e",
        "0.85",
        "--T",
        "7.8e-3",
        "--json",
    ]
    status, out, err = run_cli(capsys, argv)
    assert status == 0, err
    path = tmp_path / "fit.json"
    path.write_text(out)
    status, out, err = run_cli(capsys, ["export", "mujoco", "--from", str(path), "--json"])
    assert status == 0, err
    x = json.loads(out)
    assert x["m"] == 0.05 and x["v0"] == 2.5 and x["from"] == str(path)
    assert x["target_e"] == pytest.approx(0.85, rel=1e-6)
    assert x["target_T"] == pytest.approx(7.8e-3, rel=1e-6)


def test_export_from_a_fit_is_the_export_of_its_law(tmp_path, capsys):
    path = _fit(tmp_path)
    status, out, err = run_cli(
        capsys,
        ["export", "lammps", "--from", path, "--radius", "0.01", "--json", "--timestep", "1e-5"],
    )
    assert status == 0, err
    fit = json.loads(open(path).read())
    by_hand = [
        "export",
        "--engine",
        "lammps",
        "--law",
        "hertz_rate",
        "--param",
        *(f"{k}={v!r}" for k, v in fit["params"].items()),
        "--mass",
        "0.05",
        "--v0",
        "2.5",
        "--radius",
        "0.01",
        "--json",
        "--timestep",
        "1e-5",
    ]
    status, again, err = run_cli(capsys, by_hand)
    assert status == 0, err
    a, b = json.loads(out), json.loads(again)
    assert a["parameters"] == b["parameters"] and a["m"] == 0.05


@pytest.mark.parametrize(
    "changes, argv, contains",
    [
        (dict(law=None), [], "no law name"),
        (dict(law="hertz"), [], "law 'hertz' is not one of"),
        (dict(params={"c": "big"}), [], "parameter c = 'big' is not a finite number"),
        (dict(params={"c": 1e5, "k": 1.0}), [], "has no parameter k"),
        (dict(m=None), [], "no mass ('m'); give --mass"),
        (dict(m=-1.0), [], "mass m = -1.0 is not a number > 0"),
        ({}, ["--mass", "1"], "--mass 1 but"),
        ({}, ["--law", "kelvin_voigt"], "--law kelvin_voigt but"),
        ({}, ["--param", "c=1"], "--param conflicts with --from"),
        ({}, ["--e", "0.5"], "either --from or --e/--T"),
        (dict(rows=[{"v0": 1.0}, {"v0": 2.0}]), [], "2 speeds (1 to 2 m/s); give --v0"),
        (dict(rows=None), [], "no impact speed"),
        (dict(rows=[{"v0": "fast"}]), [], "a speed"),
        (dict(separation="penetration"), [], "fitted with separation 'penetration'"),
    ],
)
def test_export_from_refuses_missing_and_mismatched_fields(
    tmp_path, capsys, changes, argv, contains
):
    path = _fit(tmp_path, **changes)
    status, out, err = run_cli(capsys, ["export", "mujoco", "--from", path, *argv])
    assert_one_line_error(status, out, err, contains=contains)


@pytest.mark.parametrize(
    "text, contains",
    [("{", "not JSON"), ("[1, 2]", "expected the JSON object"), (None, "cannot read it")],
)
def test_export_from_a_file_that_is_no_fit(tmp_path, capsys, text, contains):
    path = tmp_path / "fit.json"
    if text is not None:
        path.write_text(text)
    status, out, err = run_cli(capsys, ["export", "mujoco", "--from", str(path)])
    assert_one_line_error(status, out, err, contains=contains)


def test_export_from_a_ranking_takes_its_best_or_the_law_named(tmp_path, capsys):
    """`calibrate --law all --json` writes a ranking: --from exports its best, or the law
    that --law names (one it ranked)."""
    best = {"law": "hertz_rate", "params": {"c": 1.02e5, "b1": 36.8}, "rows": [{"v0": 2.5}]}
    other = {"law": "kelvin_voigt", "params": {"c": 5e3, "b": 2.0}, "rows": [{"v0": 2.5}]}
    path = tmp_path / "all.json"
    path.write_text(
        json.dumps(
            {
                "m": 0.05,
                "separation": "force",
                "g": 0.0,
                "best": "hertz_rate",
                "ranking": [best, other],
            }
        )
    )
    status, out, err = run_cli(capsys, ["export", "mujoco", "--from", str(path), "--json"])
    assert status == 0, err
    assert json.loads(out)["target_e"] == pytest.approx(
        float(ji.impact(ji.law("hertz_rate", c=1.02e5, b1=36.8), m=0.05, v0=2.5).e)
    )
    status, out, err = run_cli(
        capsys, ["export", "mujoco", "--from", str(path), "--law", "maxwell"]
    )
    assert_one_line_error(status, out, err, contains="its ranking has no law 'maxwell'")


def test_export_engine_positional_and_option_must_agree(capsys):
    argv = ["export", "mujoco", "--engine", "drake", "--e", "0.5", "--T", "1e-3", "--v0", "1"]
    assert_one_line_error(*run_cli(capsys, argv), contains="disagree")
    assert_one_line_error(*run_cli(capsys, argv[:1] + argv[4:]), contains="name the engine")


def test_the_refusal_criteria_are_documented():
    """The refusal criteria are documented where a user looks: `export`'s docstring."""
    doc = textwrap.dedent(ji.export.__doc__)
    assert "cannot realise" in doc and "fewer than 5 steps" in doc and "5 %" in doc
    assert "`m` has no default" in doc
