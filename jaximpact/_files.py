"""The files a run writes: never one of its inputs, however the path is spelled, and never
half-written under the final name.

`check_outputs` refuses (a one-line `ValueError`), before any work, an output that is an
input: the same file through a relative spelling (`./in.csv`, `dir/../in.csv`), an absolute
path, a symbolic or a hard link (`os.path.samefile` where both exist, the resolved path
otherwise), or a directory that holds an input and that the run writes into or removes.
`check_suffix` refuses an extension the writer does not write (`o.xlsx` is never CSV under
another name). `atomic_output` gives a temporary name beside the final one and renames it
into place only when the writing finished: a run stopped at any instant (an error,
Ctrl-C, SIGTERM) leaves the final name as it was, the old file or none.

`read_csv` reads a small CSV file whole (`calibrate --data`, recordings); the tables of
`batch` stream in chunks through `_jobs.readers` instead.
"""

import contextlib
import csv
import os
from collections.abc import Iterable
from pathlib import Path


def same_file(a, b) -> bool:
    """Whether the paths `a` and `b` name one file: `os.path.samefile` where both exist
    (hard and symbolic links included), else their resolved absolute paths."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return _resolved(a) == _resolved(b)


def is_inside(path, directory) -> bool:
    """Whether `path` lies in `directory` (at any depth), both resolved."""
    path, directory = Path(_resolved(path)), Path(_resolved(directory))
    return directory == path or directory in path.parents


def _resolved(path) -> str:
    return os.path.normcase(os.path.realpath(os.path.abspath(os.fspath(path))))


def check_outputs(inputs: Iterable, outputs: dict, directories: dict | None = None):
    """Refuse any output that is one of the `inputs` (paths; `None` entries skipped).

    - `outputs`: label -> a file the run writes (`{"--out": "o.csv", "--out (temporary)":
      "o.csv.tmp"}`): none may be an input.
    - `directories`: label -> a directory the run writes into or removes (`o.csv.parts`):
      no input may lie in it.

    A one-line `ValueError` names the option, the output and the input it would destroy.
    """
    inputs = [Path(p) for p in inputs if p is not None]
    for label, out in outputs.items():
        if out is None:
            continue
        for source in inputs:
            if same_file(out, source):
                raise ValueError(
                    f"{label} {out} is the input {source} (the same file): writing it would "
                    "destroy the input; choose another output file"
                )
    for label, directory in (directories or {}).items():
        for source in inputs:
            if is_inside(source, directory):
                raise ValueError(
                    f"the input {source} lies in {directory}, which {label} writes and "
                    "removes; move the input or choose another output file"
                )


def check_suffix(path, suffixes: Iterable[str], what: str = "output"):
    """Refuse a file whose extension is not one of `suffixes` (`.csv`, ...; compared without
    case): a one-line `ValueError` naming those that are written."""
    suffixes = tuple(suffixes)
    suffix = Path(path).suffix.lower()
    if suffix not in suffixes:
        found = f"extension {suffix!r}" if suffix else "no extension"
        raise ValueError(
            f"{what} {path}: {found}; write one of {', '.join(suffixes)} (the extension "
            "says what is written)"
        )


def temporary_name(path) -> Path:
    """The name `atomic_output` writes `path` under first: beside it (one file system, so
    the rename is atomic), hidden, with this process's id and the same extension (writers
    that choose the format by the extension, matplotlib's, still see it)."""
    path = Path(path)
    return path.with_name(f".{path.stem}.{os.getpid()}.tmp{path.suffix}")


@contextlib.contextmanager
def atomic_output(path):
    """`with atomic_output(path) as temporary: write(temporary)`: the file appears under
    `path` (renamed with `os.replace`) only when the block ends without an exception;
    otherwise (an error, KeyboardInterrupt, SystemExit) the temporary file is removed and
    `path` is left as it was."""
    temporary = temporary_name(path)
    try:
        yield temporary
    except BaseException:
        with contextlib.suppress(OSError):
            temporary.unlink()
        raise
    os.replace(temporary, path)


def write_text(path, text: str):
    """`Path(path).write_text(text)`, renamed into place whole (`atomic_output`)."""
    with atomic_output(path) as temporary:
        temporary.write_text(text)


def read_csv(text: str, *, comments: bool = False):
    """The header and rows of a small CSV file read whole: `(header, [(line, cells), ...])`,
    each cell a string as written (the csv module's quoting: a quoted cell may hold commas
    and line breaks), `line` the number in the file (from 1) of the line the row starts on.
    Blank lines are skipped (and with `comments`, lines whose first character other than a
    space is `#`); the header is the first row kept (`[]` and no rows if none is)."""
    kept = [
        (number, line)
        for number, line in enumerate(text.splitlines(keepends=True), start=1)
        if not (comments and line.lstrip().startswith("#"))
    ]
    reader = csv.reader(line for _, line in kept)
    rows, start = [], 0
    for cells in reader:
        if cells and not (len(cells) == 1 and not cells[0].strip()):  # not a blank line
            rows.append((kept[start][0], cells))
        start = reader.line_num
    return (rows[0][1], rows[1:]) if rows else ([], [])
