"""The `jaximpact` command line.

Each subcommand is one entry of `COMMANDS`: its name and a function `add(subparsers)` that
builds its parser with `command_parser(...)` and sets its handler with
`parser.set_defaults(handler=run)`; `run(args)` prints its result and returns an exit status
(or None for 0). An entry may name its function as `"module:function"`, imported only when the
parser is built, so a subcommand can live in its own module. To add one:

    # jaximpact/_calibrate_cli.py
    from ._cli import CLIError, add_impact_arguments, add_law_arguments, add_output_arguments
    from ._cli import command_parser, emit, law_from_args

    def add_calibrate(subparsers):
        parser = command_parser(subparsers, "calibrate", help="...", description="...",
                                example="jaximpact calibrate --law hertz_rate ...")
        add_law_arguments(parser)
        add_output_arguments(parser)
        parser.set_defaults(handler=_run_calibrate)

and append `("calibrate", "jaximpact._calibrate_cli:add_calibrate")` to `COMMANDS`.

Shared conventions, kept by the helpers below: bad input is a `ValueError` (the library's)
or a `CLIError` (the command line's), reported as one line `jaximpact: error: ...` on stderr
with exit status 2, never a traceback; `--json` prints one JSON object on stdout
(`emit`); `--plot FILE` writes a figure through matplotlib's Agg backend, imported only then
(`save_figure`); anything long draws a progress bar on stderr
(`jaximpact._progress.Progress`, enabled when `sys.stderr.isatty()`). JAX runs in
float64 with a persistent compilation cache (`configure_jax`), so a second run of the same
command skips XLA's compile of the solve (not of a solve with `ts=`: diffrax checks `ts`
with a host callback, and JAX does not cache such programs).
"""

import argparse
import importlib
import json
import math
import os
import sys
import textwrap
from collections.abc import Callable, Iterable
from pathlib import Path

from ._cache import enable_persistent_cache

PROG = "jaximpact"
_DEBUG_ENV = "JAXIMPACT_DEBUG"


class CLIError(Exception):
    """Bad input found by the command line: printed as one line, exit status 2."""


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line (`jaximpact: error: ...`)."""

    def error(self, message):
        hint = f" (see '{self.prog} --help')"
        _fail(f"{message}{hint}", status=2)


def _fail(message: str, status: int):
    """Print one line `jaximpact: error: message` on stderr and exit with `status`."""
    line = " ".join(str(message).split())  # one line, whatever the message held
    print(f"{PROG}: error: {line}", file=sys.stderr)
    raise SystemExit(status)


# --------------------------------------------------------------------------------------
# Shared helpers for subcommands
# --------------------------------------------------------------------------------------


def _wrap(text: str, width: int = 88) -> str:
    """Fill each paragraph of `text` (the raw formatter keeps the epilog's layout as it is,
    and would leave a description on one long line)."""
    paragraphs = [" ".join(p.split()) for p in text.split("\n\n")]
    return "\n\n".join(textwrap.fill(p, width) for p in paragraphs)


def command_parser(
    subparsers, name: str, *, help: str, description: str, example: str
) -> argparse.ArgumentParser:
    """Add the subcommand `name`, with its description and a runnable `example` (one or
    more command lines) shown at the end of its `--help`."""
    examples = "\n".join(f"  {line}" for line in example.strip().splitlines())
    return subparsers.add_parser(
        name,
        help=help,
        description=_wrap(description),
        epilog=f"example:\n{examples}",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def add_law_arguments(parser, *, required: bool = True):
    """`--law NAME` and `--param NAME=VALUE` (repeatable); read them with `law_from_args`."""
    parser.add_argument(
        "--law",
        required=required,
        metavar="NAME",
        help="force law, one of those listed by 'jaximpact laws' (e.g. hertz_rate)",
    )
    parser.add_argument(
        "--param",
        action="extend",
        nargs="+",
        default=[],
        metavar="NAME=VALUE",
        help="a law parameter in SI units, e.g. --param c=2e6 --param b1=800 "
        "(or --param c=2e6 b1=800)",
    )


def add_impact_arguments(parser):
    """`--mass`, `--v0`, `--separation` and `--gravity`, the conditions of one impact."""
    parser.add_argument(
        "--mass", type=float, default=1.0, metavar="KG", help="mass, kg (default 1)"
    )
    parser.add_argument(
        "--v0", type=float, required=True, metavar="M/S", help="impact speed, m/s (> 0)"
    )
    parser.add_argument(
        "--separation",
        choices=("force", "penetration"),
        default="force",
        help="end of contact: when the force returns to zero (force, the default) or when "
        "the penetration does (penetration)",
    )
    parser.add_argument(
        "--gravity",
        type=float,
        default=0.0,
        metavar="M/S^2",
        help="gravity along the inward normal, m/s^2 (default 0; 9.81 for a ball on a floor)",
    )


def add_output_arguments(parser, *, plot: bool = True):
    """`--json` (one JSON object on stdout) and, if `plot`, `--plot FILE`."""
    parser.add_argument(
        "--json", action="store_true", help="print one JSON object (SI units) instead of text"
    )
    if plot:
        parser.add_argument(
            "--plot",
            metavar="FILE",
            type=Path,
            help="also write a figure to FILE (.png, .pdf, .svg ...)",
        )


def parse_params(items: Iterable[str]) -> dict[str, float]:
    """`["c=2e6", "b1=800"]` -> `{"c": 2e6, "b1": 800.0}`; a `CLIError` for anything else."""
    params = {}
    for item in items:
        name, sep, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise CLIError(f"--param {item!r} must be NAME=VALUE, e.g. --param c=2e6")
        if not name.isidentifier():
            raise CLIError(f"--param {item!r}: {name!r} is not a parameter name")
        try:
            number = float(value)
        except ValueError:
            raise CLIError(f"--param {item!r}: {value!r} is not a number") from None
        if name in params:
            raise CLIError(f"--param {name} is given twice")
        params[name] = number
    return params


def free_names(items) -> tuple[str, ...] | None:
    """`--free c,b1` or `--free c b1` -> `("c", "b1")`; None when not given."""
    if not items:
        return None
    names = [name.strip() for item in items for name in item.split(",") if name.strip()]
    if not names:
        raise CLIError("--free names no parameter, e.g. --free c,b1")
    if len(set(names)) != len(names):
        raise CLIError("--free names a parameter twice")
    return tuple(names)


def law_from_args(args):
    """The law of `--law` and `--param` (the library checks the name and the values)."""
    from ._laws import law

    return law(args.law, **parse_params(args.param))


def check_plot_path(path: Path | None):
    """Fail early (before any computation) on a `--plot` file that cannot be written."""
    if path is None:
        return
    if not path.suffix:
        raise CLIError(f"--plot {path}: give the file an extension such as .png")
    if path.parent != Path("") and not path.parent.is_dir():
        raise CLIError(f"--plot {path}: directory {str(path.parent)!r} does not exist")
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    formats = FigureCanvasAgg.get_supported_filetypes()
    if path.suffix[1:].lower() not in formats:
        raise CLIError(
            f"--plot {path}: unknown figure format {path.suffix!r}; "
            f"use one of {', '.join('.' + f for f in sorted(formats))}"
        )


def new_figure(**kwargs):
    """A matplotlib Figure drawn by the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    return Figure(**kwargs)


def save_figure(fig, path: Path):
    """Write `fig` to `path` (format from the extension); a `CLIError` if that fails."""
    try:
        fig.savefig(path, dpi=150, bbox_inches="tight")
    except OSError as error:
        raise CLIError(f"cannot write {path}: {error.strerror or error}") from None


def jsonable(value):
    """Arrays and numpy scalars as plain floats, ints and lists; NaN and inf as null."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if value is None or isinstance(value, (str, bool)):
        return value
    if hasattr(value, "tolist"):  # jax and numpy arrays and scalars
        return jsonable(value.tolist())
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    return str(value)


def emit(args, data: dict, text: str | Callable[[], str]):
    """Print `data` as one JSON object under `--json`, else `text` (or `text()`)."""
    if getattr(args, "json", False):
        print(json.dumps(jsonable(data), indent=2, allow_nan=False))
    else:
        print(text() if callable(text) else text)


_MULTIPLE_UNITS = {"N", "Pa", "W"}
_PREFIXES = [(1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n")]


def format_number(value, digits: int = 6) -> str:
    """`2e6` -> `"2e6"`, `800.0` -> `"800"`, `1.5e-05` -> `"1.5e-5"` (compact, for humans)."""
    text = f"{float(value):.{digits}g}"
    mantissa, sep, exponent = text.partition("e")
    return mantissa + (f"e{int(exponent)}" if sep else "")


def format_quantity(value, unit: str, digits: int = 4) -> str:
    """`0.007845, "s"` -> `"7.845 ms"`: an SI prefix that puts the number in [1, 1000)
    (multiples such as kN only for forces: a long time stays `1250 s`)."""
    value = float(value)
    if not math.isfinite(value) or value == 0.0:
        return f"{value:g} {unit}"
    prefixes = [(s, p) for s, p in _PREFIXES if s <= 1.0 or unit in _MULTIPLE_UNITS]
    threshold = 1 - 0.5 * 10.0**-digits  # 0.99996 s rounds to 1 s, not 1000 ms
    scale, prefix = next(((s, p) for s, p in prefixes if abs(value) >= s * threshold), prefixes[-1])
    return f"{value / scale:.{digits}g} {prefix}{unit}"


def configure_jax():
    """float64, and the persistent compilation cache (`_cache`) for every program, however
    small."""
    # XLA's CPU compiler logs harmless "algebraic simplifier ... circular" notes at error
    # level for diffrax's loops; keep them off the user's terminal unless asked for
    os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
    import jax

    jax.config.update("jax_enable_x64", True)
    enable_persistent_cache(min_compile_time_secs=0.0)


# --------------------------------------------------------------------------------------
# jaximpact laws
# --------------------------------------------------------------------------------------


def _add_laws(subparsers):
    parser = command_parser(
        subparsers,
        "laws",
        help="list the force laws, their equations, parameters and units",
        description="List every force law: its name (for --law), its equation in the seed "
        "paper (Polukoshko et al. 2007), its formula F(x, v) (N, positive pushing the body "
        "out; x penetration in m, v = dx/dt in m/s), its parameters with their SI units, "
        "and its reference.",
        example="jaximpact laws\njaximpact laws --json",
    )
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_laws)


def _concrete_units(spec, params: dict | None = None) -> dict[str, str]:
    """The parameter units of one law, with the family exponents n and p filled in
    (`N/m^n` -> `N/m^1.5` for Hertz); an exponent that is itself a parameter is filled in
    only from its value in `params`."""
    units = {name: spec.units.get(name, "-") for name in spec.parameters}
    if spec.coefficients is None:
        return units
    if "n" in spec.parameters:
        if params is None or "n" not in params:
            return units
        n, p = float(params["n"]), None
    else:
        _, n, _, p, _, _ = spec.coefficients(dict.fromkeys(spec.parameters, 1.0), 1.0)

    def power(unit, exponent):
        exponent = float(exponent)
        return unit + ("" if exponent == 1 else f"^{exponent:g}")

    for name, unit in units.items():
        if unit == "N/m^n":
            units[name] = power("N/m", n)
        elif unit == "N s/m^(p+1)" and p is not None:
            units[name] = power("N s/m", float(p) + 1)
    return units


def _law_rows():
    from ._laws import LAWS

    rows = []
    for spec in LAWS.values():
        units = _concrete_units(spec)
        rows.append(
            dict(
                name=spec.name,
                equation=spec.equation,
                formula=spec.formula,
                parameters=[
                    dict(name=p, unit=units[p], default=spec.defaults.get(p))
                    for p in spec.parameters
                ],
                reference=spec.reference,
            )
        )
    return rows


def _laws_text(rows) -> str:
    def params(row):
        return ", ".join(
            f"{p['name']} [{p['unit']}]"
            + ("" if p["default"] is None else f" = {format_number(p['default'])}")
            for p in row["parameters"]
        )

    header = ("name", "eq.", "F(x, v) [N]", "parameters")
    table = [header] + [(r["name"], r["equation"], r["formula"], params(r)) for r in rows]
    widths = [max(len(line[i]) for line in table) for i in range(4)]
    indent = " " * (widths[0] + widths[1] + 4)

    def line(cells):
        return (
            "  ".join(c.ljust(w) for c, w in zip(cells[:3], widths, strict=False)) + "  " + cells[3]
        )

    out = [
        "Force laws: F(x, v) in N, positive pushing the body out; x = penetration (m), "
        "v = dx/dt (m/s).",
        "Equation numbers: Polukoshko, Viba, Kononova & Sokolova, Proc. Estonian Acad. Sci. "
        "Eng. 13 (2007).",
        "",
        line(header).rstrip(),
        "  ".join("-" * w for w in widths),
    ]
    for cells, row in zip(table[1:], rows, strict=True):
        out.append(line(cells).rstrip())
        out.append(f"{indent}ref.: {row['reference']}")
    return "\n".join(out)


def _run_laws(args):
    rows = _law_rows()
    emit(args, {"laws": rows}, lambda: _laws_text(rows))


# --------------------------------------------------------------------------------------
# jaximpact simulate
# --------------------------------------------------------------------------------------

# field of ImpactResult -> SI unit, in the order printed
_RESULT_UNITS = {
    "e": "",
    "T": "s",
    "x_max": "m",
    "F_max": "N",
    "t_max": "s",
    "dissipated": "J",
    "v_out": "m/s",
}
_STATUS_NOTES = {
    "stuck": "a dry force held the body at rest inside the surface (e = 0); T is when it stopped",
    "captured": "the body never left the surface (e = 0); T is when the solve gave up",
    "out_of_steps": "the solver ran out of steps before the contact ended; "
    "the numbers are not to be trusted",
}


def _add_simulate(subparsers):
    parser = command_parser(
        subparsers,
        "simulate",
        help="integrate one impact and print e, T, x_max, F_max, ...",
        description="Integrate one impact of a body of mass --mass (kg) hitting the surface "
        "at --v0 (m/s) under the force law --law with parameters --param (SI units, see "
        "'jaximpact laws'), and print the coefficient of restitution e, the contact "
        "duration T, the maximum penetration x_max and when it is reached (t_max), the "
        "largest force F_max, the energy dissipated and how the contact ended.",
        example="jaximpact simulate --law hertz_rate --param c=2e6 --param b1=800 --v0 2.5\n"
        "jaximpact simulate --law kelvin_voigt --param c=2e6 b=400 --mass 1 --v0 2.5 "
        "--separation penetration --json\n"
        "jaximpact simulate --law bingham --param c=2e6 b=200 P=400 --v0 2.5 --plot bingham.png",
    )
    add_law_arguments(parser)
    add_impact_arguments(parser)
    add_output_arguments(parser)
    parser.set_defaults(handler=_run_simulate)


def _run_simulate(args):
    check_plot_path(args.plot)
    import numpy as np

    from ._impact import impact

    law = law_from_args(args)
    conditions = dict(m=args.mass, v0=args.v0, separation=args.separation, g=args.gravity)
    result = impact(law, **conditions)
    status = result.status_name
    data = {
        "law": law.name,
        "params": {k: float(v) for k, v in law.parameters.items()},
        "m": args.mass,
        "v0": args.v0,
        "separation": args.separation,
        "g": args.gravity,
    }
    data.update({k: getattr(result, k) for k in _RESULT_UNITS})
    data.update(status=status, path=result.path, num_steps=result.num_steps)
    data["units"] = {k: u or "-" for k, u in _RESULT_UNITS.items()}
    if args.plot is not None:
        from ._plotting import plot_impact

        ts = np.linspace(0.0, 1.05 * float(result.T), 600)
        history = impact(law, **conditions, ts=ts)
        fig = new_figure(figsize=(13.5, 4.2), layout="constrained")
        plot_impact(history, law, fig=fig)
        save_figure(fig, args.plot)
        data["plot"] = str(args.plot)
    emit(args, data, lambda: _simulate_text(law, data))
    return 0


def _simulate_text(law, data) -> str:
    from ._laws import LAWS

    spec = LAWS.get(law.name)
    units = _concrete_units(spec, data["params"]) if spec is not None else {}
    params = ", ".join(
        f"{k} = {format_number(v)}" + (f" {units[k]}" if units.get(k, "-") != "-" else "")
        for k, v in data["params"].items()
    )
    eq = f"eq. {spec.equation}: " if spec is not None and spec.equation != "-" else ""
    formula = f" ({eq}F = {spec.formula})" if spec is not None else ""
    lines = [
        f"law        {law.name}{formula}",
        f"params     {params}",
        f"impact     m = {format_number(data['m'])} kg, v0 = {format_number(data['v0'])} m/s, "
        f"g = {format_number(data['g'])} m/s^2, separation by {data['separation']}",
        "",
    ]
    for key, unit in _RESULT_UNITS.items():
        value = data[key]
        if value is None:
            continue
        shown = f"{float(value):.4f}" if not unit else format_quantity(value, unit)
        lines.append(f"{key:<10} = {shown}")
    note = _STATUS_NOTES.get(data["status"])
    lines.append(f"{'status':<10} = {data['status']}" + (f"  ({note})" if note else ""))
    lines.append(f"{'path':<10} = {data['path']} ({int(data['num_steps'])} solver steps)")
    if "plot" in data:
        lines.append(f"plot written to {data['plot']}")
    return "\n".join(lines)


# --------------------------------------------------------------------------------------
# The parser and main
# --------------------------------------------------------------------------------------

COMMANDS: list[tuple[str, Callable | str]] = [
    ("laws", _add_laws),
    ("simulate", _add_simulate),
    ("fit", "jaximpact._cli_fit:add_fit"),
    ("calibrate", "jaximpact._cli_calibrate:add_calibrate"),
    ("paper", "jaximpact._cli_paper:add_paper"),
    ("bench", "jaximpact._cli_bench:add_bench"),
    ("export", "jaximpact._cli_export:add_export"),
    ("engine-e", "jaximpact._cli_export:add_engine_e"),
]


def _resolve(add: Callable | str) -> Callable:
    if callable(add):
        return add
    module, _, name = add.partition(":")
    return getattr(importlib.import_module(module), name)


def build_parser() -> argparse.ArgumentParser:
    """The `jaximpact` parser, with one subcommand per entry of `COMMANDS`."""
    from . import __version__

    parser = _Parser(
        prog=PROG,
        description=_wrap(
            "Impact force laws integrated with JAX and diffrax. All quantities in SI units."
        ),
        epilog="example:\n  jaximpact laws\n"
        "  jaximpact simulate --law hertz_rate --param c=2e6 --param b1=800 --v0 2.5\n\n"
        "'jaximpact COMMAND --help' describes each command.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for _, add in COMMANDS:
        _resolve(add)(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line on `argv` (default `sys.argv[1:]`); return 0 on success.

    Bad input exits with status 2 after one line on stderr; an unexpected failure exits with
    status 1 and one line (set `JAXIMPACT_DEBUG=1` for the traceback).
    """
    parser = build_parser()
    args = parser.parse_args(argv)
    configure_jax()
    try:
        status = args.handler(args)
    except (CLIError, ValueError) as error:
        _fail(str(error), status=2)
    except KeyboardInterrupt:
        _fail("interrupted", status=130)
    except BrokenPipeError:  # e.g. `jaximpact laws | head`: stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        raise SystemExit(1) from None
    except Exception as error:
        if os.environ.get(_DEBUG_ENV):
            raise
        _fail(
            f"internal error, {type(error).__name__}: {error} "
            f"(run with {_DEBUG_ENV}=1 for the traceback)",
            status=1,
        )
    return 0 if status is None else int(status)


if __name__ == "__main__":
    raise SystemExit(main())
