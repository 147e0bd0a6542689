"""`jaximpact laws`: the force laws, their equations, parameters and units."""

from .._choices import plain_name, unknown_name
from .._format import terminal_width
from .common import (
    CLIError,
    add_output_arguments,
    command_parser,
    emit,
)

# --------------------------------------------------------------------------------------
# jaximpact laws
# --------------------------------------------------------------------------------------


def add_laws(subparsers):
    parser = command_parser(
        subparsers,
        "laws",
        help="list the force laws, their equations, parameters and units",
        description="List every force law: its name (for --law), its equation in the seed "
        "paper (Polukoshko et al. 2007), its formula F(x, v) (N, positive pushing the body "
        "out; x penetration in m, v = dx/dt in m/s), its parameters with their SI units, "
        "and its reference; then the tangential laws of oblique impacts (for --tangential, "
        "with --tparam).",
        example="jaximpact laws\njaximpact laws hertz mindlin   # the laws whose names begin so\n"
        "jaximpact laws --json",
    )
    parser.add_argument(
        "names",
        nargs="*",
        metavar="NAME",
        help="only these laws, normal or tangential; a name's beginning shows every law it "
        "begins (hertz: hertz_viscous, hertz_modified, hertz_rate)",
    )
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_laws)


def _law_rows():
    from .._laws.listing import law_rows

    return law_rows()


def _laws_text(rows, width=None, tangential=()) -> str:
    """The law table and the tangential laws' (`_laws.listing`, `_oblique.report`), fitted
    to `width` columns (default: the terminal's, 88 when stdout is not one)."""
    from .._laws.listing import laws_text
    from .._oblique.report import tangential_text

    width = terminal_width() if width is None else width
    normal = laws_text(rows, width) if rows else []
    more = tangential_text(tangential, width) if tangential else []
    return "\n".join([*normal, *([""] if normal and more else []), *more])


def _chosen(rows, tangential, names):
    """The rows of both tables whose names begin with one of `names` (a name as people
    write it: any case, `-` for `_`), or a one-line `CLIError` naming the nearest laws."""
    from .._jobs.file_law import is_file_law

    everything = [r["name"] for r in (*rows, *tangential)]
    wanted = set()
    for name in names:
        if is_file_law(name):
            raise CLIError(
                f"{name} is a user's law: 'jaximpact laws' lists the law table, and a user's "
                "law has no row in it (its parameters are those its function reads from "
                "params; --law FILE.py:NAME --param ... uses it)"
            )
        found = {n for n in everything if n.startswith(plain_name(name))}
        if not found:
            raise CLIError(unknown_name("law", name, everything))
        wanted |= found
    return [r for r in rows if r["name"] in wanted], [r for r in tangential if r["name"] in wanted]


def _run_laws(args):
    from .._oblique.report import tangential_rows

    rows, tangential = _law_rows(), tangential_rows()
    if args.names:
        rows, tangential = _chosen(rows, tangential, args.names)
    emit(
        args,
        {"laws": rows, "tangential_laws": tangential},
        lambda: _laws_text(rows, tangential=tangential),
    )
