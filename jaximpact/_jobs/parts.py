"""The finished chunks of a batch written to a file, in `OUT.parts/`, and their joining.

Each chunk `k` is written whole or not at all: `part-00000k.csv` (or `.parquet`) to a
temporary name, then renamed; then its record `part-00000k.json` (the manifest of that chunk:
the SHA-256 of its inputs and of the run's settings, its row count and the count of each
status), also renamed into place. A chunk counts as done only when its record is there and
its hash matches, so a run stopped at any instant leaves nothing that a resumed run would
take for done by mistake. `assemble` joins the parts in chunk order into `OUT` (renamed into
place at the end). Memory holds one part at a time.
"""

import json
import shutil
from pathlib import Path

import numpy as np

from .._files import atomic_output, write_text

FLOAT_OUTPUTS = ("e", "T", "x_max", "t_max", "F_max")
OUTPUTS = (*FLOAT_OUTPUTS, "status", "path")


class Parts:
    """The parts directory of the output `out` (`parquet`: parts and output in Parquet)."""

    def __init__(self, out, parquet: bool):
        self.out, self.parquet = Path(out), parquet
        self.dir = Path(f"{out}.parts")
        self.suffix = ".parquet" if parquet else ".csv"

    def part(self, index: int) -> Path:
        return self.dir / f"part-{index:06d}{self.suffix}"

    def _record(self, index: int) -> Path:
        return self.dir / f"part-{index:06d}.json"

    def done(self, index: int, digest: str) -> dict | None:
        """The record of chunk `index` if it was finished with inputs hashing to `digest`."""
        try:
            record = json.loads(self._record(index).read_text())
        except (OSError, ValueError):
            return None
        if record.get("sha256") != digest or not self.part(index).exists():
            return None
        return record

    def records(self, chunks: int) -> list:
        """The records of chunks `0 .. chunks - 1` (all must be done)."""
        return [json.loads(self._record(i).read_text()) for i in range(chunks)]

    def write(self, index: int, digest: str, columns, cells, results: dict) -> dict:
        """Write chunk `index`: the inputs (`cells`, columns `columns`, those carried
        through included, in their input order) and `results` (each
        of `OUTPUTS` -> one array or list per row), then its record. Returns the record."""
        record_path = self._record(index)
        record_path.unlink(missing_ok=True)  # a stale record never outlives its part
        with atomic_output(self.part(index)) as temporary:
            if self.parquet:
                _write_parquet(temporary, columns, cells, results)
            else:
                _write_csv(temporary, columns, cells, results)
        statuses = {}
        for name in results["status"]:
            statuses[name] = statuses.get(name, 0) + 1
        record = dict(sha256=digest, rows=cells.rows, statuses=statuses)
        write_text(record_path, json.dumps(record))
        return record

    def assemble(self, chunks: int, columns):
        """Join parts `0 .. chunks - 1` into `out` (a temporary name, renamed into place
        when complete: `_files.atomic_output`; an interrupted join leaves `out` as it was)."""
        with atomic_output(self.out) as temporary:
            if self.parquet:
                import pyarrow.parquet as pq

                writer = None
                try:
                    for index in range(chunks):
                        table = pq.read_table(self.part(index))
                        if writer is None:
                            writer = pq.ParquetWriter(temporary, table.schema)
                        writer.write_table(table)
                finally:
                    if writer is not None:
                        writer.close()
            else:
                with open(temporary, "w", newline="") as handle:
                    handle.write(",".join(map(_csv_cell, (*columns, *OUTPUTS))) + "\n")
                    for index in range(chunks):
                        with open(self.part(index), newline="") as part:
                            shutil.copyfileobj(part, handle, 1 << 20)

    def remove(self):
        shutil.rmtree(self.dir, ignore_errors=True)


def _csv_cell(text) -> str:
    """A carried cell as a CSV writes it: quoted where it holds a comma, a quote or a line
    end (or starts or ends with a space); an empty Parquet cell (None) empty."""
    if text is None:
        return ""
    if any(ch in text for ch in ',"\r\n') or text != text.strip():
        return '"' + text.replace('"', '""') + '"'
    return text


def _write_csv(path: Path, columns, cells, results):
    if cells.lines is not None:  # the inputs exactly as written (carried columns included)
        inputs = cells.lines
    else:
        texts = [
            list(map(_csv_cell, cells.carried[c].tolist()))
            if c in cells.carried
            else cells.values[c].tolist()
            if cells.values[c].dtype == object
            else list(map(repr, cells.values[c].tolist()))
            for c in columns
        ]
        inputs = list(map(",".join, zip(*texts, strict=True)))
    texts = [list(map(repr, np.asarray(results[k], float).tolist())) for k in FLOAT_OUTPUTS]
    rows = map(",".join, zip(inputs, *texts, results["status"], results["path"], strict=True))
    with open(path, "w", newline="") as handle:
        handle.write("\n".join(rows) + "\n")


def _write_parquet(path: Path, columns, cells, results):
    import pyarrow as pa
    import pyarrow.parquet as pq

    data = {}
    for c in columns:
        if c in cells.carried:  # carried through: a string column, whatever its input type
            data[c] = pa.array(cells.carried[c].tolist(), pa.string())
            continue
        value = cells.values[c]
        data[c] = pa.array(value.tolist() if value.dtype == object else value)
    for k in FLOAT_OUTPUTS:
        data[k] = pa.array(np.asarray(results[k], float))
    data["status"] = pa.array(list(results["status"]), pa.string())
    data["path"] = pa.array(list(results["path"]), pa.string())
    pq.write_table(pa.table(data), path)
