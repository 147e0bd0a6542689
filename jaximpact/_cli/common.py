"""What the subcommands share: the one-line error (`CLIError`, `fail`), the parser factory
and argument groups, reading `--param NAME=VALUE` (a user's law `--law FILE.py:NAME` is
`_jobs.file_law`'s, a fit's file `_fit.fit_file`'s), `--json` output (`emit`) and JAX's
set-up (`configure_jax`). They import nothing heavy when they load: JAX loads after
`console_environment`. `--plot FILE` goes through `jaximpact._plotting`
(matplotlib's Agg backend, imported only then); anything long reports through a meter of
`jaximpact._progress` on stderr."""

import argparse
import json
import os
import re
import sys
import textwrap
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path

from .._cache import enable_cache
from .._format import SI_NUMBERS, UNIT_WORD, jsonable, unit_hint
from .._interrupt import stop_at_once

PROG = "jaximpact"
DEBUG_ENV = "JAXIMPACT_DEBUG"


class CLIError(Exception):
    """Bad input found by the command line: printed as one line, exit status 2."""


class Parser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line (`jaximpact: error: ...`); a number
    given with a unit (`--radius 5mm`, `--mass 10 g`) is told to drop it (`unit_hint`)."""

    def parse_known_args(self, args=None, namespace=None):
        self.argv = sys.argv[1:] if args is None else list(args)  # for `error`'s hints
        return super().parse_known_args(args, namespace)

    def error(self, message):
        bad = re.search(r"invalid float value: '(.*)'$", message)
        loose = re.match(r"unrecognized arguments: (.*)$", message)
        if bad and unit_hint(bad.group(1)):
            message += f": {unit_hint(bad.group(1))}"
        elif loose and all(UNIT_WORD.fullmatch(word) for word in loose.group(1).split()):
            message += f": {SI_NUMBERS}"
        elif loose and all(_is_number(word) for word in loose.group(1).split()):
            if _takes_data(self):
                message += (
                    ": an option takes one number; several impacts go in the rows of a CSV "
                    "file, --data FILE.csv"
                )
        fail(f"{message} (see '{self.prog} --help')", status=2)


def _takes_data(parser: argparse.ArgumentParser) -> bool:
    """Whether the command being parsed (`parser` or its subcommand named in the arguments
    it was given) has a `--data` option."""
    parsers = [parser]
    words = getattr(parser, "argv", [])
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            parsers += [action.choices[w] for w in words if w in action.choices][:1]
    return any("--data" in a.option_strings for p in parsers for a in p._actions)


def _is_number(word: str) -> bool:
    try:
        float(word)
    except ValueError:
        return False
    return True


def fail(message: str, status: int):
    """Print one line `jaximpact: error: message` on stderr and exit with `status`."""
    line = " ".join(str(message).split())  # one line, whatever the message held
    print(f"{PROG}: error: {line}", file=sys.stderr)
    raise SystemExit(status)


# --------------------------------------------------------------------------------------
# Shared helpers for subcommands
# --------------------------------------------------------------------------------------


def wrap_paragraphs(text: str, width: int = 88) -> str:
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
        description=wrap_paragraphs(description),
        epilog=f"example:\n{examples}",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


LAW_HELP = (
    "force law, one of those listed by 'jaximpact laws' (e.g. hertz_rate), or a user's "
    "law FILE.py:NAME, the function NAME(x, v, params) of a Python file (its parameters "
    "all from --param)"
)


PARAM_HELP = (
    "a law parameter in SI units, e.g. --param c=2e6 --param b1=800 (or --param c=2e6 b1=800)"
)


def add_law_arguments(parser, *, required: bool = True, law=LAW_HELP, param=PARAM_HELP):
    """`--law NAME` (or `FILE.py:NAME`) and `--param NAME=VALUE` (repeatable), with the
    helps `law` and `param`; read them with `law_from_args`."""
    parser.add_argument("--law", required=required, metavar="NAME", help=law)
    add_words_argument(parser, "--param", "NAME=VALUE", param)


def add_words_argument(parser, flag: str, metavar: str, help: str):
    """`flag WORD ...`, repeatable (`--param c=2e6 b1=800`, or `--param c=2e6 --param
    b1=800`): the list of the words, empty when not given."""
    parser.add_argument(flag, action="extend", nargs="+", default=[], metavar=metavar, help=help)


def add_free_argument(parser, help: str):
    """`--free NAME ...` (or `--free c,b1`): the parameters to fit (`free_names`)."""
    parser.add_argument("--free", action="extend", nargs="+", metavar="NAME", help=help)


class _TangentialNames(Sequence):
    """`jaximpact.TANGENTIAL_LAW_NAMES`, the library's table read when argparse first asks
    (to check `--tangential` or to print its help): importing it loads the oblique solver
    (diffrax), a second that every start of the command line would otherwise spend."""

    def __getitem__(self, index):
        from .._oblique.tangential import TANGENTIAL_LAW_NAMES

        return TANGENTIAL_LAW_NAMES[index]

    def __len__(self):
        return len(self[:])


TANGENTIAL_CHOICES = _TangentialNames()


def add_tangential_arguments(parser, *, required: bool, help: str, tparam_help: str):
    """`--tangential NAME` (one of `TANGENTIAL_CHOICES`) and `--tparam NAME=VALUE ...`,
    a tangential law and its parameters (SI units); `tangential_from_args` builds it."""
    parser.add_argument(
        "--tangential",
        required=required,
        choices=TANGENTIAL_CHOICES,
        metavar="NAME",
        help=f"{help} (one of %(choices)s)",
    )
    add_words_argument(parser, "--tparam", "NAME=VALUE", tparam_help)


def tangential_from_args(args):
    """The tangential law of `--tangential` and `--tparam`, or None without them (a
    `CLIError` for `--tparam` alone)."""
    if args.tangential is None:
        if args.tparam:
            raise CLIError("--tparam needs --tangential NAME")
        return None
    from .._oblique import tangential_law

    return tangential_law(args.tangential, **parse_params(args.tparam, "--tparam"))


MASS_HELP = (
    "mass, kg (> 0; for two bodies their effective mass m1 m2 / (m1 + m2)): required, "
    "every result depends on it"
)


def require_mass(args) -> float:
    """`--mass`, or a one-line `CLIError` where it was not given: a mass is never assumed
    (DESIGN.md, "What a user touches")."""
    if args.mass is None:
        raise CLIError(
            "--mass is required: the body's mass in kg (for two bodies their effective mass "
            "m1 m2 / (m1 + m2)); e, T and a fitted law all depend on it"
        )
    return args.mass


def add_contact_arguments(parser, *, gravity: float = 0.0):
    """`--separation` and `--gravity` (default `gravity`, m/s^2): how a contact ends, and
    the gravity during it."""
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
        default=gravity,
        metavar="M/S^2",
        help=f"gravity along the inward normal, m/s^2 (default {gravity:g}; 9.81 for a ball on "
        "a floor)",
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


def parse_params(items: Iterable[str], flag: str = "--param") -> dict[str, float]:
    """`["c=2e6", "b1=800"]` -> `{"c": 2e6, "b1": 800.0}`; a `CLIError` (naming `flag`) for
    anything else."""
    from .._checks import check_scale

    params = {}
    for item in items:
        name, sep, value = item.partition("=")
        name, value = name.strip(), value.strip()
        if not sep or not name or not value:
            raise CLIError(f"{flag} {item!r} must be NAME=VALUE, e.g. {flag} c=2e6")
        if not name.isidentifier():
            raise CLIError(f"{flag} {item!r}: {name!r} is not a parameter name")
        try:
            number = float(value)
        except ValueError:
            hint = unit_hint(value)
            raise CLIError(
                f"{flag} {item!r}: {value!r} is not a number" + (f": {hint}" if hint else "")
            ) from None
        if name in params:
            raise CLIError(f"{flag} {name} is given twice")
        check_scale(f"{flag} {name}", number)
        params[name] = number
    return params


def check_argument_scales(args):
    """Every number given as an option lies within [1e-150, 1e150] in size (or is 0, or
    is left to the command's own checks: NaN, inf, a sign): a one-line error otherwise,
    1e-300 kg as 1e300 kg (`_checks.check_scale`)."""
    from .._checks import check_scale

    for dest, value in vars(args).items():
        for number in value if isinstance(value, list) else [value]:
            if isinstance(number, float):
                check_scale(f"--{dest.replace('_', '-')}", number)


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
    """The law of `--law` and `--param` (the library checks the name and the values): a law
    of the table, or a user's law `FILE.py:NAME` (`file_law`)."""
    from .._jobs.file_law import make_law

    return make_law(args.law, parse_params(args.param))


def check_plot_path(path: Path | None, inputs=()):
    """Fail early (before any computation) on a `--plot` file that cannot be written, or
    that is one of the command's `inputs` (files it reads), however spelled."""
    if path is None:
        return
    from .._files import check_outputs

    check_outputs(inputs, {"--plot": path})
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


def emit(args, data: dict, text: str | Callable[[], str]):
    """Print `data` as one JSON object under `--json`, else `text` (or `text()`)."""
    if getattr(args, "json", False):
        print(json.dumps(jsonable(data), indent=2, allow_nan=False))
    else:
        print(text() if callable(text) else text)


def console_environment():
    """The `jaximpact` console script's process, set before anything imports JAX (its
    modules read these variables when they load); not for `main` called from Python."""
    # XLA's CPU compiler logs harmless "algebraic simplifier ... circular" notes at error
    # level for diffrax's loops; the level is read when jax loads
    os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
    # equinox's run-time checks inside the compiled fits (lineax's, in the implicit
    # derivative of diffrax's event times) are host callbacks, and JAX does not store a
    # program with host callbacks in its persistent cache; as NaN instead (which the fits
    # already report as a failed solve) the second `jaximpact calibrate` skips XLA's
    # compilation: 14 s -> 8 s (benchmarks/first_calls.md). Inputs are checked before.
    os.environ.setdefault("EQX_ON_ERROR", "nan")
    # Ctrl-C or SIGTERM while the command line starts (importing JAX takes a second):
    # nothing is written yet, so stop at once with one line; `main` installs the handlers
    # that stop a running command cleanly (`_interrupt`)
    stop_at_once()


def configure_jax():
    """The command line's JAX (the library itself changes none of it): float64, and the
    persistent compilation cache (`_cache`) for every program, however small."""
    # XLA's CPU compiler logs harmless "algebraic simplifier ... circular" notes at error
    # level for diffrax's loops; keep them off the user's terminal unless asked for (read
    # when jax loads)
    os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
    import jax

    jax.config.update("jax_enable_x64", True)
    enable_cache(min_compile_time_secs=0.0)


def heartbeat_meter(delay=None):
    """A bar redrawn every 0.2 s while a fit runs (a first fit compiles for tens of seconds
    without other sign of life): after 0.5 s on a terminal; elsewhere a line every 10 s,
    none for work under 3 s; none at all when `JAXIMPACT_PROGRESS` is off."""
    from .._progress import NoMeter, TextMeter, is_terminal, progress_enabled

    if not progress_enabled():
        return NoMeter()
    if delay is None:
        delay = 0.5 if is_terminal(sys.stderr) else 3.0
    return TextMeter(interval=10.0, delay=delay, heartbeat=0.2)


def read_fit(path: str, law: str | None = None):
    """`(data, record, fit)` of the fit's JSON file `path` ('-': stdin) that `jaximpact
    calibrate --json` writes (`_fit.fit_file.read_fit_file`), a user's law FILE.py:NAME
    read from its file."""
    from .._fit.fit_file import read_fit_file
    from .._jobs.file_law import file_law, is_file_law

    def user_law(name):  # a user's law FILE.py:NAME, from its file
        return (lambda params: file_law(name, params)) if is_file_law(name) else None

    return read_fit_file(path, law, user_law=user_law)
