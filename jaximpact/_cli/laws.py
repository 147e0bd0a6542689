"""`jaximpact laws`: the force laws, their equations, parameters and units."""

from .._choices import plain_name, unknown_name
from .._format import (
    KEEP_TOGETHER,
    concrete_units,
    format_number,
    format_table,
    terminal_width,
    wrap_text,
)
from .common import (
    CLIError,
    add_output_arguments,
    command_parser,
    emit,
    is_file_law,
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


def law_title(name: str) -> str:
    """`hertz_rate (eq. 14: F = c x^1.5 + b1 x^0.5 v)`: the law `name` with its equation and
    formula (a user's law, FILE.py:NAME, by its name alone)."""
    from .._laws import LAWS

    spec = LAWS.get(name)
    if spec is None:
        return name
    eq = f"eq. {spec.equation}: " if spec.equation != "-" else ""
    return f"{name} ({eq}F = {spec.formula})"


def law_units(name: str, params: dict) -> dict[str, str]:
    """The units of the parameters of the law `name` (`-`: a pure number), its exponents
    filled in from `params`; none for a user's law (it has no row of the table)."""
    from .._laws import LAWS

    return concrete_units(LAWS[name], params) if name in LAWS else {}


def _law_rows():
    from .._laws import LAWS

    rows = []
    for spec in LAWS.values():
        units = concrete_units(spec)
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


def _tangential_rows():
    from .._oblique.tangential import TANGENTIAL_LAWS

    return [
        dict(
            name=spec.name,
            formula=spec.formula,
            parameters=[
                dict(name=p, unit=spec.units.get(p, "-"), default=spec.defaults.get(p))
                for p in spec.parameters
            ],
            also=list(spec.inputs),
            engines=spec.engines,
            reference=spec.reference,
        )
        for spec in TANGENTIAL_LAWS.values()
    ]


def _params_text(row) -> str:
    """Each parameter with its unit (and default) on one line, for `format_table`."""
    return ", ".join(
        (
            f"{p['name']} [{p['unit']}]"
            + ("" if p["default"] is None else f" = {format_number(p['default'])}")
        ).replace(" ", KEEP_TOGETHER)
        for p in row["parameters"]
    )


def _tangential_text(rows, width) -> list[str]:
    """The tangential laws' table (`--tangential`), the engines and reference under each."""
    import textwrap

    table = [
        (
            r["name"],
            r["formula"],
            _params_text(r) + (f" (or {', '.join(r['also'])})" if r["also"] else ""),
        )
        for r in rows
    ]
    notes = [f"engines: {r['engines']}; ref.: {r['reference']}" for r in rows]
    intro = (
        "Tangential laws (--tangential NAME --tparam ...): F_t in N on the sphere at its "
        "contact point, u its slip (m/s), delta the spring's stretch (m), x the overlap (m), "
        "m the sphere's mass (kg), R its radius (m)."
    )
    lines = format_table(
        ("name", "F_t [N]", "parameters"),
        table,
        width=width,
        wrap=(1, 2),
        notes=notes,
        note_column=1,
    )
    return [*textwrap.wrap(intro, width), "", *lines]


def _laws_text(rows, width=None, tangential=()) -> str:
    """The table of laws, fitted to `width` columns (default: the terminal's, 88 when
    stdout is not one): formulas and parameters wrap at spaces, the reference under each."""
    import textwrap

    width = terminal_width() if width is None else width

    header = ("name", "eq.", "F(x, v) [N]", "parameters")
    table = [(r["name"], r["equation"], r["formula"], _params_text(r)) for r in rows]
    lines = format_table(
        header,
        table,
        width=width,
        wrap=(2, 3),
        notes=[f"ref.: {r['reference']}" for r in rows],
        note_column=2,
    )
    if max(map(len, lines)) > width:  # too narrow for a table: a block per law
        lines = []
        for (name, equation, formula, parameters), row in zip(table, rows, strict=True):
            lines.append(name + ("" if equation == "-" else f" (eq. {equation})"))
            for text in (f"F = {formula}", parameters, f"ref.: {row['reference']}"):
                shown = wrap_text(text, width, first="    ", then="      ")
                lines += [line.replace(KEEP_TOGETHER, " ") for line in shown]
    intro = (
        "Force laws: F(x, v) in N, positive pushing the body out; x = penetration (m), "
        "v = dx/dt (m/s). Equation numbers: Polukoshko, Viba, Kononova & Sokolova, Proc. "
        "Estonian Acad. Sci. Eng. 13 (2007)."
    )
    more = _tangential_text(tangential, width) if tangential else []
    normal = [*textwrap.wrap(intro, width), "", *lines] if rows else []
    return "\n".join([*normal, *([""] if normal and more else []), *more])


def _chosen(rows, tangential, names):
    """The rows of both tables whose names begin with one of `names` (a name as people
    write it: any case, `-` for `_`), or a one-line `CLIError` naming the nearest laws."""
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
    rows, tangential = _law_rows(), _tangential_rows()
    if args.names:
        rows, tangential = _chosen(rows, tangential, args.names)
    emit(
        args,
        {"laws": rows, "tangential_laws": tangential},
        lambda: _laws_text(rows, tangential=tangential),
    )
