"""`jaximpact batch`: many impacts from a CSV (or Parquet) file of bodies, written to a CSV (or
Parquet) file; on one process or several (`jax.distributed`)."""

from pathlib import Path

from .common import (
    CLIError,
    add_law_arguments,
    command_parser,
    emit,
    parse_params,
)


def add_batch(subparsers):
    parser = command_parser(
        subparsers,
        "batch",
        help="impacts of every row of a CSV or Parquet file (streamed, resumable, multi-process)",
        description="One impact per row of the file IN under the force law --law. The "
        "columns of IN give, per row, any of the law's parameters and m (kg), v0 (m/s), g "
        "(m/s^2), separation (force or penetration); --param NAME=VALUE, --mass, --v0, --g "
        "and --separation give the rest (SI units); a column and an option for the same "
        "name must agree on every row (the first row where they do not is an error). OUT "
        "gets the inputs and e, T (s), x_max (m), t_max (s), F_max (N), status and path, "
        "in the order of IN; any other column of IN (an id, a name, a note) is carried "
        "through to OUT unchanged, in its place, and one whose name is close to a column "
        "read (separaton, V0) is refused. CSV always; Parquet "
        "(.parquet, .pq) with pyarrow installed (pip install 'jaximpact[parquet]'). Every "
        "value is checked before any work; chunks of --chunk-rows rows are written whole "
        "into OUT.parts/ with a SHA-256 of their inputs and joined into OUT at the end; "
        "--resume reuses the chunks of an interrupted run whose inputs did not change.\n\n"
        "A user's law, --law FILE.py:NAME (the function NAME(x, v, params) of a Python "
        "file), takes its parameters from --param and from the columns of IN: a column "
        "but m, v0, g and separation that it reads is a parameter; one it does not read is "
        "carried through.\n\n"
        "Several processes (jax.distributed): start one per process with --coordinator "
        "HOST:PORT --num-processes N --process-id K, or with --distributed alone under "
        "SLURM or Open MPI (srun, mpirun), which tell JAX the rest. Process K reads and "
        "writes the chunks k with k mod N = K; with --mesh local (default) each process runs "
        "its own, with --mesh global each round of N chunks runs as one jitted program over "
        "the devices of all processes. Process 0 writes OUT, the same file as one "
        "process writes. OUT must be on a file system all processes see.",
        example="jaximpact batch bodies.csv --law hertz_rate --param b1=800 --mass 1 "
        "--out impacts.csv\n"
        "jaximpact batch bodies.csv --law hertz_rate --param b1=800 --out impacts.csv "
        "--coordinator localhost:12345 --num-processes 2 --process-id 0",
    )
    parser.add_argument(
        "source", type=Path, metavar="IN", help="CSV or Parquet file, one body per row"
    )
    add_law_arguments(
        parser,
        law="see `jaximpact laws`; or a user's law FILE.py:NAME, the function NAME(x, v, "
        "params) of a Python file",
        param="a law parameter for every row, SI units (--param c=2e6 b1=800, or repeated)",
    )
    parser.add_argument("--mass", type=float, metavar="KG", help="m for every row, kg")
    parser.add_argument("--v0", type=float, metavar="M/S", help="impact speed for every row")
    parser.add_argument(
        "--g", type=float, metavar="M/S^2", help="gravity for every row (default 0)"
    )
    parser.add_argument(
        "--separation",
        choices=("force", "penetration"),
        help="end of contact for every row (default force)",
    )
    parser.add_argument("--out", required=True, type=Path, metavar="OUT", help="file to write")
    parser.add_argument(
        "--chunk-rows",
        type=int,
        default=100_000,
        metavar="N",
        help="rows per chunk (default 100000): the unit of memory, of work and of --resume",
    )
    parser.add_argument(
        "--resume",
        action="store_true",
        help="reuse the chunks an interrupted run left in OUT.parts/ whose inputs and "
        "settings are unchanged (a finished run leaves none)",
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    group = parser.add_argument_group("several processes (jax.distributed)")
    group.add_argument(
        "--distributed",
        action="store_true",
        help="join a jax.distributed job; under SLURM or Open MPI nothing else is needed",
    )
    group.add_argument("--coordinator", metavar="HOST:PORT", help="process 0's address")
    group.add_argument("--num-processes", type=int, metavar="N", help="processes in all")
    group.add_argument("--process-id", type=int, metavar="K", help="this process, 0 .. N-1")
    group.add_argument(
        "--mesh",
        choices=("local", "global"),
        default="local",
        help="local (default): each process computes its chunks on its own devices without "
        "waiting for the others; global: each round of chunks, one per process, runs as one "
        "jitted program over a mesh of every process's devices, in lockstep (slower on the "
        "integrated path; the same file either way)",
    )
    parser.set_defaults(handler=run_batch_command)


def _start_processes(args):
    """`jax.distributed.initialize` from the options (or the cluster's environment)."""
    given = {
        "--coordinator": args.coordinator,
        "--num-processes": args.num_processes,
        "--process-id": args.process_id,
    }
    if not args.distributed and all(v is None for v in given.values()):
        return
    if not args.distributed:
        missing = [k for k, v in given.items() if v is None]
        if missing:
            raise CLIError(
                f"{', '.join(missing)} missing: give all three, or --distributed "
                "under SLURM or Open MPI"
            )
    n, k = args.num_processes, args.process_id
    if n is not None and n < 1:
        raise CLIError(f"--num-processes must be at least 1, got {n}")
    if k is not None and not (0 <= k < (n if n is not None else k + 1)):
        raise CLIError(f"--process-id must lie in 0 .. {n - 1}, got {k}")
    if args.coordinator is not None and ":" not in args.coordinator:
        raise CLIError(f"--coordinator {args.coordinator!r} must be HOST:PORT")
    import jax

    try:
        jax.distributed.initialize(
            coordinator_address=args.coordinator, num_processes=n, process_id=k
        )
    except (RuntimeError, ValueError) as error:
        message = " ".join(str(error).split())[:300]
        raise CLIError(f"cannot join the jax.distributed job: {message}") from None


def run_batch_command(args):
    from .._jobs import batch_file, check_output_file
    from .._jobs.file_law import file_law, is_file_law

    if args.chunk_rows < 1:
        raise CLIError("--chunk-rows must be at least 1")
    # before any work: an OUT that cannot be written, or that is IN however spelled
    check_output_file(args.out, args.source, "--out")
    params = parse_params(args.param)
    # a user's law: its parameters come from --param and the columns (the job checks them)
    law = file_law(args.law, {}, complete=False) if is_file_law(args.law) else args.law
    _start_processes(args)
    result = batch_file(
        args.source,
        args.out,
        law,
        params=params,
        m=args.mass,
        v0=args.v0,
        g=args.g,
        separation=args.separation,
        chunk_rows=args.chunk_rows,
        resume=args.resume,
        progress=True,  # the default meter: none when JAXIMPACT_PROGRESS is off
        mesh=args.mesh,
    )
    counts = ", ".join(f"{n} {k}" for k, n in result.statuses.items() if n)
    where = f"process {result.process} of {result.processes}: " if result.processes > 1 else ""
    text = (
        f"{where}{result.rows} impacts written to {result.path} ({counts}); "
        f"{result.computed} chunks computed, {result.reused} reused"
    )
    emit(args, {f: getattr(result, f) for f in result.__dataclass_fields__}, text)
