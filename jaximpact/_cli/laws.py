"""`jaximpact laws`: the force laws, their equations, parameters and units."""

from .._format import concrete_units as concrete_units, format_number
from .common import add_output_arguments, command_parser, emit

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
        "and its reference.",
        example="jaximpact laws\njaximpact laws --json",
    )
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_laws)


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
