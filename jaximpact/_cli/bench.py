"""`jaximpact bench`: a short benchmark of jaximpact's default `impact` against scipy.

Runs `jaximpact._bench.run_bench` (the seed paper's conditions, scipy `solve_ivp` DOP853
with an event at the loosest rtol reaching an error in e of 1e-9, timed in alternation with
one jitted impact and a vmapped batch) and prints the ratio table with the machine it ran
on; `--json` for the numbers, `--plot` for a bar chart of the ratios against the targets.
"""

import math
import sys

from .._bench import LAWS, TARGETS, require_scipy, run_bench, steps
from .._format import format_number, format_table, terminal_width, wrap_text
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
    laws = list(dict.fromkeys(args.laws or LAWS))
    for name in laws:
        if name not in LAWS:
            raise CLIError(f"--laws {name!r}: not in the benchmark; use some of {', '.join(LAWS)}")
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


def _us(seconds) -> str:
    """Seconds as microseconds, 3 significant digits (integers from 100 up); `-` for None."""
    if seconds is None:
        return "-"
    value = seconds * 1e6
    return f"{value:.0f}" if value >= 100 else f"{value:.3g}"


def _error(value) -> str:
    if value is None or not math.isfinite(value):
        return "-"
    return "0" if value == 0 else f"{value:.1e}"


def _ratio(row, kind) -> str:
    ratio = row[f"ratio_{kind}"]
    if ratio is None:
        return "-"
    verdict = "met" if row[f"target_{kind}_met"] else "MISSED"
    return f"{ratio:.0f}x {verdict}" if ratio >= 100 else f"{ratio:.3g}x {verdict}"


def _text(data, width=None) -> str:
    """The report, fitted to `width` columns (default: the terminal's, 88 when stdout is
    not one): prose wrapped, the table's headers wrapped and, where it is still too wide,
    its columns in two tables that each repeat the law."""
    width = terminal_width() if width is None else width
    machine, cond = data["machine"], data["conditions"]
    batch = data["rows"][0]["batch_size"] if data["rows"] else 0
    rounds = data["rows"][0]["rounds"] if data["rows"] else 0
    cache = machine["compilation_cache"]

    def prose(*paragraphs) -> list[str]:  # each wrapped to the width
        return [
            line for p in paragraphs for line in (wrap_text(p, width, then="  ") if p else [""])
        ]

    out = prose(
        f"jaximpact bench{' --quick' if cond['quick'] else ''}: default impact() against scipy "
        f"solve_ivp DOP853 with an event; m = {format_number(cond['m'])} kg, "
        f"v0 = {format_number(cond['v0'])} m/s, separation at zero force, float64",
        f"machine: {machine['cpu_count']} CPUs ({machine['processor']}), jax {machine['jax']} "
        f"({machine['backend']} backend), scipy {machine['scipy']}, python {machine['python']}",
        f"load average (1, 5, 15 min): {machine['load_average']} at start, "
        f"{machine['load_average_end']} at end",
        f"compilation cache: {cache if cache else 'off'}",
        "",
    )
    header = [
        "law",
        "path",
        "err e",
        "err T",
        "jit us",
        "compile s",
        f"batch us ({batch})",
        "batch compile s",
        "scipy rtol",
        "scipy err e",
        "scipy us",
        f"single (>= {TARGETS['single']:.0f}x)",
        f"batch (>= {TARGETS['batch']:.0f}x)",
    ]
    rows = [
        [
            r["case"],
            r["path"],
            _error(r["err_e"]),
            _error(r["err_T"]),
            _us(r["single_s"]),
            f"{r['compile_s']:.2g}",
            _us(r["batch_s"]),
            f"{r['batch_compile_s']:.2g}",
            "-" if r["scipy_rtol"] is None else f"{r['scipy_rtol']:.1e}",
            _error(r["scipy_err_e"]),
            _us(r["scipy_s"]),
            _ratio(r, "single"),
            _ratio(r, "batch"),
        ]
        for r in data["rows"]
    ]
    out += format_table(header, rows, width=width)
    limit = data["targets"]["error_e"]
    loose = [r for r in data["rows"] if not (r["err_e"] is not None and r["err_e"] <= limit)]
    if loose:
        out += prose(
            f"note: the default impact's error in e is above the {limit:.0e} that scipy is "
            "held to for: " + ", ".join(f"{r['case']} ({_error(r['err_e'])})" for r in loose)
        )
    eu = data["euler"]
    out += prose(
        "",
        f"seed paper's explicit Euler (scheme as printed), dt = {format_number(eu['dt'])} s, "
        f"{eu['law']}: e = {eu['e']:.6f} against {eu['e_ref']:.6f} (contact until x = 0, "
        f"scipy DOP853 1e-13): err e {_error(eu['err_e'])}, err T {_error(eu['err_T'])}, "
        f"{_us(eu['single_s'])} us per impact (eager call)",
        "",
        "err: relative error against the reference (closed form where one exists, else scipy "
        "DOP853 at rtol 1e-13); us: microseconds per impact after compilation (batch: per "
        f"member of a jax.vmap over {batch} impact speeds in v0 x [0.8, 1.25]); compile s: "
        "first call (tracing, compilation or the cache's load); ratios: scipy time / "
        f"jaximpact time, median over {rounds} alternated rounds.",
    )
    if "plot" in data:
        out += prose(f"plot written to {data['plot']}")
    return "\n".join(out)
