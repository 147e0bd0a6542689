"""The paper's printed numbers against the converged ones, as markdown: `table.md` and
`hunt_crossley_variants.md`, with the notes that explain the differences.
"""

import numpy as np

from .._compiling import quick_jit
from .cases import COLUMNS, CRITERIA, HC_NOMINAL, SCHEMES


def format_parameters(params: dict) -> str:
    """`{"c": 2e6, "b1": 800.0}` -> `"c = 2e6, b1 = 800"`."""
    from .._format import format_number

    return ", ".join(f"{k} = {format_number(v)}" for k, v in params.items())


def _cell(row, key) -> str:
    return f"{row[f'e_{key}']:.4f} / {row[f'T_{key}'] * 1e3:.3f}"


def table_markdown(rows: list[dict]) -> str:
    """`table.md`: printed, Euler and converged `e` (and `T`, ms) for every parameter set."""
    lines = [
        "# The seed paper's restitutions, recomputed",
        "",
        "Polukoshko et al. 2007. Each cell is `e / T (ms)`. Single impacts: m = 1 kg, "
        "v0 = 2.5 m/s, no gravity. Section 7 (figs. 13-21): the first contact of a 1 kg ball "
        "dropped from 0.6 m (3.43 m/s), g = 9.81 m/s^2.",
        "",
        "- *Euler as printed*: the paper's explicit Euler at its step 2e-5 s, with the force "
        "lagging one step as its section 7 prints it; *textbook Euler*: the same step, force "
        "from the current state. Both keep contact while `x >= 0` (the penetration criterion).",
        "- *converged*: `jaximpact` (diffrax Tsit5, rtol 1e-10; Kelvin-Voigt by its closed "
        "form), separated when the force returns to zero (*force*) or the penetration does "
        "(*penetration*). Checked against scipy at rtol 1e-12 in docs/accuracy.md.",
        "- *nearest*: the column nearest to the printed value.",
        "",
        "| fig. | law, parameters | printed e | Euler as printed | textbook Euler "
        "| converged, force | converged, penetration | nearest |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for row in rows:
        printed = "-" if row["printed"] is None else f"{row['printed']:.2f}"
        note = f" ({row['note']})" if row["note"] else ""
        cells = [_cell(row, key) for key in (*SCHEMES, *CRITERIA)]
        for k, criterion in enumerate(CRITERIA, start=2):
            status = row[f"status_{criterion}"]
            if status not in ("separated", "t_end", "at_rest"):
                cells[k] += f" ({status})"
        label = f"`{row['law']}` ({format_parameters(row['params'])}){note}"
        lines.append(
            f"| {row['figure']} | {label} | {printed} | "
            + " | ".join(cells)
            + f" | {COLUMNS.get(row['nearest'], '-')} |"
        )
    lines += ["", *_figure3_verdict(rows), *_section7_notes(rows), *_kelvin_voigt_note()]
    return "\n".join(lines) + "\n"


def _figure3_verdict(rows) -> list[str]:
    cases = [row for row in rows if row["figure"] == "3"]
    if len(cases) != 2:
        return []
    printed = cases[0]["printed"]

    def gap(row):
        return abs(row[f"e_{row['nearest']}"] - printed)

    best = min(cases, key=gap)
    other = cases[1] if best is cases[0] else cases[0]
    describe = "; ".join(
        f"{row['note']}: converged e = {row['e_force']:.3f} (force), Euler as printed "
        f"{row['e_paper']:.3f}, textbook Euler {row['e_euler']:.3f}"
        for row in cases
    )
    return [
        "## Figure 3: caption against text",
        "",
        f"The caption gives b1 = 4e5, the text b1 = 4; the printed e is {printed:.2f}. "
        f"{describe}. The {best['note'].split(':')[0]}'s value matches (within "
        f"{gap(best):.3f}, {COLUMNS[best['nearest']]}); the {other['note'].split(':')[0]}'s "
        f"does not (its nearest, {COLUMNS[other['nearest']]}, is {gap(other):.3f} away).",
        "",
    ]


def _section7_notes(rows) -> list[str]:
    drops = [row for row in rows if row["figure"] in ("13-15", "16-18", "19-21")]
    if not drops:
        return []
    lines = [
        "## Section 7: the later contacts",
        "",
        "e of contacts 2, 3 and 4 of the same drops (the paper: for law 6, e rises "
        "towards 1 from one contact to the next):",
        "",
        "| figs. | law | Euler as printed | converged, force | converged, penetration |",
        "|---|---|---|---|---|",
    ]
    for row in drops:
        cells = [
            ", ".join(f"{e:.3f}" for e in row[f"e_{key}_later"]) for key in ("paper", *CRITERIA)
        ]
        lines.append(f"| {row['figure']} | `{row['law']}` | " + " | ".join(cells) + " |")
    return lines + [""]


def _kelvin_voigt_note() -> list[str]:
    return [
        "## Figures 1 and 7",
        "",
        "The paper's Kelvin-Voigt formulas mix the two criteria: its T (eq. 5) is the time the "
        "force returns to zero, its e = exp(-pi b / sqrt(4 m c - b^2)) the speed when the "
        "penetration does. `fig1_force.png` and `fig1_penetration.png` draw each criterion "
        "consistently (closed forms); `fig7_*.png` the same for Maxwell (closed form under "
        "the force criterion where under-damped, integrated otherwise).",
        "",
    ]


def hunt_crossley_variants_markdown(nominal=HC_NOMINAL, *, check: bool = True) -> str:
    """`hunt_crossley_variants.md`: the restitution each published Hunt-Crossley damping
    formula (`F = c x^n (1 + D v)`, `D` set from a nominal `e` and `v0`) really gives.

    The exact restitution depends on `D v0` only (`closed_forms.hunt_crossley_restitution`),
    so each row holds for every `c`, `n`, `m` and `v0`; `check` also integrates three
    formulas at three nominal values and states the largest difference.
    """
    import jax.numpy as jnp

    from .._laws import hunt_crossley_variants as _hysteresis_damping
    from .._laws.closed_forms import hunt_crossley_restitution

    names = list(_hysteresis_damping.FORMULAS)
    rows = {}
    for name in names:
        formula = _hysteresis_damping.FORMULAS[name]
        alpha = np.asarray([float(formula(e, 1.0)) for e in nominal])  # D v0 at v0 = 1
        rows[name] = np.asarray(hunt_crossley_restitution(alpha))
    checked = ""
    if check:  # the first three formulas at three nominal values, integrated in one program
        picks = [(name, k) for name in names[:3] for k in (0, len(nominal) // 2, len(nominal) - 2)]
        speed = 1.7
        # `hunt_crossley`'s F = c x^n (1 + 1.5 a v): a = D / 1.5
        a = jnp.asarray(
            [
                float(_hysteresis_damping.FORMULAS[name](nominal[k], speed)) / 1.5
                for name, k in picks
            ]
        )

        e = np.asarray(_integrated_restitutions(a, speed))
        worst = max(abs(e[i] - rows[name][k]) for i, (name, k) in enumerate(picks))
        checked = f"; the integrator agrees with the closed form to {worst:.1e} at 9 points"
    lines = [
        "# Hunt-Crossley damping formulas: the restitution they really give",
        "",
        "Each formula sets `D` in `F = c x^n (1 + D v)` from a nominal restitution `e` and the "
        "impact speed. The exact restitution of that law depends on `D v0` only (through the "
        "Lambert W function, `jaximpact.closed_forms.hunt_crossley_restitution`), so each row "
        f"holds for every stiffness, exponent, mass and speed{checked}.",
        "",
        "| formula | " + " | ".join(f"e = {e}" for e in nominal) + " |",
        "|---|" + "---|" * len(nominal),
    ]
    for name in names:
        cells = " | ".join(f"{value:.3f}" for value in rows[name])
        reference = _hysteresis_damping.FORMULAS[name].__doc__.split(":")[0].strip()
        lines.append(f"| `{name}` ({reference}) | {cells} |")
    target = np.asarray(nominal)
    ranked = sorted(names, key=lambda name: np.max(np.abs(rows[name] - target)))
    lines += [
        "",
        "A formula is exact where its row equals the header. Largest error "
        "|e_real - e_nominal| over the row, best first:",
        "",
    ]
    for name in ranked:
        error = np.abs(rows[name] - target)
        lines.append(f"- `{name}`: {np.max(error):.3f} (at e = {nominal[int(np.argmax(error))]})")
    return "\n".join(lines) + "\n"


def _integrated_restitutions_of(a, speed):
    """e of `hunt_crossley` (c = 1e7, m = 0.1 kg) at each damping `a` of the array, at
    `speed` (m/s), integrated at rtol 1e-12 (not read off its curve)."""
    import jax

    from .._laws import law as make_law
    from .._solve.impact import impact

    def one(a):
        law = make_law("hunt_crossley", c=1e7, a=a)
        return impact(law, m=0.1, v0=speed, method="integrate", rtol=1e-12).e

    return jax.vmap(one)(a)


# compiled quickly (nine impacts run for a millisecond): at XLA's defaults its compile took
# 8.6 s of a first `jaximpact paper`
_integrated_restitutions = quick_jit(_integrated_restitutions_of, brief=True)
