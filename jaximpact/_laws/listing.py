"""The law table as `jaximpact laws` lists it: each law's row as plain data (`law_rows`)
and as a table fitted to a width (`laws_text`); `params_text` writes a row's parameters
with their units and defaults (the tangential laws' listing, `_oblique.report`, too);
`law_title` and `law_units` name one law and its units for a report's head."""

import textwrap

from .._format import KEEP_TOGETHER, concrete_units, format_number, format_table, wrap_text


def law_rows() -> list[dict]:
    """Every law of the table as plain data: `name`, `equation`, `formula`, `parameters`
    (each `name`, `unit`, `default`) and `reference` (`jaximpact laws --json`)."""
    from .table import LAWS

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


def params_text(row) -> str:
    """Each parameter with its unit (and default) on one line, for `format_table`."""
    return ", ".join(
        (
            f"{p['name']} [{p['unit']}]"
            + ("" if p["default"] is None else f" = {format_number(p['default'])}")
        ).replace(" ", KEEP_TOGETHER)
        for p in row["parameters"]
    )


def laws_text(rows, width: int) -> list[str]:
    """The table of laws (`law_rows`) in lines of at most `width` columns: formulas and
    parameters wrap at spaces, the reference under each; a block per law where even that
    is too wide."""
    header = ("name", "eq.", "F(x, v) [N]", "parameters")
    table = [(r["name"], r["equation"], r["formula"], params_text(r)) for r in rows]
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
    return [*textwrap.wrap(intro, width), "", *lines]


def law_title(name: str) -> str:
    """`hertz_rate (eq. 14: F = c x^1.5 + b1 x^0.5 v)`: the law `name` with its equation and
    formula (a user's law, FILE.py:NAME, by its name alone)."""
    from .table import LAWS

    spec = LAWS.get(name)
    if spec is None:
        return name
    eq = f"eq. {spec.equation}: " if spec.equation != "-" else ""
    return f"{name} ({eq}F = {spec.formula})"


def law_units(law) -> dict[str, str]:
    """The units of `law`'s parameters (`{"c": "N/m^1.5", ...}`; "" for a pure number);
    a user's own law has none to give."""
    spec = law.spec
    if spec is None:
        return {}
    try:
        units = concrete_units(spec, law.parameters)
    except Exception:  # an exponent that is traced: the family's own spelling (`N/m^n`)
        units = {k: spec.units.get(k, "") for k in spec.parameters}
    return {k: "" if u == "-" else u for k, u in units.items()}
