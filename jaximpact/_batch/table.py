"""`write_table`: equal-length columns to a CSV or JSON file, without pandas."""

import csv
import json
import math
import os

import numpy as np

from .._files import atomic_output


def write_table(path, columns: dict) -> str:
    """Write equal-length 1-D columns to `path` as CSV (`.csv`) or JSON (`.json`), without
    pandas; returns the path.

    CSV: a header row of the column names, then one row per member, floats written with
    `repr` (round-trips exactly). JSON: `{"columns": [...], "rows": n, "data": {name:
    [values]}}`, NaN and infinities written as `null`.

    **Example**: `write_table("impacts.csv", impact_batch("hertz_rate", ...))`.
    """
    path = os.fspath(path)
    names = list(columns)
    if not names:
        raise ValueError("write_table needs at least one column")
    arrays = [np.asarray(columns[name]) for name in names]
    for name, array in zip(names, arrays, strict=True):
        if array.ndim != 1:
            raise ValueError(f"column {name!r} must be 1-D, got shape {array.shape}")
    lengths = {array.shape[0] for array in arrays}
    if len(lengths) != 1:
        raise ValueError(
            "columns must have equal lengths, got "
            + ", ".join(f"{n}: {a.shape[0]}" for n, a in zip(names, arrays, strict=True))
        )
    rows = lengths.pop()
    values = [array.tolist() for array in arrays]
    suffix = os.path.splitext(path)[1].lower()
    if suffix not in (".csv", ".json"):
        raise ValueError(f"write_table writes .csv or .json files, got {path!r}")
    with atomic_output(path) as temporary:  # never a half-written table under `path`
        if suffix == ".csv":
            with open(temporary, "w", newline="") as handle:
                writer = csv.writer(handle)
                writer.writerow(names)
                writer.writerows(zip(*values, strict=True))
        else:
            data = {
                name: [_json_value(v) for v in column]
                for name, column in zip(names, values, strict=True)
            }
            with open(temporary, "w") as handle:
                json.dump({"columns": names, "rows": rows, "data": data}, handle)
    return path


def _json_value(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value
