"""Tables of bodies read in chunks: a CSV file (always) or a Parquet file (with pyarrow).

`open_table(path)` checks the header and returns a reader whose `chunks(rows)` yields every
chunk of `rows` data rows as it is on disk (cheap: no number is parsed), and whose
`parse(chunk)` turns one chunk into `Cells`: the columns as arrays (float64; `separation` as
text), the columns the job does not read as text (`carry`: carried through to the output
unchanged, `carried_columns` says which), a SHA-256 of the chunk's bytes (carried columns
included), the input lines as written (CSV), and where each row is in the file (`line N` of
a CSV counting the header as 1, `row N` of a Parquet file).
A CSV is read as people save it (`_files.open_text`: UTF-8 with or without a byte-order
mark, UTF-16, any line ends, a line that is not UTF-8 as cp1252), and each number as
`_files.cell_number` reads it. Memory holds one chunk at a time. A bad header or cell is a
one-line `ValueError` naming the file, the line (or row) and the column.
"""

import contextlib
import csv
import dataclasses
import difflib
import hashlib
import itertools
from pathlib import Path

import numpy as np

from .._files import NotText, as_read, cell_number, open_text, split_unit

TEXT_COLUMNS = ("separation",)  # columns of words, not numbers
PARQUET_SUFFIXES = (".parquet", ".pq")


def is_parquet(path) -> bool:
    """Whether `path` names a Parquet file (by its suffix)."""
    return Path(path).suffix.lower() in PARQUET_SUFFIXES


def require_pyarrow(path):
    """pyarrow's Parquet module, or a one-line `ValueError` saying how to install it."""
    try:
        import pyarrow.parquet as pq
    except ImportError:
        raise ValueError(
            f"{path}: Parquet needs pyarrow (pip install 'jaximpact[parquet]'), or use a CSV file"
        ) from None
    return pq


@dataclasses.dataclass
class Cells:
    """One parsed chunk: `values` (column -> array of its `rows`: the columns the job
    reads), `digest` (SHA-256 of the chunk's bytes), `lines` (a CSV's data lines as written,
    without line ends; None for Parquet), `where(i)`: the place of row `i` in the file, for
    messages, and `carried` (column -> object array of text, None for a Parquet null: the
    columns carried through to the output unchanged)."""

    values: dict
    rows: int
    digest: bytes
    lines: list | None
    where: object
    carried: dict = dataclasses.field(default_factory=dict)


def _plain(name: str) -> str:
    """A column's name but for case, spaces, `_` and `-` (`V_0` -> `v0`)."""
    return "".join(ch for ch in str(name).lower() if ch not in " _-")


def close_column(name: str, known) -> str | None:
    """The column of `known` that `name` most likely misspells: the same but for case,
    spaces, `_` or `-` (`V0`, `v_0`, `Separation`), else the closest spelling (difflib,
    cutoff 0.75: `separaton`); None where none is close (`id`, `note`, `name`)."""
    by_plain = {_plain(k): k for k in known}
    plain = _plain(name)
    if plain in by_plain:
        return by_plain[plain]
    close = difflib.get_close_matches(plain, list(by_plain), n=1, cutoff=0.75)
    return by_plain[close[0]] if close else None


def carried_columns(columns, known, where_header: str, outputs=()) -> tuple:
    """The columns of `columns` that the job does not read (not in `known`), carried through
    to the output unchanged; a one-line `ValueError` for one whose name is close to a column
    of `known` (`close_column`: a misspelt column silently ignored would change every
    answer), naming the likely column, and for one named as a result the output writes
    (`outputs`)."""
    carried = []
    for name in columns:
        if name in known:
            continue
        column, unit = split_unit(name)
        if unit is not None and column in known:  # read as carried, it would be lost
            raise ValueError(
                f"{where_header}: column {name!r} gives {column} with a unit; a batch reads "
                f"SI units from a column named {column} alone: rename it {column} (values "
                "in SI units)"
            )
        near = close_column(name, known)
        if near is not None:
            raise ValueError(
                f"{where_header}: unknown column {name!r} (did you mean {near}?); the columns "
                f"read are {', '.join(known)}, any other is carried through to the output"
            )
        if name in outputs:
            raise ValueError(
                f"{where_header}: column {name!r} is a result the output writes "
                f"({', '.join(outputs)}); rename it"
            )
        carried.append(name)
    return tuple(carried)


def _text(value) -> str | None:
    """A carried cell as text (None stays None: an empty Parquet cell)."""
    return None if value is None else str(value)


def _text_digest(array) -> bytes:
    return "\n".join("\0" if s is None else s for s in array).encode()


def open_table(path):
    """A `CsvTable` or `ParquetTable` for `path`, its header checked: no column repeated.
    Which columns the job reads and which it carries is the job's to say: it calls `carry`
    (which checks a Parquet file's column types) before reading a chunk."""
    path = Path(path)
    if not path.exists():
        raise ValueError(f"{path}: no such file")
    if path.is_dir():
        raise ValueError(f"{path}: is a directory, not a file of bodies")
    table = ParquetTable(path) if is_parquet(path) else CsvTable(path)
    repeated = sorted({n for n in table.columns if table.columns.count(n) > 1})
    if repeated:
        raise ValueError(f"{table.where_header}: column {repeated[0]!r} appears twice")
    return table


class CsvTable:
    """A CSV file: a header line naming the columns, then one body per line (blank lines are
    skipped; their line numbers still count)."""

    def __init__(self, path: Path):
        self.path = path
        self.where_header = f"{path}, line 1"
        try:
            with open_text(path) as handle:
                first = as_read(handle.readline())
        except NotText as error:
            raise ValueError(f"{path}: {error}") from None
        except (OSError, UnicodeDecodeError) as error:
            raise ValueError(f"{path}: cannot read it as text ({error})") from None
        header = next(csv.reader([first]), None)
        if not header or not any(name.strip() for name in header):
            raise ValueError(f"{path}: empty file; its first line must name the columns")
        self.columns = tuple(name.strip() for name in header)
        self.carried = ()

    def carry(self, names):
        """Read the columns `names` as text, carried through to the output unchanged."""
        self.carried = tuple(names)

    def chunks(self, rows: int):
        """`(first line number, data lines, their line numbers or None if consecutive)` per
        chunk of `rows` data rows, in file order."""
        with open_text(self.path) as handle:
            next(handle)
            number = first = 2
            try:
                while True:
                    lines, numbers, first = [], None, number
                    for line in itertools.islice(handle, rows):
                        lines.append(line)
                    number += len(lines)
                    if not lines:
                        return
                    if any(not line.strip() for line in lines):  # blank lines: keep the numbers
                        numbers = [first + i for i, line in enumerate(lines) if line.strip()]
                        lines = [line for line in lines if line.strip()]
                        while len(lines) < rows:  # fill the chunk up to `rows` data rows
                            line = handle.readline()
                            if not line:
                                break
                            if line.strip():
                                lines.append(line)
                                numbers.append(number)
                            number += 1
                        if not lines:
                            continue
                    yield first, lines, numbers
            except UnicodeDecodeError as error:  # UTF-16 or UTF-32 whose bytes are not
                raise ValueError(
                    f"{self.path}, lines {first} on: bytes that are not "
                    f"{error.encoding.upper()}; save the file again as CSV"
                ) from None

    @staticmethod
    def size(chunk) -> int:
        """The number of data rows of `chunk`."""
        return len(chunk[1])

    def estimated_rows(self) -> int:
        """About how many data rows the file holds (from its size and first lines)."""
        with open(self.path, "rb") as handle:
            head = handle.readline() and handle.readlines(1 << 16)
        if not head:
            return 0
        return max(1, round(self.path.stat().st_size / (sum(map(len, head)) / len(head))))

    def parse(self, chunk) -> Cells:
        first, lines, numbers = chunk
        path = self.path

        def where(i):
            return f"{path}, line {numbers[i] if numbers else first + i}"

        # the lines that are not UTF-8 read as cp1252 (`_files.as_read`), one pass over all
        lines = as_read("\n".join(line.rstrip("\n") for line in lines)).split("\n")
        digest = hashlib.sha256("\n".join(lines).encode()).digest()
        columns, ncol = self.columns, len(self.columns)
        carried = self.carried
        numeric = [
            j for j, name in enumerate(columns) if name not in TEXT_COLUMNS and name not in carried
        ]
        quoted = any('"' in line for line in lines)
        rows = None
        if quoted:
            rows = list(csv.reader(lines))
            counts = [len(cells) for cells in rows]
        else:
            counts = [line.count(",") + 1 for line in lines]
        if any(c != ncol for c in counts):
            i = next(i for i, c in enumerate(counts) if c != ncol)
            raise ValueError(f"{where(i)}: {counts[i]} cells for {ncol} columns")
        table = None
        if not quoted:
            with contextlib.suppress(ValueError):
                table = np.loadtxt(
                    lines, delimiter=",", dtype=float, usecols=numeric, ndmin=2, comments=None
                )
        if table is None or table.shape != (len(lines), len(numeric)):
            # quoted cells, or a cell numpy does not read: each cell as `cell_number` reads
            # it (as every reader of tables does), the first that is not a number named
            table = _numbers(rows if quoted else csv.reader(lines), columns, numeric, where)
        values = {columns[j]: table[:, k] for k, j in enumerate(numeric)}
        texts = {}
        for j, name in enumerate(columns):
            if name in TEXT_COLUMNS or name in carried:
                if rows is None:
                    rows = [line.split(",") for line in lines]
                if name in carried:  # the cell's text as read (csv's unquoting only)
                    texts[name] = np.array([cells[j] for cells in rows], dtype=object)
                else:
                    values[name] = np.array([cells[j].strip() for cells in rows], dtype=object)
        return Cells(values, len(lines), digest, lines, where, texts)


def _numbers(rows, columns, numeric, where) -> np.ndarray:
    """The cells `numeric` of `rows` read one by one (`_files.cell_number`); a one-line
    `ValueError` naming the first that is not a number (its file, line and column)."""
    table = []
    for i, cells in enumerate(rows):
        row = []
        for j in numeric:
            try:
                row.append(cell_number(cells[j]))
            except ValueError as error:
                raise ValueError(f"{where(i)}, column {columns[j]}: {error}") from None
        table.append(row)
    return np.array(table, dtype=float).reshape(len(table), len(numeric))


class ParquetTable:
    """A Parquet file (pyarrow): numeric columns (integers or floats; `separation` text; a
    carried column of any type, read as text), read in record batches."""

    def __init__(self, path: Path):
        pq = require_pyarrow(path)
        import pyarrow as pa

        self.path = path
        self.where_header = f"{path}, columns"
        try:
            self.file = pq.ParquetFile(path)
        except (OSError, pa.ArrowException) as error:
            raise ValueError(f"{path}: cannot read it as Parquet ({error})") from None
        schema = self.file.schema_arrow
        self.columns = tuple(schema.names)
        if not self.columns:
            raise ValueError(f"{path}: empty file; it has no columns")
        self.carried = ()  # the types are checked by `carry`, once the job knows its columns

    def carry(self, names):
        """Read the columns `names` as text, carried through to the output unchanged; the
        others' types checked (numbers; `separation` text)."""
        import pyarrow as pa

        self.carried = tuple(names)
        path = self.path
        for field in self.file.schema_arrow:
            if field.name in self.carried:
                continue
            text = field.name in TEXT_COLUMNS
            ok = (
                pa.types.is_string(field.type) or pa.types.is_large_string(field.type)
                if text
                else pa.types.is_integer(field.type) or pa.types.is_floating(field.type)
            )
            if not ok:
                want = "text" if text else "numbers"
                raise ValueError(f"{path}, column {field.name}: of type {field.type}, not {want}")

    def chunks(self, rows: int):
        """`(first row index, record batch)` per chunk of `rows` rows, in file order."""
        import pyarrow as pa

        pending, count, start = [], 0, 0
        for batch in self.file.iter_batches(batch_size=rows):
            pending.append(batch)
            count += batch.num_rows
            while count >= rows:
                table = pa.Table.from_batches(pending)
                yield start, table.slice(0, rows)
                rest = table.slice(rows)
                pending = rest.to_batches() if rest.num_rows else []
                count -= rows
                start += rows
        if count:
            yield start, pa.Table.from_batches(pending)

    @staticmethod
    def size(chunk) -> int:
        """The number of rows of `chunk`."""
        return chunk[1].num_rows

    def estimated_rows(self) -> int:
        """The number of rows (from the file's metadata)."""
        return self.file.metadata.num_rows

    def parse(self, chunk) -> Cells:
        start, table = chunk
        path = self.path

        def where(i):
            return f"{path}, row {start + i + 1}"

        values, digest = {}, hashlib.sha256()
        texts = {}
        for name in self.columns:
            column = table.column(name)
            if name in self.carried:  # as text, an empty cell kept empty (None)
                array = np.array([_text(s) for s in column.to_pylist()], dtype=object)
                digest.update(name.encode() + b"\0" + _text_digest(array))
                texts[name] = array
                continue
            if column.null_count:
                i = int(np.flatnonzero(column.is_null().to_numpy(zero_copy_only=False))[0])
                raise ValueError(f"{where(i)}, column {name}: an empty cell")
            if name in TEXT_COLUMNS:
                array = np.array([str(s).strip() for s in column.to_pylist()], dtype=object)
                digest.update("\n".join(array).encode())
            else:
                array = column.to_numpy(zero_copy_only=False).astype(float)
                digest.update(array.tobytes())
            values[name] = array
        return Cells(values, table.num_rows, digest.digest(), None, where, texts)


def open_chunks(source):
    """A `ChunkTable` for `source`, an iterable of chunks (which columns the job reads and
    which it carries is the job's to say: `carry`)."""
    return ChunkTable(source)


class ChunkTable:
    """Chunks given by a script: an iterable of mappings column -> 1-D array or number (a
    dict of numpy arrays, a pandas DataFrame, ...), each chunk used as given. A list (or any
    iterable whose `iter` starts afresh) is `replayable`: read once to check every value and
    again to compute. A one-shot iterator (a generator) is read once: each chunk is checked
    just before it is computed."""

    def __init__(self, source):
        if isinstance(source, (str, bytes)) or not hasattr(source, "__iter__"):
            raise ValueError(
                "chunks must be an iterable of mappings column -> array, got "
                f"{type(source).__name__}"
            )
        iterator = iter(source)
        self.replayable = iterator is not source
        try:
            first = next(iterator)
        except StopIteration:
            raise ValueError("chunks: the iterable holds no chunk") from None
        self._first = _columns_of(first, 0)
        self.columns = tuple(self._first)
        self.where_header = "chunk 0"
        self._source = source if self.replayable else itertools.chain([first], iterator)
        self._used = False
        self.carried = ()

    def carry(self, names):
        """Read the columns `names` as text (one value, or one per row), carried through to
        the output unchanged."""
        self.carried = tuple(names)

    def chunks(self, rows: int):
        """`(index, first row, chunk)` per chunk, as given (`rows` is not used)."""
        if not self.replayable:
            if self._used:
                raise RuntimeError("a one-shot iterator of chunks can be read only once")
            self._used = True
        start = 0
        for index, chunk in enumerate(self._source):
            values = _columns_of(chunk, index)
            if tuple(values) != self.columns:
                raise ValueError(
                    f"chunk {index}: columns {', '.join(values)}, not those of chunk 0 "
                    f"({', '.join(self.columns)})"
                )
            yield index, start, values
            start += self.size((index, start, values))

    @staticmethod
    def size(chunk) -> int:
        """The number of rows of `chunk`."""
        return max((np.size(v) for v in chunk[2].values()), default=0)

    def estimated_rows(self) -> int:
        """Unknown for chunks: the count of the first chunk's rows."""
        return self.size((0, 0, self._first))

    def parse(self, chunk) -> Cells:
        index, start, values = chunk
        rows = self.size(chunk)

        def where(i):
            return f"chunk {index}, row {i} (row {start + i} of all)"

        out, texts, digest = {}, {}, hashlib.sha256()
        for name, value in values.items():
            digest.update(name.encode() + b"\0")
            if name in self.carried:
                array = np.asarray(value, dtype=object)
                if array.ndim > 1 or (array.ndim == 1 and array.size not in (1, rows)):
                    raise ValueError(
                        f"chunk {index}, column {name}: {array.size} values for {rows} rows "
                        "(give one per row, or one value)"
                    )
                array = np.broadcast_to(array, (rows,))
                texts[name] = np.array([_text(s) for s in array], dtype=object)
                digest.update(_text_digest(texts[name]))
                continue
            if name in TEXT_COLUMNS:
                array = np.broadcast_to(np.asarray(value, dtype=object), (rows,))
                array = np.array([str(s).strip() for s in array], dtype=object)
                digest.update("\n".join(array).encode())
            else:
                try:
                    array = np.asarray(value, dtype=float)
                except (TypeError, ValueError):
                    raise ValueError(
                        f"chunk {index}, column {name}: not numbers ({_shown(value)})"
                    ) from None
                if array.ndim > 1 or (array.ndim == 1 and array.size not in (1, rows)):
                    raise ValueError(
                        f"chunk {index}, column {name}: {array.size} values for {rows} rows "
                        "(give one per row, or one number)"
                    )
                array = np.array(np.broadcast_to(array, (rows,)))
                digest.update(array.tobytes())
            out[name] = array
        return Cells(out, rows, digest.digest(), None, where, texts)


def _columns_of(chunk, index: int) -> dict:
    """`chunk` as an ordered mapping column -> values (a DataFrame's columns included)."""
    if hasattr(chunk, "to_dict") and hasattr(chunk, "columns"):  # a pandas DataFrame
        return {str(name): chunk[name].to_numpy() for name in chunk.columns}
    if not hasattr(chunk, "keys"):
        raise ValueError(
            f"chunk {index}: a mapping column -> array is needed, got {type(chunk).__name__}"
        )
    return {str(name): chunk[name] for name in chunk.keys()}


def _shown(value) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."
