"""The `jaximpact` command line: one module per subcommand, each with a function
`add(subparsers)` that builds its parser with `common.command_parser` and sets its handler.

Bad input is a `ValueError` (the library's), a `CLIError` (the command line's) or an `OSError`
(a file that cannot be read or written), reported as one line `jaximpact: error: ...` on stderr
with exit status 2, never a traceback. To add a command, write `jaximpact/_cli/NAME.py` with
its `add_NAME` and append it to `COMMANDS`. The command modules import only argparse and the
helpers at import time, so `jaximpact --help` stays quick.

Started as the command line (the console script, `python -m jaximpact._cli`), this package
installs its handling of Ctrl-C and SIGTERM before it imports anything heavy (numpy, then
JAX, load in the first seconds): a signal at any moment of the start ends the process with
the one line `interrupted by SIGINT` and status 130 (`_interrupt.stop_at_once`), never a
traceback from inside an import. A closed stdout (`jaximpact ... >&-`) is refused before
any work: what the command prints would be lost.
"""

# the handlers are installed between imports, before those that load numpy and JAX
# ruff: noqa: E402
import os
import sys

from .._interrupt import (
    Interrupted,
    check_interrupt,
    handle_interrupts,
    mark_reported,
    received,
    stop_at_once,
)


def _started_as_command() -> bool:
    """Whether this process is the command line: the `jaximpact` console script, or
    `python -m jaximpact._cli` (whose `sys.argv[0]` is `-m` while this package loads)."""
    first = sys.argv[0] if sys.argv else ""
    return os.path.basename(first).removesuffix(".exe") == "jaximpact" or first == "-m"


if _started_as_command():  # before numpy and JAX load (the command modules bring them)
    stop_at_once()

import argparse
import warnings

from .batch import add_batch
from .bench import add_bench
from .calibrate import add_calibrate
from .common import (
    DEBUG_ENV,
    PROG,
    CLIError,
    Parser,
    check_argument_scales,
    configure_jax,
    console_environment,
    fail,
    wrap_paragraphs,
)
from .export import add_engine_e, add_export
from .fit import add_fit
from .laws import add_laws
from .oblique import add_fit_oblique
from .paper import add_paper
from .simulate import add_simulate

COMMANDS = [
    ("laws", add_laws),
    ("simulate", add_simulate),
    ("fit", add_fit),
    ("fit-oblique", add_fit_oblique),
    ("calibrate", add_calibrate),
    ("paper", add_paper),
    ("bench", add_bench),
    ("batch", add_batch),
    ("export", add_export),
    ("engine-e", add_engine_e),
]


def build_parser() -> argparse.ArgumentParser:
    """The `jaximpact` parser, with one subcommand per entry of `COMMANDS`."""
    from .._version import __version__

    parser = Parser(
        prog=PROG,
        description=wrap_paragraphs(
            "Impact force laws integrated with JAX and diffrax. All quantities in SI units."
        ),
        epilog="example:\n  jaximpact laws\n"
        "  jaximpact simulate --law hertz_rate --param c=2e6 --param b1=800 --v0 2.5 --mass 1\n\n"
        "'jaximpact COMMAND --help' describes each command.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for _, add in COMMANDS:
        add(subparsers)
    return parser


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """A library warning on the command line: one line, `jaximpact: warning: ...`."""
    text = " ".join(str(message).split())
    print(f"{PROG}: warning: {text}", file=sys.stderr if file is None else file)


def main(argv: list[str] | None = None) -> int:
    """Run the command line on `argv` (default `sys.argv[1:]`); return 0 on success.

    Bad input exits with status 2 after one line on stderr; an unexpected failure exits with
    status 1 and one line (set `JAXIMPACT_DEBUG=1` for the traceback); Ctrl-C (SIGINT) or
    SIGTERM with status 130 or 143 and one line saying what was kept (`_interrupt`).
    """
    if os.path.basename(sys.argv[0]) == PROG:  # the console script: before JAX loads
        console_environment()
    if sys.stdout is None:  # started with stdout closed (`>&-`): its output would be lost
        fail("cannot write the output: stdout is closed", status=2)
    parser = build_parser()
    args = parser.parse_args(argv)
    configure_jax()
    try:
        with handle_interrupts():
            return _run(args)
    except Interrupted as error:  # while the handling began or ended, outside `_run`
        _stop(error)


def _run(args) -> int:
    """The command's handler: its errors as one line, and an interrupt (SIGINT, SIGTERM) as
    one line and exit status 128 + the signal, however it surfaced (`_interrupt`)."""
    try:
        try:
            check_argument_scales(args)  # 1e-300 kg refused as 1e300 kg is, before any work
            with warnings.catch_warnings():
                warnings.showwarning = _show_warning
                status = args.handler(args)
            check_interrupt()  # a signal whose KeyboardInterrupt something swallowed
        except BaseException as error:
            signum = received()
            if signum is not None and not isinstance(error, (Interrupted, SystemExit)):
                # the interrupt came out as another error (raised inside a JAX callback)
                raise Interrupted(signum) from None
            raise
    except Interrupted as error:
        _stop(error)
    except BrokenPipeError:  # e.g. `jaximpact laws | head`: stop quietly
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        raise SystemExit(1) from None
    except (CLIError, ValueError, OSError) as error:
        fail(str(error), status=2)
    except ArithmeticError as error:  # a number of the input beyond float64 (1e300, 1e-300)
        fail(
            f"a computation left float64's range ({type(error).__name__}: {error}); check "
            "the units and sizes of the numbers given",
            status=2,
        )
    except KeyboardInterrupt:  # outside `handle_interrupts` (not the main thread)
        fail("interrupted", status=130)
    except Exception as error:
        if os.environ.get(DEBUG_ENV):
            raise
        fail(
            f"internal error, {type(error).__name__}: {error} "
            f"(run with {DEBUG_ENV}=1 for the traceback)",
            status=1,
        )
    return 0 if status is None else int(status)


def _stop(error: Interrupted):
    """The line `jaximpact: error: interrupted by SIGINT; ...`, then out at once with status
    128 + the signal: a signal that lands while XLA compiles leaves its threads running, and
    Python's own teardown beside them crashed (SIGSEGV, measured: `calibrate --law all`
    interrupted 4 s in); every file is already complete or not there under its final name
    (`_files.atomic_output`)."""
    mark_reported()
    try:
        fail(str(error), status=error.status)
    except SystemExit:
        for stream in (sys.stdout, sys.stderr):
            if stream is not None:
                stream.flush()
        os._exit(error.status)
