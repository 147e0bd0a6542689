"""The law interface: `LawSpec`, one row of the law table (every fact the library knows
about a law), `AbstractLaw`, what a law object is, and the functions that read a row.

Sign convention: `x` is the penetration (m, > 0 inside the surface), `v = dx/dt` (m/s), and a
law returns the force on the body (N), positive when it pushes the body out.
"""

import abc
import dataclasses
from collections.abc import Callable

import equinox as eqx
import jax
from jaxtyping import Array

from .dynamics import AbstractDynamics


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
    exact solution for every parameter value without gravity (`closed_forms.closed_form_for`);
    `closed_form_gravity`: that solution holds with gravity too (any `g >= 0`).
    `damping`: the parameter that sets the dissipation (what `restitution_map` varies and a
    fit frees first); `map_range`, `map_fixed`: the map's default range of it and the other
    parameters held (the seed paper's set m = 1 kg, v0 = 2.5 m/s, c = 2e6 lies inside, from
    light to heavy damping over c = 2e6 to 2e7); `restitution_table`: a table of e and T/t*
    against the one group ships for start values (`_fit.restitution_tables`); `nominal`:
    the formula `D(e, v0)` (s/m) of a Hunt-Crossley variant whose damping is set from a
    nominal restitution, so that its impact is `hunt_crossley`'s with `a = D / 1.5`.
    `positive`: the parameters that must be > 0 (the others >= 0); Maxwell's dashpot with
    b = 0 carries no force, and the body would never stop.
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
    closed_form_gravity: bool = False
    shape: tuple = ()
    damping: str | None = None
    map_range: tuple[float, float] | None = None
    map_fixed: dict[str, float] = dataclasses.field(default_factory=dict)
    restitution_table: bool = False
    nominal: Callable | None = None
    positive: tuple[str, ...] = ("c", "n")

    @property
    def shape_parameters(self) -> tuple[str, ...]:
        """The parameters that hold the shape's exponents (no repeats)."""
        return tuple(dict.fromkeys(q for q in self.shape if isinstance(q, str)))


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
