"""`jaximpact batch`: many impacts from a CSV file of bodies, written to a CSV file."""

from pathlib import Path

from .common import CLIError, command_parser, emit, parse_params


def add_batch(subparsers):
    parser = command_parser(
        subparsers,
        "batch",
        help="impacts of every row of a CSV file (streamed in chunks, resumable)",
        description="One impact per row of the CSV file IN under the force law --law. The "
        "columns of IN give, per row, any of the law's parameters and m (kg), v0 (m/s), g "
        "(m/s^2); --param NAME=VALUE, --mass, --v0 and --g give the rest (SI units). OUT gets "
        "the inputs and e, T (s), x_max (m), t_max (s), F_max (N), status and path. Every "
        "value is checked before any work; chunks are written whole into OUT.parts/ and "
        "joined into OUT at the end; --resume reuses the chunks of an interrupted run whose "
        "inputs did not change.",
        example="jaximpact batch bodies.csv --law hertz_rate --param b1=800 --mass 1 "
        "--out impacts.csv",
    )
    parser.add_argument("source", type=Path, metavar="IN", help="CSV file, one body per row")
    parser.add_argument("--law", required=True, metavar="NAME", help="see `jaximpact laws`")
    parser.add_argument("--param", action="append", default=[], metavar="NAME=VALUE")
    parser.add_argument("--mass", type=float, metavar="KG", help="m for every row, kg")
    parser.add_argument("--v0", type=float, metavar="M/S", help="impact speed for every row")
    parser.add_argument("--g", type=float, default=0.0, metavar="M/S^2", help="gravity")
    parser.add_argument(
        "--separation", choices=("force", "penetration"), default="force", help="end of contact"
    )
    parser.add_argument("--out", required=True, type=Path, metavar="OUT", help="CSV to write")
    parser.add_argument("--chunk-rows", type=int, default=100_000, metavar="N")
    parser.add_argument("--resume", action="store_true", help="reuse finished chunks")
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    parser.set_defaults(handler=run_batch_command)


def run_batch_command(args):
    from .._batch.files import batch_file
    from .._progress import progress_enabled

    if args.chunk_rows < 1:
        raise CLIError("--chunk-rows must be at least 1")
    if args.out.parent != Path("") and not args.out.parent.is_dir():
        raise CLIError(f"--out {args.out}: directory {str(args.out.parent)!r} does not exist")
    result = batch_file(
        args.source,
        args.out,
        args.law,
        params=parse_params(args.param),
        m=args.mass,
        v0=args.v0,
        g=args.g,
        separation=args.separation,
        chunk_rows=args.chunk_rows,
        resume=args.resume,
        progress=progress_enabled(),
    )
    counts = ", ".join(f"{n} {k}" for k, n in result.statuses.items() if n)
    text = (
        f"{result.rows} impacts written to {result.path} ({counts}); "
        f"{result.computed} chunks computed, {result.reused} reused"
    )
    emit(args, {f: getattr(result, f) for f in result.__dataclass_fields__}, text)
