"""Write docs/accuracy.md: the seed paper's parameter sets (m = 1 kg, v0 = 2.5 m/s, figures 2
to 11) under both separation criteria, jaximpact at its default tolerance against scipy's
DOP853 at rtol 1e-12 (tests/reference.py), beside the e the paper printed.
Run: python docs/make_accuracy_table.py
"""

import sys
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jaximpact as ji  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from reference import reference_impact  # noqa: E402

SETS = [  # name, params, figure, printed e
    ("kelvin_voigt", dict(c=2e6, b=400.0), "2", 0.69),
    ("kelvin_voigt_modified", dict(c=2e6, b1=4e5), "3 (caption b1)", 0.78),
    ("kelvin_voigt_modified", dict(c=2e6, b1=4.0), "3 (text b1)", 0.78),
    ("bingham", dict(c=2e6, b=200.0, P=400.0), "4", 0.66),
    ("bingham_modified", dict(c=2e6, b1=200.0, P=400.0), "5", 0.79),
    ("bingham_compression", dict(c=2e6, P=800.0), "6", 0.80),
    ("maxwell", dict(c=2e6, b=2000.0), "7 (map; b chosen)", None),
    ("hertz_viscous", dict(c=2e6, b=40.0), "8", 0.86),
    ("hertz_modified", dict(c=2e6, b=2e4), "9", 0.79),
    ("hertz_rate", dict(c=2e6, b1=800.0), "10", 0.85),
    ("hunt_crossley", dict(c=2e6, a=0.1), "11", 0.80),
]


def rel(a, b):
    return abs(float(a) - b) / abs(b) if b else abs(float(a))


def main():
    lines = [
        "# Accuracy on the seed paper's parameter sets",
        "",
        "m = 1 kg, v0 = 2.5 m/s. jaximpact `impact(law, m=1, v0=2.5, separation=...)` at its",
        "defaults (Tsit5, rtol 1e-10; Kelvin-Voigt by its closed form) against scipy's DOP853 at",
        "rtol 1e-12, split at maximum compression (`tests/reference.py`). Written by",
        "`python docs/make_accuracy_table.py`.",
        "",
        "| law | figure | paper's e | e (force) | T (force) ms | e (penetration) | T (pen.) ms |"
        " x_max mm | worst rel. err. e, T, x_max |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    worst_all = 0.0
    for name, params, figure, printed in SETS:
        law = ji.law(name, **params)
        cells, worst = [], 0.0
        for separation in ("force", "penetration"):
            r = ji.impact(law, m=1.0, v0=2.5, separation=separation)
            ref = reference_impact(name, params, m=1.0, v0=2.5, separation=separation)
            errors = [rel(r.x_max, ref["x_max"]), rel(r.T, ref["T"])]
            if ref["status"] == "separated":
                errors.append(rel(r.e, ref["e"]))
            worst = max(worst, *errors)
            status = "" if r.status_name == "separated" else f" ({r.status_name})"
            cells += [f"{float(r.e):.6f}{status}", f"{1e3 * float(r.T):.6f}"]
        worst_all = max(worst_all, worst)
        printed_text = "-" if printed is None else f"{printed:.2f}"
        lines.append(
            f"| `{name}` {params} | {figure} | {printed_text} | {' | '.join(cells)} | "
            f"{1e3 * float(r.x_max):.6f} | {worst:.1e} |"
        )
    lines += [
        "",
        f"Largest relative difference from scipy over the table: {worst_all:.1e}.",
        "",
        "The paper's printed values differ from the converged ones because its figures were",
        "computed by explicit Euler at a fixed step of 2e-5 s (about 100 steps per contact),",
        "whose first-order error inflates e by several percent, and because its Kelvin-Voigt",
        "formulas mix the two separation criteria. Figure 3's caption gives b1 = 4e5 and its",
        "text b1 = 4: neither reproduces the printed 0.78 exactly (e = 0.748 and 1.000).",
    ]
    out = Path(__file__).with_name("accuracy.md")
    out.write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
