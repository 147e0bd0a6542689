"""A ball dropped on a floor: free flights in closed form, one impact solve per contact.

The seed paper's system (17) (Polukoshko et al. 2007, section 7) integrates the whole motion,
flight and contact, with explicit Euler at a fixed step (`_solve.euler`). Here the free flight
is a parabola (or, with quadratic air drag, its closed form: `_solve.flight`), never
integrated, and each contact is one impact solve with gravity inside it (the same solve as
`jaximpact.impact(..., g=g)`): the law's exact solution where its row has one that holds
under gravity (Kelvin-Voigt, Bingham 7 and 9, Maxwell), else the gravity table or an
event-terminated integration. The contacts run in a `lax.scan` of static
length `max_impacts`; contacts after the end are masked, so the whole drop is one compiled
program, differentiable in both modes (shared/notes/diffrax-impact-notes.md, section 6).
"""

import dataclasses
import enum
import math
import warnings

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._checks import MemberChecks, is_traced
from .._compiling import solve_jit
from .._format import format_fields, format_value, jsonable
from .._laws import AbstractLaw
from .._status import Status
from .adjoint import auto_adjoint, reverse_only, through_forward_jacobian
from .flight import Flight
from .impact import SEPARATIONS, ImpactOptions, gravity_impact
from .options import (
    SolveOptions,
    choose_path,
    default_rtol,
    solve_options,
    with_defaults,
    with_tolerances,
)
from .phases import integrated_contact
from .results import ImpactResult, status_names, status_text


class BounceStatus(enum.IntEnum):
    """How a bounce sequence ended; `BounceResult.status` holds these as small integers.

    - `t_end`: the ball was still bouncing at `t_end` (its next landing comes later).
    - `at_rest`: the ball came to rest on the floor before `t_end`: a contact did not
      separate (gravity held the ball in the surface: the contact's status is `captured`, or
      `stuck` for a dry force), or a flight was shorter than `min_flight` (a restitution that
      stays finite at low speed gives infinitely many bounces in finite time; the sequence
      is cut there and the ball counted at rest from that landing on).
    - `max_impacts`: `max_impacts` contacts were used up before `t_end`; the results are
      right as far as they go.
    - `failed`: a contact solve ran out of steps (`max_steps`); results from that contact
      on are not to be trusted.
    - `invalid`: under `jit` or `vmap`, a drop whose inputs were refused (not finite, out
      of range, or `h0 = 0` with `v_drop = 0`): no contact, every result field NaN, while
      the other members have theirs (an eager call raises a one-line `ValueError`).
    """

    t_end = 0
    at_rest = 1
    max_impacts = 2
    failed = 3
    invalid = 4


_RUNNING = -1
# "auto": each contact from the law's exact solution with gravity where its row has one,
# else the gravity table or the integrator; "integrate": every contact integrated
BOUNCE_METHODS = ("auto", "integrate")


class BounceOptions(eqx.Module):
    """Everything static about a bounce sequence."""

    impact: ImpactOptions
    max_impacts: int = eqx.field(static=True)


def _contact(law, m, v_in, g, ts_local, options: ImpactOptions, active=True):
    """One contact at impact speed `v_in` with gravity `g`: the `ImpactResult`, the
    penetration at separation (m; > 0 when the force criterion ends contact inside the
    surface), and, with `ts_local` (s from first touch), the histories on that grid.
    Without histories, on the path `choose_path` decided (`bounce_options`): the law's
    exact solution under gravity where `options.closed_form` (Kelvin-Voigt, Bingham 7 and
    9, Maxwell), only where the contact is `active` (zeros elsewhere: a contact after the
    end of the drop costs nothing, but under `vmap`); the gravity table where
    `options.similarity` names one, for a contact whose `(beta, gamma)` it holds
    (`gravity_impact`); the others, and every contact with histories, integrated."""
    closed = None
    if ts_local is None and options.closed_form:
        closed = law.closed_form(options.separation, g_is_zero=False)
    if closed is not None:

        def exact(v_in):
            fields = closed(
                law,
                m=m,
                v0=v_in,
                g=g,
                rest_tol=options.rest_tol,
                tau_max=options.tau_max,
                with_end=True,
            )
            if not options.peaks:  # as the integrated path under peaks=False
                fields = {k: v for k, v in fields.items() if k not in ("x_max", "t_max", "F_max")}
            return fields

        def idle(v_in):
            shapes = jax.eval_shape(exact, v_in)
            return jax.tree.map(lambda a: jnp.zeros(a.shape, a.dtype), shapes)

        fields = jax.lax.cond(active, exact, idle, v_in)
        x_end = fields.pop("x_end")
        return ImpactResult(**fields, path="closed_form"), x_end
    dynamics = law.dynamics(m=m, v0=v_in, g=g)
    if ts_local is None and options.similarity is not None:
        return gravity_impact(dynamics, m, v_in, g, options)
    tau_grid = None if ts_local is None else ts_local / dynamics.t_star
    return integrated_contact(dynamics, options, m=m, v0=v_in, g=g, tau_grid=tau_grid)


class ChainState(eqx.Module):
    """What the scan over contacts carries from one contact to the next: the apex of the
    current flight (`t_apex` s, `y_apex` m), when that flight began (`t_release`, s),
    whether the drop goes on (`active`), its `BounceStatus` code so far, and where and when
    it came to rest (`t_rest` s, `y_rest` m; NaN and 0 until then)."""

    t_apex: Array
    y_apex: Array
    t_release: Array
    active: Array
    code: Array
    t_rest: Array
    y_rest: Array


def chain(law, m, g, drag, start, t_end, min_flight, ts, options: BounceOptions):
    """The scan over contacts. `start = (t0, y0, u0)`: the first flight's state (s, m, m/s,
    upward velocity). Returns the per-contact records (unmasked: a record whose `valid` is
    False comes from a dummy solve at unit speed and must not be used), the first flight,
    and the final `ChainState`."""
    flight0 = Flight.from_state(*start, g=g, drag=drag)
    zero = jnp.zeros_like(flight0.t_apex)

    def body(state: ChainState, k):
        t_apex, y_apex, t_release, active = (
            state.t_apex,
            state.y_apex,
            state.t_release,
            state.active,
        )
        code, t_rest, y_rest = state.code, state.t_rest, state.y_rest
        t_land, v_in = Flight(t_apex, y_apex, g, drag).landing()
        too_late = t_land > t_end
        too_short = ((k > 0) & (t_land - t_release < min_flight)) | (v_in <= 0)
        hit = active & ~too_late & ~too_short
        v_safe = jnp.where(hit, v_in, 1.0)
        local = None if ts is None else ts - jnp.where(hit, t_land, 0.0)
        contact, x_end = _contact(law, m, v_safe, g, local, options.impact, active=hit)
        separated = contact.status == Status.separated
        t_out = t_land + contact.T
        after = Flight.from_state(t_out, -x_end, -contact.v_out, g=g, drag=drag)
        go_on = hit & separated
        rests = active & ~too_late & too_short
        held = hit & ~separated
        failed = (contact.status == Status.out_of_steps) | (contact.status == Status.failed)
        code = jnp.where(active & too_late, BounceStatus.t_end, code)
        code = jnp.where(rests, BounceStatus.at_rest, code)
        code = jnp.where(held, jnp.where(failed, BounceStatus.failed, BounceStatus.at_rest), code)
        t_rest = jnp.where(rests, t_land, jnp.where(held & ~failed, t_out, t_rest))
        y_rest = jnp.where(held & ~failed, -x_end, y_rest)
        state = ChainState(
            t_apex=jnp.where(go_on, after.t_apex, t_apex),
            y_apex=jnp.where(go_on, after.y_apex, y_apex),
            t_release=jnp.where(go_on, t_out, t_release),
            active=go_on,
            code=code,
            t_rest=t_rest,
            y_rest=y_rest,
        )
        record = dict(
            valid=hit,
            separated=separated,
            t_land=t_land,
            v_in=v_in,
            e=contact.e,
            T=contact.T,
            v_out=-contact.v_out,
            x_end=x_end,
            t_out=t_out,
            t_apex=after.t_apex,
            y_apex=after.y_apex,
            status=contact.status,
            num_steps=contact.num_steps,
            x_max=contact.x_max,
            F_max=contact.F_max,
        )
        if ts is not None:
            record.update(x=contact.x, v=contact.v, F=contact.F)
        return state, record

    state0 = ChainState(
        t_apex=flight0.t_apex,
        y_apex=flight0.y_apex,
        t_release=zero + start[0],
        active=jnp.asarray(True),
        code=jnp.asarray(_RUNNING),
        t_rest=zero + jnp.nan,
        y_rest=zero,
    )
    state, records = jax.lax.scan(body, state0, jnp.arange(options.max_impacts))
    return records, flight0, state


class BounceResult(eqx.Module):
    """A ball dropped on a floor (SI units; `height` above the floor, velocities upward
    positive where signed).

    Arrays of length `max_impacts`, one entry per contact, padded with NaN after the last
    (`num_impacts` of them are real; `mask` says which):

    - `impact_times`, `release_times` (s): first touch and separation (NaN for a contact
      that did not separate).
    - `impact_speeds` (m/s, downward), `rebound_speeds` (m/s, upward, `e * impact_speeds`).
    - `e`, `T` (s): restitution and duration of each contact (gravity included).
    - `F_max` (N), `x_max` (m): peak contact force and maximum penetration (`None` under
      `peaks=False`).
    - `release_heights` (m): height at separation, `-x` there (negative: under the force
      criterion a damped contact ends while the surface is still pressed in).
    - `apex_times` (s), `apex_heights` (m): the top of the flight after each contact.
    - `contact_status`: each contact's `jaximpact.Status`.

    Scalars: `num_impacts`; `status` (a `BounceStatus`); `t_rest` (s): when the ball came
    to rest (NaN unless `status == at_rest`); `drop_apex_time`, `drop_apex_height`: the apex
    of the first flight (`0, h0` for a ball released at rest).

    `height(ts)`, `velocity(ts)` and `force(ts)` (N, on the ball, upward) evaluate the motion
    at any instants `ts` (s): closed-form flight between contacts, each contact's own
    solution inside it (re-integrated once, with output at `ts`), and rest on the floor after
    `t_rest`; NaN after the end of what was computed (the next landing after `t_end`, or
    after the last of `max_impacts` contacts). Before `t = 0` they continue the first flight
    backwards. At rest: after a contact that gravity held (status `captured`), the contact's
    solve stops where the ball first halts inside the surface; the decaying oscillation about
    the static deflection that follows is not integrated, and the height is held at that
    depth (within one static deflection of the floor), the velocity at 0 and the force at
    `m g`; after a flight shorter than `min_flight`, at 0.
    """

    impact_times: Array
    release_times: Array
    impact_speeds: Array
    rebound_speeds: Array
    e: Array
    T: Array
    release_heights: Array
    apex_times: Array
    apex_heights: Array
    contact_status: Array
    num_impacts: Array
    status: Array
    t_rest: Array
    drop_apex_time: Array
    drop_apex_height: Array
    num_steps: Array
    F_max: Array | None
    x_max: Array | None
    # what the histories need to re-run the contacts
    law: AbstractLaw
    m: Array
    g: Array
    drag: Array | None
    start: tuple
    t_end: Array
    min_flight: Array
    options: BounceOptions

    @property
    def mask(self) -> Array:
        """True for the entries of the per-contact arrays that are real contacts."""
        index = jnp.broadcast_to(jnp.arange(self.e.shape[-1]), self.e.shape)  # batches too
        return index < self.num_impacts[..., None]

    @property
    def status_name(self) -> str:
        """The status as a word (for one drop, not a batch)."""
        return BounceStatus(int(self.status)).name

    def summary(self, contacts: int = 6) -> str:
        """The drop as text, every number with its unit: how it ended, the number of
        contacts, when the ball came to rest, and one line per contact (time of first
        touch, speed in, `e`, `T`; the first and last when there are more than `contacts`).
        A batch of drops by the range of each field and the count of each status; inside
        `jit` the shapes."""
        rows = [
            ("status", status_text(self.status, BounceStatus)),
            ("num_impacts", format_value(self.num_impacts, None)),
            ("t_rest", _at_rest_text(self.t_rest)),
        ]
        traced = is_traced(self.e)
        if traced or np.ndim(self.num_impacts) > 0:  # the real contacts of all the drops
            for name, unit in (("e", ""), ("T", "s"), ("impact_speeds", "m/s")):
                values = getattr(self, name)
                real = values if traced else np.asarray(values)[np.asarray(self.mask)]
                rows.append((name, format_value(real, unit)))
            title = "BounceResult (SI units)" + ("" if traced else ", a batch of drops")
            return format_fields(title, rows)
        count = int(self.num_impacts)
        shown = list(range(count))
        if count > contacts:
            shown = shown[: contacts - 2] + [None] + shown[-2:]
        for k in shown:
            if k is None:
                rows.append(("...", f"{count - contacts} more contacts"))
                continue
            rows.append(
                (
                    f"contact {k + 1}",
                    f"at {format_value(self.impact_times[k], 's')}, "
                    f"{format_value(self.impact_speeds[k], 'm/s')} in, "
                    f"e = {format_value(self.e[k])}, T = {format_value(self.T[k], 's')}, "
                    f"{status_text(self.contact_status[k])}",
                )
            )
        return format_fields("BounceResult (SI units)", rows)

    def to_dict(self) -> dict:
        """The real contacts' fields as lists (SI units: s, m, m/s, N), NaN as None,
        `status` and `contact_status` as names; for a batch of drops every entry
        (padded contacts as None). Concrete results only (not inside `jit`)."""
        single = np.ndim(self.num_impacts) == 0
        count = int(self.num_impacts) if single else self.e.shape[-1]
        out = {
            name: jsonable(getattr(self, name)[..., :count])
            for name in _PER_CONTACT
            if getattr(self, name) is not None
        }
        if not single:
            out = {
                k: jsonable(np.where(np.asarray(self.mask), np.asarray(v, dtype=float), np.nan))
                for k, v in ((k, getattr(self, k)) for k in out)
            }
        out["contact_status"] = status_names(self.contact_status[..., :count])
        out["status"] = status_names(self.status, BounceStatus)
        out.update(
            {
                name: jsonable(getattr(self, name))
                for name in ("num_impacts", "t_rest", "drop_apex_time", "drop_apex_height")
            }
        )
        return out

    def __repr__(self) -> str:
        return self.summary()

    def trajectory(self, ts) -> tuple[Array, Array, Array]:
        """`(height, velocity, force)` at the times `ts` (s): m, m/s upward, N upward."""
        ts = jnp.asarray(ts, dtype=float)
        if ts.ndim != 1:
            raise ValueError("ts must be a 1-D array of times in seconds")
        if not is_traced(ts) and not bool(jnp.all(ts >= 0)):  # NaN too
            raise ValueError("ts must be times >= 0 s from the release (no NaN)")
        # any order: the solver's save times must increase, the caller's need not
        order = jnp.argsort(ts)
        back = jnp.argsort(order)
        refused = jnp.asarray(self.status) == BounceStatus.invalid  # no drop: NaN
        if refused.ndim:
            refused = False  # a batch of drops: each drop's own call (`jax.vmap`)
        return tuple(jnp.where(refused, jnp.nan, h[back]) for h in _histories(self, ts[order]))

    def height(self, ts) -> Array:
        """Height of the ball's lowest point above the undeformed floor (m) at `ts` (s);
        inside a contact `-x`, minus the penetration."""
        return self.trajectory(ts)[0]

    def velocity(self, ts) -> Array:
        """Upward velocity (m/s) at `ts` (s)."""
        return self.trajectory(ts)[1]

    def force(self, ts) -> Array:
        """Contact force on the ball (N, upward) at `ts` (s); `m g` once at rest."""
        return self.trajectory(ts)[2]


def _at_rest_text(t_rest) -> str:
    """`t_rest` as text: `-` for a drop that did not come to rest (NaN)."""
    if not is_traced(t_rest) and np.ndim(t_rest) == 0 and not np.isfinite(t_rest):
        return "- (not at rest)"
    return format_value(t_rest, "s")


# the fields of `BounceResult` that the histories re-run the drop from
_INPUTS = ("law", "m", "g", "drag", "start", "t_end", "min_flight", "options")
# the per-contact arrays of `BounceResult.to_dict` (`contact_status` apart, as names)
_PER_CONTACT = (
    "impact_times",
    "release_times",
    "impact_speeds",
    "rebound_speeds",
    "e",
    "T",
    "release_heights",
    "apex_times",
    "apex_heights",
    "F_max",
    "x_max",
)


@solve_jit
def _histories(result: BounceResult, ts):
    records, flight0, carry = chain(
        result.law,
        result.m,
        result.g,
        result.drag,
        result.start,
        result.t_end,
        result.min_flight,
        ts,
        result.options,
    )
    return trajectory_from_records(records, flight0, carry, ts, result.m, result.g, result.drag)


def trajectory_from_records(records, flight0, carry, ts, m, g, drag):
    """Height, upward velocity and contact force at `ts` from the chain's records (which
    must carry the contact histories on `ts`)."""
    valid, separated = records["valid"], records["separated"]
    t_land = jnp.where(valid, records["t_land"], jnp.inf)
    t_out = jnp.where(valid, records["t_out"], jnp.inf)
    n = ts.shape[0]
    k = jnp.searchsorted(t_land, ts, side="right") - 1  # the last contact begun, -1: none
    kk = jnp.maximum(k, 0)
    columns = jnp.arange(n)
    started = k >= 0
    in_contact = started & (ts <= t_out[kk])
    # the flight after contact k (or the first flight), and where it ends
    t_apex = jnp.concatenate([flight0.t_apex[None], records["t_apex"]])[k + 1]
    y_apex = jnp.concatenate([flight0.y_apex[None], records["y_apex"]])[k + 1]
    t_next = jnp.concatenate([t_land, jnp.asarray([jnp.inf])])[k + 1]
    final_apex, final_height = carry.t_apex, carry.y_apex
    code, t_rest, y_rest = carry.code, carry.t_rest, carry.y_rest
    next_landing = Flight(final_apex, final_height, g, drag).landing()[0]
    last_flight = ~jnp.isfinite(t_next)
    resting = code == BounceStatus.at_rest
    flight_end = jnp.where(last_flight, jnp.where(resting, t_rest, next_landing), t_next)
    in_flight = (~started | separated[kk]) & ~in_contact & (ts <= flight_end)
    at_rest = resting & ~in_contact & ~in_flight & (ts >= t_rest)
    y_flight, u_flight = Flight(t_apex, y_apex, g, drag).state(ts)
    y_rest_now = jnp.where(jnp.isfinite(y_rest), y_rest, 0.0)
    height = jnp.where(in_contact, -records["x"][kk, columns], jnp.nan)
    velocity = jnp.where(in_contact, -records["v"][kk, columns], jnp.nan)
    force = jnp.where(in_contact, records["F"][kk, columns], jnp.nan)
    height = jnp.where(in_flight, y_flight, jnp.where(at_rest, y_rest_now, height))
    velocity = jnp.where(in_flight, u_flight, jnp.where(at_rest, 0.0, velocity))
    force = jnp.where(in_flight, 0.0, jnp.where(at_rest, m * g, force))
    return height, velocity, force


@solve_jit
def solve_bounce(law, m, g, drag, start, t_end, min_flight, options: BounceOptions):
    records, flight0, carry = chain(law, m, g, drag, start, t_end, min_flight, None, options)
    valid = records["valid"]
    num = jnp.sum(valid)
    code, t_rest = carry.code, carry.t_rest
    # still bouncing after the last contact: was there time for another one?
    next_landing = Flight(carry.t_apex, carry.y_apex, g, drag).landing()[0]
    long_enough = (next_landing - carry.t_release) >= min_flight
    ran_out = (code == _RUNNING) & (next_landing <= t_end) & long_enough
    code = jnp.where(
        code == _RUNNING,
        jnp.where(
            ran_out,
            BounceStatus.max_impacts,
            jnp.where(next_landing > t_end, BounceStatus.t_end, BounceStatus.at_rest),
        ),
        code,
    )
    t_rest = jnp.where((code == BounceStatus.at_rest) & ~jnp.isfinite(t_rest), next_landing, t_rest)

    def pad(value, where=valid):
        return None if value is None else jnp.where(where, value, jnp.nan)

    separated = valid & records["separated"]
    return BounceResult(
        impact_times=pad(records["t_land"]),
        release_times=pad(records["t_out"], separated),
        impact_speeds=pad(records["v_in"]),
        rebound_speeds=pad(records["v_out"], separated),
        e=pad(records["e"]),
        T=pad(records["T"]),
        release_heights=pad(-records["x_end"], separated),
        apex_times=pad(records["t_apex"], separated),
        apex_heights=pad(records["y_apex"], separated),
        contact_status=jnp.where(valid, records["status"], -1),
        num_impacts=num,
        status=code.astype(jnp.int32),
        t_rest=t_rest,
        drop_apex_time=flight0.t_apex,
        drop_apex_height=flight0.y_apex,
        num_steps=jnp.sum(jnp.where(valid, records["num_steps"], 0)),
        F_max=pad(records["F_max"]),
        x_max=pad(records["x_max"]),
        law=law,
        m=m,
        g=g,
        drag=drag,
        start=start,
        t_end=t_end,
        min_flight=min_flight,
        options=options,
    )


def _check_real(name, value):
    """A number or array of real numbers (a traced one passes)."""
    if value is None and name == "drag" or is_traced(value):
        return
    try:
        kind = np.asarray(value).dtype.kind
    except (TypeError, ValueError):
        kind = "O"
    if kind not in "biuf":
        raise TypeError(f"{name} must be a real number, got {value!r}")


def _check_count(name, value):
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}")
    if value < 1:
        raise ValueError(f"{name} must be an integer >= 1, got {value!r}")


def _check_tolerance(name, value, below_one=False):
    """A static option: a real number > 0 (and < 1 for a relative tolerance)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, float, np.number)):
        raise TypeError(f"{name} must be a number, got {value!r}")
    if not (math.isfinite(value) and value > 0 and (value < 1 or not below_one)):
        limit = "0 < {name} < 1" if below_one else "a finite number > 0"
        raise ValueError(f"{name} must be {limit.format(name=name)}, got {value!r}")


# a drop's contacts always have gravity (`bounce` refuses g <= 0): what `choose_path` is told
_GRAVITY = 1.0


def bounce_options(
    law, solve: SolveOptions, *, separation="force", max_impacts=64, method="auto"
) -> BounceOptions:
    """The static options of a bounce of `law` (see `bounce`) from its `solve` options,
    whose `None` fields take `bounce`'s defaults (`rtol` by `default_rtol`, `rest_tol`
    1e-9; `adjoint` diffrax's `RecursiveCheckpointAdjoint`), and the path of its contacts,
    which `choose_path` decides (with gravity; `method="integrate"` integrates them)."""
    solve = with_defaults(solve, max_steps=4096, tau_max=1e4, rest_tol=1e-9, peaks=True)
    rtol = default_rtol(solve.rtol, table_law=law.spec is not None)
    if separation not in SEPARATIONS:
        raise ValueError(f"separation must be one of {SEPARATIONS}, got {separation!r}")
    if method not in BOUNCE_METHODS:
        raise ValueError(f"method must be one of {BOUNCE_METHODS}, got {method!r}")
    _check_count("max_impacts", max_impacts)
    _check_count("max_steps", solve.max_steps)
    _check_tolerance("rtol", rtol, below_one=True)
    if solve.atol is not None:
        _check_tolerance("atol", solve.atol)
    _check_tolerance("rest_tol", solve.rest_tol, below_one=True)
    _check_tolerance("tau_max", solve.tau_max)
    if not isinstance(solve.peaks, (bool, np.bool_)):
        raise TypeError(f"peaks must be True or False, got {solve.peaks!r}")
    solver, adjoint = solve.solver, solve.adjoint
    if solver is not None and not isinstance(solver, dfx.AbstractSolver):
        raise TypeError(f"solver must be a diffrax solver such as diffrax.Tsit5(), got {solver!r}")
    if adjoint is not None and not isinstance(adjoint, dfx.AbstractAdjoint):
        raise TypeError(
            f"adjoint must be a diffrax adjoint such as diffrax.ForwardMode(), got {adjoint!r}"
        )
    solve = with_tolerances(solve, rtol)
    # Tsit5 given is the default solver here: the gravity table still serves
    default = solver is None or type(solver) is dfx.Tsit5
    path = choose_path(
        law,
        separation=separation,
        method=method,
        g=_GRAVITY,
        solver=None if default else solver,
        rtol=solve.rtol,
    )
    return BounceOptions(
        impact=ImpactOptions(
            separation=separation,
            closed_form=path.name == "closed_form",
            solver=dfx.Tsit5() if solver is None else solver,
            rtol=solve.rtol,
            atol=solve.atol,
            max_steps=solve.max_steps,
            tau_max=solve.tau_max,
            rest_tol=solve.rest_tol,
            adjoint=dfx.RecursiveCheckpointAdjoint() if adjoint is None else adjoint,
            peaks=solve.peaks,
            similarity=path.key,  # the gravity table (`WithGravity`), or None
        ),
        max_impacts=int(max_impacts),
    )


def bounce(
    law: AbstractLaw,
    *,
    m,
    h0,
    t_end,
    v_drop=0.0,
    g=9.81,
    separation: str = "force",
    drag=None,
    max_impacts: int = 64,
    min_flight=1e-6,
    solver: dfx.AbstractSolver | None = None,
    rtol: float | None = None,
    atol: float | None = None,
    max_steps: int = 4096,
    tau_max: float = 1e4,
    rest_tol: float = 1e-9,
    adjoint: dfx.AbstractAdjoint | None = None,
    peaks: bool = True,
    method: str = "auto",
    throw: bool = False,
    options: SolveOptions | None = None,
) -> BounceResult:
    """A ball of mass `m` (kg) released at height `h0` (m) above a floor at `t = 0`, with
    downward speed `v_drop` (m/s; 0: dropped from rest), bouncing until `t_end` (s).

    The seed paper's system (17) (Polukoshko et al. 2007, section 7): `m y'' = -m g + N`,
    with the contact force `N` of `law` while the ball presses into the floor. Each free
    flight is solved in closed form (a parabola; with `drag`, the closed form of
    `u' = -g - k u |u|`), each contact by one impact solve of `m x'' = -F(x, x') + m g`
    from first touch to separation (the solve of `jaximpact.impact` with gravity). A
    contact that ends with the surface still pressed in (force criterion) starts its
    flight at that depth.

    - `separation`: `"force"` (the floor stops pushing) or `"penetration"` (x back to 0),
      as in `impact`.
    - `drag`: `k = rho C_d A / (2 m)` (1/m), or None for no air drag.
    - `max_impacts`: static bound on the number of contacts (the length of the compiled
      scan); running out of it before `t_end` gives `status == max_impacts`.
    - `min_flight` (s): a flight shorter than this ends the sequence with the ball at rest
      (with a speed-independent restitution the bounces accumulate in finite time).
    - `solver`, `rtol`, `atol`, `max_steps`, `tau_max`, `rest_tol`, `peaks`: each contact's
      solve, as in `impact` (`rtol` by default 1e-11 for a law of the table, 1e-12 for a
      user's law: each contact's e, T and x_max within 1e-9; `peaks=False` leaves `F_max`
      and `x_max` out and integrates each contact in one phase; the histories always use
      the three phases, so they then agree with the per-contact arrays to the solver's
      tolerance rather than exactly); `adjoint`:
      default picks the cheapest diffrax adjoint for the transformation in use
      (`ForwardMode` under `jax.jacfwd`). Tolerances must lie in (0, 1), `tau_max` be > 0,
      `max_steps` and `max_impacts` integers >= 1 (a ValueError otherwise).
    - `method`: `"auto"` takes each contact from the law's exact solution with gravity where
      its row has one (Kelvin-Voigt, Bingham 7 and 9, Maxwell: no ODE solve, `num_steps`
      0; `height`, `velocity` and `force` at given times still integrate them), else from
      the gravity table where it holds, else integrates; `"integrate"` integrates every
      contact.
    - `h0 = 0` needs a downward (or upward) `v_drop`: a ball at rest on the floor is refused.
    - `throw`: raise if the sequence failed or ran out of `max_impacts`; by default an
      eager call whose sequence failed (a contact's solve ran out of steps or failed) warns,
      and keeps the contacts before the failed one (the failed one's fields are NaN).
    - `options`: a `SolveOptions` holding any of `solver`, `rtol`, `atol`, `max_steps`,
      `tau_max`, `rest_tol`, `adjoint`, `peaks`, `throw` as one record (its `None` fields
      take the defaults above); a keyword that sets one of them to another value than the
      record does is refused (`ValueError`).
    Differentiable (forward and reverse mode) in the law's parameters, `m`, `h0`, `v_drop`,
    `g` and `drag`; works under `jax.vmap`. Under `jax.grad` alone (no `adjoint` given) the
    sequence's forward-mode Jacobian is transposed (`impact`'s rule).

    **Example**:
    ```python
    b = bounce(law("hertz_rate", c=1e6, b1=1350.0), m=1.0, h0=0.6, t_end=3.0)
    b.impact_times[:4], b.e[:4], b.height(jnp.linspace(0.0, 3.0, 500))
    ```
    """
    if not isinstance(law, AbstractLaw):
        raise TypeError(
            f"bounce needs a law from jaximpact.law(...) or jaximpact.custom_law(...), "
            f"got {type(law).__name__}"
        )
    for name, value in (
        ("m", m),
        ("h0", h0),
        ("t_end", t_end),
        ("g", g),
        ("v_drop", v_drop),
        ("min_flight", min_flight),
        ("drag", drag),
    ):
        _check_real(name, value)
    # eager: a one-line ValueError; traced: a bad member is NaN and invalid (`MemberChecks`)
    checks = MemberChecks()
    m = jnp.asarray(checks.positive("mass m", m, "kg"), dtype=float)
    h0 = jnp.asarray(checks.nonnegative("drop height h0", h0, "m", harmless=1.0), dtype=float)
    t_end = jnp.asarray(checks.positive("t_end", t_end, "s"), dtype=float)
    g = jnp.asarray(checks.positive("gravity g", g, "m/s^2"), dtype=float)
    v_drop = checks.values(v_drop, lambda a: False, "v_drop must be finite", harmless=0.0)
    v_drop = jnp.asarray(v_drop, float)
    min_flight = jnp.asarray(checks.nonnegative("min_flight", min_flight, "s"), dtype=float)
    if drag is not None:
        drag = checks.positive("air drag coefficient drag", drag, "1/m")
        drag = jnp.asarray(drag, dtype=float)
        concrete = not any(is_traced(a) for a in (drag, v_drop, g))
        if concrete and float(v_drop) > 0 and float(v_drop) ** 2 * float(drag) >= float(g):
            raise ValueError(
                f"v_drop = {float(v_drop)} m/s is not below the terminal speed "
                f"sqrt(g / drag) = {float(jnp.sqrt(g / drag)):.4g} m/s"
            )
    for name, value in (("m", m), ("h0", h0), ("t_end", t_end), ("g", g), ("v_drop", v_drop)):
        if jnp.ndim(value):
            raise ValueError(f"bounce takes a scalar {name}; use jax.vmap for a batch")
    resting = (h0 == 0) & (v_drop == 0)
    message = (
        "h0 = 0 with v_drop = 0: the ball starts at rest on the floor and never bounces "
        "(give a drop height h0 > 0 m or a downward speed v_drop > 0 m/s)"
    )
    if not any(is_traced(a) for a in (h0, v_drop)):
        if bool(resting):
            raise ValueError(message)
    else:
        h0 = checks.mark(resting, h0, 1.0)
    solve = solve_options(
        bounce,
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
    # jax.grad alone: the forward-mode Jacobian, transposed (`adjoint.by_forward_jacobian`)
    by_forward = solve.adjoint is None and reverse_only(law, m, h0, v_drop, g, drag, t_end)
    if by_forward:
        solve = dataclasses.replace(solve, adjoint=dfx.ForwardMode())
    elif solve.adjoint is None:
        solve = dataclasses.replace(solve, adjoint=auto_adjoint(law, m, h0, v_drop, g, drag, t_end))
    options = bounce_options(
        law, solve, separation=separation, max_impacts=max_impacts, method=method
    )
    start = (jnp.zeros(()), h0, -v_drop)
    if by_forward:
        result = through_forward_jacobian(
            lambda *args: solve_bounce(*args, options),
            law,
            m,
            g,
            drag,
            start,
            t_end,
            min_flight,
            closes_over=law.spec is None,
        )
    else:
        result = solve_bounce(law, m, g, drag, start, t_end, min_flight, options)
    # the inputs the histories re-run are kept (harmless); `trajectory` gives NaN for them
    result = checks.refuse(
        result, keep=_INPUTS, status=BounceStatus.invalid, num_impacts=0, contact_status=-1
    )
    if solve.throw:
        result = eqx.error_if(
            result,
            (result.status == BounceStatus.failed) | (result.status == BounceStatus.max_impacts),
            "the bounce sequence failed (a contact ran out of steps) or used up max_impacts",
        )
    elif not is_traced(result.status) and np.ndim(result.status) == 0:
        if int(result.status) == BounceStatus.failed:
            # the contacts before the failed one are right and worth having: a warning, the
            # failed contact and those after it NaN (the failure rule, `Status`)
            warnings.warn(
                f"the bounce sequence failed at contact {int(result.num_impacts)}: its solve "
                f"ran out of steps (max_steps={solve.max_steps}) or failed; the contacts before it "
                "are right, the rest NaN (raise max_steps or loosen rtol; throw=True raises)",
                stacklevel=2,
            )
    return result
