"""What the command line reads and draws through the library: a small CSV of numbers
(`_files.read_table`), a user's law file (`_laws.custom.load_law_function`), a fit's JSON
whose user's law cannot be loaded (`common.read_fit`: the loader's own line), and the
commands' figures (`_plotting`)."""

import json
import math
import re

import numpy as np
import pytest

from jaximpact import _plotting
from jaximpact._cli.common import read_fit
from jaximpact._files import read_table
from jaximpact._laws.custom import LawFileError, load_law_function

COLUMNS = ("v0", "e", "T")


def _table(tmp_path, text):
    path = tmp_path / "d.csv"
    path.write_text(text)
    return read_table(path, COLUMNS, label="--data d.csv", hint="v0,e[,T]", needed=("v0", "e"))


def test_read_table_reads_numbers_comments_and_empty_cells(tmp_path):
    header, rows = _table(tmp_path, "# drops\nv0,e,T\n1,0.8,\n\n2,0.7,1e-3\n")
    assert header == ["v0", "e", "T"]
    assert [line for line, _ in rows] == [3, 5]
    assert rows[0][1]["v0"] == 1.0 and math.isnan(rows[0][1]["T"])
    assert rows[1][1] == {"v0": 2.0, "e": 0.7, "T": 1e-3}


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "--data d.csv is empty"),
        ("v0,e,x\n1,2,3\n", "--data d.csv: unknown column 'x'; the columns are v0,e[,T]"),
        ("v0,v0,e\n1,2,3\n", "a column is named twice"),
        ("v0,T\n1,2\n", "no column 'e' (need v0,e[,T])"),
        ("v0,e\n1,2,3\n", "--data d.csv, line 2: 3 cells for 2 columns"),
        ("v0,e\n1,x\n", "--data d.csv, line 2, column e: 'x' is not a number"),
    ],
)
def test_read_table_says_what_is_wrong_in_one_line(tmp_path, text, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        _table(tmp_path, text)


def test_load_law_function_loads_once_and_refuses_in_one_line(tmp_path):
    path = tmp_path / "mylaw.py"
    path.write_text("def force(x, v, params):\n    return params['c'] * x\n")
    fn = load_law_function(f"{path}:force")
    assert fn(2.0, 0.0, {"c": 3.0}) == 6.0
    assert load_law_function(f"{path}:force") is fn  # the file imported once per content
    for text, said in [
        (f"{path}:forse", "has no 'forse' (did you mean force?); its callables: force"),
        (f"{tmp_path}/none.py:f", "no such file"),
        (f"{tmp_path / 'law.txt'}:f", "is not a .py file"),
        (f"{path}", "a user's law is FILE.py:NAME"),
    ]:
        with pytest.raises(LawFileError, match=re.escape(said)):
            load_law_function(text)


def test_read_fit_keeps_the_law_files_own_line(tmp_path):
    path = tmp_path / "fit.json"
    row = dict(v0=1.0, e=0.5, T=None, e_fit=0.5, T_fit=1e-3, x_max=1e-3, F_max=1.0)
    record = {"law": "nofile.py:f", "params": {"c": 1.0}, "m": 1.0, "rows": [row]}
    path.write_text(json.dumps(record))
    with pytest.raises(LawFileError, match="^--law nofile.py:f: no such file nofile.py$"):
        read_fit(str(path))


def _is_png(path):
    return path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_the_commands_figures_are_written(tmp_path):
    speeds = np.geomspace(0.5, 5.0, 5)
    data = dict(v0=[1.0, 2.0], e=[0.8, 0.7], T=[1e-3, math.nan], sigma_e=None, sigma_T=None)
    curves = [("a", [0.8] * 5, [1e-3] * 5), ("b", [0.7] * 5, [2e-3] * 5)]
    _plotting.plot_fitted_speeds(tmp_path / "fit.png", data, speeds, curves, "a, b fitted")
    _plotting.plot_speed_sweep(tmp_path / "sweep.png", [1, 2], [0.8, 0.7], [1e-3, 2e-3], "x")
    fitted = {"e_t": [0.5, 0.3], "omega_out": [10.0, 20.0]}
    _plotting.plot_oblique(tmp_path / "oblique.png", [10.0, 40.0], fitted)
    _plotting.plot_oblique(tmp_path / "measured.png", [10.0, 40.0], fitted, fitted)
    rows = [dict(case="hertz_rate (integrated)", ratio_single=80.0, ratio_batch=None)]
    bench = dict(rows=rows, machine=dict(cpu_count=2, backend="cpu", load_average="1.0"))
    _plotting.plot_bench(tmp_path / "bench.png", bench, {"single": 50.0, "batch": 1000.0})
    for name in ("fit", "sweep", "oblique", "measured", "bench"):
        assert _is_png(tmp_path / f"{name}.png")
