"""The seed paper's conditions, the one copy the library, the tests and the benchmarks
use: the mass and impact speed of its figures, its Euler step, and every parameter set it
prints (single impacts, bounces, maps), by figure.
"""

from typing import NamedTuple

M, V0 = 1.0, 2.5  # kg, m/s: every single-impact figure of the paper


EULER_STEP = 2e-5  # s, the paper's step (section 7)


HC_NOMINAL = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99)


class PaperCase(NamedTuple):
    """One parameter set of the paper: its figure(s), law, parameters (SI) and printed `e`."""

    figure: str
    law: str
    params: dict
    printed: float | None
    note: str = ""


LOOPS = (
    PaperCase("2", "kelvin_voigt", dict(c=2e6, b=400.0), 0.69),
    PaperCase("3", "kelvin_voigt_modified", dict(c=2e6, b1=4e5), 0.78, "caption: b1 = 4e5"),
    PaperCase("3", "kelvin_voigt_modified", dict(c=2e6, b1=4.0), 0.78, "text: b1 = 4"),
    PaperCase("4", "bingham", dict(c=2e6, b=200.0, P=400.0), 0.66),
    PaperCase("5", "bingham_modified", dict(c=2e6, b1=200.0, P=400.0), 0.79, "caption's b as b1"),
    PaperCase("6", "bingham_compression", dict(c=2e6, P=800.0), 0.80),
    PaperCase("8", "hertz_viscous", dict(c=2e6, b=40.0), 0.86),
    PaperCase("9", "hertz_modified", dict(c=2e6, b=2e4), 0.79),
    PaperCase("10", "hertz_rate", dict(c=2e6, b1=800.0), 0.85),
    PaperCase("11", "hunt_crossley", dict(c=2e6, a=0.1), 0.80),
)


BOUNCES = (
    PaperCase("13-15", "hertz_rate", dict(c=1e6, b1=1350.0), 0.64),
    PaperCase("16-18", "kelvin_voigt", dict(c=2e6, b=480.0), 0.64),
    PaperCase("19-21", "kelvin_voigt_modified", dict(c=2e6, b1=8e5), 0.54),
)


MAPS = (PaperCase("1", "kelvin_voigt", {}, None), PaperCase("7", "maxwell", {}, None))


FIGURES = tuple(dict.fromkeys(case.figure for case in MAPS + LOOPS + BOUNCES))


CRITERIA = ("force", "penetration")


def select_cases(only) -> list[PaperCase]:
    """The cases of the figures in `only` (`"3"`, `"13"` or `"13-15"`; None: all)."""
    cases = sorted(MAPS + LOOPS + BOUNCES, key=lambda case: int(case.figure.split("-")[0]))
    if only is None:
        return cases
    wanted = set()
    for item in only:
        item = str(item).strip()
        group = next((f for f in FIGURES if item == f or item in figure_numbers(f)), None)
        if group is None:
            raise ValueError(
                f"the paper has no recomputable figure {item!r}; choose from {', '.join(FIGURES)}"
            )
        wanted.add(group)
    return [case for case in cases if case.figure in wanted]


def figure_numbers(group: str) -> list[str]:
    first, _, last = group.partition("-")
    return [str(k) for k in range(int(first), int(last or first) + 1)]


DROP_HEIGHT, GRAVITY, DROP_DURATION = 0.6, 9.81, 3.0  # m, m/s^2, s (section 7)
SCHEMES = {"paper": "Euler as printed", "euler": "textbook Euler"}
COLUMNS = {**SCHEMES, "force": "converged, force", "penetration": "converged, penetration"}
