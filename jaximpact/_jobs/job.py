"""A file job: a table of bodies on disk (CSV or Parquet) or a script's chunks in, one impact
per row out, written with the inputs (the columns the job does not read carried through
unchanged, in their places) beside `e`, `T`, `x_max`, `t_max`, `F_max`, `status` and `path`.

`batch_file` drives it in four steps, each a function of the job's record `Job`:

- `plan`: the arguments checked, the table opened (its header), the values every row
  shares, the run's settings;
- `check`: every value checked once (`row_checks`) before any work, each chunk's inputs
  hashed (SHA-256);
- `compute`: each chunk computed (`chunks`, through `_batch`) and written whole or not at
  all into `OUT.parts/` with its record (`parts`); `resume` skips the chunks whose part and
  hash are there and recomputes those whose input changed;
- `join`: the parts joined into `OUT` (renamed into place) once all are done.

From `check` to `join` the run holds `OUT.lock` (`_files.output_lock`): a second run on the
same output is refused in one line, before any work, naming the first run's process.

Memory holds one chunk at a time. Under `jax.distributed` chunk `k` is process `k mod N`'s to
read, check and write (`processes`); each process runs its own chunks on its own devices
(`mesh="local"`), or each round of chunks, one per process, runs as one program over the
devices of all processes (`mesh="global"`); process 0 joins the parts: the same file, bit
for bit, as one process writes.
"""

import contextlib
import dataclasses
import hashlib
import json
import os
import time
from pathlib import Path

from .._files import check_outputs, check_suffix, lock_name, output_lock, temporary_name
from .._interrupt import check_interrupt, set_note
from .._progress import AbstractMeter, metered
from .._status import Status
from .chunks import compute_chunk
from .job_law import JobLaw, job_law
from .parts import OUTPUTS, Parts
from .processes import ProcessGroup
from .readers import (
    PARQUET_SUFFIXES,
    TEXT_COLUMNS,
    carried_columns,
    is_parquet,
    open_chunks,
    open_table,
    require_pyarrow,
)
from .row_checks import KINEMATICS, check_fixed, check_rows

OUT_SUFFIXES = (".csv", *PARQUET_SUFFIXES)  # what `out` may be: the extension says which
_FORMAT = 3  # bump when the output of a chunk changes for the same inputs


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


@dataclasses.dataclass(frozen=True)
class Job:
    """A file job, as each step leaves it (`plan`, `check`, `compute`).

    `law`, the law as the job reads it (`job_law.JobLaw`: a name of the law table, a law of
    the table or a user's law); `table`, the reader of the rows (`readers`), `label`
    its name for messages and `from_file` whether it is a file; `out` and its `parts`;
    `columns` of the table; `fixed`: the values every row takes from the arguments (law
    parameters, `m`, `v0`, `g`, `separation`); `agree`: the arguments that a column of
    the same name must agree with; `impact_options` (`method`, `rtol`, ...); `settings`:
    all of these as text, hashed with each chunk's inputs; `group`: the processes;
    `chunk_rows`, `resume`, `progress`, `mesh` as given; `one_pass`: the chunks can be
    read once only (a generator: checked as they come). Then what the steps found: the
    `rows` and `chunks` in all, the `digests` of this process's chunks, and how many of
    them it `computed` and `reused`.
    """

    law: JobLaw
    table: object
    label: str
    from_file: bool
    out: Path
    parts: Parts
    columns: tuple
    fixed: dict
    agree: dict
    impact_options: dict
    settings: str
    group: ProcessGroup
    chunk_rows: int
    resume: bool
    progress: bool | AbstractMeter
    mesh: str
    one_pass: bool
    rows: int = 0
    chunks: int = 0
    digests: dict = dataclasses.field(default_factory=dict)
    computed: int = 0
    reused: int = 0

    @property
    def tag(self) -> str:
        """` (process K of N)` for the meters of several processes."""
        return (
            f" (process {self.group.index} of {self.group.count})" if self.group.count > 1 else ""
        )


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

    - `source`, `out`: CSV files, or Parquet (`.parquet`, `.pq`; needs pyarrow). `out`
      holds the input columns in their order (a CSV's text as written) and `e`, `T` (s),
      `x_max` (m), `t_max` (s), `F_max` (N), `status` (a `Status` name) and `path` per row,
      in file order. A column the job does not read (an `id`, a `name`, a `note` in free
      text: neither a parameter the law reads nor `m`, `v0`, `g`, `separation`) is carried
      through as text, unchanged (a string column in Parquet), and its cells are part of the
      inputs a resume compares; one whose name is close to a column the job reads
      (`separaton`, `V0`, `b_1`) or that names a result (`e`, `status`, ...) is refused, a
      `ValueError` naming the likely column. `source` may also be an iterable of chunks
      from a script: mappings column -> 1-D array or number (dicts of numpy arrays, pandas
      DataFrames), each chunk used as given (not `chunk_rows`). A list is read twice (every
      value checked first); a generator once, each chunk checked just before it is computed.
    - `law`: a name of `LAW_NAMES`, a law from `jaximpact.law` (its parameters are the
      values every row takes unless a column or `params` gives them) or a user's law from
      `custom_law` (the same; and a column other than `m`, `v0`, `g`, `separation` that its
      function reads is a parameter, as is every name of `params`: a name of `params` it
      does not read is refused, and so is a parameter it reads that nothing gives; a column
      it does not read is carried through). The file's columns give, per row, any of its
      parameters and `m` (kg), `v0` (m/s), `g` (m/s^2), `separation`; `params`,
      `m`, `v0`, `g`, `separation` give the rest (SI units; `g` 0 and `separation` "force"
      where neither gives them). A column and an argument for the same name must agree on
      every row: a `ValueError` names the first row where they do not.
    - `impact_options` (`method`, `rtol`, ...): as in `impact`.
    - `chunk_rows`: rows per chunk (the unit of memory, of work per process and of
      resumption). `resume`: reuse the chunks an interrupted run left in `OUT.parts/` whose
      inputs and settings have not changed (the law among them: a user's law by its
      function's name, file and code, and its parameters); recompute the others.
    - `progress`: a meter of the checking pass and of the chunks: `True` the default one (on
      stderr), `False` none, or an `AbstractMeter`.

    Every value is checked once, before anything is computed or written: a `ValueError`
    names the first bad column or row (CSV line numbers count the header as 1). Rows that
    fail (stuck, captured, out of steps, results float64 cannot hold) are kept with their
    status. Under `jax.distributed` (call `jax.distributed.initialize()` first) chunk `k` is
    process `k % process_count`'s to read and write, and process 0 joins them into `out`;
    `mesh="local"` (default): each process computes its chunks on its own devices;
    `mesh="global"`: each round of chunks, one per process, runs as one jitted program over
    a mesh of every process's devices, in lockstep (slower on the integrated path:
    benchmarks/batch_files.md). Either way the file is the one a single process writes, bit
    for bit.

    **Example**: `batch_file("bodies.csv", "impacts.csv", "hertz_rate", params={"b1": 800.0},
    m=1.0)`, or with a user's law
    `batch_file("bodies.csv", "impacts.csv", custom_law(f, c=2e6, b1=800.0), m=1.0)`.
    """
    given = {"m": m, "v0": v0, "g": g, "separation": separation}
    job = plan(
        source,
        out,
        law,
        params=params,
        given=given,
        run=Run(chunk_rows=chunk_rows, resume=resume, progress=progress, mesh=mesh),
        impact_options=impact_options,
    )
    with _one_writer(job):
        return join(compute(check(job)))


@contextlib.contextmanager
def _one_writer(job: Job):
    """Process 0 holds the lock of `job.out` (`_files.output_lock`) from the check to the
    join, so that two runs never write one output and its parts: a second run is refused
    in one line before any work, and every process of this one learns of it."""
    with contextlib.ExitStack() as stack:
        problem = None
        if job.group.index == 0:
            try:
                stack.enter_context(output_lock(job.out))
            except ValueError as error:
                problem = str(error)
        problem = next((p for p in job.group.gather(problem) if p is not None), None)
        if problem is not None:
            raise ValueError(problem)
        yield


@dataclasses.dataclass(frozen=True)
class Run:
    """How a file job runs, as `batch_file` takes it: `chunk_rows` (rows per chunk),
    `resume`, `progress` (a meter, `True` or `False`) and `mesh` (`"local"` or
    `"global"`)."""

    chunk_rows: int = 100_000
    resume: bool = False
    progress: bool | AbstractMeter = True
    mesh: str = "local"


def plan(source, out, law, *, params, given, run: Run, impact_options) -> Job:
    """The job of `batch_file`'s arguments (`given`: its `m`, `v0`, `g`, `separation`;
    `run`: its `chunk_rows`, `resume`, `progress`, `mesh`), each checked, and the table
    opened: a one-line `ValueError` before any work."""
    law = job_law(law)
    chunk_rows, mesh = run.chunk_rows, run.mesh
    if mesh not in ("global", "local"):
        raise ValueError(f"mesh must be 'global' or 'local', got {mesh!r}")
    if isinstance(chunk_rows, bool) or not (isinstance(chunk_rows, int) and chunk_rows >= 1):
        raise ValueError(f"chunk_rows must be a positive integer, got {chunk_rows!r}")
    from_file = isinstance(source, (str, os.PathLike))
    out = Path(out)
    source = Path(source) if from_file else source
    check_output_file(out, source if from_file else None)
    if is_parquet(out):
        require_pyarrow(out)
    params = params or {}
    fixed, agree = _given_for_every_row(law, params, given)
    table = open_table(source) if from_file else open_chunks(source)
    columns = table.columns
    law = law.complete(columns, params, source.name if from_file else "chunks")
    carried = carried_columns(columns, law.known_columns, table.where_header, OUTPUTS)
    table.carry(carried)  # read as text, written unchanged (a Parquet file's types checked)
    missing = [k for k in (*law.parameters, "m", "v0") if k not in columns and k not in fixed]
    if missing:
        unread = f" (carried through unread: {', '.join(carried)})" if carried else ""
        raise ValueError(
            f"{source if from_file else 'chunks'}: no value for {', '.join(missing)}: give a "
            f"column or a fixed value (--param NAME=VALUE, --mass, --v0){unread}"
        )
    fixed = {k: v for k, v in fixed.items() if k not in columns}
    agree = {k: v for k, v in agree.items() if k in columns}  # checked row by row
    settings = json.dumps(
        [
            _FORMAT,
            law.identity,
            columns,
            sorted((k, repr(v)) for k, v in fixed.items()),
            sorted((k, repr(v)) for k, v in impact_options.items()),
            is_parquet(out),
        ]
    )
    return Job(
        law=law,
        table=table,
        label=source.name if from_file else "chunks",
        from_file=from_file,
        out=out,
        parts=Parts(out, parquet=is_parquet(out)),
        columns=columns,
        fixed=fixed,
        agree=agree,
        impact_options=dict(impact_options),
        settings=settings,
        group=ProcessGroup.current(),
        chunk_rows=chunk_rows,
        resume=run.resume,
        progress=run.progress,
        mesh=mesh,
        one_pass=not getattr(table, "replayable", True),  # a generator: checked as it comes
    )


def _given_for_every_row(law: JobLaw, params: dict, given: dict) -> tuple[dict, dict]:
    """`(fixed, agree)`: the values every row takes where no column gives them (the law's
    defaults, `params`, `given`; `g` 0 and `separation` "force" by default), each checked,
    and the arguments the caller gave, which a column of the same name must agree with. A
    user's law takes any name in `params` but `m`, `v0`, `g`, `separation` (what its
    function reads is checked once the table's columns are known: `JobLaw.complete`)."""
    named = [k for k in params if k in (*KINEMATICS, *TEXT_COLUMNS)] if law.user else params
    unknown = sorted(set(named) - set(law.parameters))
    if unknown:
        own = [k for k in unknown if k in (*KINEMATICS, *TEXT_COLUMNS)]
        hint = (
            f" ({', '.join(own)}: not a law parameter; pass it as its own argument, "
            "m=, v0=, g=, separation= (the command line's --mass, --v0, --g, --separation), "
            "or as a column)"
            if own
            else ""
        )
        takes = ", ".join(law.parameters) or "what its function reads"
        raise ValueError(
            f"law {law.label!r} has no parameter {', '.join(unknown)}; it takes {takes}{hint}"
        )
    agree = {**params, **{k: v for k, v in given.items() if v is not None}}
    fixed = {**law.defaults, **params, "separation": given["separation"] or "force"}
    fixed.update({k: given[k] for k in KINEMATICS if given[k] is not None})
    fixed.setdefault("g", 0.0)
    check_fixed(law, fixed)
    return fixed, agree


def check(job: Job) -> Job:
    """Every value of the table checked once (`row_checks`: each process its own chunks)
    and each chunk's inputs hashed, before anything is written; the first bad value of any
    process is the error of all. A table read once (`one_pass`) is checked chunk by chunk
    in `compute`. Returns the job with its `rows`, `chunks` and `digests`."""
    set_note(f"nothing computed yet, {job.out} not written")
    digests, rows, chunks, problem = {}, 0, 0, None
    table, group = job.table, job.group
    estimate = max(1, -(-table.estimated_rows() // job.chunk_rows))
    meter = False if job.one_pass else job.progress
    with metered(meter, estimate, f"checking {job.label}{job.tag}") as bar:
        for index, chunk in enumerate(() if job.one_pass else table.chunks(job.chunk_rows)):
            if group.owns(index) and problem is None:
                try:
                    cells = table.parse(chunk)
                    check_rows(job.law, cells.values, job.fixed, cells.where, job.agree)
                except ValueError as error:
                    problem = (index, str(error))
                else:
                    digests[index] = _digest(job.settings, cells.digest)
            rows += table.size(chunk)
            chunks += 1
            bar.total = max(bar.total, chunks)
            bar.update(1, f"{rows:,} rows")
        bar.total = chunks
    problems = sorted(tuple(p) for p in group.gather(problem) if p is not None)
    if problems:
        raise ValueError(problems[0][1])
    if rows == 0 and not job.one_pass:
        raise ValueError(
            f"{job.label}: no data rows" + (" under the header" if job.from_file else "")
        )
    return dataclasses.replace(job, rows=rows, chunks=chunks, digests=digests)


def compute(job: Job) -> Job:
    """Each process computes its chunks (`chunks.compute_chunk`) and writes each as a part,
    reusing those an earlier run finished (`resume`); a chunk read once is checked just
    before. Every process then says how it went (`ProcessGroup.report`), so that none
    waits for a dead one's parts. Returns the job with what this process `computed` and
    `reused` (and the `rows` and `chunks` of a table read once)."""
    group, parts, table = job.group, job.parts, job.table
    own = [i for i in range(job.chunks) if group.owns(i)]
    # said before the parts directory exists: a stop once it does is resumable (a signal
    # between the two printed "nothing computed yet" without --resume; measured under load)
    _note_kept(parts, job.out, 0, len(own))
    if group.index == 0:
        if not job.resume:
            parts.remove()
        parts.dir.mkdir(parents=True, exist_ok=True)
        group.clear(parts.dir)
    group.gather(None)  # the others wait for the parts directory
    together = job.mesh == "global" and group.count > 1  # one program over every process
    digests, rows, chunks = dict(job.digests), job.rows, job.chunks
    computed = reused = done_rows = 0
    own_rows, start, failed = _own_rows(job, own), time.perf_counter(), True
    try:
        with metered(job.progress, max(len(own), 1), f"batch {job.law.label}{job.tag}") as bar:
            for round_ in _rounds(enumerate(table.chunks(job.chunk_rows)), group.count):
                check_interrupt()  # a safe point: Ctrl-C or SIGTERM stops here at the latest
                if job.one_pass:
                    rows += sum(table.size(chunk) for _, chunk in round_)
                    chunks += len(round_)
                    bar.total = max(bar.total, -(-chunks // group.count))
                mine = next(((i, chunk) for i, chunk in round_ if group.owns(i)), None)
                todo, problem = None, None  # the cells of this process's chunk to compute
                if mine is not None:
                    try:
                        todo = _cells_to_compute(job, *mine, digests)
                    except ValueError as error:
                        problem = str(error)
                if together:  # every process learns of a bad chunk before the program runs
                    problem = next((p for p in group.gather(problem) if p is not None), None)
                if problem is not None:
                    raise ValueError(problem)
                if todo is not None or together:  # `together`: each process takes part
                    results = compute_chunk(
                        job.law, todo, job.fixed, job.impact_options, group if together else None
                    )
                if todo is not None:
                    parts.write(mine[0], digests[mine[0]], job.columns, todo, results)
                    computed += 1
                elif mine is not None:
                    reused += 1
                _note_kept(parts, job.out, computed + reused, len(own))
                if mine is not None:
                    done_rows += table.size(mine[1])
                    bar.update(1, _rate(done_rows, own_rows, time.perf_counter() - start))
        if job.one_pass and rows == 0:
            raise ValueError("chunks: no rows in any chunk")
        failed = False
    finally:  # every process says how it went, so that none waits for a dead one's parts
        if not group.peer_failed:
            if not together:  # no exchange in the loop: wait for the others on the disk
                group.wait_for_all(parts.dir)
            failed = group.report(failed)
    if failed or group.peer_failed:
        raise RuntimeError("another process of the batch failed; run again with --resume")
    if job.one_pass and group.count > 1:  # each process counted the chunks it read
        chunks = max(group.gather(chunks))
    return dataclasses.replace(
        job, rows=rows, chunks=chunks, digests=digests, computed=computed, reused=reused
    )


def join(job: Job) -> BatchFile:
    """Process 0 joins the parts into `out` (renamed into place when complete) and removes
    them; every process returns the `BatchFile` once the joined file is there."""
    group, parts = job.group, job.parts
    statuses = dict.fromkeys((s.name for s in Status), 0)
    if group.index == 0:
        for record in parts.records(job.chunks):
            for name, count in record["statuses"].items():
                statuses[name] += count
        check_interrupt()
        parts.assemble(job.chunks, job.columns)
        set_note(f"{job.out} was written whole")
        parts.remove()
    statuses = group.gather(statuses)[0]  # and every process waits for the joined file
    set_note(None)
    return BatchFile(
        str(job.out),
        job.rows,
        job.chunks,
        job.computed,
        job.reused,
        statuses,
        group.index,
        group.count,
    )


def check_output_file(out, source=None, label: str = "out"):
    """Refuse, before any work, an output `out` that `batch_file` cannot write or that
    would destroy the input file `source`: an extension other than `OUT_SUFFIXES`, a
    directory that does not exist, `out` (or the temporary name it is written under, or
    its lock `OUT.lock`) the same file as `source` however spelled (links included), or
    `source` inside `OUT.parts/`, which the run writes and removes. A one-line
    `ValueError` that names the output as `label` (the command line's `--out`)."""
    out = Path(out)
    check_suffix(out, OUT_SUFFIXES, label)
    if out.parent != Path("") and not out.parent.is_dir():
        raise ValueError(f"{label} {out}: directory {str(out.parent)!r} does not exist")
    if out.is_dir():
        raise ValueError(f"{label} {out}: is a directory; name the file to write")
    check_outputs(
        [source],
        {
            label: out,
            f"{label} (written first as)": temporary_name(out),
            f"{label} (its lock)": lock_name(out),
        },
        {f"{label} (its parts directory)": Parts(out, parquet=is_parquet(out)).dir},
    )


def _own_rows(job: Job, own: list) -> int | None:
    """The rows of this process's chunks (None for a table read once: not known ahead)."""
    if job.from_file:
        return sum(min(job.chunk_rows, job.rows - i * job.chunk_rows) for i in own)
    if job.one_pass:
        return None
    sizes = [job.table.size(chunk) for chunk in job.table.chunks(job.chunk_rows)]  # no parsing
    return sum(sizes[i] for i in own)


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


def _cells_to_compute(job: Job, index: int, chunk, digests: dict):
    """The parsed cells of chunk `index`, or None where the parts hold it finished with the
    same inputs and settings (`resume`); a chunk read once (`one_pass`) is checked here (a
    ValueError naming its row), and its digest added to `digests`."""
    cells = None
    if job.one_pass:
        cells = job.table.parse(chunk)
        check_rows(job.law, cells.values, job.fixed, cells.where, job.agree)
        digests[index] = _digest(job.settings, cells.digest)
    if job.resume and job.parts.done(index, digests[index]):
        return None
    return cells or job.table.parse(chunk)


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
