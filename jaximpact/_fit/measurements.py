"""Measured restitution (and contact durations) at several impact speeds, as a table holds
them (`jaximpact calibrate --data FILE.csv`): `read_measurements` reads the columns
`v0,e[,T,sigma_e,sigma_T]` (an empty cell a missing value), `measured` checks that they
make one data set for `calibrate` (a sigma on every row or on none, sigma_T with T).
Bad input is a one-line `ValueError`."""

import math

from .._files import read_table

COLUMNS = ("v0", "e", "T", "sigma_e", "sigma_T")
# their SI units: a header may give v0 and T in others (`T (ms)`, `v0 [mm/s]`)
UNITS = dict(v0="m/s", e="1", T="s", sigma_e="1", sigma_T="s")


def read_measurements(path, label: str | None = None) -> dict:
    """`{column: [float, ...]}` from a CSV with a header naming some of `COLUMNS`; empty
    cells are NaN; blank lines and lines starting with `#` are skipped; a header may give
    v0 and T with a unit (`v0 (m/s)`, `T [ms]`: read in it, held in SI). `label`: how the
    messages name the file (default its path)."""
    label, hint = label or str(path), "v0,e[,T,sigma_e,sigma_T]"
    header, rows = read_table(
        path, COLUMNS, label=label, hint=hint, needed=("v0", "e"), units=UNITS
    )
    for line, values in rows:
        for name in ("v0", "e"):
            if math.isnan(values[name]):
                what = "impact speed" if name == "v0" else "restitution (T may be left empty)"
                raise ValueError(f"{label}, line {line}: no {name}; every row needs its {what}")
    if not rows:
        raise ValueError(f"{label} has a header but no rows")
    return {name: [values[name] for _, values in rows] for name in header}


def measured(columns: dict) -> dict:
    """The data set of `columns` (`read_measurements`'s): `v0`, `e` (lists), `T`, `sigma_e`,
    `sigma_T` (lists or None: T None where no row has one, else NaN on the rows without;
    sigma_T 1 there) and `rows`, their number."""
    T = columns.get("T")
    if T is not None and all(math.isnan(t) for t in T):
        T = None
    sigma_e, sigma_T = columns.get("sigma_e"), columns.get("sigma_T")
    if sigma_e is not None and any(math.isnan(s) for s in sigma_e):
        raise ValueError("sigma_e is missing on some rows: give it on every row or on none")
    if sigma_T is not None:
        if T is None:
            raise ValueError("sigma_T is given without any T")
        if any(math.isnan(s) and not math.isnan(t) for s, t in zip(sigma_T, T, strict=True)):
            raise ValueError("sigma_T is missing on a row with a T: give both or neither")
        sigma_T = [1.0 if math.isnan(t) else s for s, t in zip(sigma_T, T, strict=True)]
    if T is not None and (sigma_e is None) != (sigma_T is None):
        raise ValueError(
            "the residuals are weighted by the sigmas: give sigma_e and sigma_T together "
            "(or neither) when T is measured"
        )
    if sigma_e is None and sigma_T is not None:
        raise ValueError("give sigma_e with sigma_T")
    rows = len(columns["v0"])
    return dict(v0=columns["v0"], e=columns["e"], T=T, sigma_e=sigma_e, sigma_T=sigma_T, rows=rows)
