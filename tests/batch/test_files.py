"""`batch_file` and `jaximpact batch`: a CSV (or Parquet) of bodies in, one impact per row out,
streamed in chunks, resumable, every bad value refused before any work; several processes
under `jax.distributed` write the same file as one (slow tests, real processes)."""

import csv
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

import jaximpact as ji
from jaximpact._jobs import job

N, CHUNK = 250, 100


def _bodies(path, n=N, seed=1, **extra):
    rng = np.random.default_rng(seed)
    columns = dict(
        c=rng.uniform(1e6, 3e6, n),
        b1=rng.uniform(100.0, 2000.0, n),
        m=rng.uniform(0.5, 2.0, n),
        v0=rng.uniform(0.5, 5.0, n),
        **extra,
    )
    with open(path, "w") as handle:
        handle.write(",".join(columns) + "\n")
        for row in zip(*columns.values(), strict=True):
            handle.write(",".join(x if isinstance(x, str) else repr(float(x)) for x in row))
            handle.write("\n")
    return columns


def _read(path):
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    return {k: [row[k] for row in rows] for k in rows[0]}


def _run(tmp_path, name="out.csv", law="hertz_rate", **kwargs):
    kwargs = {"chunk_rows": CHUNK, "progress": False, **kwargs}
    return ji.batch_file(tmp_path / "in.csv", tmp_path / name, law, **kwargs)


def test_every_row_equals_the_batch_in_memory(tmp_path):
    columns = _bodies(tmp_path / "in.csv")
    result = _run(tmp_path)
    assert (result.rows, result.chunks, result.computed, result.reused) == (N, 3, 3, 0)
    assert result.statuses["separated"] == N
    assert not (tmp_path / "out.csv.parts").exists()
    out = _read(tmp_path / "out.csv")
    assert list(out) == [
        "c",
        "b1",
        "m",
        "v0",
        "e",
        "T",
        "x_max",
        "t_max",
        "F_max",
        "status",
        "path",
    ]
    want = ji.impact_batch(
        "hertz_rate",
        {"c": columns["c"], "b1": columns["b1"]},
        m=columns["m"],
        v0=columns["v0"],
        fields=("e", "T", "x_max", "t_max", "F_max", "status"),
        progress=False,
    )
    for key in ("e", "T", "x_max", "t_max", "F_max"):
        np.testing.assert_array_equal(np.asarray(out[key], float), want[key], err_msg=key)
    for key in ("c", "b1", "m", "v0"):  # the inputs as given, not reformatted
        assert out[key] == [repr(float(x)) for x in columns[key]]
    assert set(out["path"]) == {"similarity"} and set(out["status"]) == {"separated"}


def test_any_chunk_size_gives_the_same_rows(tmp_path):
    """Rows neither lost, repeated nor moved; values equal to rounding (vectorised arithmetic
    may change the last bit with the size of a chunk, never with the number of processes)."""
    _bodies(tmp_path / "in.csv")
    _run(tmp_path, "a.csv", chunk_rows=7)
    _run(tmp_path, "b.csv", chunk_rows=1000)
    a, b = _read(tmp_path / "a.csv"), _read(tmp_path / "b.csv")
    for key in ("c", "b1", "m", "v0", "status", "path"):
        assert a[key] == b[key]
    for key in ("e", "T", "x_max", "t_max", "F_max"):
        np.testing.assert_allclose(
            np.asarray(a[key], float), np.asarray(b[key], float), rtol=1e-14, err_msg=key
        )


@pytest.mark.slow  # moved from the fast suite to keep it near 3 minutes
def test_columns_for_separation_and_failing_rows_kept_with_their_status(tmp_path):
    """Over-damped Kelvin-Voigt under `penetration` is captured (e = 0): kept, not dropped;
    each separation as `impact_batch` gives it in memory."""
    rng = np.random.default_rng(3)
    n = 60
    b = rng.uniform(100.0, 8000.0, n)  # critical damping 2 sqrt(c m) = 2828 N s/m
    separation = rng.choice(["force", "penetration"], n)
    with open(tmp_path / "in.csv", "w") as handle:
        handle.write("b,separation\n")
        handle.writelines(f"{x!r},{s}\n" for x, s in zip(b.tolist(), separation, strict=True))
    result = _run(tmp_path, law="kelvin_voigt", params={"c": 2e6}, m=1.0, v0=2.0, chunk_rows=16)
    out = _read(tmp_path / "out.csv")
    assert out["separation"] == separation.tolist() and result.rows == n
    for word in ("force", "penetration"):
        rows = separation == word
        want = ji.impact_batch(
            "kelvin_voigt",
            {"c": 2e6, "b": b[rows]},
            m=1.0,
            v0=2.0,
            separation=word,
            fields=("e", "T", "status"),
            progress=False,
        )
        got = {k: np.asarray(out[k])[rows] for k in ("e", "T", "status")}
        np.testing.assert_allclose(got["e"].astype(float), want["e"], rtol=1e-13, atol=1e-17)
        np.testing.assert_allclose(got["T"].astype(float), want["T"], rtol=1e-13)
        assert got["status"].tolist() == [ji.Status(int(s)).name for s in want["status"]]
    assert result.statuses["captured"] == sum(s == "captured" for s in out["status"]) > 0
    assert set(out["path"]) == {"closed_form"}


def _interrupted(tmp_path, monkeypatch, after, **kwargs):
    """A run stopped (KeyboardInterrupt) once `after` chunks were written."""
    real, done = job.compute_chunk, []

    def compute(*args):
        if len(done) == after:
            raise KeyboardInterrupt
        done.append(1)
        return real(*args)

    monkeypatch.setattr(job, "compute_chunk", compute)
    with pytest.raises(KeyboardInterrupt):
        _run(tmp_path, **kwargs)
    monkeypatch.setattr(job, "compute_chunk", real)
    assert not (tmp_path / "out.csv").exists()  # nothing half-written where OUT goes


def test_resume_completes_an_interrupted_run_with_nothing_lost_or_repeated(tmp_path, monkeypatch):
    _bodies(tmp_path / "in.csv")
    _run(tmp_path, "whole.csv")
    _interrupted(tmp_path, monkeypatch, after=2)
    result = _run(tmp_path, resume=True)
    assert (result.computed, result.reused) == (1, 2)
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()


def test_resume_recomputes_a_chunk_whose_input_changed(tmp_path, monkeypatch):
    _bodies(tmp_path / "in.csv")
    _interrupted(tmp_path, monkeypatch, after=2)
    lines = (tmp_path / "in.csv").read_text().splitlines()
    lines[5] = "2e6,800.0,1.0,2.5"  # a row of the first chunk
    (tmp_path / "in.csv").write_text("\n".join(lines) + "\n")
    result = _run(tmp_path, resume=True)
    assert (result.computed, result.reused) == (2, 1)
    assert _run(tmp_path, "fresh.csv").computed == 3
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "fresh.csv").read_bytes()


def test_resume_recomputes_everything_when_the_settings_changed(tmp_path, monkeypatch):
    """A fixed value (here the mass) is part of every chunk's hash."""
    _bodies(tmp_path / "in.csv")
    (tmp_path / "in.csv").write_text(
        "\n".join(
            ",".join(line.split(",")[:2] + line.split(",")[3:])
            for line in (tmp_path / "in.csv").read_text().splitlines()
        )
        + "\n"
    )
    _interrupted(tmp_path, monkeypatch, after=2, m=1.0)
    result = _run(tmp_path, resume=True, m=2.0)
    assert (result.computed, result.reused) == (3, 0)
    _run(tmp_path, "fresh.csv", m=2.0)
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "fresh.csv").read_bytes()


def test_a_part_without_its_record_is_recomputed(tmp_path, monkeypatch):
    """A run stopped between writing a part and its record: the part is not taken as done."""
    _bodies(tmp_path / "in.csv")
    _interrupted(tmp_path, monkeypatch, after=2)
    (tmp_path / "out.csv.parts" / "part-000001.json").unlink()
    (tmp_path / "out.csv.parts" / "part-000001.csv").write_text("garbage\n")
    result = _run(tmp_path, resume=True)
    assert (result.computed, result.reused) == (2, 1)
    _run(tmp_path, "fresh.csv")
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "fresh.csv").read_bytes()


@pytest.mark.parametrize(
    "text, kwargs, match",
    [
        (None, {}, "no such file"),
        ("", {}, "empty file"),
        ("c,b1,mass,v0\n2e6,800,1,2.5\n", {}, r"no value for m: .*carried through unread: mass"),
        ("c,b1,m,v_0\n2e6,800,1,2.5\n", {}, r"line 1: unknown column 'v_0' \(did you mean v0\?\)"),
        ("c,b1,m,m\n2e6,800,1,2.5\n", {}, r"line 1: column 'm' appears twice"),
        ("c,v0\n2e6,2.5\n", {"m": 1.0}, "no value for b1"),
        ("c,b1,m,v0\n2e6,800,1,2.5\n2e6,eight,1,2.5\n", {}, r"line 3, column b1: 'eight'"),
        ("c,b1,m,v0\n2e6,800,1,2.5\n2e6,,1,2.5\n", {}, r"line 3, column b1: an empty cell"),
        ("c,b1,m,v0\n2e6,800,nan,2.5\n", {}, r"line 2, column m: m = nan must be"),
        ("c,b1,m,v0\n2e6,800,1,2.5\n\n2e6,800,1,-2\n", {}, r"line 4, column v0: v0 = -2.0"),
        ("c,b1,m,v0\n-2e6,800,1,2.5\n", {}, r"line 2, column c: c = -2000000.0 must be .* > 0"),
        ("c,b1,m,v0\n2e6,800,1\n", {}, r"line 2: 3 cells for 4 columns"),
        ("c,b1,m,v0\n", {}, "no data rows"),
        ("c,b1,v0\n2e6,800,2.5\n", {"m": -1.0}, "fixed value m"),
        ("c,b1,v0\n2e6,800,2.5\n", {"m": 1.0, "params": {"b": 1.0}}, "no parameter b"),
        ("c,b1,m,v0,separation\n2e6,800,1,2.5,forces\n", {}, "'forces' is not 'force'"),
    ],
)
def test_bad_input_is_named_before_any_work(tmp_path, text, kwargs, match):
    source = tmp_path / "in.csv"
    if text is not None:
        source.write_text(text)
    with pytest.raises(ValueError, match=match):
        ji.batch_file(source, tmp_path / "out.csv", "hertz_rate", progress=False, **kwargs)
    assert not (tmp_path / "out.csv").exists() and not (tmp_path / "out.csv.parts").exists()


def test_a_bad_row_in_a_late_chunk_stops_the_run_before_any_chunk_is_written(tmp_path):
    _bodies(tmp_path / "in.csv")
    lines = (tmp_path / "in.csv").read_text().splitlines()
    lines[230] = "2e6,800.0,1.0,inf"
    (tmp_path / "in.csv").write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match="line 231, column v0: v0 = inf"):
        _run(tmp_path)
    assert not (tmp_path / "out.csv.parts").exists()


def test_parquet_in_and_out(tmp_path):
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    columns = _bodies(tmp_path / "in.csv")
    pq.write_table(pa.table(columns), tmp_path / "in.parquet", row_group_size=37)
    _run(tmp_path, "csv.csv")
    ji.batch_file(
        tmp_path / "in.parquet",
        tmp_path / "out.parquet",
        "hertz_rate",
        chunk_rows=CHUNK,
        progress=False,
    )
    ji.batch_file(
        tmp_path / "in.parquet", tmp_path / "pq.csv", "hertz_rate", chunk_rows=CHUNK, progress=False
    )
    assert (tmp_path / "pq.csv").read_bytes() == (tmp_path / "csv.csv").read_bytes()
    table = pq.read_table(tmp_path / "out.parquet").to_pydict()
    want = _read(tmp_path / "csv.csv")
    for key in ("c", "b1", "m", "v0", "e", "T", "x_max", "t_max", "F_max"):
        assert table[key] == [float(x) for x in want[key]], key
    assert table["status"] == want["status"] and table["path"] == want["path"]
    bad = pa.table({**columns, "m": pa.array([1.0] * (N - 1) + [None])})
    pq.write_table(bad, tmp_path / "bad.parquet")
    with pytest.raises(ValueError, match=f"row {N}, column m: an empty cell"):
        ji.batch_file(tmp_path / "bad.parquet", tmp_path / "o.csv", "hertz_rate", progress=False)


def _chunks(columns, sizes=(100, 100, 50)):
    """`columns` cut into chunks of `sizes` rows (mappings column -> array)."""
    edges = np.cumsum((0, *sizes))
    bounds = zip(edges[:-1], edges[1:], strict=True)
    return [{k: v[a:b] for k, v in columns.items()} for a, b in bounds]


def test_chunks_from_a_script_give_the_file_of_the_command(tmp_path):
    """A list of chunks and a generator of them, through `impact_batch(..., out=)`, write
    the same rows (and results, bit for bit) as `batch_file` on the CSV of those rows."""
    columns = _bodies(tmp_path / "in.csv")
    _run(tmp_path, "from_file.csv")
    chunks = _chunks(columns)
    listed = ji.impact_batch("hertz_rate", chunks, out=tmp_path / "listed.csv", progress=False)
    made = ji.impact_batch(
        "hertz_rate", (c for c in chunks), out=tmp_path / "made.csv", progress=False
    )
    assert (listed.rows, listed.chunks, made.rows, made.chunks) == (N, 3, N, 3)
    assert (tmp_path / "listed.csv").read_bytes() == (tmp_path / "made.csv").read_bytes()
    want, got = _read(tmp_path / "from_file.csv"), _read(tmp_path / "listed.csv")
    for key in ("c", "b1", "m", "v0", "e", "T", "x_max", "t_max", "F_max"):
        np.testing.assert_array_equal(np.asarray(got[key], float), np.asarray(want[key], float))
    assert got["status"] == want["status"] and got["path"] == want["path"]
    # a number for a whole chunk is broadcast, as a fixed value would be
    fixed = [{**c, "c": 2e6} for c in chunks]
    out = ji.batch_file(fixed, tmp_path / "fixed.csv", "hertz_rate", progress=False)
    assert out.rows == N and set(_read(tmp_path / "fixed.csv")["c"]) == {"2000000.0"}


def test_a_generator_stops_at_its_first_bad_chunk_and_resume_completes_it(tmp_path):
    """A generator is checked as it comes: a bad row in chunk 1 is named after chunk 0 was
    written; OUT is not there; fixed, `resume` reuses chunk 0 and writes the whole file."""
    columns = _bodies(tmp_path / "in.csv")
    good = _chunks(columns)
    bad = [good[0], {**good[1], "m": np.r_[good[1]["m"][:7], -1.0, good[1]["m"][8:]]}, good[2]]
    with pytest.raises(ValueError, match=r"chunk 1, row 7 \(row 107 of all\), column m"):
        ji.batch_file((c for c in bad), tmp_path / "out.csv", "hertz_rate", progress=False)
    assert not (tmp_path / "out.csv").exists()
    with pytest.raises(ValueError, match=r"chunk 1, row 7"):  # a list: before any work
        ji.batch_file(bad, tmp_path / "list.csv", "hertz_rate", progress=False)
    assert not Path(f"{tmp_path / 'list.csv'}.parts").exists()
    again = ji.batch_file(
        (c for c in good), tmp_path / "out.csv", "hertz_rate", resume=True, progress=False
    )
    assert (again.computed, again.reused) == (2, 1)
    whole = ji.batch_file(good, tmp_path / "whole.csv", "hertz_rate", progress=False)
    assert whole.computed == 3
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()


@pytest.mark.parametrize(
    "chunks, kwargs, match",
    [
        (
            [{"c": [1e6], "b1": [1.0], "v0": [1.0]}, {"c": [1e6], "v0": [1.0]}],
            {},
            "chunk 1: columns c, v0, not those of chunk 0",
        ),
        ([[1, 2, 3]], {}, "chunk 0: a mapping column -> array is needed, got list"),
        ([], {}, "holds no chunk"),
        (
            [{"c": [1e6, 2e6], "b1": [1.0, 2.0, 3.0], "v0": 1.0}],
            {},
            "column c: 2 values for 3 rows",
        ),
        ([{"c": ["a"], "b1": [1.0], "v0": 1.0}], {}, "column c: not numbers"),
        (
            [{"c": [1e6], "b1": [1.0], "v0": [1.0], "V0": [2.0]}],
            {},
            r"chunk 0: unknown column 'V0' \(did you mean v0\?\)",
        ),
        ([{"c": [1e6], "b1": [1.0]}], {}, "no value for v0"),
    ],
)
def test_bad_chunks_are_named_in_one_line(tmp_path, chunks, kwargs, match):
    with pytest.raises(ValueError, match=match) as info:
        ji.impact_batch("hertz_rate", chunks, out=tmp_path / "o.csv", m=1.0, progress=False)
    assert "\n" not in str(info.value)
    assert not (tmp_path / "o.csv").exists()


def test_impact_batch_streaming_needs_a_name_and_a_path(tmp_path):
    chunks = [{"c": [1e6], "b1": [1.0], "v0": [1.0]}]
    with pytest.raises(ValueError, match="needs out="):
        ji.impact_batch("hertz_rate", chunks, m=1.0)
    with pytest.raises(ValueError, match="takes a law name"):  # or a law (a user's: its tests)
        ji.impact_batch(object(), chunks, m=1.0, out=tmp_path / "o.csv")
    with pytest.raises(ValueError, match="needs m= .* and v0="):
        ji.impact_batch("hertz_rate", {"c": 1e6, "b1": 1.0})


def test_progress_reports_rows_per_second_and_time_left():
    assert job._rate(1000, 4000, 2.0) == "1,000 rows, 500 rows/s, 0m06s left"


def test_cli_batch(capsys, tmp_path):
    _bodies(tmp_path / "in.csv", n=20)
    out = tmp_path / "out.csv"
    argv = ["batch", str(tmp_path / "in.csv"), "--law", "hertz_rate", "--out", str(out)]
    status, text, err = run_cli(capsys, [*argv, "--chunk-rows", "8"])
    assert status == 0 and "20 impacts written" in text and "3 chunks computed" in text
    assert set(_read(out)["path"]) == {"similarity"}
    status, text, err = run_cli(capsys, [*argv, "--chunk-rows", "8", "--resume"])
    assert status == 0 and "3 chunks computed" in text  # OUT done: its parts are gone
    for bad, message in [
        ("c,b1,m,v0\n2e6,800,1,oops\n", "line 2, column v0"),
        ("c,b1,m\n2e6,800,1\n", "no value for v0"),
    ]:
        (tmp_path / "bad.csv").write_text(bad)
        result = run_cli(
            capsys,
            [
                "batch",
                str(tmp_path / "bad.csv"),
                "--law",
                "hertz_rate",
                "--out",
                str(tmp_path / "o.csv"),
            ],
        )
        assert_one_line_error(*result, contains=message)
        assert not (tmp_path / "o.csv").exists() and not (tmp_path / "o.csv.parts").exists()
    result = run_cli(capsys, [*argv, "--num-processes", "2"])
    assert_one_line_error(*result, contains="--coordinator, --process-id missing")
    result = run_cli(
        capsys, [*argv, "--coordinator", "localhost:1", "--num-processes", "2", "--process-id", "2"]
    )
    assert_one_line_error(*result, contains="--process-id must lie in 0 .. 1")


# -- several processes: real `jaximpact batch` processes on this machine ---------------------


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


def _env():
    flags = os.environ.get("XLA_FLAGS", "")  # the same compiler flags in every process
    return dict(os.environ, JAX_PLATFORMS="cpu", XLA_FLAGS=flags, JAXIMPACT_PROGRESS="off")


def _start(argv, processes: int, **popen):
    """`jaximpact batch argv` as `processes` processes of one jax.distributed job."""
    command = [sys.executable, "-m", "jaximpact._cli", "batch", *argv]
    if processes == 1:
        return [subprocess.Popen(command, env=_env(), **popen)]
    port = _free_port()
    return [
        subprocess.Popen(
            [
                *command,
                "--coordinator",
                f"localhost:{port}",
                "--num-processes",
                str(processes),
                "--process-id",
                str(k),
            ],
            env=_env(),
            **popen,
        )
        for k in range(processes)
    ]


def _finish(procs, timeout=400):
    outputs = [p.communicate(timeout=timeout) for p in procs]
    for p, (_, err) in zip(procs, outputs, strict=True):
        assert p.returncode == 0, err.decode()[-2000:]
    return [out.decode() for out, _ in outputs]


@pytest.mark.slow
@pytest.mark.parametrize(
    "mesh",
    # each takes 2 minutes on 2 cores: `local` (each process on its own devices, the
    # simpler plan) is `very_slow` (run with -m very_slow)
    ["global", pytest.param("local", marks=pytest.mark.very_slow)],
)
def test_two_processes_write_the_file_of_one_bit_for_bit(tmp_path, mesh):
    """Integrated (gravity on some rows) and curves rows under both criteria, 2 processes
    against 1: one program over both processes' devices (`global`, row groups a process
    lacks in a round included) or each process on its own (`local`)."""
    rng = np.random.default_rng(7)
    separation = np.where(rng.random(300) < 0.3, "penetration", "force")
    _bodies(
        tmp_path / "in.csv",
        n=300,
        g=np.where(rng.random(300) < 0.2, 9.81, 0.0),
        separation=separation,
    )
    # 9 chunks: process 1 has none in the last round, and takes part in it all the same
    argv = [str(tmp_path / "in.csv"), "--law", "hertz_rate", "--chunk-rows", "35"]
    pipes = dict(stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    one = _finish(_start([*argv, "--out", str(tmp_path / "one.csv")], 1, **pipes))
    two = _finish(_start([*argv, "--out", str(tmp_path / "two.csv"), "--mesh", mesh], 2, **pipes))
    assert "300 impacts written" in one[0] and "9 chunks computed" in one[0]
    assert "process 0 of 2" in two[0] and "5 chunks computed" in two[0]
    assert "process 1 of 2" in two[1] and "4 chunks computed" in two[1]
    assert (tmp_path / "two.csv").read_bytes() == (tmp_path / "one.csv").read_bytes()
    out = _read(tmp_path / "one.csv")
    g = np.asarray(out["g"], float)
    assert set(np.asarray(out["path"])[g > 0]) == {"integrated"}
    assert set(np.asarray(out["path"])[g == 0]) == {"similarity"}
    rows = g > 0  # the integrated rows against the batch in memory
    rows &= np.asarray(out["separation"]) == "force"
    want = ji.impact_batch(
        "hertz_rate",
        {k: np.asarray(out[k], float)[rows] for k in ("c", "b1")},
        m=np.asarray(out["m"], float)[rows],
        v0=np.asarray(out["v0"], float)[rows],
        g=9.81,
        progress=False,
    )
    np.testing.assert_allclose(np.asarray(out["e"], float)[rows], want["e"], rtol=1e-9)
    np.testing.assert_allclose(np.asarray(out["T"], float)[rows], want["T"], rtol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("mesh", ["global", "local"])
def test_a_killed_run_of_two_processes_is_completed_by_resume(tmp_path, mesh):
    """Process 1 killed midway (SIGKILL), process 0 then stopped; `--resume` on two
    processes finishes the file: equal, bit for bit, to a run never stopped."""
    _bodies(tmp_path / "in.csv", n=4000)
    argv = [str(tmp_path / "in.csv"), "--law", "hertz_rate", "--chunk-rows", "5"]
    _finish(
        _start(
            [*argv, "--out", str(tmp_path / "whole.csv")],
            1,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
    )
    out = tmp_path / "out.csv"
    parts = Path(f"{out}.parts")
    quiet = dict(stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    procs = _start([*argv, "--out", str(out), "--mesh", mesh], 2, **quiet)
    deadline = time.monotonic() + 300
    while not list(parts.glob("part-*1.json")) and time.monotonic() < deadline:
        time.sleep(0.01)  # until process 1 has finished a few chunks
    for p in reversed(procs):
        os.kill(p.pid, signal.SIGKILL)
        p.wait()
    done = len(list(parts.glob("part-*.json")))
    assert 0 < done < 800 and not out.exists()
    pipes = dict(stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    texts = _finish(_start([*argv, "--out", str(out), "--resume", "--mesh", mesh], 2, **pipes))
    reused = sum(int(t.split(" reused")[0].rsplit(", ", 1)[1]) for t in texts)
    assert reused == done
    assert out.read_bytes() == (tmp_path / "whole.csv").read_bytes()
    assert not parts.exists()
