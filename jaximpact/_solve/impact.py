"""One impact: read off the universal curves, taken from a closed form, or integrated
with diffrax and ended by events (`_integrate`, imported only when needed), on the path that
`options.choose_path` decides."""

import dataclasses
import math
import warnings

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._checks import MemberChecks, check_scale, is_traced
from .._compiling import solve_jit
from .._curves.gravity import WithGravity, gravity_fields
from .._curves.similarity import similarity_fields
from .._laws import AbstractLaw
from .._status import Status
from .options import (
    SEPARATIONS as SEPARATIONS,
    ImpactOptions as ImpactOptions,
    SolveOptions,
    check_choices,
    check_options,
    choose_path,
    is_no_gravity,
    make_options,
    similarity_reason as similarity_reason,
    solve_options,
    with_tolerances,
)
from .results import ImpactResult


@solve_jit
def solve_impact(law, m, v0, g, ts, options: ImpactOptions) -> ImpactResult:
    """The compiled part of `impact`, cached per law structure and options; no input
    checks (callers inside the library that have validated their inputs use it)."""
    if not options.gravity:  # g is 0, a static fact: no gravity's branches are compiled
        g = 0.0
    dynamics = law.dynamics(m=m, v0=v0, g=g)
    if isinstance(options.similarity, WithGravity):
        return gravity_impact(dynamics, m, v0, g, options)[0]
    if options.similarity is not None:
        fields = similarity_fields(dynamics, options.similarity, m=m, v0=v0, peaks=options.peaks)
        return ImpactResult(**fields, path="similarity")
    if options.closed_form:
        # gravity reaches here only for a law whose closed form holds for every g
        closed = law.closed_form(options.separation)
        fields = closed(law, m=m, v0=v0, g=g, rest_tol=options.rest_tol, tau_max=options.tau_max)
        return ImpactResult(**fields, path="closed_form")
    from .phases import integrated_contact

    tau_grid = None if ts is None else ts / dynamics.t_star
    # with a time grid the histories need the integration itself
    creep = dynamics.creeping(options.rest_tol) if tau_grid is None else None
    return integrated_contact(
        dynamics,
        options,
        m=m,
        v0=v0,
        g=g,
        tau_grid=tau_grid,
        hold=None if creep is None else creep["captured"],
        creep=creep,
    )[0]


def raise_if_failed(result, *, max_steps, rtol, what="the impact's solve"):
    """An eager (concrete, scalar) result whose solve failed raises a one-line
    `RuntimeError` that says what to change; traced or batched results pass (their failed
    members are NaN with their status)."""
    status = result.status
    if is_traced(status) or np.ndim(status) != 0:
        return
    status = Status(int(status))
    if status == Status.out_of_steps:
        raise RuntimeError(
            f"{what} ran out of steps (max_steps={max_steps}) before the contact ended: "
            f"raise max_steps or loosen rtol (now {rtol:g}); throw=False returns NaN "
            "with status out_of_steps"
        )
    if status == Status.failed:
        raise RuntimeError(
            f"{what} failed (the step size fell below diffrax's minimum or the force was "
            "not a number along the solve): check that the law is finite inside the "
            "surface or loosen rtol; throw=False returns NaN with status failed"
        )


def _check_representable(result, m, v0, g):
    """A concrete impact with a result that float64 cannot hold (its scales under- or
    overflow, e.g. v0 = 1e-300 m/s or g = 1e300 m/s^2) is refused, not returned as T = 0
    or NaN."""
    if is_traced(result.T) or np.ndim(result.T) != 0:
        return
    if Status(int(result.status)).is_failure:
        return  # NaN by the failure rule, its status says why
    fields = {k: getattr(result, k) for k in ("e", "T", "x_max", "F_max", "t_max", "dissipated")}
    values = {k: float(v) for k, v in fields.items() if v is not None}
    separated = int(result.status) == Status.separated
    if all(np.isfinite(list(values.values()))) and not (separated and values["T"] <= 0):
        return
    raise ValueError(
        f"m = {float(m):g} kg, v0 = {float(v0):g} m/s, g = {float(g):g} m/s^2 put the "
        f"contact's scales outside float64's range (T = {values['T']:g} s, x_max = "
        f"{values.get('x_max', math.nan):g} m): express the inputs in other units"
    )


# what to write instead, for the errors of Python and numpy code given traced x, v, params
_IF_HINT = (
    "; x, v and the parameters are traced arrays: write if, max, min, abs and math on "
    "them with jnp (jnp.where, jnp.maximum, jnp.minimum, jnp.abs, jnp.sqrt)"
)
_TRACED_HINTS = {
    "TracerBoolConversionError": _IF_HINT,
    "ConcretizationTypeError": _IF_HINT,
    "TracerIntegerConversionError": _IF_HINT,
    "TracerArrayConversionError": "; use jax.numpy (jnp), not numpy (np), inside the law",
}


def check_custom_law(law, v0):
    """A user's law is tried at first touch before it is integrated: its function must give
    one real force (a `TypeError` or `ValueError` says what it gave instead), finite; one
    that pulls the body in there (`F(0, v0) < 0`) is not a contact force law, and what
    `impact` returns for it is said to be so (a warning), not left as a plain number."""
    if law.spec is not None:  # a law of the table: checked by its row
        return
    try:
        out = jax.eval_shape(law.force, 0.0, v0)
    except Exception as error:  # the user's function failed: say where, in one line
        first = (str(error).strip().splitlines() or [""])[0]
        kind = TypeError if isinstance(error, TypeError) else ValueError
        raise kind(
            f"the custom law's function failed at x = 0, v = v0 ({type(error).__name__}: "
            f"{first}); it must take (x, v, params) and return the force in N"
            + _TRACED_HINTS.get(type(error).__name__, "")
        ) from error
    batch = np.broadcast_shapes(*(np.shape(p) for p in law.parameters.values()))
    if (
        not hasattr(out, "dtype")
        or not jnp.issubdtype(out.dtype, jnp.floating)
        and not (jnp.issubdtype(out.dtype, jnp.integer))
    ):
        raise TypeError(
            f"the custom law's function must return a real force (N), got {out!r} at x = 0"
        )
    if out.shape not in ((), batch):
        raise TypeError(
            f"the custom law's function must return one force for one (x, v), got shape "
            f"{out.shape} at x = 0 (parameters of shape {batch})"
        )
    if is_traced(v0) or out.shape != ():
        return
    try:
        force = float(law.force(0.0, v0))
    except (TypeError, ValueError, jax.errors.ConcretizationTypeError):
        return  # traced parameters (inside jit): nothing to say before the solve
    if not math.isfinite(force):
        raise ValueError(
            f"the custom law's force at first touch is not a number (F(x = 0, v = "
            f"{float(v0):g} m/s) = {force}); give a law that is finite at x = 0 (guard "
            "fractional powers with jaximpact.safe_pow)"
        )
    if force < 0:
        warnings.warn(
            f"the law pulls the body in at first touch (F(x = 0, v = {float(v0):g} m/s) = "
            f"{force:.4g} N < 0): a contact force pushes (F >= 0); read e and T as those of "
            "an unphysical law",
            stacklevel=3,
        )


def _warn_if_energy_gained(law, result, m, v0):
    """A user's law that gives the body energy over the contact (`dissipated < 0`, e > 1
    without gravity: it pulls during the contact or its damping is negative) is said to be
    unphysical: a passive contact takes energy (it once returned e = 8.4 as a result)."""
    if law.spec is not None or is_traced(result.e):
        return
    if np.ndim(result.e) != 0 or int(result.status) != Status.separated:
        return
    kinetic = 0.5 * float(m) * float(v0) ** 2
    if float(result.dissipated) < -1e-6 * kinetic:
        warnings.warn(
            f"the law gives the body energy during the contact ({-float(result.dissipated):.4g}"
            f" J, e = {float(result.e):.4g}): a passive contact takes energy (its force pulls "
            "somewhere, or its damping is negative); read e and T as those of an unphysical "
            "law",
            stacklevel=3,
        )


def gravity_impact(dynamics, m, v0, g, options: ImpactOptions):
    """One contact from a two-group table (`_curves.gravity`: gravity, or a dry force in
    both phases) where `(beta, gamma)` (or `(beta, pi)`) lies in it, else integrated with
    `options` (a `lax.cond`; under `vmap` both run, and the integration skips the members
    the table serves, so a batch pays for the solver only where some member is outside;
    with `options.integrate_outside` False those members are NaN with the status
    `failed`, and nothing is integrated).
    Returns the `ImpactResult` (path `"similarity"`) and the penetration at separation (m)."""
    from .phases import integrated_contact

    fields, x_end, in_range = gravity_fields(
        dynamics,
        options.similarity.key,
        m=m,
        v0=v0,
        g=g,
        peaks=options.peaks,
        group=options.similarity.group,
    )

    def same_types(values):
        return {
            k: jnp.asarray(v, jnp.int32 if k in ("status", "num_steps") else float)
            for k, v in values.items()
        }

    def table(_):
        return same_types(fields), jnp.asarray(x_end, float)

    if not options.integrate_outside:  # the caller integrates those members itself
        values, x = table(None)
        outside = {"status": Status.failed, "num_steps": 0}
        values = {k: jnp.where(in_range, v, outside.get(k, jnp.nan)) for k, v in values.items()}
        return ImpactResult(**values, path="similarity"), jnp.where(in_range, x, jnp.nan)

    def integrated(_):
        result, x = integrated_contact(dynamics, options, m=m, v0=v0, g=g, hold=in_range)
        return same_types({k: getattr(result, k) for k in fields}), jnp.asarray(x, float)

    values, x = jax.lax.cond(in_range, table, integrated, None)
    return ImpactResult(**values, path="similarity"), x


def impact(
    law: AbstractLaw,
    *,
    m,
    v0,
    separation: str = "force",
    g=0.0,
    ts=None,
    method: str = "auto",
    solver=None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int = 4096,
    tau_max: float = 1e4,
    rest_tol: float = 1e-7,
    adjoint=None,
    peaks: bool = True,
    throw: bool | None = None,
    options: SolveOptions | None = None,
) -> ImpactResult:
    """One impact of a body of mass `m` (kg) hitting the surface at speed `v0` (m/s).

    Integrates `m x'' = -F(x, x') + m g` from `x = 0`, `x' = v0` in the law's natural units
    (`x*`, `t* = x*/v0`), in three phases ended by events with a root finder (to the first
    force peak, to maximum compression, to separation), so `e` and `T` are exact to the
    tolerance and differentiable. `separation="force"` ends contact where the force returns
    to zero, `"penetration"` where `x` returns to zero.

    - `g`: gravity along the inward normal (m/s^2), 0 for an isolated impact.
    - `ts`: times (s from first touch) at which to return `x`, `v`, `F`; nothing is stored
      otherwise.
    - `method`: `"auto"` uses an exact closed form where one holds for every parameter value
      and no `ts` is asked (Kelvin-Voigt, Bingham 7 and 9, Maxwell: any `g`; Thornton and
      JKR: `g = 0`), else the universal curves where the impact
      depends on one group `beta` (a one-group law of the table, `g = 0`, no `ts`, no
      `solver` chosen, `rtol >= 1e-11`, and a shape whose impacts always separate; see
      `options.choose_path`), else integrates. `"integrate"` always integrates,
      `"closed_form"` and `"similarity"` insist (a `ValueError` says why they cannot).
    - `solver` (default `diffrax.Tsit5()`), `rtol`, `atol` (default `rtol`): in the
      nondimensional variables, so they are relative to the contact's own scales. The
      default, 1e-11 for a law of the table and 1e-12 for a user's law (whose `x^0.5`
      terms the solver meets as written, with their infinite slope at the surface), keeps
      e, T, x_max and F_max within 1e-9 of the exact values (the x^1.5 laws lose the
      solver's order where contact starts and ends).
    - `tau_max`: horizon in units of `t*`; a contact still going on there is `captured`.
    - `rest_tol`: a body whose speed (in units of `v0`) plus net force (in units of
      `m v0^2/x*`) falls below this is at rest: `captured` (or `stuck`), `T` is that time.
    - In float32 (JAX's x64 off) `rtol`, `atol` below 1e-7 and `rest_tol` below 1e-5 are
      raised to those values, with a warning: finer ones cannot be met in that precision.
    - `adjoint`: default picks the cheapest diffrax adjoint for the transformation in use
      (`ForwardMode` under `jax.jacfwd`; under `jax.grad` alone the forward-mode Jacobian,
      transposed, which runs about 10 times faster than diffrax's reverse mode for a few
      inputs; `RecursiveCheckpointAdjoint` otherwise). A given `adjoint` is used as is.
    - `peaks`: find `x_max`, `t_max`, `F_max` (extra events); `False` integrates a smooth
      law in a single phase, which is what fitting e and T needs.
    - `throw`: what a solve that did not end in separation does. `None` (default): an
      eager call whose solve failed (status `out_of_steps` or `failed`) raises a one-line
      `RuntimeError` that says what to change; under `jit` or `vmap` a failed member has
      NaN in every result field and its status says why. `True`: raise for any ending
      but `separated` (stuck and captured too; `eqx.error_if`, so also under `jit`).
      `False`: never raise (a failed result is NaN with its status).
    - `options`: a `SolveOptions` holding any of `solver`, `rtol`, `atol`, `max_steps`,
      `tau_max`, `rest_tol`, `adjoint`, `peaks`, `throw` as one record (its `None` fields
      take the defaults above); a keyword that sets one of them to another value than the
      record does is refused (`ValueError`).
    - Bad values (`m` or `v0` not > 0, `g` < 0, not finite): an eager call raises a one-line
      `ValueError`; under `jit`, `vmap` or `grad` that member has NaN in every result field
      (and its derivatives) and status `invalid`, and the other members are computed.

    **Example**:
    `impact(law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5).e` is about 0.83.
    """
    if not isinstance(law, AbstractLaw):
        raise TypeError(
            f"impact needs a law from jaximpact.law(...) or jaximpact.custom_law(...), "
            f"got {type(law).__name__}"
        )
    solve = solve_options(
        impact,
        options,
        solver=solver,
        rtol=rtol,
        atol=atol,
        max_steps=max_steps,
        tau_max=tau_max,
        rest_tol=rest_tol,
        adjoint=adjoint,
        peaks=peaks,
        throw=throw,
    )
    rtol = check_choices(separation, method, solve.rtol, table_law=law.spec is not None)
    check_options(
        rtol=rtol,
        atol=solve.atol,
        rest_tol=solve.rest_tol,
        max_steps=solve.max_steps,
        tau_max=solve.tau_max,
    )
    # eager: a one-line ValueError; traced: a bad member is NaN and invalid (`MemberChecks`)
    checks = MemberChecks()
    # 1e-300 kg is refused as 1e300 kg is: the contact's scales would under- or overflow
    m = check_scale("mass m", checks.positive("mass m", m, "kg"), "kg")
    v0 = check_scale("impact speed v0", checks.positive("impact speed v0", v0, "m/s"), "m/s")
    m = jnp.asarray(m, dtype=float)
    v0 = jnp.asarray(v0, dtype=float)
    given_g = g  # a number 0 is no gravity, a static fact (choose_path)
    g = jnp.asarray(checks.nonnegative("gravity g", g, "m/s^2"), dtype=float)
    if jnp.ndim(m) or jnp.ndim(v0) or jnp.ndim(g):
        raise ValueError("impact takes scalar m, v0 and g; use jax.vmap for a batch")
    path = choose_path(
        law, separation=separation, method=method, g=given_g, ts=ts, solver=solve.solver, rtol=rtol
    )
    check_custom_law(law, v0)
    if ts is not None:
        ts = jnp.asarray(ts, dtype=float)
        if ts.ndim != 1:
            raise ValueError("ts must be a 1-D array of times in seconds")
    options = make_options(
        path,
        with_tolerances(solve, rtol),
        separation=separation,
        inputs=(law, m, v0, g, ts),
        gravity=not is_no_gravity(given_g),
    )
    result = None
    if path.integrates and solve.adjoint is None:  # diffrax is imported there (`make_options`)
        import diffrax as dfx

        from .adjoint import reverse_only, through_forward_jacobian

        if reverse_only(law, m, v0, g, ts):
            # jax.grad through the integration: the forward-mode Jacobian, transposed
            # (`adjoint.by_forward_jacobian`): 10x faster than a reverse solve, compiled sooner
            forward = dataclasses.replace(options, adjoint=dfx.ForwardMode())
            result = through_forward_jacobian(
                lambda *args: solve_impact(*args, forward),
                law,
                m,
                v0,
                g,
                ts,
                closes_over=law.spec is None,
            )
    if result is None:
        result = solve_impact(law, m, v0, g, ts, options)
    result = checks.refuse(result, status=Status.invalid)
    if path.name in ("gravity_table", "dry_table") and not is_traced(result.num_steps):
        if int(result.num_steps) > 0:  # outside the table: integrated, and said so
            fields = {f.name: getattr(result, f.name) for f in dataclasses.fields(result)}
            result = ImpactResult(**{**fields, "path": "integrated"})
    if solve.throw is not False:
        raise_if_failed(result, max_steps=solve.max_steps, rtol=options.rtol)
    _check_representable(result, m, v0, g)
    _warn_if_energy_gained(law, result, m, v0)
    if solve.throw:
        result = eqx.error_if(
            result,
            result.status != Status.separated,
            "the impact did not end in separation (stuck, captured or out of steps)",
        )
    return result
