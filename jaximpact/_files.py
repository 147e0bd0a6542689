"""The files a run writes: never one of its inputs, however the path is spelled, never
half-written under the final name, and never by two runs at once.

`check_outputs` refuses (a one-line `ValueError`), before any work, an output that is an
input: the same file through a relative spelling (`./in.csv`, `dir/../in.csv`), an absolute
path, a symbolic or a hard link (`os.path.samefile` where both exist, the resolved path
otherwise), or a directory that holds an input and that the run writes into or removes.
`check_suffix` refuses an extension the writer does not write (`o.xlsx` is never CSV under
another name). `atomic_output` gives a temporary name beside the final one and renames it
into place only when the writing finished: a run stopped at any instant (an error,
Ctrl-C, SIGTERM) leaves the final name as it was, the old file or none. `output_lock`
holds `OUT.lock` while a run writes `OUT` (and `OUT.parts/`): a second run on the same
output, however spelled, is refused in one line naming the first one's process.

The tables a run reads are opened as people save them, by one owner for every reader:
`open_text` (and `read_text`, the whole file) reads UTF-8 with or without a byte-order mark
(Excel's "CSV UTF-8"), UTF-16 or UTF-32 with one, and any line ends; a line whose bytes are
not UTF-8 (Excel's plain "CSV" on a Western system, a Latin-1 note) is read as cp1252
(`as_read`), so that only a cell the run reads can make it fail, as a number that is not
one. `cell_number` is the one reading of a number in a cell. `read_csv` reads a small CSV
file whole (`calibrate --data`, recordings), and `read_table` checks its header and numbers
(one-line `ValueError`s naming the file, line and column); the tables of `batch` stream in
chunks through `_jobs.readers` instead.
"""

import codecs
import contextlib
import csv
import os
import socket
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


def lock_name(path) -> Path:
    """The lock file of the output `path`: `OUT.lock` beside the file `path` resolves to, so
    that every spelling of one output (relative, absolute, through a symbolic link) has one
    lock."""
    return Path(_resolved(path) + ".lock")


@contextlib.contextmanager
def output_lock(path):
    """`with output_lock(path):` the block is the only run writing `path`.

    The lock is the operating system's on the file `lock_name(path)` (`fcntl.flock`;
    `msvcrt.locking` on Windows), which holds this process's id and host. It ends with the
    block, and with the process however that ends (an error, Ctrl-C, SIGTERM, even
    SIGKILL): a lock file left by a process that is gone holds no lock, and is taken over.
    A second run on `path` while the lock is held is refused, a one-line `ValueError`:
    `another run (pid N) is writing PATH; wait for it or choose another output file`. On a
    file system that has no locks (an NFS mount without its lock service) the run goes on
    unlocked."""
    name = lock_name(path)
    while True:
        try:
            fd = os.open(name, os.O_RDWR | os.O_CREAT, 0o644)
        except OSError as error:
            raise ValueError(f"cannot write {name}: {error.strerror or error}") from None
        try:
            _lock_file(fd)
        except BlockingIOError:
            holder = _holder(fd)
            os.close(fd)
            raise ValueError(
                f"another run{holder} is writing {path}; wait for it or choose another output file"
            ) from None
        try:  # the file locked is still the one under the name (not one its holder removed)
            if os.path.samestat(os.fstat(fd), os.stat(name)):
                break
        except OSError:
            pass
        os.close(fd)
    try:
        os.ftruncate(fd, 0)
        os.write(fd, f"{os.getpid()} {socket.gethostname()}\n".encode())
        yield name
    finally:
        with contextlib.suppress(OSError):  # removed while held, then unlocked by the close
            name.unlink()
        os.close(fd)


def _lock_file(fd: int):
    """Lock the open file `fd` for this process, or raise `BlockingIOError` at once if
    another process holds it (a file system without locks: nothing)."""
    try:
        import fcntl
    except ImportError:  # Windows: a byte past the process id, which others still read
        import msvcrt

        os.lseek(fd, 1 << 20, os.SEEK_SET)
        try:
            msvcrt.locking(fd, msvcrt.LK_NBLCK, 1)
        except OSError as error:
            raise BlockingIOError(str(error)) from None
        finally:
            os.lseek(fd, 0, os.SEEK_SET)
        return
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        raise
    except OSError:  # ENOLCK, EOPNOTSUPP: this file system keeps no locks
        pass


def _holder(fd: int) -> str:
    """` (pid N)` (` (pid N on HOST)` from another host) of the lock file `fd`, or `""`
    where it does not say (its holder is writing it)."""
    with contextlib.suppress(OSError, ValueError):
        os.lseek(fd, 0, os.SEEK_SET)
        pid, host = os.read(fd, 256).decode().split()
        return f" (pid {int(pid)})" if host == socket.gethostname() else f" (pid {pid} on {host})"
    return ""


def write_text(path, text: str):
    """`Path(path).write_text(text)`, renamed into place whole (`atomic_output`)."""
    with atomic_output(path) as temporary:
        temporary.write_text(text)


class NotText(ValueError):
    """A file that is not text: a NUL byte in a file without a UTF-16 or UTF-32 byte-order
    mark (a spreadsheet's own format, an image), or bytes its byte-order mark's encoding
    cannot decode. The message says why; the reader adds what the file was for."""


# byte-order marks, UTF-32's first: its little-endian mark begins with UTF-16's
_BOMS = (
    (codecs.BOM_UTF32_LE, "utf-32"),
    (codecs.BOM_UTF32_BE, "utf-32"),
    (codecs.BOM_UTF16_LE, "utf-16"),
    (codecs.BOM_UTF16_BE, "utf-16"),
)
_HEAD = 8192  # bytes looked at for a byte-order mark and for NUL bytes


def open_text(path):
    """`path` opened for reading as a text table, however it was saved: UTF-16 or UTF-32
    where it starts with their byte-order mark, else UTF-8 (its byte-order mark dropped);
    each line ends in `\\n` whatever its line end was (`\\r\\n`, `\\r`). Bytes that are not UTF-8
    come as Python's surrogate escapes, which `as_read` turns into text; a file with a NUL
    byte in its first 8 kB and no UTF-16 or UTF-32 mark is refused (`NotText`). Decoding
    errors of UTF-16 or UTF-32 are `UnicodeDecodeError`s as the lines are read."""
    with open(path, "rb") as handle:
        head = handle.read(_HEAD)
    encoding = next((name for bom, name in _BOMS if head.startswith(bom)), None)
    if encoding is not None:  # the codec reads the mark: its byte order, then drops it
        return open(path, encoding=encoding, newline=None)
    if b"\0" in head:
        raise NotText("not a text file (a NUL byte in it; save the table as CSV, UTF-8 or UTF-16)")
    return open(path, encoding="utf-8-sig", errors="surrogateescape", newline=None)


def as_read(text: str) -> str:
    """`text` from `open_text` with each line whose bytes were not UTF-8 read as cp1252
    (Windows' Western encoding, a superset of Latin-1's printable characters), or as
    Latin-1 where cp1252 has no character for one of its bytes; other lines unchanged."""
    try:
        text.encode("utf-8")
    except UnicodeEncodeError:  # surrogate escapes: bytes that were not UTF-8
        return "\n".join(map(_as_read_line, text.split("\n")))
    return text


def _as_read_line(line: str) -> str:
    try:
        line.encode("utf-8")
        return line
    except UnicodeEncodeError:
        raw = line.encode("utf-8", "surrogateescape")  # the bytes as they were on disk
    try:
        return raw.decode("cp1252")
    except UnicodeDecodeError:
        return raw.decode("latin-1")


def read_text(path) -> str:
    """The whole text of the table file `path` (`open_text`, `as_read`); a `NotText` for a
    file that is not text, an `OSError` for one that cannot be read."""
    try:
        with open_text(path) as handle:
            return as_read(handle.read())
    except UnicodeDecodeError as error:
        raise NotText(
            f"not a text file (bytes that are not {error.encoding.upper()} after its "
            "byte-order mark)"
        ) from None


def cell_number(text: str) -> float:
    """The number in a table's cell, as `float` and numpy read it (surrounding spaces
    ignored; `nan` and `inf` are numbers, which the run's checks then refuse where they
    must), but for Python's own spellings, which numpy refuses: digits grouped by
    underscores (`2_000_000`) and digits of other scripts. A `ValueError` otherwise, whose
    message says what the cell is (the reader adds the file, the line and the column):
    `'2_000_000' is not a number: write 2000000`."""
    cell = text.strip()
    if cell.isascii() and "_" not in cell:
        with contextlib.suppress(ValueError):
            return float(cell)
    hint = ""
    if cell.isascii() and "_" in cell:
        with contextlib.suppress(ValueError):
            float(cell)  # Python reads it: say how to write it
            hint = f": write {cell.replace('_', '')}"
    raise ValueError(f"{repr(cell) if cell else 'an empty cell'} is not a number{hint}")


def read_csv(text: str, *, comments: bool = False):
    """The header and rows of a small CSV file read whole: `(header, [(line, cells), ...])`,
    each cell a string as written (the csv module's quoting: a quoted cell may hold commas
    and line breaks), `line` the number in the file (from 1) of the line the row starts on.
    Blank lines are skipped (and with `comments`, lines whose first character other than a
    space is `#`); the header is the first row kept (`[]` and no rows if none is)."""
    lines = [line + "\n" for line in text.split("\n")]  # line ends as `open_text` reads them
    lines[-1] = lines[-1][:-1]
    kept = [
        (number, line)
        for number, line in enumerate(lines, start=1)
        if line and not (comments and line.lstrip().startswith("#"))
    ]
    reader = csv.reader(line for _, line in kept)
    rows, start = [], 0
    for cells in reader:
        if cells and not (len(cells) == 1 and not cells[0].strip()):  # not a blank line
            rows.append((kept[start][0], cells))
        start = reader.line_num
    return (rows[0][1], rows[1:]) if rows else ([], [])


# the units a header may give a column in (`T (ms)`, `v0 [mm/s]`), by the column's SI unit,
# each with how many of it make the SI unit (a divisor: 0.9 ms is 0.9 / 1000 s, rounded once);
# a unit's first spelling is the one messages show, the others are its aliases
HEADER_UNITS = {
    "s": {"s": 1.0, "ms": 1e3, "µs": 1e6, "us": 1e6, "μs": 1e6},
    "m/s": {"m/s": 1.0, "mm/s": 1e3, "cm/s": 1e2},
    "m": {"m": 1.0, "mm": 1e3, "cm": 1e2},
    "1": {"1": 1.0, "-": 1.0},
}


def split_unit(name: str) -> tuple[str, str | None]:
    """`(column, unit)` of a header cell: `T (ms)` and `T [ms]` are `("T", "ms")`, `T` is
    `("T", None)`."""
    stripped = name.strip()
    if not stripped.endswith((")", "]")) or "(" not in stripped and "[" not in stripped:
        return stripped, None
    cut = max(stripped.rfind("("), stripped.rfind("["))
    return stripped[:cut].strip(), stripped[cut + 1 : -1].strip()


def header_unit(name: str, units: dict, label: str) -> tuple[str, float]:
    """`(column, divisor to SI)` of a header cell `name`: a column alone (1), or a
    column with its unit in brackets, `T (ms)` or `T [ms]`, where `units` gives the
    column's SI unit (a key of `HEADER_UNITS`); a one-line `ValueError` for a unit that
    column cannot take."""
    column, unit = split_unit(name)
    if unit is None or column not in units:
        return name.strip(), 1.0  # no unit, or an unknown column, which the caller names
    accepted = HEADER_UNITS[units[column]]
    if unit not in accepted:
        first = {}  # each unit by its first spelling
        for spelling, divisor in accepted.items():
            first.setdefault(divisor, spelling)
        raise ValueError(
            f"{label}: column {column!r} in {unit!r}: give it in one of {', '.join(first.values())}"
        )
    return column, accepted[unit]


def read_table(path: Path, columns, *, label: str, hint: str, needed=(), units=None):
    """`(header, rows)` of the small CSV file at `path` (`read_text` and `read_csv`:
    as people save it, `#` comments skipped), its header stripped and checked against
    `columns` (those in `needed` must be there), each row `(line number, {column: number})`,
    an empty cell NaN. `units`: each column's SI unit (a key of `HEADER_UNITS`), where a
    header may give the column in another (`T (ms)`: the numbers are read in ms and held
    in s). One-line `ValueError`s that name the file as `label` (e.g. `--data in.csv`) for
    a file that cannot be read or is not text, is empty, has an unknown column or unit
    (`hint`: the columns expected, in words), a column named twice or one of `needed`
    missing, a row with too many or too few cells, or a cell that is not a number."""
    import math

    try:
        text = read_text(path)  # as people save it: a byte-order mark, UTF-16, cp1252
    except OSError as error:
        raise ValueError(f"cannot read {label}: {error.strerror or error}") from None
    except NotText:
        raise ValueError(f"{label} is not a text file (a CSV with columns {hint})") from None
    header, rows = read_csv(text, comments=True)
    if not header:
        raise ValueError(f"{label} is empty")
    read = [header_unit(name, units or {}, label) for name in header]
    header, divisors = [column for column, _ in read], [divisor for _, divisor in read]
    unknown = [name for name in header if name not in columns]
    if unknown:
        raise ValueError(
            f"{label}: unknown column {', '.join(map(repr, unknown))}; the columns are {hint}"
        )
    if len(set(header)) != len(header):
        raise ValueError(f"{label}: a column is named twice in the header")
    for name in needed:
        if name not in header:
            raise ValueError(f"{label}: no column {name!r} (need {hint})")
    numbers = []
    for line, cells in rows:
        if len(cells) != len(header):
            raise ValueError(f"{label}, line {line}: {len(cells)} cells for {len(header)} columns")
        values = {}
        for column, divisor, cell in zip(header, divisors, cells, strict=True):
            try:
                values[column] = cell_number(cell) / divisor if cell.strip() else math.nan
            except ValueError as error:
                raise ValueError(f"{label}, line {line}, column {column}: {error}") from None
        numbers.append((line, values))
    return header, numbers
