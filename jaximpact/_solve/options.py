"""The options a user gives a solve (`SolveOptions`, one record accepted whole by `impact`,
`impact_batch`, `bounce`, `calibrate` and `fit_bounces`), what is static about a compiled
impact solve (`ImpactOptions`), and the one decision of how an impact is computed
(`choose_path`): the law's exact closed form, the universal curves, the two-group gravity
table (integrated where it ends), or the integration. `impact`, `impact_batch`, `bounce`
(and `fit_bounces`) and `calibrate` all ask `choose_path`, once per call (a batch: once for
all its rows)."""

import dataclasses
import functools
import inspect
import math
from typing import NamedTuple

import equinox as eqx

from .._checks import is_traced
from .._curves.gravity import WithDryForce, WithGravity, table_for
from .._curves.shapes import CurveKey, curve_key
from .._curves.similarity import serves
from .._curves.store import curves_for
from .._laws import shape_of
from .precision import resolvable_tolerances

SEPARATIONS = ("force", "penetration")
METHODS = ("auto", "integrate", "closed_form", "similarity")
PATHS = ("closed_form", "similarity", "gravity_table", "dry_table", "integrated")
# the curves are accurate to about 2e-11 relative (docs/similarity.md): a finer `rtol`
# asked of `impact` integrates instead
CURVES_RTOL = 1e-11
# the default tolerances: a law of the table, a user's law (measured: `c x sqrt(x) + b
# sqrt(x) v` as written is 1.6e-9 off in e at 1e-11, 2.2e-10 at 1e-12)
DEFAULT_RTOL = 1e-11
CUSTOM_RTOL = 1e-12


class SolveOptions(eqx.Module):
    """How an impact is solved, as one record: what `impact`, `impact_batch`, `bounce`,
    `calibrate` and `fit_bounces` take whole as `options=`, beside their keywords of the
    same names (as diffrax takes a `stepsize_controller`). Every field left `None` is the
    entry point's own default (the defaults stay those of its keywords); a keyword given
    with `options=` that sets the same field to another value is refused (`ValueError`).
    The fields are static: one compiled program per distinct record, and a record closed
    over or passed through `jax.jit` and `jax.vmap` is configuration, not data.

    - `rtol`, `atol` (dimensionless): tolerances of the integration in the contact's own
      units (`x* = (m v0^2/c)^(1/(n+1))` m, `t* = x*/v0` s), so relative to the contact's
      scales; default `rtol` 1e-11 for a law of the table and 1e-12 for a user's law
      (`impact`, `bounce`, `fit_bounces`), 1e-10 (`calibrate`), 1e-11 (`impact_batch`
      of arrays); `atol` defaults to `rtol`. Both in (0, 1).
    - `max_steps` (integer >= 1, default 4096): the integrator's step budget per phase.
    - `tau_max` (units of `t*`, default 1e4): the horizon; a contact still going on there is
      `captured`.
    - `rest_tol` (dimensionless, default 1e-7 for `impact`, 1e-9 for `bounce` and the
      fits): a body whose speed (units of `v0`) plus net force (units of `m v0^2/x*`)
      falls below it is at rest.
    - `solver`: a diffrax solver (default `diffrax.Tsit5()`; choosing one integrates
      instead of reading the universal curves).
    - `adjoint`: a diffrax adjoint (default: the cheapest for the transformation in use;
      the fits differentiate in forward mode and take none).
    - `peaks` (bool, default True): find `x_max`, `t_max`, `F_max` (the fits choose this
      themselves and take none).
    - `throw` (bool or None): what a solve that did not separate does, as `impact`'s and
      `bounce`'s `throw` (`impact_batch` and the fits report a status and take none).

    **Example**:
    ```python
    options = jaximpact.SolveOptions(rtol=1e-12, max_steps=16384)
    jaximpact.impact(law, m=1.0, v0=2.5, options=options)   # as rtol=1e-12, max_steps=16384
    jax.vmap(lambda v: jaximpact.impact(law, m=1.0, v0=v, options=options).e)(speeds)
    ```
    """

    rtol: float | None = eqx.field(static=True, default=None)
    atol: float | None = eqx.field(static=True, default=None)
    max_steps: int | None = eqx.field(static=True, default=None)
    tau_max: float | None = eqx.field(static=True, default=None)
    rest_tol: float | None = eqx.field(static=True, default=None)
    solver: object = eqx.field(static=True, default=None)  # a diffrax solver
    adjoint: object = eqx.field(static=True, default=None)  # a diffrax adjoint
    peaks: bool | None = eqx.field(static=True, default=None)
    throw: bool | None = eqx.field(static=True, default=None)


SOLVE_FIELDS = tuple(f.name for f in dataclasses.fields(SolveOptions))
# the options an entry point decides itself, and why (`solve_options(refused=...)`)
FIT_DECIDES = {
    "adjoint": "a fit differentiates its solves in forward mode",
    "peaks": "a fit asks for them where it needs them",
    "throw": "a fit reports its solves in converged",
}
BATCH_DECIDES = {"throw": "a batch reports each row's status"}


@functools.cache
def _keyword_defaults(entry) -> dict:
    """The defaults of `entry`'s keywords (read once per function)."""
    return {
        name: p.default
        for name, p in inspect.signature(entry).parameters.items()
        if p.default is not inspect.Parameter.empty
    }


def _same(a, b) -> bool:
    if a is b:
        return True
    try:
        return bool(a == b)
    except Exception:  # an array, a value that cannot be compared: not the same
        return False


def solve_options(entry, options, *, refused: dict | None = None, **given) -> SolveOptions:
    """The `SolveOptions` of a call of `entry` (the public function, or its name where every
    keyword in `given` was passed by the caller): its keywords `given` (by name, as the call
    received them) with the record `options`. A keyword left at its default gives way to
    the record's value; a keyword given another value where the record sets a third is
    refused in one line (`ValueError`), as is a field of `refused` (field -> why) that the
    record sets (an option `entry` decides itself). Fields neither given nor set stay
    `None` (the entry point's default)."""
    if options is None:
        return SolveOptions(**given)
    name = entry if isinstance(entry, str) else entry.__name__
    if not isinstance(options, SolveOptions):
        raise TypeError(
            f"{name}'s options must be a jaximpact.SolveOptions, got {type(options).__name__}"
        )
    for field, why in (refused or {}).items():
        if getattr(options, field) is not None:
            raise ValueError(
                f"{name} takes no {field} (options.{field}={getattr(options, field)!r}: "
                f"{why}); leave it None"
            )
    defaults = {} if isinstance(entry, str) else _keyword_defaults(entry)
    merged = {}
    for field in SOLVE_FIELDS:
        held = getattr(options, field)
        if field not in given:
            merged[field] = held
            continue
        value = given[field]
        if held is None or _same(value, held) or _same(value, defaults.get(field)):
            merged[field] = value if held is None else held
            continue
        raise ValueError(
            f"{name} got {field}={value!r} and options.{field}={held!r}: give {field} once "
            "(as a keyword or in options)"
        )
    return SolveOptions(**merged)


def with_defaults(solve: SolveOptions, **defaults) -> SolveOptions:
    """`solve` with each field named in `defaults` that is None set to its default (the
    defaults of an entry point whose record fields are not all keywords of it)."""
    unset = {k: v for k, v in defaults.items() if getattr(solve, k) is None}
    return dataclasses.replace(solve, **unset) if unset else solve


def with_tolerances(solve: SolveOptions, rtol: float) -> SolveOptions:
    """`solve` with `rtol` (its default resolved), `atol` (default `rtol`) and `rest_tol`
    as the working precision can meet them (`precision.resolvable_tolerances`)."""
    atol = rtol if solve.atol is None else solve.atol
    rtol, atol, rest_tol = resolvable_tolerances(rtol, atol, solve.rest_tol)
    return dataclasses.replace(solve, rtol=rtol, atol=atol, rest_tol=rest_tol)


class ImpactOptions(eqx.Module):
    """Everything static about an impact solve: one compiled program per distinct value.

    The library builds it from a call's `SolveOptions` and the path `choose_path` decided
    (`make_options`); a user gives `SolveOptions` (or the keywords), not this record, which
    a caller that runs `solve_impact` itself (a fit, a batch, a test) may build.

    - `separation`: `"force"` or `"penetration"`, the end of contact.
    - `closed_form`: take the law's exact solution (`AbstractLaw.closed_form`).
    - `solver`, `adjoint`: the diffrax solver and adjoint of an integrated solve (None for
      a path that does not integrate).
    - `rtol`, `atol`: tolerances in the contact's own units (`x*`, `t*`); `max_steps`;
      `tau_max`: the horizon in units of `t*`; `rest_tol`: the speed plus net force
      (in units of `v0` and `m v0^2/x*`) below which the body is at rest.
    - `peaks`: find `x_max`, `t_max`, `F_max`.
    - `similarity`: the universal curves' `CurveKey` to read the impact off, or
      `WithGravity(key)` for the two-group gravity table, `WithDryForce(key)` for the
      dry force's (Bingham-modified); None otherwise.
    - `gravity`: False where `g` is known to be 0 (a number 0 given): the solve then
      compiles without gravity's branches (a traced `g` would compile both).
    - `integrate_outside`: with a two-group table, integrate the impacts outside it (the
      default); False leaves them NaN with the status `failed`, for a caller that
      integrates those itself in a second program (a fit on the host: the table alone
      compiles in about a second, with the integration beside it in about eight).

    **Example**: `jaximpact.ImpactOptions(separation="force", closed_form=True, solver=None,
    rtol=1e-11, atol=1e-11, max_steps=4096, tau_max=1e4, rest_tol=1e-7, adjoint=None,
    peaks=True)`, the options of a Kelvin-Voigt impact.
    """

    separation: str = eqx.field(static=True)
    closed_form: bool = eqx.field(static=True)
    solver: object = eqx.field(static=True)  # a diffrax solver (None: not integrated)
    rtol: float = eqx.field(static=True)
    atol: float = eqx.field(static=True)
    max_steps: int = eqx.field(static=True)
    tau_max: float = eqx.field(static=True)
    rest_tol: float = eqx.field(static=True)
    adjoint: object = eqx.field(static=True)  # a diffrax adjoint (None: not integrated)
    peaks: bool = eqx.field(static=True)
    similarity: CurveKey | WithGravity | None = eqx.field(static=True, default=None)
    gravity: bool = eqx.field(static=True, default=True)
    integrate_outside: bool = eqx.field(static=True, default=True)


class Path(NamedTuple):
    """How an impact is computed: `name`, one of `PATHS`, and for the curves their `key`
    (a `CurveKey`, or `WithGravity(key)` / `WithDryForce(key)` for a two-group table)."""

    name: str
    key: CurveKey | WithGravity | None = None

    @property
    def integrates(self) -> bool:
        """Whether the solve needs the integrator (the gravity table integrates the impacts
        that leave it)."""
        return self.name in ("gravity_table", "dry_table", "integrated")


def check_choices(separation: str, method: str, rtol, *, table_law: bool):
    """One-line ValueErrors for an unknown `separation` or `method`; the `rtol` to use (its
    default: 1e-11 for a law of the table, 1e-12 for a user's law)."""
    if separation not in SEPARATIONS:
        raise ValueError(f"separation must be one of {SEPARATIONS}, got {separation!r}")
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    return default_rtol(rtol, table_law=table_law)


def default_rtol(rtol, *, table_law: bool):
    """`rtol`, or where it is None the default that meets 1e-9 in e, T and x_max: 1e-11
    for a law of the table, 1e-12 for a user's law (`impact`, `bounce`, `fit_bounces`)."""
    if rtol is None:
        return DEFAULT_RTOL if table_law else CUSTOM_RTOL
    return rtol


def check_options(*, rtol, atol, rest_tol, max_steps, tau_max):
    """One-line errors for options outside their range (before anything is traced)."""
    for name, value in (("rtol", rtol), ("atol", atol), ("rest_tol", rest_tol)):
        if value is None and name == "atol":
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0 < value < 1:
            raise ValueError(f"{name} must be a number in (0, 1), got {value!r}")
    if isinstance(max_steps, bool) or not isinstance(max_steps, int) or max_steps < 1:
        raise ValueError(f"max_steps must be a positive integer, got {max_steps!r}")
    if (
        isinstance(tau_max, bool)
        or not isinstance(tau_max, (int, float))
        or not (tau_max > 0 and math.isfinite(tau_max))
    ):
        raise ValueError(f"tau_max must be a finite number > 0 (units of t*), got {tau_max!r}")


def similarity_reason(
    law, separation: str, *, g_is_zero: bool = True, ts=None, gravity_table: bool = False
) -> str | None:
    """Why the universal curves cannot give this impact, or `None` if they can.

    They need a one-group law of the table (`F = c x^n + b x^p v`: no dry force, which adds
    the group `P/(c x*^n)`; not Maxwell; not a custom law), no gravity (which adds
    `gamma = g x*/v0^2`) unless `gravity_table` (the caller can read the two-group table
    of `_curves.gravity` and integrate where it ends: `gravity_impact`) and the shape has
    one, no time histories, exponents known as numbers, and a shape whose impacts always
    separate (Hertz viscous under `"penetration"` is captured above a threshold, near which
    the contact lasts for ever)."""
    name = law.name
    if not g_is_zero and not gravity_table:
        return "gravity adds a second group m g/(c x*^n); pass g=0 (a Python 0) or integrate"
    if ts is not None:
        return "time histories (ts=...) need the integration"
    if not (law.spec and law.spec.one_group):
        return (
            f"law {name!r} is not one-group (a dry force, Maxwell's state or a custom law); "
            "use method='integrate'"
        )
    shape = shape_of(law)
    if shape is None:
        return (
            f"law {name!r} has its exponents {', '.join(law.spec.shape_parameters)} as traced "
            "values; give them as numbers"
        )
    key = curve_key(*shape, separation)
    if not serves(key):
        return (
            f"under separation={separation!r} the shape n={shape[0]:g}, p={shape[1]:g} is "
            "captured above a damping threshold, where the curves end; use method='integrate'"
        )
    if not g_is_zero and table_for(key) is None:
        return (
            f"gravity adds a second group g x*/v0^2, and the shape n={shape[0]:g}, "
            f"p={shape[1]:g} under separation={separation!r} has no gravity table; integrate"
        )
    return None


def choose_path(
    law,
    *,
    separation: str = "force",
    method: str = "auto",
    g=0.0,
    ts=None,
    solver=None,
    rtol: float = DEFAULT_RTOL,
    fit: bool = False,
) -> Path:
    """How an impact of `law` is computed (the only place that decides it): asked by
    `impact`, `impact_batch` (once for its rows), `bounce` and `fit_bounces` (once for every
    contact: `g` their gravity) and `calibrate` (`fit=True`).

    `method="auto"`: the law's closed form where one holds for these inputs (every `g`
    where its row says so, else `g = 0`; no time histories `ts`), else the universal
    curves (`similarity_reason`; with gravity the two-group table, integrated where it
    ends) unless a `solver` was chosen or `rtol < CURVES_RTOL`, else the integration.
    `"integrate"` always integrates; `"closed_form"` and `"similarity"` insist (a
    `ValueError` says why they cannot serve). Gravity is none only where `g` is a number
    0 (a static fact); an array or a traced value counts as gravity.

    `fit=True` is a fit's route (`calibrate`, its `method` one of `"auto"`,
    `"similarity"`, `"integrate"`): the curves first where they serve without gravity
    (before a closed form: the fit also starts on them), then a two-group table of the
    law's own (a dry force, an adhesion), then the closed form; no gravity table for a
    one-group law. The curves of a path that reads them are loaded (or, for a shape not
    shipped, built and cached) here, through `similarity_reason`, before anything is
    compiled: a compiled solve or fit never builds curves.
    """
    g_is_zero = is_no_gravity(g)
    if fit:
        return _fit_path(law, separation, method, g_is_zero, solver, rtol)
    closed = None if ts is not None else law.closed_form(separation, g_is_zero=g_is_zero)
    if method == "closed_form" and closed is None:
        raise ValueError(
            f"no closed form for law {law.name!r} with separation={separation!r}, "
            f"g={_shown(g)} and ts={'given' if ts is not None else None}"
        )
    if method == "similarity" or (method == "auto" and closed is None):
        reason = similarity_reason(law, separation, g_is_zero=g_is_zero, ts=ts, gravity_table=True)
        if reason is not None and method == "similarity":
            raise ValueError(f"method='similarity' cannot serve this impact: {reason}")
        # "auto" leaves the curves to a caller who chose how to integrate
        if reason is None and (method == "similarity" or (solver is None and rtol >= CURVES_RTOL)):
            key = curve_key(*shape_of(law), separation)
            return Path("similarity", key) if g_is_zero else Path("gravity_table", WithGravity(key))
    if closed is not None and method != "integrate":
        return Path("closed_form")
    if method in ("auto", "similarity") and solver is None and rtol >= CURVES_RTOL:
        table = table_key(law, separation, g_is_zero=g_is_zero, ts=ts)
        if table is not None:
            return _table_path(table)
    return Path("integrated")


def _fit_path(law, separation, method, g_is_zero, solver, rtol) -> Path:
    """`choose_path(..., fit=True)`: a fit's route."""
    fast = solver is None and rtol >= CURVES_RTOL  # "auto": the curves and tables
    if method in ("auto", "similarity"):
        reason = similarity_reason(law, separation, g_is_zero=g_is_zero)
        if reason is None and (method == "similarity" or fast):
            return Path("similarity", curve_key(*shape_of(law), separation))
        if method == "similarity":
            raise ValueError(f"method='similarity' cannot serve this fit: {reason}")
    elif method != "integrate":
        raise ValueError(f"method must be 'auto', 'similarity' or 'integrate', got {method!r}")
    if method == "auto" and fast:
        table = table_key(law, separation, g_is_zero=g_is_zero)
        if table is not None:
            return _table_path(table)
    if method == "auto" and law.closed_form(separation, g_is_zero=g_is_zero) is not None:
        return Path("closed_form")
    return Path("integrated")


def _table_path(table) -> Path:
    """The path of a two-group table, with the universal curves it corrects loaded now
    (shipped, cached or built: never inside a compiled solve or fit)."""
    curves_for(curve_key(table.key.n, table.key.p, table.key.separation))
    return Path(f"{table.group}_table", table)


def adhesion_table_key(law, *, ts=None) -> WithGravity | None:
    """The gravity table that reads a law whose constant force acts alike in both phases
    (its row's `constant_force`: DMT's adhesion pulls in as gravity does, `gamma - P/(c
    x*^n)`, any `g`), under the penetration criterion (its contact ends at `x = 0`); else
    `None`. Impacts outside the table (near capture) are integrated."""
    if not (law.spec and law.spec.constant_force) or ts is not None:
        return None
    key = curve_key(*(float(q) for q in law.spec.shape), "penetration")
    return WithGravity(key) if table_for(key) is not None else None


def table_key(law, separation: str, *, g_is_zero: bool, ts=None):
    """The two-group table that serves a law the curves do not (`dry_table_key`,
    `adhesion_table_key`), or `None`."""
    dry = dry_table_key(law, separation, g_is_zero=g_is_zero, ts=ts)
    return dry if dry is not None else adhesion_table_key(law, ts=ts)


def dry_table_key(law, separation: str, *, g_is_zero: bool, ts=None) -> WithDryForce | None:
    """The two-group table of a law whose dry force acts in both phases (its row's
    `dry_table`: Bingham-modified, eq. 8), where it serves: no gravity (a third group), no
    time histories, a shipped table for the law's shape under `separation`; else `None`.
    Impacts outside the table (a dry force near the one that holds the body) are
    integrated."""
    if not (law.spec and law.spec.dry_table) or not g_is_zero or ts is not None:
        return None
    key = CurveKey(*(float(q) for q in law.spec.shape), separation)
    return WithDryForce(key) if table_for(key, "dry") is not None else None


def make_options(
    path: Path, solve: SolveOptions, *, separation: str, inputs: tuple = (), gravity: bool = True
) -> ImpactOptions:
    """The `ImpactOptions` of a solve on `path` with the call's options `solve` (its
    tolerances resolved: `with_tolerances`; `max_steps`, `tau_max`, `peaks` set). Where the
    path integrates, `solve.solver` defaults to `diffrax.Tsit5()` and `solve.adjoint` to the
    cheapest one for the tracers in `inputs` (`adjoint.auto_adjoint`; no tracers:
    `RecursiveCheckpointAdjoint`); `gravity=False` where `g` is a number 0 (`is_no_gravity`)."""
    solver, adjoint = solve.solver, solve.adjoint
    if path.integrates:
        import diffrax as dfx

        from .adjoint import auto_adjoint

        solver = dfx.Tsit5() if solver is None else solver
        adjoint = auto_adjoint(*inputs) if adjoint is None else adjoint
    return ImpactOptions(
        separation=separation,
        closed_form=path.name == "closed_form",
        solver=solver,
        rtol=solve.rtol,
        atol=solve.atol,
        max_steps=solve.max_steps,
        tau_max=solve.tau_max,
        rest_tol=solve.rest_tol,
        adjoint=adjoint,
        peaks=solve.peaks,
        similarity=path.key,
        gravity=gravity,
    )


def is_no_gravity(g) -> bool:
    """Whether `g` is a number 0 (a Python or numpy scalar, not an array or a tracer):
    the one static fact that lets a solve compile without gravity."""
    return isinstance(g, (int, float)) and not isinstance(g, bool) and g == 0


def _shown(g) -> str:
    """`g` as a number for a message (a traced or per-row value as such)."""
    if is_traced(g):
        return "a traced value"
    try:
        return str(float(g))
    except (TypeError, ValueError):
        return "an array"
