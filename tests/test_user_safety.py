"""What a user touches (DESIGN.md; issue 24): an output never overwrites an input however its
path is spelled, an extension says what is written, an interrupt stops a run with one line
and no partial file, inputs float64 cannot carry are refused alike (1e-300 as 1e300), results
print as numbers with units, and `dir(jaximpact)` holds the public names only."""

import json
import math
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli
from hypothesis import HealthCheck, given, settings, strategies as st

import jaximpact as ji
from jaximpact._checks import check_scale
from jaximpact._files import atomic_output, check_outputs, same_file
from jaximpact._laws.named_law import batch_law

CSV = "c,b1,m,v0\n2e6,800,1,2.5\n1.5e6,600,0.5,1.5\n"
ONCE = settings(
    max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)


def _write_bodies(path: Path, n: int = 2, seed: int = 1) -> str:
    rng = np.random.default_rng(seed)
    lines = ["c,b1,m,v0"] + [
        f"{c!r},{b!r},{m!r},{v!r}"
        for c, b, m, v in zip(
            rng.uniform(1e6, 3e6, n),
            rng.uniform(100, 2000, n),
            rng.uniform(0.5, 2.0, n),
            rng.uniform(0.5, 5.0, n),
            strict=True,
        )
    ]
    text = "\n".join(lines) + "\n"
    path.write_text(text)
    return text


# ------------------------------------------------------------- 1. an output is never an input


def _spell(tmp_path: Path, source: Path, how: str) -> Path:
    """Another name of the file `source`: relative, through `..`, absolute, a link."""
    if how == "relative":
        return Path(os.path.relpath(source))
    if how == "dot":
        return Path(os.path.relpath(source.parent)) / "." / source.name
    if how == "dotdot":
        (tmp_path / "sub").mkdir(exist_ok=True)
        return tmp_path / "sub" / ".." / source.name
    if how == "absolute":
        return source.resolve()
    if how == "symlink":
        link = tmp_path / f"link-{source.stem}{source.suffix}"
        link.unlink(missing_ok=True)
        link.symlink_to(source.name)
        return link
    if how == "hardlink":
        link = tmp_path / f"hard-{source.stem}{source.suffix}"
        link.unlink(missing_ok=True)
        os.link(source, link)
        return link
    raise AssertionError(how)


SPELLINGS = ["relative", "dot", "dotdot", "absolute", "symlink", "hardlink"]


@ONCE
@given(how=st.sampled_from(SPELLINGS), suffix=st.sampled_from([".csv", ".CSV", ".parquet"]))
def test_batch_file_refuses_an_output_that_is_its_input(tmp_path_factory, how, suffix):
    tmp_path = tmp_path_factory.mktemp("same")
    source = tmp_path / f"bodies{suffix}"
    source.write_text(CSV)  # (a Parquet name holding text: the refusal comes first)
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        out = _spell(tmp_path, source, how)
        with pytest.raises(ValueError, match="is the input") as error:
            ji.batch_file(source, out, "hertz_rate", progress=False)
    finally:
        os.chdir(cwd)
    assert len(str(error.value).splitlines()) == 1
    assert source.read_text() == CSV  # untouched, and nothing begun
    assert not any(p.name.endswith(".parts") for p in tmp_path.iterdir())


def test_an_output_is_refused_where_the_run_would_write_or_remove_an_input(tmp_path):
    parts = tmp_path / "out.csv.parts"
    parts.mkdir()
    source = parts / "bodies.csv"
    source.write_text(CSV)
    with pytest.raises(ValueError, match="parts directory"):  # removed at the start of a run
        ji.batch_file(source, tmp_path / "out.csv", "hertz_rate", progress=False)
    assert source.read_text() == CSV
    # an output that does not exist yet is compared by its resolved path
    assert same_file(tmp_path / "new.csv", tmp_path / "sub" / ".." / "new.csv")
    assert not same_file(tmp_path / "new.csv", tmp_path / "other.csv")
    with pytest.raises(ValueError, match="--plot"):
        check_outputs([source], {"--plot": parts / "." / "bodies.csv"})


def test_cli_refuses_an_output_that_is_an_input_before_any_work(capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    Path("bodies.csv").write_text(CSV)
    for out in ["bodies.csv", "./bodies.csv", str(tmp_path / "bodies.csv")]:
        status, out_text, err = run_cli(
            capsys, ["batch", "bodies.csv", "--law", "hertz_rate", "--out", out]
        )
        assert_one_line_error(status, out_text, err, contains="is the input")
    Path("data.csv").write_text("v0,e\n2.5,0.8\n")
    status, out_text, err = run_cli(
        capsys,
        [
            "calibrate",
            "--mass",
            "1",
            "--law",
            "hertz_rate",
            "--data",
            "data.csv",
            "--plot",
            "./data.csv",
        ],
    )
    assert_one_line_error(status, out_text, err, contains="is the input")
    assert Path("bodies.csv").read_text() == CSV and Path("data.csv").read_text().startswith("v0")


# -------------------------------------------------------- 2. the extension says what is written


@ONCE
@given(suffix=st.from_regex(r"\A(\.[a-zA-Z0-9]{1,6})?\Z"))
def test_an_unknown_output_extension_is_refused(tmp_path_factory, suffix):
    if suffix.lower() in (".csv", ".parquet", ".pq"):
        return
    tmp_path = tmp_path_factory.mktemp("ext")
    (tmp_path / "in.csv").write_text(CSV)
    out = tmp_path / f"o{suffix}"
    with pytest.raises(ValueError, match=r"\.csv, \.parquet, \.pq") as error:
        ji.batch_file(tmp_path / "in.csv", out, "hertz_rate", progress=False)
    assert len(str(error.value).splitlines()) == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.csv"]


def test_write_table_is_atomic_and_knows_its_extensions(tmp_path):
    with pytest.raises(ValueError, match=r"\.csv or \.json"):
        ji.write_table(tmp_path / "o.xlsx", {"a": np.arange(3.0)})
    (tmp_path / "o.csv").write_text("old\n")

    class Boom(Exception):
        pass

    with pytest.raises(Boom), atomic_output(tmp_path / "o.csv") as temporary:
        temporary.write_text("half")
        raise Boom
    assert (tmp_path / "o.csv").read_text() == "old\n"  # the final name as it was
    assert sorted(p.name for p in tmp_path.iterdir()) == ["o.csv"]  # no temporary left


# ------------------------------------------------------------------------------ 3. interrupts


def _python(code: str) -> subprocess.Popen:
    return subprocess.Popen(
        [sys.executable, "-c", textwrap.dedent(code)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_an_interrupt_that_something_swallows_still_stops_the_command(signum):
    """A KeyboardInterrupt caught and ignored (as a JAX callback may): the watchdog ends the
    process within the grace time, one line, status 128 + signal."""
    child = _python(
        """
        import time
        from jaximpact._interrupt import handle_interrupts, set_note
        with handle_interrupts():
            set_note("3 of 9 chunks kept")
            print("ready", flush=True)
            while True:  # swallowed wherever the signal's raise lands, as a callback may
                try:
                    while True:
                        try:
                            time.sleep(0.05)
                        except BaseException:
                            pass
                except BaseException:
                    pass
        """
    )
    assert child.stdout.readline().strip() == "ready"
    time.sleep(0.3)  # into the swallowing loop (a signal at `print` would escape it)
    start = time.perf_counter()
    child.send_signal(signum)
    out, err = child.communicate(timeout=30)
    from jaximpact._interrupt import GRACE

    assert child.returncode == 128 + signum
    assert time.perf_counter() - start < GRACE + 3
    name = signal.Signals(signum).name
    assert err.strip().splitlines() == [
        f"jaximpact: error: interrupted by {name}; 3 of 9 chunks kept"
    ]


def test_an_interrupt_landing_in_a_gc_callback_prints_nothing_and_is_raised_again():
    """CI caught SIGINT raised inside JAX's `_xla_gc_callback`: Python printed "Exception
    ignored in ..." with a traceback before the one line. Such an unraisable `Interrupted` is
    recorded, not printed, and the next safe point raises it; other unraisables still print."""
    child = _python(
        """
        import gc, signal
        from jaximpact._interrupt import check_interrupt, handle_interrupts, Interrupted

        def gc_callback(phase, info):  # as JAX's: a signal's raise lands here
            if phase == "start":
                gc.callbacks.remove(gc_callback)
                signal.raise_signal(signal.SIGINT)

        with handle_interrupts():
            gc.callbacks.append(gc_callback)
            gc.collect()
            print("went on", flush=True)
            class Other:
                def __del__(self):
                    raise ValueError("not an interrupt")
            Other()
            try:
                check_interrupt()
            except Interrupted as stop:
                print("raised again:", stop.status, flush=True)
        """
    )
    out, err = child.communicate(timeout=30)
    assert out.splitlines() == ["went on", "raised again: 130"]
    assert "Interrupted" not in err and "interrupted by SIGINT" not in err
    assert "ValueError: not an interrupt" in err  # only our own exception is kept quiet


ROWS = 12_000  # at 20 rows a chunk: 600 chunks, a few seconds of batch


def _bodies_for_a_long_run(path: Path, rows: int):
    rng = np.random.default_rng(3)
    data = np.column_stack(
        [
            rng.uniform(1e6, 3e6, rows),
            rng.uniform(100, 2000, rows),
            rng.uniform(0.5, 2, rows),
            rng.uniform(0.5, 5, rows),
        ]
    )
    np.savetxt(path, data, delimiter=",", header="c,b1,m,v0", comments="", fmt="%.17g")


def _cli(*argv) -> subprocess.Popen:
    env = {**os.environ, "JAXIMPACT_PROGRESS": "off"}
    return subprocess.Popen(
        [sys.executable, "-m", "jaximpact._cli", *argv],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )


@pytest.mark.parametrize(
    "signum, after_parts",
    [
        (signal.SIGINT, 20),
        pytest.param(signal.SIGTERM, 60, marks=pytest.mark.slow),
        pytest.param(signal.SIGINT, 0, marks=pytest.mark.slow),  # while JAX compiles
    ],
)
def test_an_interrupted_batch_stops_says_what_it_kept_and_resume_completes_it(
    tmp_path, signum, after_parts
):
    source, out = tmp_path / "bodies.csv", tmp_path / "impacts.csv"
    _bodies_for_a_long_run(source, ROWS)
    argv = [str(source), "--law", "hertz_rate", "--out", str(out), "--chunk-rows", "20"]
    child = _cli("batch", *argv)
    parts = Path(f"{out}.parts")
    deadline = time.perf_counter() + 60
    while time.perf_counter() < deadline and child.poll() is None:
        done = len(list(parts.glob("part-*.json"))) if parts.is_dir() else 0
        if (after_parts == 0 and parts.is_dir()) or (after_parts and done >= after_parts):
            break
        time.sleep(0.01)
    assert child.poll() is None, "the run ended before the signal: make it longer"
    start = time.perf_counter()
    child.send_signal(signum)
    stdout, err = child.communicate(timeout=60)
    assert time.perf_counter() - start < 5, "the interrupt did not stop the run promptly"
    assert child.returncode == 128 + signum, err
    assert stdout == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith(f"jaximpact: error: interrupted by {signal.Signals(signum).name}")
    assert "chunks kept" in lines[0] and "--resume" in lines[0]
    assert not out.exists()  # no file under the final name
    assert not list(tmp_path.glob(".*tmp*"))  # nor a temporary one beside it

    resumed = _cli("batch", *argv, "--resume", "--json")
    stdout, err = resumed.communicate(timeout=120)
    assert resumed.returncode == 0, err
    summary = json.loads(stdout)
    assert summary["rows"] == ROWS and summary["reused"] >= after_parts
    assert summary["statuses"]["separated"] == ROWS
    written = np.loadtxt(out, delimiter=",", skiprows=1, usecols=range(5))
    given = np.loadtxt(source, delimiter=",", skiprows=1)
    np.testing.assert_array_equal(written[:, :4], given)  # nothing lost, repeated or moved
    assert np.all((written[:, 4] > 0) & (written[:, 4] < 1))  # e of every row


@pytest.mark.slow
@pytest.mark.parametrize(
    "signum, after, fitting",
    [(signal.SIGINT, 1.0, False), (signal.SIGINT, 4.0, True), (signal.SIGTERM, 5.0, True)],
)
def test_an_interrupted_calibrate_all_stops_with_one_line(signum, after, fitting):
    """At several moments (importing JAX; the fits under way) and for both signals."""
    child = _cli(
        "calibrate", "--law", "all", "--mass", "1", "--v0", "2.5", "--e", "0.8", "--T", "7.8e-3"
    )
    time.sleep(after)
    assert child.poll() is None
    start = time.perf_counter()
    child.send_signal(signum)
    stdout, err = child.communicate(timeout=60)
    assert time.perf_counter() - start < 5
    assert child.returncode == 128 + signum and stdout == ""
    lines = err.strip().splitlines()
    name = signal.Signals(signum).name
    assert len(lines) == 1 and lines[0].startswith(f"jaximpact: error: interrupted by {name}")
    if fitting:
        assert "laws fitted" in lines[0]


# ------------------------------------------------- 4. sizes float64 cannot carry, refused alike


@settings(max_examples=40, deadline=None)
@given(exponent=st.floats(-400, 400), sign=st.sampled_from([1.0, -1.0]))
def test_check_scale_refuses_tiny_and_huge_alike(exponent, sign):
    value = sign * 10.0**exponent if exponent < 308 else sign * math.inf
    inside = value == 0 or not math.isfinite(value) or 1e-150 <= abs(value) <= 1e150
    if inside:
        assert check_scale("m", value, "kg") == value
    else:
        with pytest.raises(ValueError, match="1e-150 to 1e150"):
            check_scale("m", value, "kg")
        if math.isfinite(1.0 / value):  # mirrored about 1, alike
            with pytest.raises(ValueError, match="1e-150 to 1e150"):
                check_scale("m", 1.0 / value, "kg")


@pytest.mark.parametrize("m", ["1e-300", "1e300", "1e-151", "1e151"])
def test_cli_refuses_a_mass_float64_cannot_carry(capsys, m):
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
    status, out, err = run_cli(capsys, [*argv, "--mass", m])
    assert_one_line_error(status, out, err, contains="1e-150 to 1e150")


def test_cli_refuses_contact_scales_float64_cannot_carry(capsys):
    """Each input within range, their product not: m v0^2 = 1e-240 J."""
    argv = ["simulate", "--mass", "1", "--law", "hertz_rate", "--param", "c=2e6", "b1=800"]
    status, out, err = run_cli(capsys, [*argv, "--v0", "1e-120", "--mass", "1"])
    assert_one_line_error(status, out, err, contains="energy m v0^2")


@pytest.mark.parametrize("m", [1e-300, 1e300])
def test_calibrate_refuses_a_mass_float64_cannot_carry(m):
    with pytest.raises(ValueError, match="1e-150 to 1e150"):
        ji.calibrate(ji.law("hertz_rate", c=1e6, b1=100.0), m=m, v0=2.5, e=0.85, T=7.8e-3)


@pytest.mark.parametrize("m", [1e-300, 1e300, 1e-151, 1e151])
@pytest.mark.parametrize("engine", ["mujoco", "lammps"])
def test_export_refuses_a_mass_float64_cannot_carry(engine, m):
    """`ji.export` as the rest of the library: the same window, the same one line."""
    with pytest.raises(ValueError, match="1e-150 to 1e150") as error:
        ji.export(ji.law("hertz_rate", c=2e6, b1=800.0), engine, m=m, v0=2.5, radius=0.01)
    assert "\n" not in str(error.value)


# ------------------------------------------------------- 5. results print as numbers with units


def test_an_impact_prints_numbers_with_units():
    r = ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5)
    for text in (repr(r), str(r), r.summary()):
        assert "f64[" not in text and "Array(" not in text
        assert "T          = 7.845 ms" in text and "status     = separated" in text
        assert "kN" in text  # F_max
    d = r.to_dict()
    assert d["status"] == "separated" and d["path"] == r.path
    assert d["T"] == pytest.approx(float(r.T)) and isinstance(d["e"], float)
    json.dumps(d, allow_nan=False)


def test_a_batch_of_impacts_prints_ranges_and_a_traced_one_its_shapes():
    def one(c):
        return ji.impact(ji.law("hertz_rate", c=c, b1=800.0), m=1.0, v0=2.5)

    batch = jax.vmap(one)(jnp.linspace(1e6, 3e6, 6))
    text = repr(batch)
    assert "6 values" in text and "ms to" in text and "separated 6" in text
    assert len(batch.to_dict()["status"]) == 6
    shown = []

    @jax.jit
    def traced(c):
        shown.append(repr(one(c)))
        return one(c).e

    traced(2e6)
    assert "traced f64[]" in shown[0]


def test_a_fit_and_a_ranking_print_numbers_with_units():
    fit = ji.calibrate(ji.law("hertz_rate", c=1e6, b1=100.0), m=1.0, v0=2.5, e=0.85, T=7.8e-3)
    text = repr(fit)
    assert "f64[" not in text and "N/m^1.5" in text and "N s/m^1.5" in text
    assert "target [7.8 ms]" in text
    json.dumps(fit.to_dict(), allow_nan=False)
    (ranking,) = ji.compare_laws(
        m=1.0, v0=[1.0, 2.0], e=[0.9, 0.87], laws=("hertz_rate",), progress=False
    )
    text = repr(ranking)
    assert text.startswith("Ranking of hertz_rate") and "chi2" in text and "f64[" not in text
    assert "(fixed)" in text  # c, held fixed where e alone was measured
    assert "T          = [" in text and "(not measured)" in text
    json.dumps(ranking.to_dict(), allow_nan=False)


def test_a_law_prints_as_the_call_that_builds_it_with_its_units():
    """A law printed as an equinox pytree showed `c=f64[]`: no value. It now prints as the
    call that builds it, in SI units: a row of the table, a law with a state, a user's law
    (no row, no units), a tangential law, a batch of laws and a traced one."""
    assert repr(ji.law("hertz_rate", c=2e6, b1=800.0)) == (
        "law('hertz_rate', c=2e6 N/m^1.5, b1=800 N s/m^1.5)"
    )
    assert repr(ji.law("thornton", c=2.176e10, x_y=5.986e-7)) == (
        "law('thornton', c=2.176e10 N/m^1.5, x_y=598.6 nm)"
    )
    assert str(ji.law("jkr", c=1e9, R=2.45e-6, w=0.2)) == (
        "law('jkr', c=1e9 N/m^1.5, R=2.45 µm, w=200 mJ/m^2)"
    )

    def kelvin_voigt(x, v, p):
        return p["c"] * x + p["b"] * v

    assert (
        repr(ji.custom_law(kelvin_voigt, c=2e6, b=40.0)) == "custom_law(kelvin_voigt, c=2e6, b=40)"
    )
    assert repr(ji.tangential_law("mindlin", G_star=1.35e10, mu=0.3)) == (
        "tangential_law('mindlin', G_star=13.5 GPa, mu=0.3, beta=0)"
    )
    # a batch of laws (one per row, as `impact_batch` and the maps build them; `law` takes
    # one number per parameter)
    batch = batch_law("hertz_rate", c=jnp.array([1e6, 2e6]), b1=800.0)
    assert repr(batch) == "law('hertz_rate', c=[1e6 N/m^1.5, 2e6 N/m^1.5], b1=800 N s/m^1.5)"
    shown = []
    jax.vmap(lambda c: shown.append(repr(ji.law("hertz_rate", c=c, b1=800.0))) or c)(
        jnp.array([1e6, 2e6])
    )
    assert shown == ["law('hertz_rate', c=traced f64[], b1=800 N s/m^1.5)"]
    # a JKR microsphere's energies are femtojoules
    assert ji._format.format_quantity(3.742e-15, "J") == "3.742 fJ"


# --------------------------------------------------------------- 6. the package's namespace


def test_dir_of_the_package_lists_its_public_names_only():
    names = dir(ji)
    for private in ("os", "sys", "importlib"):
        assert private not in names
    public = [n for n in names if not (n.startswith("__") and n.endswith("__"))]
    assert public == sorted(ji.__all__)
    for name in ("impact", "law", "calibrate", "export", "batch_file", "ImpactResult", "Fit"):
        assert name in public and getattr(ji, name) is not None
    assert "__version__" in names


def test_importing_and_reading_every_name_leaves_jax_and_the_environment_alone():
    """JAX's configuration is the user's: only the command line (and `enable_cache()`, when
    called) changes it; a fresh process, since this one's conftest turned the cache on."""
    child = _python(
        """
        import json, os
        import jax
        flags = ("jax_enable_x64", "jax_compilation_cache_dir",
                 "jax_persistent_cache_min_compile_time_secs",
                 "jax_persistent_cache_min_entry_size_bytes")
        before = [getattr(jax.config, f) for f in flags], dict(os.environ)
        import jaximpact
        for name in jaximpact.__all__:
            getattr(jaximpact, name)
        after = [getattr(jax.config, f) for f in flags], dict(os.environ)
        print(json.dumps(before == after))
        """
    )
    out, err = child.communicate(timeout=120)
    assert child.returncode == 0, err
    assert out.strip() == "true"


@pytest.mark.parametrize("m", [1e-300, 1e300])
def test_impact_refuses_a_mass_float64_cannot_carry(m):
    """`ji.impact` itself, not only the command line: 1e-300 kg once printed underflowed
    values (T = 3.9e-180 ns) as results; refused in one line, as 1e300 kg is."""
    import jaximpact as ji

    with pytest.raises(ValueError, match="float64 cannot hold") as error:
        ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=m, v0=2.5)
    assert "\n" not in str(error.value)


@pytest.mark.parametrize(
    "call, said",
    [
        (
            lambda: ji.law("hertz", c=1e9),
            "did you mean hertz_viscous, hertz_modified or hertz_rate?",
        ),
        (lambda: ji.law("Hunt-Crossley", c=1e9), "did you mean hunt_crossley?"),
        (lambda: ji.law("jkrr", c=1e9), "did you mean jkr?"),
        (lambda: ji.tangential_law("Mindlin", G_star=1e10, mu=0.3), "did you mean mindlin?"),
        (
            lambda: ji.export(ji.law("kelvin_voigt", c=1e6, b=10.0), "Lammps", m=1.0, v0=1.0),
            "did you mean lammps?",
        ),
    ],
)
def test_a_mistyped_name_is_told_the_nearest_names(call, said):
    """A law, tangential law or engine named as people say it (`hertz`, `Hunt-Crossley`) is
    refused in one line that names the nearest names first, then lists them all."""
    with pytest.raises(ValueError, match=re.escape(said)) as error:
        call()
    assert "choose one of: " in str(error.value) and "\n" not in str(error.value)


def test_a_name_like_no_other_gets_the_list_alone():
    with pytest.raises(ValueError) as error:
        ji.law("xyz", c=1.0)
    message = str(error.value)
    assert "did you mean" not in message and "choose one of: kelvin_voigt" in message


@pytest.mark.parametrize(
    "call, shown",
    [
        (lambda law, tl: ji.impact(law, m=2.6e-4, v0="3 m/s"), "impact speed v0"),
        (
            lambda law, tl: ji.oblique_impact(law, tl, m=2.6e-4, R="2.5mm", v_n=3.0, v_t=1.0),
            "radius R",
        ),
        (lambda law, tl: ji.impact(law, m=[1.0, "a"], v0=1.0), "mass m"),
    ],
)
def test_a_number_given_with_its_unit_is_refused_in_one_line(call, shown):
    """A number written with its unit ('2.5mm'), or a word among numbers, is refused before
    any solve with the input's name, its SI unit and what to give instead (numpy's own
    "could not convert string to float" named nothing)."""
    law = ji.law("hunt_crossley", c=2.6e10, a=0.0)
    tl = ji.tangential_law("mindlin", G=1.5e11, nu=0.23, mu=0.092)
    with pytest.raises(ValueError, match=shown) as info:
        call(law, tl)
    assert "\n" not in str(info.value) and "plain number in SI units" in str(info.value)
