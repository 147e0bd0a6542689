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
    `(c, n, b, p, P_compression, P_restitution)` in SI units; `None` for a law outside the
    family. `state`: a law that carries a contact state beyond `(x, v)` (Maxwell's force,
    eqs. 10-11; later a plastic law's largest overlap, an adhesive neck) is its own final
    class (an `AbstractLaw` with its own `dynamics`), named here; `law(name, ...)` builds
    that class, and `None` builds the family's `Law` from `coefficients`. `split`: the force
    jumps at maximum compression (a dry force), so the
    contact is integrated as two smooth phases; `dry`: that force can hold the body at rest.
    `gap` says where the force criterion ends contact: `"force"` (a dry force makes `F`
    itself cross zero), `"x"` (the force only vanishes at `x = 0`), or the exponent `n - p`
    of the reduced force `F / x^p` (`"power"`: computed from the law's own `n` and `p`).
    `one_group`: without gravity the impact depends on the one group `beta` alone (the
    family without a dry force), so `impact` can read it off the universal curves, whose
    shipped shapes are those of these rows (`table.SHIPPED_SHAPES`);
    `dry_table`: the dry force acts in both phases of a family law with numbers for
    exponents (Bingham-modified), so without gravity the impact depends on `beta` and
    `P/(c x*^n)` and `impact` reads it off the two-group dry table (`_curves.gravity`).
    `constant_force`: the family's `P` acts alike in both phases while in contact (DMT's
    adhesion, `P = -2 pi w R`), so it enters the impact as gravity does (`gamma - P/(c
    x*^n)`) and `impact` reads it off the gravity table of its shape under the penetration
    criterion (`gap="x"`: contact ends at `x = 0`).
    `shape`: the exponents `(n, p)` of a family law, each a number or the name of the
    parameter that holds it (`shape_parameters`: those names, which must be known numbers,
    not traced values, for the curves to serve); `()` outside the family. `closed_form`:
    the exact impact for every parameter value without gravity, as a function
    `closed_form(separation) -> f(law, *, m, v0, g, rest_tol, tau_max, with_end) -> dict` of
    `ImpactResult`
    fields (`closed_forms.py`; `None`: none), which `AbstractLaw.closed_form` hands to
    `impact`; `closed_form_gravity`: that solution holds with gravity too (any `g >= 0`).
    `damping`: the parameter that sets the dissipation (what `restitution_map` varies and a
    fit frees first); `map_range`, `map_fixed`: the map's default range of it and the other
    parameters held (the seed paper's set m = 1 kg, v0 = 2.5 m/s, c = 2e6 lies inside, from
    light to heavy damping over c = 2e6 to 2e7); `restitution_table`: a table of e and T/t*
    against the one group ships for start values (`_fit.restitution_tables`); `nominal`:
    the formula `D(e, v0)` (s/m) of a Hunt-Crossley variant whose damping is set from a
    nominal restitution, so that its impact is `hunt_crossley`'s with `a = D / 1.5`.
    `positive`: the parameters that must be > 0 (the others >= 0); Maxwell's dashpot with
    b = 0 carries no force, and the body would never stop. `captures`: the law holds the
    body below a speed (an adhesive neck), so a measured `e = 0` is data a fit matches
    with a `captured` impact, not an error. `geometry`: parameters that are the bodies'
    geometry (a radius), which the user gives and no fit frees or guesses. `start`: the
    row's own start for a fit, `start(m, v0, e, T) -> params` (SI; `T` may be None), where
    the family's (an undamped contact time and a damping ratio) does not apply. `kind`:
    what makes `e` fall, `"viscoelastic"` (damping), `"plastic"` (a yield) or `"adhesive"`
    (a neck): an engine without the law exports its nearest one, and says so.
    """

    name: str
    equation: str
    formula: str
    parameters: tuple[str, ...]
    units: dict[str, str]
    reference: str
    coefficients: Callable | None = None
    state: type | None = None
    gap: str | float = "force"
    split: bool = False
    dry: bool = False
    defaults: dict[str, float] = dataclasses.field(default_factory=dict)
    one_group: bool = False
    dry_table: bool = False
    constant_force: bool = False
    closed_form: Callable | None = None
    closed_form_gravity: bool = False
    shape: tuple = ()
    damping: str | None = None
    map_range: tuple[float, float] | None = None
    map_fixed: dict[str, float] = dataclasses.field(default_factory=dict)
    restitution_table: bool = False
    nominal: Callable | None = None
    positive: tuple[str, ...] = ("c", "n")
    captures: bool = False
    geometry: tuple[str, ...] = ()
    start: Callable | None = None
    kind: str = "viscoelastic"

    def __post_init__(self):
        if (self.coefficients is None) == (self.state is None):
            raise ValueError(f"row {self.name!r}: give coefficients (the family) or state")

    @property
    def shape_parameters(self) -> tuple[str, ...]:
        """The parameters that hold the shape's exponents (no repeats)."""
        return tuple(dict.fromkeys(q for q in self.shape if isinstance(q, str)))


class AbstractLaw(eqx.Module):
    """A contact force law. Its array fields are its parameters (what a fit updates).

    What every law declares: `name`, its row `spec` of the law table (`None` for a user's
    own law, which has no row), `params` (its parameters by name, arrays), whether its
    force is a contact state (`has_state`: it has no `force(x, v)`; Maxwell), its
    `dynamics` and `replace`. The rest of the library reads these, never probes for them.
    The concrete laws are final: `Law` (the family of the table), `MaxwellLaw`, `CustomLaw`.
    """

    name: eqx.AbstractVar[str]
    spec: eqx.AbstractVar[LawSpec | None]
    params: eqx.AbstractVar[dict[str, Array]]
    has_state: eqx.AbstractClassVar[bool]

    @abc.abstractmethod
    def dynamics(self, *, m, v0, g) -> AbstractDynamics:
        """The nondimensional equations of one contact (mass m in kg, speed v0 in m/s,
        gravity g in m/s^2 along the inward normal)."""

    @abc.abstractmethod
    def replace(self, **params) -> "AbstractLaw":
        """The same law with some parameters changed."""

    def __repr__(self):
        """The call that builds the law, with its values in SI units:
        `law('hertz_rate', c=2e6 N/m^1.5, b1=800 s/m)`; a user's law as
        `custom_law(fn, c=2e6, b=40)` (no units: it has no row of the table)."""
        from .._format import call_text, concrete_units

        if self.spec is None:
            name = getattr(getattr(self, "fn", None), "__name__", self.name)
            return call_text("custom_law", name, self.params, {})
        return call_text(
            "law", repr(self.name), self.params, concrete_units(self.spec, self.params)
        )

    def _refuse_unknown(self, params: dict, who: str | None = None):
        """A one-line `ValueError` for names in `params` that are not the law's parameters
        (what every `replace` checks first)."""
        unknown = sorted(set(params) - set(self.params))
        if unknown:
            raise ValueError(
                f"{who or f'law {self.name!r}'} has no parameter {', '.join(unknown)}; "
                f"it has {', '.join(self.params)}"
            )

    @abc.abstractmethod
    def force(self, x, v, **kwargs):
        """The contact force (N) at penetration `x` (m) and velocity `v` (m/s); a law whose
        force is a state (`has_state`) raises instead."""

    @property
    def parameters(self) -> dict[str, Array]:
        """The law's parameters by name."""
        return dict(self.params)

    def coefficients(self, v0):
        """The family coefficients `(c, n, b, p, P_compression, P_restitution)` (SI) of a law
        of the family `F = c x^n + b x^p v + P d(v)` at impact speed `v0`; `None` for the
        others (a force that is a state, a user's law)."""
        return None

    def closed_form(self, separation: str, *, g_is_zero: bool = True):
        """The exact impact `impact` may take for this law, or `None` (a static decision):
        the row's `closed_form` built for `separation`, where it holds (every `g` where the
        row says `closed_form_gravity`, else `g = 0` only). The function returned is
        `f(law, *, m, v0, g, rest_tol) -> dict` of `ImpactResult` fields."""
        spec = self.spec
        if not (spec and spec.closed_form) or not (g_is_zero or spec.closed_form_gravity):
            return None
        return spec.closed_form(separation)

    def __getattr__(self, item):
        params = self.__dict__.get("params")
        if params is not None and item in params:
            return params[item]
        raise AttributeError(item)


def shape_of(law) -> tuple[float, float] | None:
    """The exponents `(n, p)` of a one-group law as numbers, or `None` (not one-group, or
    its exponents are traced values under a transformation)."""
    if not (law.spec and law.spec.one_group):
        return None
    try:
        return tuple(
            float(law.params[q]) if isinstance(q, str) else float(q) for q in law.spec.shape
        )
    except (TypeError, jax.errors.ConcretizationTypeError, jax.errors.TracerArrayConversionError):
        return None


_DAMPING_NAMES = ("b", "b1", "a", "d", "e_nominal", "P")


def damping_parameter(law) -> str | None:
    """The parameter that sets a law's (or a row's) dissipation: the row's `damping`; for a
    user's own law, the first of b, b1, a, d, e_nominal, P that it has, else `c` where it
    also has `k` (the names of `m x'' + c x' + k x = 0`) (None: none)."""
    spec = law if isinstance(law, LawSpec) else law.spec
    if spec and spec.damping is not None:
        return spec.damping
    named = next((k for k in _DAMPING_NAMES if k in law.parameters), None)
    if named is None and {"k", "c"} <= set(law.parameters):
        return "c"
    return named


def stiffness_parameter(law) -> str | None:
    """The parameter that sets a law's stiffness, which a contact duration fixes: `c` (the
    table's name), or `k` for a user's law whose `c` is its damping (None: neither)."""
    damping = damping_parameter(law)
    return next((k for k in ("c", "k") if k in law.parameters and k != damping), None)


def exponents(spec, params=None) -> tuple[float, float]:
    """The exponents `(n, p)` of a family law's row, a name read from `params` (else the
    row's defaults, else law 14's 1.5 and 0.5)."""
    params = {**{"n": 1.5, "p": 0.5}, **spec.defaults, **(params or {})}
    return tuple(float(params[q]) if isinstance(q, str) else float(q) for q in spec.shape)
