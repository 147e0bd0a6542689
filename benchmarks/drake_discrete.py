"""Drake's discrete plant against the continuous promise: the e that Drake realises with the
exported `point_contact_stiffness` and `hunt_crossley_dissipation` at several time steps and
discrete contact approximations (real Drake, sphere on a half space, gravity off), run by
the test harness (tests/engines/harness.py).

    python benchmarks/drake_discrete.py    # writes benchmarks/drake_discrete.md
"""

import importlib.metadata
import os
import platform
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
sys.path.insert(0, os.path.join(HERE, "..", "tests", "engines"))

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

from harness import run_drake  # noqa: E402

import jaximpact as ji  # noqa: E402

M, V0, T = 1.0, 1.0, 1e-2
TARGETS = (0.9, 0.6)
STEPS = (1e-3, 2.5e-4, 1e-4, 1e-5)
APPROXIMATIONS = ("tamsi", "sap", "lagged", "similar")


def main():

    lines = [
        "# Drake's discrete plant against the continuous promise",
        "",
        f"Drake {importlib.metadata.version('drake')}, "
        f"Python {platform.python_version()}, {platform.machine()} ({os.cpu_count()} cores); "
        "`python "
        "benchmarks/drake_discrete.py`. A sphere of 1 kg on a half space at 1 m/s, gravity "
        f"off; the export's parameters for the target e and T = {T:g} s (the continuous plant "
        "realises them to 1e-9). Each cell: the e Drake realises (relative error).",
        "",
    ]
    for e in TARGETS:
        x = ji.export(None, "drake", m=M, v0=V0, e=e, T=T, curves=False)
        es_cont, _ = run_drake(x.parameters, m=M, v0=V0)
        header = "| time step (s) | steps per contact | " + " | ".join(APPROXIMATIONS) + " |"
        lines += [
            f"## target e = {e}, continuous plant e = {es_cont:.6f}",
            "",
            header,
            "|" + "---|" * (len(APPROXIMATIONS) + 2),
        ]
        for h in STEPS:
            cells = []
            for approximation in APPROXIMATIONS:
                try:
                    got, _ = run_drake(
                        x.parameters, m=M, v0=V0, time_step=h, approximation=approximation
                    )
                    cells.append(f"{got:.4f} ({got / e - 1:+.1%})")
                except Exception as error:  # an approximation this Drake does not have
                    cells.append(f"n/a ({type(error).__name__})")
                print(e, h, approximation, cells[-1], flush=True)
            lines.append(f"| {h:g} | {T / h:.0f} | " + " | ".join(cells) + " |")
        lines.append("")
    path = os.path.join(HERE, "drake_discrete.md")
    with open(path, "w") as handle:
        handle.write("\n".join(lines) + "\n")
    print(f"written {path}")


if __name__ == "__main__":
    main()
