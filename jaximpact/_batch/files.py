"""Many impacts from a table on disk: `batch_file(source, out, law, ...)` reads a CSV (or
Parquet) file of bodies in chunks, runs `impact_batch` on each, and writes the inputs with
`e`, `T`, `x_max`, `t_max`, `F_max`, `status` and `path` beside them.

Nothing is lost: every value is checked before any work (one line naming the row and the
column); each chunk is written whole or not at all into `OUT.parts/` with a record of the
SHA-256 of its inputs and of the run's settings (`parts`); `resume=True` skips the chunks
whose part and hash are there and recomputes those whose input changed; the parts are joined
into `OUT` (renamed into place) only when all are done. Memory holds one chunk at a time.
Under `jax.distributed` chunk `k` is process `k mod N`'s to read, check and write
(`processes`); each process runs its own chunks on its own devices (`mesh="local"`), or each
round of chunks, one per process, runs as one program over the devices of all processes
(`mesh="global"`); process 0 joins the parts: the same file, bit for bit, as one process
writes.
"""

import dataclasses
import hashlib
import json
import os
import time
import warnings
from pathlib import Path

import numpy as np

from .._files import check_outputs, check_suffix, temporary_name
from .._interrupt import check_interrupt, set_note
from .._laws import LAWS, law as make_law
from .._progress import AbstractMeter, metered
from .._status import Status
from .impacts import batch_path, impact_batch
from .parts import FLOAT_OUTPUTS, OUTPUTS, Parts
from .processes import ProcessGroup
from .readers import (
    PARQUET_SUFFIXES,
    TEXT_COLUMNS,
    is_parquet,
    open_chunks,
    open_table,
    require_pyarrow,
)
from .row_checks import KINEMATICS, check_fixed, check_rows
from .runner import GLOBAL

__all__ = ["OUTPUTS", "OUT_SUFFIXES", "BatchFile", "batch_file"]
OUT_SUFFIXES = (".csv", *PARQUET_SUFFIXES)  # what `out` may be: the extension says which
_FORMAT = 3  # bump when the output of a chunk changes for the same inputs
_STATUS_NAMES = np.array([Status(i).name if i in set(map(int, Status)) else "" for i in
                          range(max(map(int, Status)) + 1)], object)  # fmt: skip


@dataclasses.dataclass(frozen=True)
class BatchFile:
    """What `batch_file` did: the output `path`, the number of `rows`, the `chunks` in all,
    how many this process `computed` and `reused` from an earlier run (`resume=True`), the
    count of each `status` name over the whole file, and this process's place (`process`
    of `processes`)."""

    path: str
    rows: int
    chunks: int
    computed: int
    reused: int
    statuses: dict
    process: int = 0
    processes: int = 1


def batch_file(
    source,
    out,
    law,
    *,
    params: dict | None = None,
    m: float | None = None,
    v0: float | None = None,
    g: float | None = None,
    separation: str | None = None,
    chunk_rows: int = 100_000,
    resume: bool = False,
    progress: bool | AbstractMeter = True,
    mesh: str = "local",
    **impact_options,
) -> BatchFile:
    """Run `impact_batch` over the rows of the file `source` and write `out`.

    - `source`, `out`: CSV files, or Parquet (`.parquet`, `.pq`; needs pyarrow). The output
      holds the input columns (a CSV's text as written) and `e`, `T` (s), `x_max` (m),
      `t_max` (s), `F_max` (N), `status` (a `Status` name) and `path` per row, in file order.
      `source` may also be an iterable of chunks from a script: mappings column -> 1-D array
      or number (dicts of numpy arrays, pandas DataFrames), each chunk used as given (not
      `chunk_rows`). A list is read twice (every value checked first); a generator once,
      each chunk checked just before it is computed.
    - `law`: a name of `LAW_NAMES`. The file's columns give, per row, any of its parameters
      and `m` (kg), `v0` (m/s), `g` (m/s^2), `separation`; `params`, `m`, `v0`, `g`,
      `separation` give the rest (SI units; `g` 0 and `separation` "force" where neither
      gives them). A column and an argument for the same name must agree on every row: a
      `ValueError` names the first row where they do not.
    - `impact_options` (`method`, `rtol`, ...): as in `impact`.
    - `chunk_rows`: rows per chunk (the unit of memory, of work per process and of
      resumption).
    - `resume`: reuse the chunks an interrupted run left in `OUT.parts/` whose inputs and
      settings have not changed; recompute the others.
    - `progress`: a meter of the checking pass and of the chunks: `True` the default one (on
      stderr), `False` none, or an `AbstractMeter`.

    A `ValueError` names the first bad column or row (CSV line numbers count the header as
    1) before anything is computed or written. Rows that fail (stuck, captured, out of steps,
    results float64 cannot hold) are kept with their status.

    Under `jax.distributed` (call `jax.distributed.initialize()` first) the chunks go round
    robin, chunk `k` to process `k % process_count`, each process reads and writes its own,
    and process 0 joins them into `out`. `mesh="local"` (default): each process computes its
    chunks on its own devices, never waiting for the others; `mesh="global"`: the processes
    take one round of chunks at a time and compute them together, one jitted program over a
    mesh of every process's devices (`run_batch(devices="global")`), in lockstep (slower
    where an integrated solve all-reduces its loop condition at every step:
    benchmarks/batch_files.md). Either way the file is the one a single process writes, bit
    for bit.

    **Example**: `batch_file("bodies.csv", "impacts.csv", "hertz_rate", params={"b1": 800.0},
    m=1.0)`.
    """
    if law not in LAWS:
        raise ValueError(f"unknown law {law!r}; see `jaximpact laws`")
    if mesh not in ("global", "local"):
        raise ValueError(f"mesh must be 'global' or 'local', got {mesh!r}")
    if isinstance(chunk_rows, bool) or not (isinstance(chunk_rows, int) and chunk_rows >= 1):
        raise ValueError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    from_file = isinstance(source, (str, os.PathLike))
    out = Path(out)
    if from_file:
        source = Path(source)
    check_output_file(out, source if from_file else None)
    if is_parquet(out):
        require_pyarrow(out)
    spec = LAWS[law]
    # what the caller gave for every row: a column of the same name must agree with it
    options = {**(params or {})}
    options.update({k: v for k, v in (("m", m), ("v0", v0), ("g", g), ("separation",
                    separation)) if v is not None})  # fmt: skip
    fixed = {**spec.defaults, **(params or {}), "separation": separation or "force"}
    fixed.update({k: v for k, v in (("m", m), ("v0", v0), ("g", g)) if v is not None})
    fixed.setdefault("g", 0.0)
    unknown = sorted(set(params or {}) - set(spec.parameters))
    if unknown:
        own = [k for k in unknown if k in (*KINEMATICS, *TEXT_COLUMNS)]
        hint = (
            f" ({', '.join(own)}: not a law parameter; pass it as its own argument, "
            "m=, v0=, g=, separation= (the command line's --mass, --v0, --g, --separation), "
            "or as a column)"
            if own
            else ""
        )
        raise ValueError(f"law {law!r} has no parameter {', '.join(unknown)}; it takes "
                         f"{', '.join(spec.parameters)}{hint}")  # fmt: skip
    check_fixed(law, fixed)
    allowed = (*spec.parameters, *KINEMATICS, *TEXT_COLUMNS)
    table = open_table(source, allowed) if from_file else open_chunks(source, allowed)
    label = source.name if from_file else "chunks"
    one_pass = not getattr(table, "replayable", True)  # a generator: check as it comes
    columns = table.columns
    missing = [k for k in (*spec.parameters, "m", "v0") if k not in columns and k not in fixed]
    if missing:
        raise ValueError(
            f"{source if from_file else 'chunks'}: no value for {', '.join(missing)}: give a "
            "column or a fixed value (--param NAME=VALUE, --mass, --v0)"
        )
    fixed = {k: v for k, v in fixed.items() if k not in columns}
    options = {k: v for k, v in options.items() if k in columns}  # checked row by row
    settings = json.dumps(
        [_FORMAT, law, columns, sorted((k, repr(v)) for k, v in fixed.items()),
         sorted((k, repr(v)) for k, v in impact_options.items()), is_parquet(out)]
    )  # fmt: skip
    group = ProcessGroup.current()
    tag = f" (process {group.index} of {group.count})" if group.count > 1 else ""
    parts = Parts(out, parquet=is_parquet(out))

    # 1. every value checked (each process its own chunks) before anything is written
    set_note(f"nothing computed yet, {out} not written")
    digests, rows, chunks, problem = {}, 0, 0, None
    estimate = max(1, -(-table.estimated_rows() // chunk_rows))
    with metered(False if one_pass else progress, estimate, f"checking {label}{tag}") as bar:
        for index, chunk in enumerate(() if one_pass else table.chunks(chunk_rows)):
            if group.owns(index) and problem is None:
                try:
                    cells = table.parse(chunk)
                    check_rows(law, cells.values, fixed, cells.where, options)
                except ValueError as error:
                    problem = (index, str(error))
                else:
                    digests[index] = _digest(settings, cells.digest)
            rows += table.size(chunk)
            chunks += 1
            bar.total = max(bar.total, chunks)
            bar.update(1, f"{rows:,} rows")
        bar.total = chunks
    problems = sorted(tuple(p) for p in group.gather(problem) if p is not None)
    if problems:
        raise ValueError(problems[0][1])
    if rows == 0 and not one_pass:
        raise ValueError(f"{label}: no data rows" + (" under the header" if from_file else ""))

    # 2. each process computes its chunks, reusing those an earlier run finished
    if group.index == 0 and not resume:
        parts.remove()
    if group.index == 0:
        parts.dir.mkdir(parents=True, exist_ok=True)
    group.gather(None)  # the others wait for the parts directory
    own = [i for i in range(chunks) if group.owns(i)]
    own_rows = sum(min(chunk_rows, rows - i * chunk_rows) for i in own) if from_file else None
    if not from_file and not one_pass:
        sizes = [table.size(chunk) for chunk in table.chunks(chunk_rows)]  # cheap: no parsing
        own_rows = sum(sizes[i] for i in own)
    together = mesh == "global" and group.count > 1  # one program over every process
    computed = reused = done_rows = 0
    start = time.perf_counter()
    failed = True
    _note_kept(parts, out, 0, len(own))
    try:
        with metered(progress, max(len(own), 1), f"batch {law}{tag}") as bar:
            for round_ in _rounds(enumerate(table.chunks(chunk_rows)), group.count):
                check_interrupt()  # a safe point: Ctrl-C or SIGTERM stops here at the latest
                if one_pass:
                    rows += sum(table.size(chunk) for _, chunk in round_)
                    chunks += len(round_)
                    bar.total = max(bar.total, -(-chunks // group.count))
                mine = next(((i, chunk) for i, chunk in round_ if group.owns(i)), None)
                todo, problem = None, None  # the cells of this process's chunk to compute
                if mine is not None:
                    try:
                        todo = _cells_to_compute(*mine, table, law, fixed, options, settings,
                                                 digests, parts if resume else None,
                                                 one_pass)  # fmt: skip
                    except ValueError as error:
                        problem = str(error)
                if together:  # every process learns of a bad chunk before the program runs
                    problem = next((p for p in group.gather(problem) if p is not None), None)
                if problem is not None:
                    raise ValueError(problem)
                if todo is not None or together:  # `together`: each process takes part
                    results = _compute(law, todo, fixed, impact_options,
                                       group if together else None)  # fmt: skip
                if todo is not None:
                    parts.write(mine[0], digests[mine[0]], columns, todo, results)
                    computed += 1
                elif mine is not None:
                    reused += 1
                _note_kept(parts, out, computed + reused, len(own))
                if mine is not None:
                    done_rows += table.size(mine[1])
                    bar.update(1, _rate(done_rows, own_rows, time.perf_counter() - start))
        if one_pass and rows == 0:
            raise ValueError("chunks: no rows in any chunk")
        failed = False
    finally:  # every process says how it went, so that none waits for a dead one's parts
        if not group.peer_failed:
            failed = group.report(failed)
    if failed or group.peer_failed:
        raise RuntimeError("another process of the batch failed; run again with --resume")
    if one_pass and group.count > 1:  # each process counted the chunks it read
        chunks = max(group.gather(chunks))

    # 3. process 0 joins the parts into OUT
    statuses = dict.fromkeys((s.name for s in Status), 0)
    if group.index == 0:
        for record in parts.records(chunks):
            for name, count in record["statuses"].items():
                statuses[name] += count
        check_interrupt()
        parts.assemble(chunks, columns)
        set_note(f"{out} was written whole")
        parts.remove()
    statuses = group.gather(statuses)[0]  # and every process waits for the joined file
    set_note(None)
    return BatchFile(str(out), rows, chunks, computed, reused, statuses, group.index, group.count)


def check_output_file(out, source=None, label: str = "out"):
    """Refuse, before any work, an output `out` that `batch_file` cannot write or that
    would destroy the input file `source`: an extension other than `OUT_SUFFIXES`, a
    directory that does not exist, `out` (or the temporary name it is written under) the
    same file as `source` however spelled (links included), or `source` inside
    `OUT.parts/`, which the run writes and removes. A one-line `ValueError` that names the
    output as `label` (the command line's `--out`)."""
    out = Path(out)
    check_suffix(out, OUT_SUFFIXES, label)
    if out.parent != Path("") and not out.parent.is_dir():
        raise ValueError(f"{label} {out}: directory {str(out.parent)!r} does not exist")
    if out.is_dir():
        raise ValueError(f"{label} {out}: is a directory; name the file to write")
    check_outputs(
        [source],
        {label: out, f"{label} (written first as)": temporary_name(out)},
        {f"{label} (its parts directory)": Parts(out, parquet=is_parquet(out)).dir},
    )


def _note_kept(parts: Parts, out: Path, done: int, total: int):
    """What an interrupt now keeps (printed by the command line, `_interrupt`)."""
    set_note(
        f"{done} of {total} chunks kept in {parts.dir}{os.sep}, {out} not written; run the "
        "same command with --resume to continue"
    )


def _rounds(items, size: int):
    """`items` in lists of `size` (the last may be shorter): the rounds of chunks, one
    chunk per process."""
    batch = []
    for item in items:
        batch.append(item)
        if len(batch) == size:
            yield batch
            batch = []
    if batch:
        yield batch


def _cells_to_compute(index, chunk, table, law, fixed, options, settings, digests, parts,
                      one_pass):  # fmt: skip
    """The parsed cells of chunk `index`, or None where `parts` (None: no resuming) holds it
    finished with the same inputs and settings; a chunk read once (`one_pass`) is checked
    here (a ValueError naming its row; `options`: the arguments its columns must agree
    with)."""
    cells = None
    if one_pass:
        cells = table.parse(chunk)
        check_rows(law, cells.values, fixed, cells.where, options)
        digests[index] = _digest(settings, cells.digest)
    if parts is not None and parts.done(index, digests[index]):
        return None
    return cells or table.parse(chunk)


def _digest(settings: str, inputs: bytes) -> str:
    return hashlib.sha256(settings.encode() + inputs).hexdigest()


def _rate(done: int, total: int, seconds: float) -> str:
    """`12,345 rows, 5,678 rows/s, 1m05s left`."""
    rate = done / seconds if seconds > 0 else 0.0
    if rate <= 0:
        return f"{done:,} rows"
    if total is None:
        return f"{done:,} rows, {rate:,.0f} rows/s"
    left = int(round((total - done) / rate))
    return f"{done:,} rows, {rate:,.0f} rows/s, {left // 60}m{left % 60:02d}s left"


def _compute(law: str, cells, fixed: dict, options: dict, group: ProcessGroup | None) -> dict:
    """`impact_batch` over one chunk (`cells`); rows grouped by separation, by whether
    gravity is zero and by the law's shape parameters, so that each row's path depends on
    that row alone (not on the chunk it falls in). Returns `OUTPUTS` -> one entry per row.

    With `group`, every process of it calls `_compute` at once (`cells` None where it has
    nothing to compute): the processes agree on the row groups of the round, and each row
    group runs as one program over the devices of them all (`devices="global"`), every
    process giving the same number of rows: the group's first row of the first process
    that has it (so that every process takes the same path and shapes), its own rows, and
    that first row again as padding."""
    spec = LAWS[law]
    rows = 0 if cells is None else cells.rows
    values = {} if cells is None else cells.values
    given = {k: np.broadcast_to(np.asarray(v, float), (rows,)) for k, v in fixed.items()
             if k != "separation"}  # fmt: skip
    given.update({k: v for k, v in values.items() if k != "separation"})
    given.setdefault("g", np.zeros(rows))
    sep = values.get("separation", np.full(rows, fixed.get("separation", "force"), object))
    columns = (*spec.parameters, "m", "v0", "g")
    local = _row_groups(spec, given, sep, values) if rows else {}  # key -> this chunk's rows
    plan = {key: (None, idx.size) for key, idx in local.items()}  # key -> (first row, rows)
    if group is not None:
        plan = _shared_plan(group, local, given, columns)
    results = {k: np.full(rows, np.nan) for k in FLOAT_OUTPUTS}
    status = np.empty(rows, object)
    path = np.empty(rows, object)
    for key in sorted(plan):
        separation = json.loads(key)[0]
        idx = local.get(key, np.zeros(0, int))
        inputs = {k: given.get(k, np.zeros(0))[idx] for k in columns}
        first, size = plan[key]
        if group is not None:  # the first row, this process's rows, the first row as padding
            inputs = {k: np.concatenate([[first[j]], inputs[k], np.full(size - idx.size, first[j])])
                      for j, k in enumerate(columns)}  # fmt: skip
        with warnings.catch_warnings():  # invalid rows are counted in the statuses
            warnings.simplefilter("ignore")
            out = impact_batch(
                law, {k: inputs[k] for k in spec.parameters}, m=inputs["m"], v0=inputs["v0"],
                g=inputs["g"], separation=separation, fields=(*FLOAT_OUTPUTS, "status"),
                progress=False, invalid="mark",
                **({"devices": GLOBAL} if group is not None else {}), **options,
            )  # fmt: skip
        if not idx.size:
            continue
        mine = slice(1, 1 + idx.size) if group is not None else slice(None)
        for k in FLOAT_OUTPUTS:
            results[k][idx] = out[k][mine]
        status[idx] = _STATUS_NAMES[out["status"][mine]]
        first_law = make_law(law, **{k: float(given[k][idx[0]]) for k in spec.parameters})
        zero_g = bool(given["g"][idx[0]] == 0.0)
        path[idx] = batch_path(first_law, separation, g_is_zero=zero_g, **options)
    return {**results, "status": status.tolist(), "path": path.tolist()}


def _row_groups(spec, given: dict, sep, values: dict) -> dict:
    """The rows of a chunk by group, `json` key `[separation, g == 0, shape parameters]` ->
    row indices: the rows that share a path and a compiled program."""
    keys = [np.unique(sep, return_inverse=True)[1]] if "separation" in values else []
    keys += [given["g"] == 0.0] if "g" in values else []
    keys += [np.unique(values[k], return_inverse=True)[1] for k in spec.shape_parameters
             if k in values]  # fmt: skip
    group_of = np.zeros(len(sep), int)
    if keys:
        _, group_of = np.unique(np.stack(keys, axis=1), axis=0, return_inverse=True)
        group_of = group_of.reshape(-1)
    groups = {}
    for number in range(int(group_of.max()) + 1):
        idx = np.flatnonzero(group_of == number)
        shape = [float(given[k][idx[0]]) for k in spec.shape_parameters]
        groups[json.dumps([str(sep[idx[0]]), bool(given["g"][idx[0]] == 0.0), shape])] = idx
    return groups


def _shared_plan(group: ProcessGroup, local: dict, given: dict, columns) -> dict:
    """Every process's row groups of the round (`local`: this one's), each key -> (the values
    of `columns` in its first row on the first process that has it, the most rows any
    process has of it): the same on every process."""
    shared = {key: ([float(given[k][idx[0]]) for k in columns], int(idx.size))
              for key, idx in local.items()}  # fmt: skip
    plan = {}
    for theirs in group.gather(shared):
        for key, (first, size) in theirs.items():
            known_first, known_size = plan.get(key, (first, 0))
            plan[key] = (known_first, max(known_size, size))
    return plan
