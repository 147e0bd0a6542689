"""Recorded bounces read from files: a video track or a list of impact times.

Formats (detected from the file unless `fmt` says):

- an ImageJ MTrack2 export (`Frame X1 Y1 Flag1 ...`, whitespace or commas): a video track,
  time in frames, `Y1` in pixels pointing down;
- a CSV with a header: a time column (`t`, `time`, `time_s`, ...) and a height column (`y`,
  `height`, `h`, `z`, ...) is a trajectory; a time column alone (`event_time_s`,
  `impact_time`, `t`, ...) is a list of impact times, one group per drop when the file has
  other columns that tell drops apart (`where` selects some);
- plain numbers: two columns are `t y`, one column is impact times.

The file is read as people save it (`_files.read_text`: a byte-order mark, UTF-16, a note
in cp1252) and each number as `_files.cell_number` reads it.
"""

import math
from pathlib import Path

from .._files import NotText, cell_number, read_csv, read_text

_TIME_NAMES = ("t", "time", "time_s", "t_s", "times", "seconds", "frame")
_IMPACT_NAMES = ("event_time_s", "impact_time", "impact_times", "impact_time_s", "event_time")
_HEIGHT_NAMES = ("y", "height", "h", "z", "y_m", "height_m", "position", "y1")
_IGNORED = ("impact_index", "index", "n")
_LINE = object()  # the key of a row's line number in the rows of `_read_csv`


class Recording:
    """What a file held: `kind` ("trajectory" or "impacts"), and per group of rows (drop)
    either `(t, y)` or the impact times; `video`: a pixel track (y down, scale unknown)."""

    def __init__(self, kind, groups, video=False, columns=()):
        self.kind, self.groups, self.video, self.columns = kind, groups, video, columns


def parse_number(text):
    """The number in `text` (`_files.cell_number`), or None when it is not a finite one."""
    try:
        value = cell_number(text)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _number(cell, where: str) -> float:
    """The finite number in `cell`; a one-line `ValueError` naming the file, line and column
    (`where`) of one that is not."""
    try:
        value = cell_number(cell or "")
    except ValueError as error:
        raise ValueError(f"{where}: {error}") from None
    if not math.isfinite(value):
        raise ValueError(f"{where}: {cell.strip()!r} is not a finite number")
    return value


def _read_mtrack(lines):
    times, heights = [], []
    for line in lines[1:]:
        if line.lstrip().startswith("Track ") and times:
            break  # the summary table MTrack2 appends ("Track Length Distance ...")
        parts = line.replace(",", " ").split()
        values = [parse_number(p) for p in parts[:3]]
        if len(values) < 3 or any(v is None for v in values):
            continue  # "Tracks 1 to 2" and the like
        times.append(values[0])
        heights.append(values[2])
    if len(times) < 8:
        raise ValueError("the MTrack2 file has fewer than 8 tracked frames")
    return Recording("trajectory", {"track 1": (times, heights)}, video=True)


def _read_plain(lines):
    rows = []
    for line in lines:
        parts = line.replace(",", " ").split()
        if not parts:
            continue
        values = [parse_number(p) for p in parts]
        if any(v is None for v in values):
            raise ValueError(f"cannot read {line.strip()!r} as numbers (a header needs names)")
        rows.append(values)
    widths = {len(r) for r in rows}
    if len(widths) != 1 or not rows:
        raise ValueError("every line must have the same number of columns")
    width = widths.pop()
    if width == 1:
        return Recording("impacts", {"all": [r[0] for r in rows]})
    if width == 2:
        return Recording("trajectory", {"all": ([r[0] for r in rows], [r[1] for r in rows])})
    raise ValueError(f"{width} unnamed columns: give the file a header (t, y) or (impact_time)")


def _pick(columns, names):
    lowered = {c.strip().lower(): c for c in columns}
    for name in names:
        if name in lowered:
            return lowered[name]
    return None


def _read_csv(text, where, fmt, path):
    columns, cells = read_csv(text)
    # as `csv.DictReader` reads them: a short row's missing cells None, a long row's extra
    # cells dropped; each row's line in the file kept for the messages (`_LINE`)
    rows = [
        {**dict(zip(columns, row + [None] * (len(columns) - len(row)), strict=False)), _LINE: n}
        for n, row in cells
    ]
    for condition in where:
        column, sep, value = condition.partition("=")
        if not sep or column not in columns:
            raise ValueError(
                f"--where {condition!r}: need COLUMN=VALUE with COLUMN one of {', '.join(columns)}"
            )
        rows = [r for r in rows if r[column].strip() == value.strip()]
    if not rows:
        raise ValueError("no rows left after --where")
    impact_column = _pick(columns, _IMPACT_NAMES)
    time_column = _pick(columns, _TIME_NAMES)
    height_column = _pick(columns, _HEIGHT_NAMES)
    kind = fmt
    if kind == "auto":
        kind = "trajectory" if time_column and height_column and not impact_column else "impacts"
    if kind == "trajectory":
        if not (time_column and height_column):
            raise ValueError(
                f"a trajectory needs a time column ({', '.join(_TIME_NAMES)}) and a height "
                f"column ({', '.join(_HEIGHT_NAMES)}); the file has {', '.join(columns)}"
            )
        used = {time_column, height_column}
    else:
        impact_column = impact_column or time_column
        if impact_column is None:
            raise ValueError(
                "impact times need a column named one of "
                f"{', '.join(_IMPACT_NAMES + _TIME_NAMES)}; the file has {', '.join(columns)}"
            )
        used = {impact_column}
    group_by = [c for c in columns if c not in used and c.strip().lower() not in _IGNORED]
    groups: dict = {}
    for row in rows:
        key = ", ".join(f"{c}={row[c]}" for c in group_by if c != "source_file") or "all"
        groups.setdefault(key, []).append(row)

    def numbers(group, column):
        return [_number(r[column], f"{path}, line {r[_LINE]}, column {column}") for r in group]

    if kind == "trajectory":
        data = {k: (numbers(g, time_column), numbers(g, height_column)) for k, g in groups.items()}
    else:
        data = {k: numbers(g, impact_column) for k, g in groups.items()}
    return Recording(kind, data, columns=tuple(columns))


def read_recording(path: Path, fmt: str = "auto", where=()) -> Recording:
    """Read FILE (see the module docstring); a `ValueError` for anything it cannot use."""
    try:
        text = read_text(path)
    except OSError as error:
        raise ValueError(f"cannot read {path}: {error.strerror or error}") from None
    except NotText:
        raise ValueError(f"{path} is not a text file") from None
    lines = [line for line in text.splitlines() if line.strip()]
    if not lines:
        raise ValueError(f"{path} is empty")
    head = lines[0].replace(",", " ").split()
    if head[:1] == ["Frame"] and "Y1" in head:
        if fmt == "impacts":
            raise ValueError(f"{path} is a video track (MTrack2), not impact times")
        if where:
            raise ValueError("--where applies to CSV files with named columns")
        return _read_mtrack(lines)
    if all(parse_number(p) is not None for p in head):
        recording = _read_plain(lines)
        if where:
            raise ValueError("--where applies to CSV files with named columns")
    else:
        recording = _read_csv(text, where, fmt, path)
    if fmt != "auto" and recording.kind != fmt:
        raise ValueError(f"{path} holds {recording.kind}, not {fmt}")
    return recording
