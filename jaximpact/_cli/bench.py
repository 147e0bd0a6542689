"""`jaximpact bench`: a short benchmark of jaximpact's default `impact` against scipy.

Runs `jaximpact._bench.run_bench` (the seed paper's conditions, scipy `solve_ivp` DOP853
with an event at the loosest rtol reaching an error in e of 1e-9, timed in alternation with
one jitted impact and a vmapped batch) and prints the ratio table with the machine it ran
on; `--json` for the numbers, `--plot` for a bar chart of the ratios against the targets.
"""

import sys

from .._bench import LAWS, TARGETS, bench_text, require_scipy, run_bench, steps
from .._plotting import plot_bench
from .._progress import is_terminal, metered
from .common import (
    CLIError,
    add_output_arguments,
    check_plot_path,
    command_parser,
    emit,
)


def add_bench(subparsers):
    parser = command_parser(
        subparsers,
        "bench",
        help="run a short benchmark against scipy and print the speed-up table",
        description="Time jaximpact's default impact() against scipy's solve_ivp (DOP853 "
        "with a terminal event) at the seed paper's conditions (m = 1 kg, v0 = 2.5 m/s, "
        "separation at zero force): Kelvin-Voigt (closed form, and integrated), Maxwell, "
        "law 14 (hertz_rate) and Hunt-Crossley. For each law: the relative error in e and T "
        "against a closed form or scipy DOP853 at rtol 1e-13; microseconds per impact of one "
        "jitted impact and per impact in a jax.vmap-ed batch of 1000 impact speeds, with "
        "the compile times apart; scipy at the loosest half-decade rtol whose error in e is "
        "<= 1e-9; the ratios scipy / jaximpact against the project's targets (>= 50x for "
        "one impact, >= 1000x per impact in a batch), timed in alternation so both see the "
        "same load. Also the seed paper's explicit Euler at 2e-5 s, for its error in e. "
        "About 1-2 minutes on 2 cores (less on a second run, which reuses JAX's "
        "compilation cache); numbers depend on the machine and its load, printed with the "
        "table. Needs scipy.",
        example="jaximpact bench\n"
        "jaximpact bench --quick --laws hertz_rate --json\n"
        "jaximpact bench --plot bench.png",
    )
    parser.add_argument(
        "--laws",
        nargs="+",
        metavar="NAME",
        help=f"laws to run, some of {', '.join(LAWS)} (default: all)",
    )
    parser.add_argument(
        "--quick",
        action="store_true",
        help="a smoke test: batch of 100, three short timing rounds (noisy ratios)",
    )
    add_output_arguments(parser)
    parser.set_defaults(handler=_run_bench)


def _run_bench(args):
    laws = list(dict.fromkeys(args.laws or LAWS))  # run_bench refuses a law it lacks
    try:
        require_scipy()
    except ImportError:
        raise CLIError("jaximpact bench compares against scipy: pip install scipy") from None
    check_plot_path(args.plot)
    with metered(is_terminal(sys.stderr), steps(laws), "bench") as bar:
        data = run_bench(laws, quick=args.quick, on_step=lambda note: bar.update(1, note))
    if args.plot is not None:
        plot_bench(args.plot, data, TARGETS)
        data["plot"] = str(args.plot)
    emit(args, data, lambda: _text(data))


def _text(data, width=None) -> str:
    """The report of `run_bench`'s `data` (`_bench.bench_text`), fitted to `width` columns."""
    return bench_text(data, width)
