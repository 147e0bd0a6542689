"""The exports as recorded: `Export.to_dict()` of every engine, normal law and tangential law
that the export tests of tests/engines build, against `recorded_exports.json` (written at
the code before the engines became tables of sub-models, issue 36). Floats to 1e-7
relative, numbers inside strings (an engine's command line) the same, names, keys and the
rest of each string exactly: a refactoring of `_engines/` changes none of them. Many values
come from an adaptive solve or a root find (an engine's realised e and spin, JKR's w), so
their last digits follow XLA's rounding: compiling a lone oblique solve with the quick
options (d89f065) moved them by up to 3e-9, as another machine's XLA moved the gravity
table's end at stop 38. 1e-7 is far above that and far below any change of an export.

Record again (only where an export is meant to change, and say why in the commit):

    JAXIMPACT_RECORD=1 python -m pytest -q -p no:xdist -m "" tests/engines/test_recorded_exports.py

which writes the cases it runs into the file (the rest kept) and passes. The exports with a
tangential law compile their oblique impacts (about 15 s each): marked slow.
"""

import json
import math
import os
import pathlib
import re
import warnings

import pytest

import jaximpact as ji

RECORD = pathlib.Path(__file__).with_name("recorded_exports.json")
REL = 1e-7
NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")

# the scenes of the export tests (test_export*.py, test_*_tangential.py, test_real_*.py)
SMALL = dict(m=0.004, v0=1.0, radius=0.005)  # WALL_M, WALL_R
RUBBER_R, RUBBER_M = 0.005, 0.004  # test_export_plastic_adhesive's rubber-like sphere
E, NU = 1e7, 0.3
ALUMINA_R = 2.5e-3  # Kharaz's alumina sphere at 3.9 m/s
ALUMINA_M = 4000.0 * 4.0 / 3.0 * math.pi * ALUMINA_R**3
KHARAZ = dict(m=ALUMINA_M, v0=3.9, radius=ALUMINA_R)


def _jkr(geometry):
    R2, R_eff = (None, RUBBER_R) if geometry == "wall" else (RUBBER_R, RUBBER_R / 2)
    return ji.law("jkr", c=ji.hertz_stiffness(E=E, nu=NU, R=RUBBER_R, R2=R2), R=R_eff, w=1.0)


def _jkr_viscoelastic(geometry):
    R2, R_eff = (None, RUBBER_R) if geometry == "wall" else (RUBBER_R, RUBBER_R / 2)
    c = ji.hertz_stiffness(E=E, nu=NU, R=RUBBER_R, R2=R2)
    return ji.law("jkr_viscoelastic", c=c, b=3.0, R=R_eff, w=10.0)


def _dmt():
    return ji.law("dmt", c=ji.hertz_stiffness(E=E, nu=NU, R=RUBBER_R), b=3.0, R=RUBBER_R, w=30.0)


def _thornton():
    m = 4 / 3 * math.pi * RUBBER_R**3 * 7800
    law = ji.law(
        "thornton",
        c=ji.hertz_stiffness(E=2.1e11, nu=0.3, R=RUBBER_R, E2=math.inf),
        x_y=ji.yield_overlap(E=2.1e11, nu=0.3, R=RUBBER_R, Y=1e9, E2=math.inf),
    )
    return law, m


def _sticking(law):
    return float(law.sticking_speed(RUBBER_M))


def _tl(name, **params):
    return ji.tangential_law(name, **params)


def _cases():
    """name -> `(law or None, engine, keyword arguments)`: built on demand."""
    hertz_rate = ji.law("hertz_rate", c=2e6, b1=800.0)
    tsuji = ji.law("tsuji", c=4.2e9, b=15.0)
    steel, steel_m = _thornton()
    G = dict(G_star=1.35e10, mu=0.092)
    cases = {
        # targets, each engine and scene
        "mujoco targets": (None, "mujoco", dict(m=0.05, v0=1.0, e=0.6, T=5e-3)),
        "mujoco targets per kg": (None, "mujoco", dict(v0=1.0, e=0.6, curves=False)),
        "mujoco coarse step": (
            None,
            "mujoco",
            dict(m=1.0, v0=1.0, e=0.5, T=2e-3, timestep=2e-4, curves=False),
        ),
        "drake": (None, "drake", dict(m=1.0, v0=1.0, e=0.7, T=0.02)),
        "drake discrete": (None, "drake", dict(m=1.0, v0=1.0, e=0.7, T=0.02, timestep=2e-4)),
        "lammps spheres": (None, "lammps", dict(e=0.5, T=5e-4, **SMALL)),
        "lammps wall": (
            None,
            "lammps",
            dict(e=0.5, T=5e-4, geometry="wall", curves=False, **SMALL),
        ),
        "lammps limit_damping": (
            None,
            "lammps",
            dict(e=0.5, T=5e-4, limit_damping=True, curves=False, **SMALL),
        ),
        "lammps unrealised": (
            None,
            "lammps",
            dict(e=0.5, T=5e-4, timestep=2e-4, strict=False, curves=False, **SMALL),
        ),
        "liggghts spheres": (None, "liggghts", dict(e=0.8, T=1e-3, **SMALL)),
        "liggghts wall": (
            None,
            "liggghts",
            dict(e=0.8, T=1e-3, geometry="wall", curves=False, **SMALL),
        ),
        "liggghts limit_damping": (
            None,
            "liggghts",
            dict(e=0.5, T=1e-3, limit_damping=True, poisson=0.25, curves=False, **SMALL),
        ),
        "yade spheres": (None, "yade", dict(e=0.5, T=1e-3, m=0.01, v0=1.0, radius=0.01)),
        "yade wall": (
            None,
            "yade",
            dict(e=0.5, T=1e-3, m=0.01, v0=1.0, radius=0.01, geometry="wall", curves=False),
        ),
        "chrono spheres": (None, "chrono", dict(e=0.6, T=1e-3, **SMALL)),
        "chrono wall": (
            None,
            "chrono",
            dict(e=0.6, T=1e-3, geometry="wall", curves=False, **SMALL),
        ),
        # laws: each engine's own family and the laws it lacks
        "mujoco law": (hertz_rate, "mujoco", dict(m=1.0, v0=2.5)),
        "drake law": (ji.law("point_contact", c=2e5, d=0.5), "drake", dict(m=0.05, v0=1.0)),
        "lammps law": (tsuji, "lammps", dict(curves=False, **KHARAZ)),
        "liggghts law": (tsuji, "liggghts", dict(geometry="wall", curves=False, **KHARAZ)),
        "yade law": (
            ji.law("kelvin_voigt", c=2e5, b=3.0),
            "yade",
            dict(m=0.05, v0=1.0, radius=0.01, geometry="wall", curves=False),
        ),
        "chrono law": (hertz_rate, "chrono", dict(m=0.05, v0=1.0, radius=0.01, curves=False)),
        "lammps jkr spheres": (_jkr("spheres"), "lammps", dict(geometry="spheres")),
        "lammps jkr wall": (_jkr("wall"), "lammps", dict(geometry="wall")),
        "lammps jkr_viscoelastic spheres": (
            _jkr_viscoelastic("spheres"),
            "lammps",
            dict(m=RUBBER_M, v0=0.3, radius=RUBBER_R),
        ),
        "lammps jkr_viscoelastic wall": (
            _jkr_viscoelastic("wall"),
            "lammps",
            dict(m=RUBBER_M, v0=0.3, radius=RUBBER_R, geometry="wall", curves=False),
        ),
        "lammps dmt spheres": (_dmt(), "lammps", dict(m=RUBBER_M, v0=0.3, radius=RUBBER_R)),
        "lammps dmt wall": (
            _dmt(),
            "lammps",
            dict(m=RUBBER_M, v0=0.3, radius=RUBBER_R, geometry="wall", curves=False),
        ),
        "lammps thornton": (
            steel,
            "lammps",
            dict(m=steel_m, v0=1.0, radius=RUBBER_R, geometry="wall", curves=False),
        ),
        "lammps thornton speeds": (
            steel,
            "lammps",
            dict(m=steel_m, v0=[0.1, 0.3, 1.0, 3.0], radius=RUBBER_R, geometry="wall"),
        ),
        "mujoco jkr speeds": (_jkr("wall"), "mujoco", dict(m=RUBBER_M, v0="jkr speeds")),
        # tangential laws: every row of every engine's table
        **{
            f"lammps wall {name}": (
                tsuji,
                "lammps",
                dict(geometry="wall", curves=False, tangential=tangential, **KHARAZ),
            )
            for name, tangential in {
                "linear_history": _tl("linear_history", kt=1e6, mu=0.092),
                "mindlin": _tl("mindlin", **G),
                "mindlin_force": _tl("mindlin_force", **G),
                "mindlin_rescale": _tl("mindlin_rescale", **G),
                "mindlin_rescale_force": _tl("mindlin_rescale_force", **G),
            }.items()
        },
        "lammps spheres mindlin": (
            tsuji,
            "lammps",
            dict(curves=False, tangential=_tl("mindlin", **G), **KHARAZ),
        ),
        "lammps jkr mindlin": (
            _jkr("wall"),
            "lammps",
            dict(geometry="wall", curves=False, tangential=_tl("mindlin", G_star=1e8, mu=0.3)),
        ),
        "liggghts wall mindlin": (
            tsuji,
            "liggghts",
            dict(geometry="wall", curves=False, tangential=_tl("mindlin", **G), **KHARAZ),
        ),
        "liggghts wall mindlin damped": (
            ji.law("tsuji", c=4.2e9, b=300.0),
            "liggghts",
            dict(
                geometry="wall",
                curves=False,
                **KHARAZ,
                tangential=_tl("mindlin", G_star=1.35e10, mu=0.3, beta=0.2),
            ),
        ),
        "liggghts spheres mindlin": (
            tsuji,
            "liggghts",
            dict(curves=False, **KHARAZ, tangential=_tl("mindlin", **G)),
        ),
        "yade wall linear_history": (
            ji.law("kelvin_voigt", c=2e5, b=3.0),
            "yade",
            dict(
                m=0.05,
                v0=1.0,
                radius=0.01,
                geometry="wall",
                curves=False,
                tangential=_tl("linear_history", kt=1e5, mu=0.3),
            ),
        ),
        "yade spheres linear_history": (
            ji.law("kelvin_voigt", c=2e5, b=3.0),
            "yade",
            dict(
                m=0.05,
                v0=1.0,
                radius=0.01,
                curves=False,
                tangential=_tl("linear_history", kt=1e5, mu=0.3),
            ),
        ),
        "mujoco mindlin": (
            tsuji,
            "mujoco",
            dict(curves=False, tangential=_tl("mindlin", **G), **KHARAZ),
        ),
        "mujoco frictionless": (
            tsuji,
            "mujoco",
            dict(curves=False, **KHARAZ, tangential=_tl("mindlin", G_star=1.35e10, mu=0.0)),
        ),
        "drake linear_history": (
            ji.law("point_contact", c=2e5, d=0.5),
            "drake",
            dict(
                m=0.05,
                v0=1.0,
                radius=0.01,
                curves=False,
                tangential=_tl("linear_history", kt=1e5, mu=0.3),
            ),
        ),
        "mujoco targets mindlin": (
            None,
            "mujoco",
            dict(
                m=0.05,
                v0=1.0,
                e=0.6,
                T=5e-3,
                radius=0.01,
                curves=False,
                tangential=_tl("mindlin", G_star=1e9, mu=0.3),
            ),
        ),
    }
    return cases


NAMES = list(_cases())


def _build(name):
    law, engine, kwargs = _cases()[name]
    kwargs = dict(kwargs)
    if "geometry" in kwargs and "jkr" in name and "v0" not in kwargs:  # at 4 V_s, as the tests
        kwargs.update(m=RUBBER_M, v0=4.0 * _sticking(law), radius=RUBBER_R, curves=False)
    if kwargs.get("v0") == "jkr speeds":
        V_s = _sticking(law)
        kwargs["v0"] = [1.2 * V_s, 5 * V_s, 20 * V_s]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ji.export(law, engine, **kwargs).to_dict()


def _plain(value):
    """`value` as JSON holds it: tuples as lists, numpy scalars as floats, NaN as "nan"."""
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_plain(v) for v in value]
    if isinstance(value, bool) or value is None or isinstance(value, str | int):
        return value
    value = float(value)
    return value if math.isfinite(value) else repr(value)


def _close(got, want):
    return got == want or abs(got - want) <= REL * max(abs(got), abs(want))


def _compare(got, want, where=""):
    """A list of the places where `got` differs from `want` (floats to `REL`)."""
    if isinstance(want, dict):
        if not isinstance(got, dict) or list(got) != list(want):
            return [
                f"{where}: keys {list(got) if isinstance(got, dict) else got!r} != {list(want)}"
            ]
        return [d for k in want for d in _compare(got[k], want[k], f"{where}.{k}")]
    if isinstance(want, list):
        if not isinstance(got, list) or len(got) != len(want):
            return [f"{where}: {got!r} != {want!r}"]
        return [
            d
            for i, (a, b) in enumerate(zip(got, want, strict=True))
            for d in _compare(a, b, f"{where}[{i}]")
        ]
    if isinstance(want, float) and isinstance(got, float) and not isinstance(want, bool):
        return [] if _close(got, want) else [f"{where}: {got!r} != {want!r}"]
    if isinstance(want, str) and isinstance(got, str):
        same_words = NUMBER.split(got) == NUMBER.split(want)
        numbers = NUMBER.findall(got), NUMBER.findall(want)
        same_numbers = len(numbers[0]) == len(numbers[1]) and all(
            _close(float(a), float(b)) for a, b in zip(*numbers, strict=True)
        )
        return [] if same_words and same_numbers else [f"{where}: {got!r} != {want!r}"]
    return [] if (type(got) is type(want) and got == want) else [f"{where}: {got!r} != {want!r}"]


def _marks(name):
    return [pytest.mark.slow] if "tangential" in _cases()[name][2] else []


@pytest.mark.parametrize("name", [pytest.param(n, marks=_marks(n)) for n in NAMES])
def test_the_export_is_as_recorded(name):
    got = _plain(_build(name))
    if os.environ.get("JAXIMPACT_RECORD"):
        record = json.loads(RECORD.read_text()) if RECORD.exists() else {}
        record[name] = got
        RECORD.write_text(json.dumps({k: record[k] for k in sorted(record)}, indent=1) + "\n")
        return
    want = json.loads(RECORD.read_text())[name]
    differences = _compare(got, want)
    assert not differences, "\n".join(differences[:20])
