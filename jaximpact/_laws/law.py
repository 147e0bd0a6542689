"""Contact force laws: the seed paper's ten, the Hunt-Crossley family, and the user's own.

Sign convention: `x` is the penetration (m, > 0 inside the surface), `v = dx/dt` (m/s), and a
law returns the force on the body (N), positive when it pushes the body out. Most laws are
one family, `F = c x^n + b x^p v + P d(v)`; the table `LAWS` maps each name to its
coefficients in that family. Equation numbers refer to Polukoshko, Viba, Kononova and
Sokolova, "Rigid body impact models partially considering deformation" (2007; shared/seeds).
"""

import abc
import dataclasses
from collections.abc import Callable

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._checks import check_nonnegative, check_positive, check_values
from .._powers import contact_pow
from . import hunt_crossley_variants as _hysteresis_damping
from .dynamics import (
    AbstractDynamics,
    maxwell_dynamics,
    power_dynamics,
    scaled_dynamics,
)


@dataclasses.dataclass(frozen=True)
class LawSpec:
    """One row of the law table.

    `coefficients(params, v0)` returns the family coefficients
    `(c, n, b, p, P_compression, P_restitution)` in SI units; `None` for laws outside the
    family (Maxwell). `split`: the force jumps at maximum compression (a dry force), so the
    contact is integrated as two smooth phases; `dry`: that force can hold the body at rest.
    `gap` says where the force criterion ends contact: `"force"` (a dry force makes `F`
    itself cross zero), `"x"` (the force only vanishes at `x = 0`), or the exponent `n - p`
    of the reduced force `F / x^p` (`"power"`: computed from the law's own `n` and `p`).
    `one_group`: without gravity the impact depends on the one group `beta` alone (the
    family without a dry force), so `impact` can read it off the universal curves;
    `shape`: the exponents `(n, p)`, each a number or the name of the parameter that holds
    it (`shape_parameters`: those names, which must be known numbers, not traced values,
    for the curves to serve). `closed_form`: `impact` has an
    exact solution for every parameter value (`_closed_forms.closed_form_for`).
    `damping`: the parameter that sets the dissipation (what `restitution_map` varies and a
    fit frees first); `map_range`, `map_fixed`: the map's default range of it and the other
    parameters held (the seed paper's set m = 1 kg, v0 = 2.5 m/s, c = 2e6 lies inside, from
    light to heavy damping over c = 2e6 to 2e7); `restitution_table`: a table of e and T/t*
    against the one group ships for start values (`_fit.restitution_tables`); `nominal`:
    the formula `D(e, v0)` (s/m) of a Hunt-Crossley variant whose damping is set from a
    nominal restitution, so that its impact is `hunt_crossley`'s with `a = D / 1.5`.
    """

    name: str
    equation: str
    formula: str
    parameters: tuple[str, ...]
    units: dict[str, str]
    reference: str
    coefficients: Callable | None
    gap: str | float = "force"
    split: bool = False
    dry: bool = False
    defaults: dict[str, float] = dataclasses.field(default_factory=dict)
    one_group: bool = False
    closed_form: bool = False
    shape: tuple = ()
    damping: str | None = None
    map_range: tuple[float, float] | None = None
    map_fixed: dict[str, float] = dataclasses.field(default_factory=dict)
    restitution_table: bool = False
    nominal: Callable | None = None

    @property
    def shape_parameters(self) -> tuple[str, ...]:
        """The parameters that hold the shape's exponents (no repeats)."""
        return tuple(dict.fromkeys(q for q in self.shape if isinstance(q, str)))


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
        closed_form=True,
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
    ),
    LawSpec(
        name="maxwell",
        damping="b",
        map_range=(3000.0, 20000.0),
        restitution_table=True,  # Fig. 7: 4 b^2 > m c
        equation="10-11",
        formula="spring c in series with dashpot b: dF/dt = c (v - F/b)",
        parameters=("c", "b"),
        units={"c": "N/m", "b": "N s/m"},
        reference=f"{_PAPER}, eqs. 10-11",
        coefficients=None,
    ),
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

LAWS: dict[str, LawSpec] = {spec.name: spec for spec in _SPECS}
LAW_NAMES: tuple[str, ...] = tuple(LAWS)


class AbstractLaw(eqx.Module):
    """A contact force law. Its array fields are its parameters (what a fit updates)."""

    @abc.abstractmethod
    def dynamics(self, *, m, v0, g) -> AbstractDynamics:
        """The nondimensional equations of one contact (mass m in kg, speed v0 in m/s,
        gravity g in m/s^2 along the inward normal)."""

    @property
    @abc.abstractmethod
    def parameters(self) -> dict[str, Array]:
        """The law's parameters by name."""

    @abc.abstractmethod
    def replace(self, **params) -> "AbstractLaw":
        """The same law with some parameters changed."""

    def __getattr__(self, item):
        params = self.__dict__.get("params")
        if params is not None and item in params:
            return params[item]
        raise AttributeError(item)


class Law(AbstractLaw):
    """A law of the table `LAWS`, built by `jaximpact.law(name, **params)`.

    **Example**: `jaximpact.law("hertz_rate", c=2e6, b1=800.0).force(1e-3, 1.0)`.
    """

    name: str = eqx.field(static=True)
    params: dict[str, Array]

    @property
    def spec(self) -> LawSpec:
        return LAWS[self.name]

    @property
    def parameters(self):
        return dict(self.params)

    def replace(self, **params):
        unknown = sorted(set(params) - set(self.params))
        if unknown:
            raise ValueError(
                f"law {self.name!r} has no parameter {', '.join(unknown)}; "
                f"it has {', '.join(self.params)}"
            )
        return law(self.name, **{**self.params, **params})

    def dynamics(self, *, m, v0, g):
        if self.name == "maxwell":
            return maxwell_dynamics(self.params["c"], self.params["b"], m=m, v0=v0, g=g)
        c, n, b, p, p_in, p_out = self.spec.coefficients(self.params, v0)
        gap = self.spec.gap
        if gap == "power":
            gap = _power_gap(n, p)
        return power_dynamics(
            c,
            n,
            b,
            p,
            p_in,
            p_out,
            m=m,
            v0=v0,
            g=g,
            gap=gap,
            split=self.spec.split,
            can_stick=self.spec.dry,
        )

    def force(self, x, v, *, v0=None, compressing=None):
        """Contact force (N) at penetration `x` (m) and velocity `v` (m/s).

        The dry force's sign follows `compressing` (default: `v > 0`); the Hunt-Crossley
        variants need the impact speed `v0`. Not defined for Maxwell, whose force is a state.
        """
        if self.name == "maxwell":
            raise ValueError(
                "the Maxwell force is a state, not a function of (x, v): "
                "read it from impact(..., ts=...).F"
            )
        if v0 is None and self.name in _hysteresis_damping.FORMULAS:
            raise ValueError(f"law {self.name!r} needs the impact speed: pass v0=...")
        c, n, b, p, p_in, p_out = self.spec.coefficients(self.params, v0)
        x, v = jnp.asarray(x, dtype=float), jnp.asarray(v, dtype=float)
        compressing = v > 0 if compressing is None else compressing
        dry = jnp.where(compressing, p_in, p_out)
        return c * contact_pow(x, n) + b * contact_pow(x, p) * v + dry


class CustomLaw(AbstractLaw):
    """A user's law `F = fn(x, v, params)` in SI units (N), built by `custom_law`."""

    fn: Callable = eqx.field(static=True)
    params: dict[str, Array]
    name: str = eqx.field(static=True, default="custom")

    @property
    def parameters(self):
        return dict(self.params)

    def replace(self, **params):
        unknown = sorted(set(params) - set(self.params))
        if unknown:
            raise ValueError(
                f"this custom law has no parameter {', '.join(unknown)}; "
                f"it has {', '.join(self.params)}"
            )
        return CustomLaw(self.fn, {**self.params, **_as_arrays(params)}, self.name)

    def dynamics(self, *, m, v0, g):
        return scaled_dynamics(self.fn, self.params, m=m, v0=v0, g=g)

    def force(self, x, v, **_):
        """Contact force (N) at penetration `x` (m) and velocity `v` (m/s)."""
        return self.fn(jnp.asarray(x, dtype=float), jnp.asarray(v, dtype=float), self.params)


def _power_gap(n, p):
    """`PowerDynamics.gap` of the power law: `"x"` where `n = p` (the force vanishes at
    `x = 0` only), else `n - p`; the force itself if the exponents are traced values."""
    try:
        k = float(n) - float(p)
    except (TypeError, jax.errors.ConcretizationTypeError, jax.errors.TracerArrayConversionError):
        return "force"
    return "x" if k == 0 else k


def shape_of(law) -> tuple[float, float] | None:
    """The exponents `(n, p)` of a one-group law as numbers, or `None` (not one-group, or
    its exponents are traced values under a transformation)."""
    spec = getattr(law, "spec", None)
    if spec is None or not spec.one_group:
        return None
    try:
        return tuple(float(law.params[q]) if isinstance(q, str) else float(q) for q in spec.shape)
    except (TypeError, jax.errors.ConcretizationTypeError, jax.errors.TracerArrayConversionError):
        return None


_DAMPING_NAMES = ("b", "b1", "a", "d", "e_nominal", "P")


def damping_parameter(law) -> str | None:
    """The parameter that sets a law's (or a row's) dissipation: the row's `damping`; for a
    user's own law, the first of b, b1, a, d, e_nominal, P that it has (None: none)."""
    spec = law if isinstance(law, LawSpec) else getattr(law, "spec", None)
    if spec is not None and spec.damping is not None:
        return spec.damping
    return next((k for k in _DAMPING_NAMES if k in law.parameters), None)


def exponents(spec, params=None) -> tuple[float, float]:
    """The exponents `(n, p)` of a family law's row, a name read from `params` (else the
    row's defaults, else law 14's 1.5 and 0.5)."""
    params = {**{"n": 1.5, "p": 0.5}, **spec.defaults, **(params or {})}
    return tuple(float(params[q]) if isinstance(q, str) else float(q) for q in spec.shape)


def _as_arrays(params, numbers=()):
    """The parameters as JAX arrays; those named in `numbers` (a law's shape exponents)
    stay numpy arrays when given as numbers, so that they are still known numbers when the
    law is built inside `jax.jit` (where `jnp.asarray` of a constant is a traced value)."""
    arrays = {}
    for key, value in params.items():
        if key in numbers and isinstance(value, (int, float, np.number, np.ndarray)):
            arrays[key] = np.asarray(value, dtype=jnp.result_type(float))
        else:
            arrays[key] = jnp.asarray(value, dtype=float)
    return arrays


def _check_law_parameters(name, params):
    """The parameters, each passed through its value check (eager `ValueError`, or
    `eqx.error_if` under `jit`, whose result must be used)."""
    checked = {}
    for key, value in params.items():
        if key == "c":
            checked[key] = check_positive(f"{name}: stiffness c", value, _UNITS["c"])
        elif key == "n":
            checked[key] = check_positive(f"{name}: exponent n", value)
        elif key == "e_nominal":
            checked[key] = check_values(
                value,
                lambda a: (a <= 0) | (a > 1),
                f"{name}: e_nominal must lie in (0, 1], got {value}",
            )
        else:
            checked[key] = check_nonnegative(f"{name}: {key}", value, _UNITS.get(key, ""))
    return checked


def law(name: str, **params) -> Law:
    """Build the law `name` of `LAW_NAMES` with its parameters (SI units).

    Parameter names are the seed paper's: `c` stiffness, `b` or `b1` damping, `P` dry force,
    `a` Hunt-Crossley damping, `n` exponent, `e_nominal` the restitution a published
    Hunt-Crossley damping formula is asked for. `jaximpact laws` lists them all.

    **Example**: `law("kelvin_voigt", c=2e6, b=400.0)`.
    """
    if name not in LAWS:
        raise ValueError(f"unknown law {name!r}; choose one of: {', '.join(LAW_NAMES)}")
    spec = LAWS[name]
    unknown = sorted(set(params) - set(spec.parameters))
    if unknown:
        raise ValueError(
            f"law {name!r} has no parameter {', '.join(unknown)}; "
            f"it takes {', '.join(spec.parameters)}"
        )
    given = {**spec.defaults, **params}
    missing = [k for k in spec.parameters if k not in given]
    if missing:
        raise ValueError(
            f"law {name!r} needs {', '.join(missing)}; it takes {', '.join(spec.parameters)}"
            + (f" (defaults: {spec.defaults})" if spec.defaults else "")
        )
    given = {k: given[k] for k in spec.parameters}
    if name == "power" and _concrete_numbers(given["n"], given["p"]):
        if not 0 <= float(given["p"]) <= float(given["n"]):
            raise ValueError(
                f"law 'power' needs exponents 0 <= p <= n, got n={given['n']}, p={given['p']}"
            )
    return Law(name, _as_arrays(_check_law_parameters(name, given), spec.shape_parameters))


def _concrete_numbers(*values) -> bool:
    return all(not isinstance(v, jax.core.Tracer) and jnp.ndim(v) == 0 for v in values)


def custom_law(fn: Callable, **params) -> CustomLaw:
    """Wrap a user's force law `fn(x, v, params) -> F` (SI units, N, positive pushing out).

    `fn` must be a pure JAX function of the penetration `x` (m), the velocity `v` (m/s)
    and the dict `params`; it is called with `x` slightly below 0 by the solver's last
    step, so guard fractional powers with `jaximpact.safe_pow`.

    **Example**:
    `custom_law(lambda x, v, p: p["k"] * x + p["d"] * safe_pow(x, 0.5) * v, k=2e6, d=800.0)`.
    """
    if not callable(fn):
        raise ValueError("custom_law needs a function f(x, v, params) as its first argument")
    if not params:
        raise ValueError("custom_law needs the law's parameters as keywords, e.g. k=2e6")
    return CustomLaw(fn, _as_arrays(params))
