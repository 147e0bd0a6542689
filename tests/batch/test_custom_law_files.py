"""A user's law to a file: `batch_file` and `impact_batch(..., out=)` take a `custom_law` as
they take a law name (issue 34, item 2: `TypeError: unhashable type: 'dict'` before), its
rows equal to `impact` of the same law and to the table's `hertz_rate` (law 14, the same
force) to 1e-9; a resume reuses only the chunks of the same law and parameters.

Compilation: every test runs the one law function on chunks of 3 rows (one compiled block
shape), so the file tests share one compiled program; `impact` compiles once more."""

import csv

import jax.numpy as jnp
import numpy as np
import pytest
from helpers import assert_rel

import jaximpact as ji
from jaximpact._jobs import job

N, CHUNK = 6, 3
B1 = 800.0


def hertz_rate(x, v, p):
    """Law 14 as a user writes it: `c x^1.5 + b1 x^0.5 v`."""
    return p["c"] * x**1.5 + p["b1"] * jnp.sqrt(x) * v


LAW = ji.custom_law(hertz_rate, c=2e6, b1=B1)
COLUMNS = dict(
    c=np.linspace(1.5e6, 3e6, N),
    m=np.linspace(0.5, 2.0, N),
    v0=np.linspace(0.5, 4.0, N),
)
FIELDS = ("e", "T", "x_max", "t_max", "F_max")


def _write_bodies(path):
    with open(path, "w") as handle:
        handle.write(",".join(COLUMNS) + "\n")
        for row in zip(*COLUMNS.values(), strict=True):
            handle.write(",".join(repr(float(x)) for x in row) + "\n")


def _read(path):
    with open(path, newline="") as handle:
        rows = list(csv.DictReader(handle))
    return {k: [row[k] for row in rows] for k in rows[0]}


def _run(tmp_path, name="out.csv", law=LAW, **kwargs):
    kwargs = {"chunk_rows": CHUNK, "progress": False, **kwargs}
    return ji.batch_file(tmp_path / "in.csv", tmp_path / name, law, **kwargs)


@pytest.fixture(scope="module")
def whole(tmp_path_factory):
    """The file of a whole run with the user's law, and its record."""
    tmp_path = tmp_path_factory.mktemp("whole")
    _write_bodies(tmp_path / "in.csv")
    record = _run(tmp_path)
    return tmp_path / "out.csv", record


def test_batch_file_takes_a_users_law(whole, tmp_path):
    path, record = whole
    assert (record.rows, record.chunks, record.computed, record.reused) == (N, 2, 2, 0)
    assert record.statuses["separated"] == N
    out = _read(path)
    assert list(out) == [*COLUMNS, *FIELDS, "status", "path"]
    assert set(out["status"]) == {"separated"} and set(out["path"]) == {"grid"}
    got = {k: np.asarray(out[k], float) for k in FIELDS}
    for i in (0, 3, 5):  # `impact` of the same law, row by row (the file: the grid)
        r = ji.impact(LAW.replace(c=COLUMNS["c"][i]), m=COLUMNS["m"][i], v0=COLUMNS["v0"][i])
        for k in FIELDS:
            assert_rel(got[k][i], getattr(r, k), 1e-9, f"row {i}: {k}")  # grid vs events
    _write_bodies(tmp_path / "in.csv")  # the table's law 14, the same force
    _run(tmp_path, "table.csv", law="hertz_rate", params={"b1": B1})
    table = _read(tmp_path / "table.csv")
    for k in FIELDS:
        assert_rel(got[k], np.asarray(table[k], float), 1e-9, k)


def test_impact_batch_to_a_file_takes_a_users_law(whole, tmp_path):
    chunks = [{k: v[i : i + CHUNK] for k, v in COLUMNS.items()} for i in range(0, N, CHUNK)]
    record = ji.impact_batch(LAW, chunks, out=tmp_path / "o.csv", progress=False)
    assert isinstance(record, ji.BatchFile) and (record.rows, record.chunks) == (N, 2)
    out, want = _read(tmp_path / "o.csv"), _read(whole[0])
    for k in (*FIELDS, "status", "path"):  # the same rows as the file's, bit for bit
        assert out[k] == want[k], k


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
    assert not (tmp_path / "out.csv").exists()


def test_resume_takes_the_same_users_law_and_refuses_a_changed_one(whole, tmp_path, monkeypatch):
    _write_bodies(tmp_path / "in.csv")
    _interrupted(tmp_path, monkeypatch, after=1)
    again = ji.custom_law(hertz_rate, c=2e6, b1=B1)  # the same law, made anew
    record = _run(tmp_path, law=again, resume=True)
    assert (record.computed, record.reused) == (1, 1)
    assert (tmp_path / "out.csv").read_bytes() == whole[0].read_bytes()
    (tmp_path / "out.csv").unlink()
    _interrupted(tmp_path, monkeypatch, after=1)
    record = _run(tmp_path, law=LAW.replace(b1=900.0), resume=True)  # a parameter changed
    assert (record.computed, record.reused) == (2, 0)
    assert _read(tmp_path / "out.csv")["e"] != _read(whole[0])["e"]


def test_a_resume_tells_users_laws_apart():
    """What a resume compares: the function (its name, file and code), not the parameter
    values (those are hashed with each chunk's inputs)."""
    from jaximpact._jobs.job_law import job_law

    def other(x, v, p):
        return p["c"] * x**1.5

    same = job_law(ji.custom_law(hertz_rate, c=1.0, b1=2.0)).identity
    assert job_law(LAW).identity == same
    assert job_law(ji.custom_law(other, c=2e6, b1=B1)).identity != same
    assert job_law("hertz_rate").identity == "hertz_rate"  # the table's: as before


def test_columns_and_params_are_parameters_the_users_law_reads(tmp_path):
    (tmp_path / "in.csv").write_text("c,m,v0\n2e6,1,1\n")
    with pytest.raises(ValueError, match=r'custom reads params\["b1"\]: give a column b1'):
        _run(tmp_path, law=ji.custom_law(hertz_rate, c=2e6))
    (tmp_path / "in.csv").write_text("c,b_1,m,v0\n2e6,1,1,1\n")  # `zz` would be carried through
    with pytest.raises(ValueError, match=r"unknown column 'b_1' \(did you mean b1\?\)"):
        _run(tmp_path)
    (tmp_path / "in.csv").write_text("c,B1,m,v0\n2e6,1,1,1\n")
    with pytest.raises(ValueError, match=r'reads params\["b1"\]: .* \(column \'B1\' is not b1\)'):
        _run(tmp_path, law=ji.custom_law(hertz_rate, c=2e6))
    with pytest.raises(ValueError, match="column 'c' is not a parameter of custom .*reads c2"):
        _run(tmp_path, law=ji.custom_law(lambda x, v, p: p["c2"] * x**1.5, c=2e6, c2=2e6))
    (tmp_path / "in.csv").write_text("c,m,v0\n2e6,1,1\n")
    with pytest.raises(ValueError, match=r'custom does not read params\["zz"\]'):
        _run(tmp_path, params={"zz": 1.0})
    with pytest.raises(ValueError, match="c = nan must be a finite number"):
        (tmp_path / "in.csv").write_text("c,m,v0\nnan,1,1\n")
        _run(tmp_path)
    with pytest.raises(ValueError, match="parameter c holds 2 values"):
        _run(tmp_path, law=ji.custom_law(hertz_rate, c=[1e6, 2e6], b1=B1))
    with pytest.raises(ValueError, match="law must be a name of LAW_NAMES, a law"):
        _run(tmp_path, law=3.0)
    with pytest.raises(ValueError, match="takes a law name .* got float"):
        ji.impact_batch(3.0, [{"c": [1e6], "m": [1.0], "v0": [1.0]}], out=tmp_path / "o.csv")
    assert not (tmp_path / "out.csv").exists() and not (tmp_path / "o.csv").exists()


def test_a_users_law_takes_parameters_of_any_sign(tmp_path):
    """A user's law decides its parameters' signs: a negative value given for every row
    is no error of the file (checked without computing: `plan` and `check` only)."""
    (tmp_path / "in.csv").write_text("c,m,v0\n2e6,1,1\n")
    law = ji.custom_law(lambda x, v, p: p["c"] * x**1.5 + p["s"] * 0.0 * v, c=2e6, s=-1.0)
    planned = job.check(
        job.plan(
            tmp_path / "in.csv",
            tmp_path / "out.csv",
            law,
            params=None,
            given={"m": None, "v0": None, "g": None, "separation": None},
            run=job.Run(chunk_rows=CHUNK, resume=False, progress=False, mesh="local"),
            impact_options={},
        )
    )
    assert planned.rows == 1 and planned.law.parameters == ("c", "s")
    assert planned.fixed == {"s": -1.0, "separation": "force", "g": 0.0}
