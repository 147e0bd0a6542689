"""Many impacts from a table on disk: `batch_file(source, out, law, ...)` reads a CSV of bodies
in chunks, runs `impact_batch` on each, and writes the inputs with `e`, `T`, `x_max`,
`t_max`, `F_max`, `status` and `path` beside them.

Nothing is lost: every value is checked before any work (one line naming the row and the
column); each chunk is written whole or not at all (a temporary file renamed) into
`OUT.parts/`, with a manifest holding a SHA-256 of the chunk's input text; `resume=True`
skips the chunks whose part and hash are there and recomputes those whose input changed; the
parts are joined into `OUT` (again renamed into place) only when all are done. Memory holds
one chunk at a time.
"""

import csv
import dataclasses
import hashlib
import json
import math
import os
import shutil
from pathlib import Path

import numpy as np

from .._laws import LAWS, law as make_law
from .._progress import Progress
from .._status import Status
from .impacts import batch_path, impact_batch

KINEMATICS = ("m", "v0", "g")
OUTPUTS = ("e", "T", "x_max", "t_max", "F_max", "status", "path")
_POSITIVE = ("m", "v0", "c", "n")


@dataclasses.dataclass(frozen=True)
class BatchFile:
    """What `batch_file` did: the output `path`, the number of `rows`, the `chunks` in all,
    how many were `computed` and how many `reused` from an earlier run (`resume=True`), and
    the count of each `status` name."""

    path: str
    rows: int
    chunks: int
    computed: int
    reused: int
    statuses: dict


def batch_file(
    source,
    out,
    law,
    *,
    params: dict | None = None,
    m: float | None = None,
    v0: float | None = None,
    g: float = 0.0,
    separation: str = "force",
    chunk_rows: int = 100_000,
    resume: bool = False,
    progress: bool = True,
    **impact_options,
) -> BatchFile:
    """Run `impact_batch` over the rows of the CSV file `source` and write `out` (CSV).

    - `law`: a name of `LAW_NAMES`. The file's columns give, per row, any of its parameters
      and `m` (kg), `v0` (m/s), `g` (m/s^2); `params`, `m`, `v0`, `g` give the rest (SI units).
    - `separation` and `impact_options` (`method`, `rtol`, ...): as in `impact`.
    - `chunk_rows`: rows per chunk (memory and the unit of resumption).
    - `resume`: reuse the chunks an interrupted run left in `OUT.parts/` whose inputs have not
      changed.

    A `ValueError` names the first bad column or row (line numbers count the header as 1)
    before anything is computed. **Example**: `batch_file("bodies.csv", "impacts.csv",
    "hertz_rate", params={"b1": 800.0}, m=1.0)`.
    """
    if law not in LAWS:
        raise ValueError(f"unknown law {law!r}; see `jaximpact laws`")
    if not (isinstance(chunk_rows, int) and chunk_rows >= 1):
        raise ValueError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    source, out = Path(source), Path(out)
    spec = LAWS[law]
    fixed = {**spec.defaults, **(params or {})}
    fixed.update({k: v for k, v in (("m", m), ("v0", v0), ("g", g)) if v is not None})
    columns = _header(source, allowed=(*spec.parameters, *KINEMATICS))
    missing = [k for k in (*spec.parameters, "m", "v0") if k not in columns and k not in fixed]
    if missing:
        raise ValueError(
            f"{source}: no value for {', '.join(missing)}: give a column or a fixed value "
            f"(--param NAME=VALUE, --mass, --v0)"
        )
    for key, value in fixed.items():
        _check_value(key, value, f"fixed value {key}")
    rows = _validate(source, columns)
    parts = Path(f"{out}.parts")
    if parts.exists() and not resume:
        shutil.rmtree(parts)
    parts.mkdir(parents=True, exist_ok=True)
    manifest = _read_manifest(parts) if resume else {}
    chunks = max(1, math.ceil(rows / chunk_rows))
    computed = reused = 0
    statuses = dict.fromkeys((s.name for s in Status), 0)
    with Progress(chunks, f"batch {law}", enabled=progress) as bar:
        for index, (text, cells) in enumerate(_chunks(source, columns, chunk_rows)):
            digest = hashlib.sha256(text.encode()).hexdigest()
            part = parts / f"part-{index:06d}.csv"
            entry = manifest.get(str(index))
            if entry and entry["sha256"] == digest and part.exists():
                reused += 1
                counts = entry["statuses"]
            else:
                counts = _run_chunk(cells, columns, fixed, law, separation, impact_options, part)
                manifest[str(index)] = dict(sha256=digest, rows=len(cells), statuses=counts)
                _write_manifest(parts, manifest)
                computed += 1
            for name, count in counts.items():
                statuses[name] += count
            bar.update(f"{(index + 1) * chunk_rows:,} rows" if index + 1 < chunks else "")
    _join(parts, chunks, out, header=(*columns, *OUTPUTS))
    shutil.rmtree(parts)
    return BatchFile(str(out), rows, chunks, computed, reused, statuses)


def _header(source: Path, allowed) -> tuple[str, ...]:
    """The file's column names, checked: known, not repeated."""
    try:
        with open(source, newline="") as handle:
            header = next(csv.reader(handle), None)
    except FileNotFoundError:
        raise ValueError(f"{source}: no such file") from None
    except (OSError, UnicodeDecodeError) as error:
        raise ValueError(f"{source}: cannot read it as text ({error})") from None
    if not header or not any(name.strip() for name in header):
        raise ValueError(f"{source}: empty file; its first line must name the columns")
    names = tuple(name.strip() for name in header)
    for name in names:
        if name not in allowed:
            raise ValueError(
                f"{source}, line 1: unknown column {name!r}; the columns may be "
                f"{', '.join(allowed)}"
            )
    repeated = sorted({n for n in names if names.count(n) > 1})
    if repeated:
        raise ValueError(f"{source}, line 1: column {repeated[0]!r} appears twice")
    return names


def _check_value(key, value, where):
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{where}: {value!r} is not a number") from None
    positive = key in _POSITIVE
    if not math.isfinite(number) or number < 0 or (positive and number == 0):
        need = "> 0" if positive else ">= 0"
        raise ValueError(f"{where}: {key} = {value!s} must be a finite number {need}")
    return number


def _validate(source: Path, columns) -> int:
    """Every cell a finite number in range; returns the number of data rows."""
    rows = 0
    with open(source, newline="") as handle:
        reader = csv.reader(handle)
        next(reader)
        for line, cells in enumerate(reader, start=2):
            if not cells or not any(c.strip() for c in cells):
                continue
            if len(cells) != len(columns):
                raise ValueError(
                    f"{source}, line {line}: {len(cells)} cells for {len(columns)} columns"
                )
            for key, cell in zip(columns, cells, strict=True):
                _check_value(key, cell.strip(), f"{source}, line {line}, column {key}")
            rows += 1
    if rows == 0:
        raise ValueError(f"{source}: no data rows under the header")
    return rows


def _chunks(source: Path, columns, chunk_rows: int):
    """`(text, rows of cells)` per chunk, `text` the chunk's lines as read (for its hash)."""
    with open(source, newline="") as handle:
        reader = csv.reader(handle)
        next(reader)
        cells = []
        for row in reader:
            if row and any(c.strip() for c in row):
                cells.append([c.strip() for c in row])
            if len(cells) == chunk_rows:
                yield _text(cells), cells
                cells = []
        if cells:
            yield _text(cells), cells


def _text(cells) -> str:
    return "\n".join(",".join(row) for row in cells)


def _run_chunk(cells, columns, fixed, law, separation, impact_options, part: Path) -> dict:
    table = np.asarray(cells, dtype=float).reshape(len(cells), len(columns))
    given = {**fixed, **{key: table[:, i] for i, key in enumerate(columns)}}
    params = {k: given[k] for k in LAWS[law].parameters}
    out = impact_batch(
        law,
        params,
        m=given["m"],
        v0=given["v0"],
        g=given.get("g", 0.0),
        separation=separation,
        fields=OUTPUTS[:-2] + ("status",),
        progress=False,
        invalid="raise",
        **impact_options,
    )
    first = make_law(law, **{k: np.asarray(v).ravel()[0] for k, v in params.items()})
    g_zero = bool(np.all(np.asarray(given.get("g", 0.0)) == 0.0))
    path = batch_path(first, separation, g_is_zero=g_zero, **impact_options)
    names = [Status(int(s)).name for s in out["status"]]
    temporary = part.with_suffix(".tmp")
    with open(temporary, "w", newline="") as handle:
        writer = csv.writer(handle)
        for i, row in enumerate(cells):
            values = [repr(float(out[k][i])) for k in OUTPUTS[:-2]]
            writer.writerow([*row, *values, names[i], path])
    os.replace(temporary, part)
    return {name: names.count(name) for name in set(names)}


def _read_manifest(parts: Path) -> dict:
    try:
        return json.loads((parts / "manifest.json").read_text())
    except (OSError, ValueError):
        return {}


def _write_manifest(parts: Path, manifest: dict):
    temporary = parts / "manifest.tmp"
    temporary.write_text(json.dumps(manifest))
    os.replace(temporary, parts / "manifest.json")


def _join(parts: Path, chunks: int, out: Path, header):
    temporary = out.with_name(out.name + ".tmp")
    with open(temporary, "w", newline="") as handle:
        csv.writer(handle).writerow(header)
        for index in range(chunks):
            with open(parts / f"part-{index:06d}.csv", newline="") as part:
                shutil.copyfileobj(part, handle)
    os.replace(temporary, out)
