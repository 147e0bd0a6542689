"""`jaximpact paper`: the seed paper's figures and restitutions, recomputed into a directory."""

from pathlib import Path

from .common import CLIError, add_output_arguments, command_parser, emit


def add_paper(subparsers):
    parser = command_parser(
        subparsers,
        "paper",
        help="recompute the seed paper's figures and tables (e printed, Euler, converged)",
        description="Recompute every figure of the seed paper (Polukoshko et al. 2007) that "
        "has numbers behind it into --out: the e and T maps (figs. 1 and 7), the "
        "force-displacement loops (figs. 2-6, 8-11) and the bouncing ball (figs. 13-21) as PNG "
        "files; table.md with, for every parameter set, the e printed in the paper, the e of "
        "the paper's own explicit Euler scheme at its step 2e-5 s, and the converged e and T "
        "under each separation criterion; and hunt_crossley_variants.md, the restitution each "
        "published Hunt-Crossley damping formula really gives. Takes a few minutes the first "
        "time (JAX compiles one solve per law; later runs reuse the compilation cache).",
        example="jaximpact paper --out paper\njaximpact paper --out paper --figures 3 13-15 --json",
    )
    parser.add_argument(
        "--out", type=Path, required=True, metavar="DIR", help="directory to write into"
    )
    parser.add_argument(
        "--figures",
        nargs="+",
        metavar="N",
        help="only these figures (e.g. 2 10 13-15; default: all, and the variants table)",
    )
    parser.add_argument(
        "--no-plots", action="store_true", help="write the tables only, no PNG files"
    )
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_paper)


def _run_paper(args):
    import sys

    from .._paper.cases import select_cases
    from .._paper.report import paper_text
    from .._paper.reproduce import reproduce_paper

    if args.out.exists() and not args.out.is_dir():
        raise CLIError(f"--out {args.out}: exists and is not a directory")
    if not args.out.parent.is_dir() and args.out.parent != Path(""):
        raise CLIError(f"--out {args.out}: directory {str(args.out.parent)!r} does not exist")
    select_cases(args.figures)  # a bad figure number fails before any work
    result = reproduce_paper(
        args.out, only=args.figures, figures=not args.no_plots, progress=sys.stderr.isatty()
    )
    emit(args, dict(out=str(args.out), **result), lambda: paper_text(result))
