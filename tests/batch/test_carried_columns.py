"""Columns a file job does not read (`id`, `name`, `note`: free text) are carried through to
the output unchanged, in their input position, so that a user can join the tables; a column
whose name is close to one the job reads (`separaton`, `V0`, `b_1`) is still refused, naming
the likely column (a misspelt column silently ignored would change every answer).

Compilation: the laws and chunk sizes of test_files.py (`hertz_rate`, 250 rows in chunks of
100) and test_custom_law_files.py (a user's law, 6 rows in chunks of 3): no new program."""

import csv
import re

import jax.numpy as jnp
import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

import jaximpact as ji
from jaximpact._jobs import job

N, CHUNK = 250, 100  # test_files.py
USER_N, USER_CHUNK = 6, 3  # test_custom_law_files.py
RESULTS = ["e", "T", "x_max", "t_max", "F_max", "status", "path"]
NOTES = ["café", "premier essai", "essai, n° 2", 'dit "bon"', "Zürich"]


def hertz_rate(x, v, p):
    """Law 14 as a user writes it (test_custom_law_files.py)."""
    return p["c"] * x**1.5 + p["b1"] * jnp.sqrt(x) * v


def _write(path, columns: dict):
    """`columns` as a CSV saved by Excel on Windows: cp1252, CRLF, text quoted where needed."""
    rows = zip(*columns.values(), strict=True)
    with open(path, "w", encoding="cp1252", newline="") as handle:
        writer = csv.writer(handle, lineterminator="\r\n")
        writer.writerow(columns)
        writer.writerows([x if isinstance(x, str) else repr(float(x)) for x in row] for row in rows)


def _read(path):
    with open(path, newline="", encoding="utf-8") as handle:
        rows = list(csv.DictReader(handle))
    return {k: [row[k] for row in rows] for k in rows[0]}


def _table_columns(n=N, carried=True):
    rng = np.random.default_rng(1)
    numbers = dict(
        c=rng.uniform(1e6, 3e6, n),
        b1=rng.uniform(100.0, 2000.0, n),
        m=rng.uniform(0.5, 2.0, n),
        v0=rng.uniform(0.5, 5.0, n),
    )
    if not carried:
        return numbers
    ids = [f"B-{i:04d}" for i in range(n)]
    notes = [NOTES[i % len(NOTES)] for i in range(n)]
    return dict(
        id=ids, c=numbers["c"], b1=numbers["b1"], note=notes, m=numbers["m"], v0=numbers["v0"]
    )


def test_text_columns_are_carried_through_row_for_row_with_a_table_law(tmp_path):
    columns = _table_columns()
    _write(tmp_path / "in.csv", columns)
    _write(tmp_path / "plain.csv", _table_columns(carried=False))
    kwargs = dict(chunk_rows=CHUNK, progress=False)
    record = ji.batch_file(tmp_path / "in.csv", tmp_path / "out.csv", "hertz_rate", **kwargs)
    assert (record.rows, record.chunks) == (N, 3)
    ji.batch_file(tmp_path / "plain.csv", tmp_path / "plain_out.csv", "hertz_rate", **kwargs)
    out, plain = _read(tmp_path / "out.csv"), _read(tmp_path / "plain_out.csv")
    assert list(out) == ["id", "c", "b1", "note", "m", "v0", *RESULTS]  # input position
    assert out["id"] == columns["id"] and out["note"] == columns["note"]  # cp1252 decoded
    for key in ("c", "b1", "m", "v0", *RESULTS):  # the same rows as without the text
        assert out[key] == plain[key], key


def test_the_command_line_carries_a_note_column(tmp_path, capsys):
    _write(
        tmp_path / "in.csv",
        {"m": [1.0] * N, "v0": np.linspace(0.5, 5, N), "note": [NOTES[i % 5] for i in range(N)]},
    )
    status, _, err = run_cli(
        capsys,
        [
            "batch",
            str(tmp_path / "in.csv"),
            "--out",
            str(tmp_path / "out.csv"),
            "--law",
            "hertz_rate",
            "--param",
            "c=2e6",
            "b1=800",
            "--chunk-rows",
            str(CHUNK),
        ],
    )
    assert status == 0, err
    out = _read(tmp_path / "out.csv")
    assert list(out) == ["m", "v0", "note", *RESULTS]
    assert out["note"] == [NOTES[i % 5] for i in range(N)]


def test_text_columns_are_carried_through_with_a_users_law(tmp_path):
    law = ji.custom_law(hertz_rate, c=2e6, b1=800.0)
    columns = dict(
        id=[str(i) for i in range(USER_N)],
        c=np.linspace(1.5e6, 3e6, USER_N),
        m=np.linspace(0.5, 2.0, USER_N),
        note=NOTES[: USER_N - 1] + ["fin"],
        v0=np.linspace(0.5, 4.0, USER_N),
    )
    _write(tmp_path / "in.csv", columns)
    record = ji.batch_file(
        tmp_path / "in.csv", tmp_path / "out.csv", law, chunk_rows=USER_CHUNK, progress=False
    )
    assert record.statuses["separated"] == USER_N
    out = _read(tmp_path / "out.csv")
    assert list(out) == ["id", "c", "m", "note", "v0", *RESULTS]
    assert out["id"] == columns["id"] and out["note"] == columns["note"]
    # chunks from a script carry their text columns too (a user's law, the same rows)
    chunks = [
        {k: v[i : i + USER_CHUNK] for k, v in columns.items()} for i in range(0, USER_N, USER_CHUNK)
    ]
    ji.impact_batch(law, chunks, out=tmp_path / "chunks.csv", progress=False)
    assert _read(tmp_path / "chunks.csv") == out


@pytest.mark.parametrize(
    "header, law, match",
    [
        (
            "c,b1,m,v0,separaton",
            "hertz_rate",
            r"unknown column 'separaton' \(did you mean separation\?\)",
        ),
        ("c,b1,m,V0,note", "hertz_rate", r"unknown column 'V0' \(did you mean v0\?\)"),
        ("c,b_1,m,v0", "hertz_rate", r"unknown column 'b_1' \(did you mean b1\?\)"),
        ("c,m,v0,Separation", "user", r"unknown column 'Separation' \(did you mean separation\?\)"),
        ("c,B_1,m,v0", "user", r"unknown column 'B_1' \(did you mean b1\?\)"),
        ("c,b1,m,v0,status", "hertz_rate", r"column 'status' is a result the output writes"),
    ],
)
def test_a_misspelt_column_is_refused_with_the_nearest_name(tmp_path, header, law, match):
    (tmp_path / "in.csv").write_text(header + "\n" + ",".join(["1"] * len(header.split(","))))
    if law == "user":
        law = ji.custom_law(hertz_rate, c=2e6, b1=800.0)
    with pytest.raises(ValueError, match=r"in\.csv, line 1: " + match) as info:
        ji.batch_file(tmp_path / "in.csv", tmp_path / "out.csv", law, progress=False)
    assert "\n" not in str(info.value)
    assert not (tmp_path / "out.csv").exists()


def test_the_command_line_refuses_a_misspelt_column(tmp_path, capsys):
    (tmp_path / "in.csv").write_text("m,v0,separaton\n1,2,force\n")
    result = run_cli(
        capsys,
        [
            "batch",
            str(tmp_path / "in.csv"),
            "--out",
            str(tmp_path / "out.csv"),
            "--law",
            "hertz_rate",
            "--param",
            "c=2e6",
            "b1=800",
        ],
    )
    assert_one_line_error(*result, contains="did you mean separation?")


def test_a_missing_column_names_the_columns_carried_unread(tmp_path):
    (tmp_path / "in.csv").write_text("c,b1,mass,v0\n2e6,800,1,2.5\n")
    with pytest.raises(ValueError, match=r"no value for m: .*\(carried through unread: mass\)"):
        ji.batch_file(tmp_path / "in.csv", tmp_path / "out.csv", "hertz_rate", progress=False)


@pytest.mark.parametrize("header", ["v0 (m/s)", "v0 [mm/s]", "c (N/m^1.5)"])
def test_a_read_column_with_a_unit_is_refused_not_carried(tmp_path, header):
    """`v0 (m/s)` carried unread beside --v0 would give every row the option's speed next
    to the file's own: one line says to name the column alone, in SI units."""
    cells = {"v0": "c,b1,m,{}\n2e6,800,1,2.5\n", "c": "{},b1,m,v0\n2e6,800,1,2.5\n"}
    (tmp_path / "in.csv").write_text(cells[header.split()[0]].format(header))
    name = header.split()[0]
    with pytest.raises(ValueError, match=rf"column '{re.escape(header)}' gives {name} with a unit"):
        ji.batch_file(
            tmp_path / "in.csv", tmp_path / "out.csv", "hertz_rate", v0=2.5, progress=False
        )


def test_a_resume_checks_the_carried_columns(tmp_path):
    """The carried columns are part of each chunk's input: a changed note changes the hash
    of its chunk only (a resume recomputes that chunk)."""

    def digests(columns):
        _write(tmp_path / "in.csv", columns)
        planned = job.plan(
            tmp_path / "in.csv",
            tmp_path / "out.csv",
            "hertz_rate",
            params={},
            given=dict.fromkeys(("m", "v0", "g", "separation")),
            run=job.Run(chunk_rows=CHUNK, resume=True, progress=False, mesh="local"),
            impact_options={},
        )
        return job.check(planned).digests

    columns = _table_columns()
    before = digests(columns)
    columns["note"] = [*columns["note"][:150], "changed", *columns["note"][151:]]
    after = digests(columns)
    assert [before[i] == after[i] for i in range(3)] == [True, False, True]


def test_parquet_keeps_the_text_columns(tmp_path):
    pa = pytest.importorskip("pyarrow")
    pq = pytest.importorskip("pyarrow.parquet")
    columns = _table_columns()
    _write(tmp_path / "in.csv", columns)
    kwargs = dict(chunk_rows=CHUNK, progress=False)
    ji.batch_file(tmp_path / "in.csv", tmp_path / "csv.csv", "hertz_rate", **kwargs)
    ji.batch_file(tmp_path / "in.csv", tmp_path / "out.parquet", "hertz_rate", **kwargs)
    table = pq.read_table(tmp_path / "out.parquet")
    assert table.column_names == ["id", "c", "b1", "note", "m", "v0", *RESULTS]
    assert table.schema.field("note").type == pa.string()
    assert table.column("note").to_pylist() == columns["note"]
    assert table.column("id").to_pylist() == columns["id"]
    # Parquet in (an integer id, a text note): text columns out, in Parquet and in CSV
    source = pa.table(
        {
            **{k: columns[k] for k in ("c", "b1", "m", "v0")},
            "id": pa.array(range(N), pa.int64()),
            "note": columns["note"],
        }
    )
    pq.write_table(source, tmp_path / "in.parquet", row_group_size=37)
    ji.batch_file(tmp_path / "in.parquet", tmp_path / "pq.parquet", "hertz_rate", **kwargs)
    ji.batch_file(tmp_path / "in.parquet", tmp_path / "pq.csv", "hertz_rate", **kwargs)
    again = pq.read_table(tmp_path / "pq.parquet")
    assert again.schema.field("id").type == pa.string()
    assert again.column("id").to_pylist() == [str(i) for i in range(N)]
    assert again.column("note").to_pylist() == columns["note"]
    out, want = _read(tmp_path / "pq.csv"), _read(tmp_path / "csv.csv")
    assert list(out) == ["c", "b1", "m", "v0", "id", "note", *RESULTS]
    assert out["note"] == columns["note"]  # quoted where it holds a comma or a quote
    for key in RESULTS:
        assert out[key] == want[key], key
