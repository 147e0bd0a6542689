"""The law table `LAWS`: the seed paper's ten laws, the Hunt-Crossley family, the power
family and the engines' own laws, one keyword row (`LawSpec`) each. Adding a law is one row.

Most laws are one family, `F = c x^n + b x^p v + P d(v)`; a row's `coefficients` maps its
parameters to that family. Equation numbers refer to Polukoshko, Viba, Kononova and Sokolova,
"Rigid body impact models partially considering deformation" (2007; shared/seeds).
"""

import jax.numpy as jnp

from . import hunt_crossley_variants as _hysteresis_damping
from .base import LawSpec
from .closed_forms import (
    bingham_closed_form,
    bingham_compression_closed_form,
    kelvin_voigt_closed_form,
)
from .jkr import JKR, JKR_VISCOELASTIC
from .maxwell import MAXWELL
from .thornton import THORNTON

_PAPER = "Polukoshko et al. 2007"
_UNITS = {
    "c": "N/m^n",
    "b": "N s/m^(p+1)",
    "b1": "N s/m^(p+1)",
    "P": "N",
    "a": "s/m",
    "n": "-",
    "e_nominal": "-",
}


def _family(c, n, b, p, p_in=0.0, p_out=0.0):
    zero = jnp.zeros_like(jnp.asarray(c, dtype=float))
    return c, n, b + zero, p, p_in + zero, p_out + zero


def _dmt_adhesion(q):
    """DMT's pull-off force `2 pi w R` (N), acting while in contact."""
    return 2.0 * jnp.pi * q["w"] * q["R"]


_SPECS = [
    LawSpec(
        name="kelvin_voigt",
        damping="b",
        map_range=(200.0, 1000.0),
        restitution_table=True,  # the paper's Fig. 1
        equation="1",
        formula="c x + b v",
        parameters=("c", "b"),
        units=_UNITS,
        reference=f"{_PAPER}, eq. 1",
        coefficients=lambda q, v0: _family(q["c"], 1, q["b"], 0),
        gap=1,
        shape=(1.0, 0.0),
        one_group=True,
        closed_form=kelvin_voigt_closed_form,
        closed_form_gravity=True,
    ),
    LawSpec(
        name="kelvin_voigt_modified",
        damping="b1",
        map_range=(5e4, 1e6),
        restitution_table=True,
        equation="6",
        formula="c x + b1 x v",
        parameters=("c", "b1"),
        units=_UNITS,
        reference=f"{_PAPER}, eq. 6",
        coefficients=lambda q, v0: _family(q["c"], 1, q["b1"], 1),
        gap=0,
        shape=(1.0, 1.0),
        one_group=True,
    ),
    LawSpec(
        name="bingham",
        damping="b",
        map_range=(100.0, 1000.0),
        map_fixed={"P": 400.0},
        shape=(1.0, 0.0),
        equation="7",
        formula="c x + b v + P sgn(v)",
        parameters=("c", "b", "P"),
        units=_UNITS,
        reference=f"{_PAPER}, eq. 7",
        coefficients=lambda q, v0: _family(q["c"], 1, q["b"], 0, q["P"], -q["P"]),
        split=True,
        dry=True,
        closed_form=bingham_closed_form,
        closed_form_gravity=True,
    ),
    LawSpec(
        name="bingham_modified",
        damping="b1",
        map_range=(1e4, 1e6),
        map_fixed={"P": 400.0},
        shape=(1.0, 1.0),
        equation="8",
        formula="c x + b1 x v + P sgn(v)",
        parameters=("c", "b1", "P"),
        units=_UNITS,
        reference=f"{_PAPER}, eq. 8",
        coefficients=lambda q, v0: _family(q["c"], 1, q["b1"], 1, q["P"], -q["P"]),
        split=True,
        dry=True,
        dry_table=True,  # (beta, P/(c x*)) without gravity: the two-group dry table
    ),
    LawSpec(
        name="bingham_compression",
        damping="P",
        map_range=(100.0, 2000.0),
        shape=(1.0, 0.0),  # the dry force dissipates
        equation="9",
        formula="c x + P while v > 0, c x after",
        parameters=("c", "P"),
        units=_UNITS,
        reference=f"{_PAPER}, eq. 9",
        coefficients=lambda q, v0: _family(q["c"], 1, 0.0, 0, q["P"], 0.0),
        gap=1,
        split=True,
        closed_form=bingham_compression_closed_form,
        closed_form_gravity=True,
    ),
    MAXWELL,  # a law with a state: its own class, its row beside it (maxwell.py)
    LawSpec(
        name="hertz_viscous",
        damping="b",
        map_range=(10.0, 200.0),
        restitution_table=True,
        equation="12",
        formula="c x^1.5 + b v",
        parameters=("c", "b"),
        units=_UNITS,
        reference=f"{_PAPER}, eq. 12",
        coefficients=lambda q, v0: _family(q["c"], 1.5, q["b"], 0),
        gap=1.5,
        shape=(1.5, 0.0),
        one_group=True,
    ),
    LawSpec(
        name="hertz_modified",
        damping="b",
        map_range=(5e3, 1e5),
        restitution_table=True,
        equation="13",
        formula="c x^1.5 + b x v",
        parameters=("c", "b"),
        units=_UNITS,
        reference=f"{_PAPER}, eq. 13",
        coefficients=lambda q, v0: _family(q["c"], 1.5, q["b"], 1),
        gap=0.5,
        shape=(1.5, 1.0),
        one_group=True,
    ),
    LawSpec(
        name="hertz_rate",
        damping="b1",
        map_range=(200.0, 2000.0),
        restitution_table=True,
        equation="14",
        formula="c x^1.5 + b1 x^0.5 v",
        parameters=("c", "b1"),
        units=_UNITS,
        reference=f"{_PAPER}, eq. 14 (the paper's proposal; Kuwabara & Kono 1987)",
        coefficients=lambda q, v0: _family(q["c"], 1.5, q["b1"], 0.5),
        gap=1,
        shape=(1.5, 0.5),
        one_group=True,
    ),
    LawSpec(
        name="hunt_crossley",
        damping="a",
        map_range=(0.02, 0.4),
        restitution_table=True,
        equation="15-16",
        formula="c x^n (1 + 1.5 a v)",
        parameters=("c", "a", "n"),
        units=_UNITS,
        reference=f"{_PAPER}, eqs. 15-16; Hunt & Crossley, J. Appl. Mech. 42 (1975) 440",
        coefficients=lambda q, v0: _family(q["c"], q["n"], 1.5 * q["a"] * q["c"], q["n"]),
        gap="x",
        defaults={"n": 1.5},
        shape=("n", "n"),
        one_group=True,
    ),
]


def _nominal_spec(name, formula):
    def coefficients(q, v0):
        damping = formula(q["e_nominal"], v0)
        return _family(q["c"], q["n"], damping * q["c"], q["n"])

    return LawSpec(
        name=name,
        damping="e_nominal",
        map_range=(0.3, 0.99),
        nominal=formula,
        equation="-",
        formula=f"c x^n (1 + D v), {formula.__doc__.split(':')[-1].strip().strip('`.')}",
        parameters=("c", "e_nominal", "n"),
        units=_UNITS,
        reference=formula.__doc__.split(":")[0].strip(),
        coefficients=coefficients,
        gap="x",
        defaults={"n": 1.5},
        shape=("n", "n"),
        one_group=True,
    )


_SPECS += [_nominal_spec(name, formula) for name, formula in _hysteresis_damping.FORMULAS.items()]

_SPECS.append(
    LawSpec(
        name="power",
        damping="b",
        map_range=(200.0, 2000.0),
        map_fixed={"n": 1.5, "p": 0.5},  # law 14's shape
        equation="-",
        formula="c x^n + b x^p v",
        parameters=("c", "n", "b", "p"),
        units=_UNITS,
        reference="the family of eqs. 1, 6, 12-16 with the user's own exponents (0 <= p <= n)",
        coefficients=lambda q, v0: _family(q["c"], q["n"], q["b"], q["p"]),
        gap="power",
        shape=("n", "p"),
        one_group=True,
    )
)

# the engines' own laws (jaximpact._engines; formulas and sources in docs/engines.md)
_ENGINE_UNITS = {**_UNITS, "d": "s/m", "m_eff": "kg"}


def _log_damping(e):
    """`-ln e / sqrt(pi^2 + ln^2 e)`: the damping ratio of a linear spring-dashpot whose
    penetration-criterion restitution is `e`."""
    log_e = jnp.log(e)
    return -log_e / jnp.sqrt(jnp.pi**2 + log_e**2)


_SPECS += [
    LawSpec(
        name="dmt",
        damping="b",
        map_range=(200.0, 2000.0),
        map_fixed={"w": 0.1},  # a surface energy of 0.1 J/m^2 (glass in air is 0.1-0.4)
        equation="DMT 1975",
        formula="c x^1.5 + b x^0.5 v - 2 pi w R while x > 0 (contact ends at x = 0)",
        parameters=("c", "b", "R", "w"),
        units={"c": "N/m^1.5", "b": "N s/m^1.5", "R": "m", "w": "J/m^2"},
        reference="Derjaguin, Muller & Toporov, J. Colloid Interface Sci. 53 (1975) 314; "
        "LAMMPS pair granular dmt (pull-off 4 pi cohesion R = 2 pi w R), damping viscoelastic",
        coefficients=lambda q, v0: _family(
            q["c"], 1.5, q["b"], 0.5, -_dmt_adhesion(q), -_dmt_adhesion(q)
        ),
        gap="x",  # the adhesion holds the contact until x = 0 under either criterion
        shape=(1.5, 0.5),
        constant_force=True,  # read off law 14's gravity table (penetration)
        positive=("c", "R"),
        captures=True,  # below the sticking speed: e = 0, captured
        geometry=("R",),
        kind="adhesive",
    ),
    LawSpec(
        name="tsuji",
        damping="b",
        map_range=(50.0, 1000.0),
        equation="-",
        formula="c x^1.5 + b x^0.25 v",
        parameters=("c", "b"),
        units=_ENGINE_UNITS,
        reference="Tsuji, Tanaka & Ishida, Powder Technol. 71 (1992) 239; LAMMPS pair granular "
        "hertz/material with damping coeff_restitution or tsuji, LIGGGHTS, Chrono SMC Hertz",
        coefficients=lambda q, v0: _family(q["c"], 1.5, q["b"], 0.25),
        gap=1.25,
        one_group=True,
        shape=(1.5, 0.25),
    ),
    LawSpec(
        name="tsuji_restitution",
        damping="e_nominal",
        map_range=(0.3, 0.99),
        map_fixed={"m_eff": 1.0},
        equation="-",
        formula="c x^1.5 + b x^0.25 v, b = sqrt(5) (-ln e) / sqrt(pi^2 + ln^2 e) sqrt(m_eff c)",
        parameters=("c", "e_nominal", "m_eff"),
        units=_ENGINE_UNITS,
        reference="LAMMPS pair granular, damping coeff_restitution (src/GRANULAR/"
        "gran_sub_mod_damping.cpp); LIGGGHTS model hertz; Chrono ChContactSMC Hertz",
        coefficients=lambda q, v0: _family(
            q["c"],
            1.5,
            jnp.sqrt(5.0) * _log_damping(q["e_nominal"]) * jnp.sqrt(q["m_eff"] * q["c"]),
            0.25,
        ),
        gap=1.25,
        one_group=True,
        shape=(1.5, 0.25),
    ),
    LawSpec(
        name="spring_dashpot_restitution",
        damping="e_nominal",
        map_range=(0.3, 0.99),
        map_fixed={"m_eff": 1.0},
        equation="-",
        formula="c x + b v, b = 2 (-ln e) / sqrt(pi^2 + ln^2 e) sqrt(m_eff c)",
        parameters=("c", "e_nominal", "m_eff"),
        units=_ENGINE_UNITS,
        reference="LAMMPS pair granular hooke, damping coeff_restitution; a MuJoCo dampratio set "
        "from e the same way; exact under separation='penetration' only",
        coefficients=lambda q, v0: _family(
            q["c"], 1, 2.0 * _log_damping(q["e_nominal"]) * jnp.sqrt(q["m_eff"] * q["c"]), 0
        ),
        gap=1,
        one_group=True,
        shape=(1.0, 0.0),
    ),
    LawSpec(
        name="point_contact",
        damping="d",
        map_range=(0.02, 0.4),
        equation="-",
        formula="c x (1 + d v)",
        parameters=("c", "d"),
        units=_ENGINE_UNITS,
        reference="Drake MultibodyPlant point contact (point_contact_stiffness c, "
        "hunt_crossley_dissipation d); Hunt & Crossley with n = 1",
        coefficients=lambda q, v0: _family(q["c"], 1, q["c"] * q["d"], 1),
        gap="x",
        one_group=True,
        shape=(1.0, 1.0),
    ),
]

# laws with a contact state beyond the seed paper: plastic (thornton.py), adhesive (jkr.py)
_SPECS += [THORNTON, JKR, JKR_VISCOELASTIC]

LAWS: dict[str, LawSpec] = {spec.name: spec for spec in _SPECS}
LAW_NAMES: tuple[str, ...] = tuple(LAWS)


def _shipped_shapes():
    """The exponents `(n, p)` of every one-group row, as numbers (a shape parameter at the
    row's default or `map_fixed` value), each once, in the table's order."""
    shapes = {}
    for spec in _SPECS:
        if spec.one_group:
            known = {**spec.defaults, **spec.map_fixed}
            shapes[tuple(float(known.get(q, q)) for q in spec.shape)] = None
    return tuple(shapes)


# the shapes whose universal curves ship with the package (`_curves.store.SHIPPED`)
SHIPPED_SHAPES: tuple[tuple[float, float], ...] = _shipped_shapes()
