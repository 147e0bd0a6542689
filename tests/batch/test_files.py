"""`batch_file` and `jaximpact batch`: a CSV of bodies in, one impact per row out, streamed in
chunks, resumable, every bad value refused before any work."""

import csv

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

import jaximpact as ji
from jaximpact._batch import files

N, CHUNK = 250, 100


def _bodies(path, n=N, seed=1):
    rng = np.random.default_rng(seed)
    columns = dict(
        c=rng.uniform(1e6, 3e6, n),
        b1=rng.uniform(100.0, 2000.0, n),
        m=rng.uniform(0.5, 2.0, n),
        v0=rng.uniform(0.5, 5.0, n),
    )
    with open(path, "w") as handle:
        handle.write(",".join(columns) + "\n")
        for row in zip(*columns.values(), strict=True):
            handle.write(",".join(repr(float(x)) for x in row) + "\n")
    return columns


def _read(path):
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    return {k: [row[k] for row in rows] for k in rows[0]}


def test_every_row_equals_the_batch_in_memory(tmp_path):
    columns = _bodies(tmp_path / "in.csv")
    result = ji.batch_file(
        tmp_path / "in.csv", tmp_path / "out.csv", "hertz_rate", chunk_rows=CHUNK, progress=False
    )
    assert (result.rows, result.chunks, result.computed, result.reused) == (N, 3, 3, 0)
    assert result.statuses["separated"] == N
    assert not (tmp_path / "out.csv.parts").exists()
    out = _read(tmp_path / "out.csv")
    want = ji.impact_batch(
        "hertz_rate",
        {"c": columns["c"], "b1": columns["b1"]},
        m=columns["m"],
        v0=columns["v0"],
        progress=False,
    )
    for key in ("e", "T", "x_max", "F_max"):
        np.testing.assert_array_equal(np.asarray(out[key], float), want[key], err_msg=key)
    for key in ("c", "b1", "m", "v0"):  # the inputs as given, not reformatted
        assert out[key] == [repr(float(x)) for x in columns[key]]
    assert set(out["path"]) == {"similarity"} and set(out["status"]) == {"separated"}


def _interrupted(tmp_path, monkeypatch, source, after):
    """A run stopped (KeyboardInterrupt) once `after` chunks were written."""
    real, done = files._run_chunk, []

    def run_chunk(*args):
        if len(done) == after:
            raise KeyboardInterrupt
        done.append(1)
        return real(*args)

    monkeypatch.setattr(files, "_run_chunk", run_chunk)
    with pytest.raises(KeyboardInterrupt):
        ji.batch_file(source, tmp_path / "out.csv", "hertz_rate", chunk_rows=CHUNK, progress=False)
    monkeypatch.setattr(files, "_run_chunk", real)
    assert not (tmp_path / "out.csv").exists()  # nothing half-written where OUT goes


def test_resume_completes_an_interrupted_run_with_nothing_lost_or_repeated(tmp_path, monkeypatch):
    _bodies(tmp_path / "in.csv")
    ji.batch_file(
        tmp_path / "in.csv", tmp_path / "whole.csv", "hertz_rate", chunk_rows=CHUNK, progress=False
    )
    _interrupted(tmp_path, monkeypatch, tmp_path / "in.csv", after=2)
    result = ji.batch_file(
        tmp_path / "in.csv",
        tmp_path / "out.csv",
        "hertz_rate",
        chunk_rows=CHUNK,
        resume=True,
        progress=False,
    )
    assert (result.computed, result.reused) == (1, 2)
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "whole.csv").read_bytes()


def test_resume_recomputes_a_chunk_whose_input_changed(tmp_path, monkeypatch):
    _bodies(tmp_path / "in.csv")
    _interrupted(tmp_path, monkeypatch, tmp_path / "in.csv", after=2)
    lines = (tmp_path / "in.csv").read_text().splitlines()
    lines[5] = "2e6,800.0,1.0,2.5"  # a row of the first chunk
    (tmp_path / "in.csv").write_text("\n".join(lines) + "\n")
    result = ji.batch_file(
        tmp_path / "in.csv",
        tmp_path / "out.csv",
        "hertz_rate",
        chunk_rows=CHUNK,
        resume=True,
        progress=False,
    )
    assert (result.computed, result.reused) == (2, 1)
    fresh = ji.batch_file(
        tmp_path / "in.csv", tmp_path / "fresh.csv", "hertz_rate", chunk_rows=CHUNK, progress=False
    )
    assert fresh.computed == 3
    assert (tmp_path / "out.csv").read_bytes() == (tmp_path / "fresh.csv").read_bytes()


@pytest.mark.parametrize(
    "text, kwargs, match",
    [
        (None, {}, "no such file"),
        ("", {}, "empty file"),
        ("c,b1,mass,v0\n2e6,800,1,2.5\n", {}, r"line 1: unknown column 'mass'"),
        ("c,v0\n2e6,2.5\n", {"m": 1.0}, "no value for b1"),
        ("c,b1,m,v0\n2e6,800,1,2.5\n2e6,eight,1,2.5\n", {}, r"line 3, column b1: 'eight'"),
        ("c,b1,m,v0\n2e6,800,nan,2.5\n", {}, r"line 2, column m: m = nan must be"),
        ("c,b1,m,v0\n2e6,800,1,2.5\n2e6,800,1,-2\n", {}, r"line 3, column v0"),
        ("c,b1,m,v0\n2e6,800,1\n", {}, r"line 2: 3 cells for 4 columns"),
        ("c,b1,m,v0\n", {}, "no data rows"),
        ("c,b1,v0\n2e6,800,2.5\n", {"m": -1.0}, "fixed value m"),
    ],
)
def test_bad_input_is_named_before_any_work(tmp_path, text, kwargs, match):
    source = tmp_path / "in.csv"
    if text is not None:
        source.write_text(text)
    with pytest.raises(ValueError, match=match):
        ji.batch_file(source, tmp_path / "out.csv", "hertz_rate", progress=False, **kwargs)
    assert not (tmp_path / "out.csv").exists() and not (tmp_path / "out.csv.parts").exists()


def test_cli_batch(capsys, tmp_path):
    _bodies(tmp_path / "in.csv", n=20)
    out = tmp_path / "out.csv"
    argv = ["batch", str(tmp_path / "in.csv"), "--law", "hertz_rate", "--out", str(out)]
    status, text, err = run_cli(capsys, [*argv, "--chunk-rows", "8"])
    assert status == 0 and "20 impacts written" in text and "3 chunks computed" in text
    assert set(_read(out)["path"]) == {"similarity"}
    (tmp_path / "bad.csv").write_text("c,b1,m,v0\n2e6,800,1,oops\n")
    result = run_cli(capsys, ["batch", str(tmp_path / "bad.csv"), "--law", "hertz_rate",
                              "--out", str(tmp_path / "o.csv")])  # fmt: skip
    assert_one_line_error(*result, contains="line 2, column v0")
    assert not (tmp_path / "o.csv").exists()
