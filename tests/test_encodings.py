"""Input files as people save them (issue 34, item 5): UTF-8 with or without a byte-order mark
(Excel's "CSV UTF-8"), UTF-16 with one (either byte order), CRLF line ends, and Latin-1 or
cp1252 bytes where the job reads no number, all read alike by every reader of tables
(`_files.read_text` and `open_text`); a cell that is not a number (`2_000_000` included) is
refused in one line naming the file, the line and the column."""

import csv
from pathlib import Path

import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli

import jaximpact as ji
from jaximpact._cli import calibrate as cli_calibrate
from jaximpact._files import cell_number, read_csv, read_text

BODIES = "c,b1,m,v0\n2e6,800,1,2.5\n2e6,900,1,2.0\n2e6,1000,1,1.5\n"
SAVED_AS = {
    "utf-8": lambda text: text.encode("utf-8"),
    "utf-8 with a BOM": lambda text: text.encode("utf-8-sig"),
    "utf-16 (LE, BOM)": lambda text: b"\xff\xfe" + text.encode("utf-16-le"),
    "utf-16 (BE, BOM)": lambda text: b"\xfe\xff" + text.encode("utf-16-be"),
    "utf-8, CRLF": lambda text: text.replace("\n", "\r\n").encode("utf-8"),
    "utf-16, CRLF": lambda text: text.replace("\n", "\r\n").encode("utf-16"),
    "cp1252": lambda text: text.encode("cp1252"),
}


def _saved(path: Path, text: str, how: str) -> Path:
    path.write_bytes(SAVED_AS[how](text))
    return path


def _rows(path):
    with open(path, newline="", encoding="utf-8") as handle:
        return list(csv.DictReader(handle))


@pytest.mark.parametrize("how", SAVED_AS)
def test_read_text_reads_a_table_however_it_was_saved(tmp_path, how):
    text = "v0,e,note\n2.5,0.8,café à 20 °C\n"
    assert read_text(_saved(tmp_path / "t.csv", text, how)) == text


def test_bytes_of_latin_1_or_cp1252_are_read_line_by_line(tmp_path):
    utf8 = "v0,e,note\n2.5,0.8,déjà\n".encode()
    latin = "2.0,0.7,café – 20 °C\n".encode("cp1252")
    undefined = b"1.5,0.6,\x81\xe9\n"  # 0x81: no character in cp1252, read as Latin-1
    path = tmp_path / "mixed.csv"
    path.write_bytes(utf8 + latin + undefined)
    header, rows = read_csv(read_text(path))
    assert header == ["v0", "e", "note"]
    assert [cells[2] for _, cells in rows] == ["déjà", "café – 20 °C", "\x81é"]


def test_a_binary_file_is_not_text(tmp_path):
    path = tmp_path / "book.csv"
    path.write_bytes(b"PK\x03\x04\x14\x00\x06\x00" + bytes(range(256)))  # an .xlsx renamed
    with pytest.raises(ValueError, match="not a text file"):
        read_text(path)


@pytest.mark.parametrize(
    "cell, message",
    [
        ("2_000_000", "'2_000_000' is not a number: write 2000000"),
        ("２", "'２' is not a number"),
        ("", "an empty cell is not a number"),
        ("1,5", "'1,5' is not a number"),
    ],
)
def test_cell_number_refuses_python_s_own_spellings(cell, message):
    with pytest.raises(ValueError, match=f"^{message}$"):
        cell_number(cell)


def test_cell_number_reads_what_numpy_reads():
    assert cell_number(" 2e6 ") == 2e6 and cell_number("\xa01.5") == 1.5
    assert cell_number("+.5") == 0.5 and np.isinf(cell_number("inf"))


def test_batch_file_reads_every_encoding_alike(tmp_path):
    want = None
    for k, how in enumerate(SAVED_AS):
        source = _saved(tmp_path / f"in{k}.csv", BODIES, how)
        result = ji.batch_file(source, tmp_path / f"out{k}.csv", "hertz_rate", progress=False)
        assert result.rows == 3, how
        rows = _rows(tmp_path / f"out{k}.csv")
        assert list(rows[0])[:4] == ["c", "b1", "m", "v0"], how
        got = [(r["c"], r["b1"], r["m"], r["v0"], r["e"]) for r in rows]
        want = want or got
        assert got == want, how


@pytest.mark.parametrize(
    "cells, column, shown",
    [
        ("2_000_000,900,1,2.0", "c", "'2_000_000' is not a number: write 2000000"),
        ("2e6,900,1,2.0µ", "v0", "'2.0µ' is not a number"),  # cp1252 in a number column
    ],
)
def test_batch_file_names_file_line_and_column_of_a_bad_number(tmp_path, cells, column, shown):
    text = BODIES.replace("2e6,900,1,2.0", cells)
    source = _saved(tmp_path / "in.csv", text, "cp1252")
    with pytest.raises(ValueError) as error:
        ji.batch_file(source, tmp_path / "out.csv", "hertz_rate", progress=False)
    assert str(error.value) == f"{source}, line 3, column {column}: {shown}"


def test_cli_batch_reads_utf_16_and_names_a_bad_number(capsys, tmp_path):
    source = _saved(tmp_path / "in.csv", BODIES, "utf-16 (LE, BOM)")
    out = tmp_path / "out.csv"
    status, text, err = run_cli(
        capsys, ["batch", str(source), "--law", "hertz_rate", "--out", str(out)]
    )
    assert status == 0 and "3 impacts written" in text, err
    bad = _saved(tmp_path / "bad.csv", BODIES.replace("900", "9_00"), "utf-8 with a BOM")
    result = run_cli(capsys, ["batch", str(bad), "--law", "hertz_rate", "--out", str(out)])
    assert_one_line_error(*result, contains=f"{bad}, line 3, column b1: '9_00' is not a number")


DATA = "# mesuré à 20 °C\nv0,e,T\n2.5,0.8,7.8e-3\n1.5,0.85,\n"


@pytest.mark.parametrize("how", SAVED_AS)
def test_calibrate_data_reads_every_encoding_alike(tmp_path, how):
    data = cli_calibrate.read_data(_saved(tmp_path / "d.csv", DATA, how))
    assert data["v0"] == [2.5, 1.5] and data["e"] == [0.8, 0.85]
    assert data["T"][0] == 7.8e-3 and np.isnan(data["T"][1])


@pytest.mark.parametrize(
    "header",
    ["v0,e,T", "v0 (m/s),e,T (s)", "v0 [mm/s],e (-),T [ms]", "v0 (cm/s),e,T (µs)"],
)
def test_calibrate_data_reads_the_units_its_header_gives(tmp_path, header):
    """Excel's habit of a unit in the header: read in that unit, held in SI, once rounded
    (0.9 ms is 0.9 / 1000 s, the same float as 9e-4 typed in s)."""
    scale = {"mm/s": 1e3, "cm/s": 1e2, "ms": 1e3, "µs": 1e6}
    unit = [cell.split("(")[-1].split("[")[-1].strip(")]") for cell in header.split(",")]
    v0, T = [2.5, 1.5], [9e-4, 7.8e-3]
    rows = [
        f"{v * scale.get(unit[0], 1):g},0.8,{t * scale.get(unit[2], 1):g}"
        for v, t in zip(v0, T, strict=True)
    ]
    path = _saved(tmp_path / "d.csv", "\n".join([header, *rows]) + "\n", "utf-8 with a BOM")
    data = cli_calibrate.read_data(path)
    assert data["v0"] == v0 and data["T"] == T and data["e"] == [0.8, 0.8]


@pytest.mark.parametrize(
    "header, said",
    [
        ("v0,e,T (min)", "column 'T' in 'min': give it in one of s, ms, µs"),
        ("v0 (km/h),e", "column 'v0' in 'km/h': give it in one of m/s, mm/s, cm/s"),
        ("speed (m/s),e", "unknown column 'speed (m/s)'"),
    ],
)
def test_calibrate_data_refuses_a_unit_it_cannot_read(capsys, tmp_path, header, said):
    path = _saved(tmp_path / "d.csv", f"{header}\n1,0.8" + ",1" * header.count("T") + "\n", "utf-8")
    argv = ["calibrate", "--law", "hertz_rate", "--mass", "1", "--data", str(path)]
    assert_one_line_error(*run_cli(capsys, argv), contains=said)


@pytest.mark.parametrize(
    "row, column, bad", [("2_500,0.8", "v0", "2_500"), ("2.5,0.8µ", "e", "0.8µ")]
)
def test_calibrate_data_names_file_line_and_column(capsys, tmp_path, row, column, bad):
    text = DATA.replace("2.5,0.8", row)
    path = _saved(tmp_path / "d.csv", text, "cp1252")
    argv = ["calibrate", "--law", "hertz_rate", "--mass", "1", "--data", str(path)]
    assert_one_line_error(
        *run_cli(capsys, argv), contains=f"--data {path}, line 3, column {column}: {bad!r}"
    )


def test_read_recording_keeps_a_latin_1_note_and_names_a_bad_time(tmp_path):
    text = "drop,note,impact_time\n1,café,0.10\n1,café,0.35\n2,thé,0.20\n2,thé,0.41\n"
    path = _saved(tmp_path / "r.csv", text, "cp1252")
    recording = ji.read_recording(path)
    assert set(recording.groups) == {"drop=1, note=café", "drop=2, note=thé"}
    _saved(path, text.replace("0.35", "0.3_5"), "utf-16 (BE, BOM)")
    with pytest.raises(ValueError) as error:
        ji.read_recording(path)
    assert str(error.value) == (
        f"{path}, line 3, column impact_time: '0.3_5' is not a number: write 0.35"
    )


def test_oblique_rebounds_and_tracks_read_the_units_their_header_gives(tmp_path):
    """`fit-oblique`'s files take the same header units: speeds in mm/s, a track's times
    in ms and positions in mm are held in SI."""
    from jaximpact._oblique.report import read_rebounds

    plain = _saved(tmp_path / "a.csv", "v_n,v_t,e_t\n3.9,1.2,0.5\n", "utf-8")
    headed = _saved(tmp_path / "b.csv", "v_n (mm/s),v_t [mm/s],e_t\n3900,1200,0.5\n", "utf-8")
    assert read_rebounds(headed, None) == read_rebounds(plain, None)
    with pytest.raises(ValueError, match=r"column 't' in 'min': give it in one of s, ms, µs"):
        read_rebounds(_saved(tmp_path / "c.csv", "t (min),x,y,phi\n0,0,0,0\n", "utf-8"), None)
