"""`impact_batch`: many impacts of one law from rows of parameters, masses, speeds and
gravities, arrays in and arrays out. The rows are checked once (`prepare_rows`), then
`run_impacts` computes them through `run_batch` with no further check, on the path that
`choose_path` decides once for the batch (`solve_impact` per row); a cost key (the
dimensionless groups that fix an impact's step count) orders the integrated rows so that
each chunk holds members of similar cost. An integrated batch of a law whose force is a
function of `(x, v)` first runs every row on the grid (`_solve.grid`: no event search), then
integrates, in a second batched pass, only the rows the grid did not serve. Files of rows
are `_jobs`'.
"""

import functools
import os
import sys
import warnings
from collections.abc import Mapping
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from .._checks import check_nonnegative, check_positive, invalid_entries
from .._choices import unknown_name
from .._laws import LAW_NAMES, LAWS, AbstractLaw, CustomLaw, custom_law
from .._laws.named_law import batch_law, invalid_parameter_rows, table_law
from .._solve.grid import GRID_FIELDS, grid_contact, grid_serves
from .._solve.impact import check_custom_law, solve_impact
from .._solve.options import (
    BATCH_DECIDES,
    SolveOptions,
    check_choices,
    check_options,
    choose_path,
    make_options,
    solve_options,
    with_defaults,
    with_tolerances,
)
from .._status import Status
from .runner import GLOBAL, run_batch

IMPACT_FIELDS = ("e", "T", "x_max", "F_max", "status")


_ALL_FIELDS = (
    "e",
    "T",
    "x_max",
    "t_max",
    "F_max",
    "dissipated",
    "v_out",
    "status",
    "num_steps",
    "path",  # the path that served each row (a string per row)
)


_GROUPS = ("beta", "mu", "dry_in", "dry_out", "gamma")  # dimensionless groups, by importance


def law_skeleton(law):
    """A hashable description of a law's structure (everything but its parameter values)."""
    if isinstance(law, str):
        return ("law", law)
    if isinstance(law, CustomLaw):
        return ("custom", law.fn, law.name)
    if isinstance(law, AbstractLaw) and law.spec is not None:
        return ("law", law.name)
    raise TypeError(
        f"impact_batch takes a law name or a law from jaximpact.law / custom_law, "
        f"got {type(law).__name__}"
    )


def build_law(skeleton, params):
    """The law of `skeleton` with `params` (arrays, possibly traced), without re-checking
    them (impact_batch has checked the whole batch at once). A table law's skeleton may
    carry fixed shape parameters as numbers (`_fix_shape`), which the row then lacks."""
    if skeleton[0] == "law":
        fixed = dict(skeleton[2]) if len(skeleton) > 2 else {}
        params = {**{k: jnp.asarray(v, dtype=float) for k, v in fixed.items()}, **params}
        return table_law(skeleton[1], {k: params[k] for k in LAWS[skeleton[1]].parameters})
    return CustomLaw(skeleton[1], params, skeleton[2])


@functools.lru_cache(maxsize=64)
def _impact_member(skeleton, fields: tuple, options, gravity: bool):
    """One checked row -> the requested `ImpactResult` fields of `solve_impact` with the
    batch's `options` (an `ImpactOptions`); cached per law structure and options, so every
    batch of the same kind reuses one compiled program per block shape. A batch without
    gravity has no `g` in its rows: `g` is then the constant 0."""

    def member(row):
        law = build_law(skeleton, row["params"])
        g = row["g"] if gravity else jnp.asarray(0.0, dtype=float)
        result = solve_impact(law, row["m"], row["v0"], g, None, options)
        return {name: getattr(result, name) for name in fields if getattr(result, name) is not None}

    return member


@functools.lru_cache(maxsize=64)
def _grid_member(skeleton, fields: tuple, separation: str):
    """One checked row (no gravity) -> the `fields` of its contact on the grid
    (`grid_contact`) and `served`, whether the grid served it; cached as `_impact_member`."""

    def member(row):
        law = build_law(skeleton, row["params"])
        out = grid_contact(law, row["m"], row["v0"], separation=separation)
        return {name: out[name] for name in (*fields, "served")}

    return member


@functools.lru_cache(maxsize=64)
def _dynamics_fn(skeleton):
    def dynamics(params, m, v0, g):
        return build_law(skeleton, params).dynamics(m=m, v0=v0, g=g)

    return jax.jit(jax.vmap(dynamics))


def cost_key(skeleton, params, m, v0, g):
    """Sort keys that predict an impact's step count: its dimensionless groups (the damping
    group `beta` or Maxwell's `mu` first, then the dry-force and gravity groups), each on a
    log scale binned to 1/20 of a decade so that the later keys order rows of similar
    damping. `None` for a user's own law (its groups are unknown)."""
    if skeleton[0] != "law":
        return None
    groups = _dynamics_fn(skeleton)(params, m, v0, g)
    keys = []
    for name in _GROUPS:
        value = getattr(groups, name, None)
        if value is None:
            continue
        value = np.abs(np.asarray(value, dtype=float))
        if np.ptp(value) == 0:
            continue
        keys.append(np.round(20.0 * np.log10(value + 1e-300)))
    return keys or None


def _fix_shape(skeleton, params):
    """Move a table law's shape parameters (Hunt-Crossley's `n`, the power law's `n` and
    `p`) into the skeleton as numbers when they are the same on every row, so that the
    rows can be read off the universal curves (which need the shape as numbers).

    `build_law` makes them `jnp` constants, which a trace sees as traced values (JAX
    0.10): such rows are integrated today, and said to be (`_member_path`); keeping them
    numpy numbers would read them off the curves, a change of results left to its own
    issue."""
    if skeleton[0] != "law" or not LAWS[skeleton[1]].shape_parameters:
        return skeleton, params
    shape = LAWS[skeleton[1]].shape_parameters
    if not all(np.ptp(params[k]) == 0 for k in shape):
        return skeleton, params
    fixed = tuple((k, float(params[k][0])) for k in shape)
    return (*skeleton, fixed), {k: v for k, v in params.items() if k not in shape}


# a batch's `path` per row: on the gravity table, "integrated" (the batch does not tell the
# rows the table served from those it integrated)
_LABELS = {"gravity_table": "integrated", "dry_table": "integrated"}
# the keywords of `impact` that a batch passes on (beyond separation, method, rtol, peaks)
IMPACT_OPTIONS = ("solver", "atol", "max_steps", "tau_max", "rest_tol", "adjoint")
# `run_batch`'s keywords, passed on by `run_impacts`
_RUN = ("chunk_size", "progress", "devices", "exact")


def batch_path(law, separation, *, method="auto", rtol=1e-11, g=0.0, **impact_options) -> str:
    """The `path` that a batch of impacts of `law` (with its parameters, those of one row)
    reports: `"closed_form"`, `"similarity"` (the universal curves) or `"integrated"`, as
    `run_impacts` decides it (`choose_path` for the law as the batch's members see it; `g`
    an array: gravity given per row)."""
    params = {k: np.atleast_1d(np.asarray(v, dtype=float)) for k, v in law.parameters.items()}
    skeleton, params = _fix_shape(law_skeleton(law), params)
    gravity = not (isinstance(g, (int, float)) and g == 0)
    path, _ = _member_path(
        skeleton,
        params,
        gravity,
        separation=separation,
        method=method,
        solver=impact_options.get("solver"),
        rtol=rtol,
    )
    return _LABELS.get(path.name, path.name)


def prepare_rows(law, params, *, m, v0, g=0.0, invalid: str = "raise"):
    """Check a batch of impacts once, eagerly, and lay it out as rows.

    Returns `(skeleton, params, kinematics, bad)`: the law's hashable structure, its
    parameters and `{"m", "v0", "g"}` as 1-D float arrays of one common length (numbers and
    arrays broadcast), and the rows whose values were refused. `invalid="raise"`: a one-line
    `ValueError` naming the first bad value (`bad` is all False); `"mark"`: bad rows are
    filled with a good row's values (so that the batch runs) and flagged in `bad`; a batch
    with no good row still raises. Every row's values are checked once: by the law's own
    checks (`"raise"`), or row by row (`"mark"`, the names then by the law built from one
    row); `run_impacts` checks nothing again.
    """
    if invalid not in ("raise", "mark"):
        raise ValueError(f"invalid must be 'raise' or 'mark', got {invalid!r}")
    skeleton = law_skeleton(law)
    base = {} if isinstance(law, str) else dict(law.parameters)
    given = {**base, **(params or {})}
    if skeleton[0] == "law":
        name = skeleton[1]
        if name not in LAWS:
            raise ValueError(unknown_name("law", name, LAW_NAMES))
        given = {**LAWS[name].defaults, **given}
    arrays = {k: np.asarray(v, dtype=float) for k, v in given.items()}
    if {"m", "v0", "g"} & set(arrays):
        raise ValueError("a law parameter may not be called m, v0 or g")
    arrays.update(m=np.asarray(m, dtype=float), v0=np.asarray(v0, dtype=float))
    arrays["g"] = np.asarray(g, dtype=float)
    for key, value in arrays.items():
        if value.ndim > 1:
            raise ValueError(f"{key} must be a number or a 1-D array, got shape {value.shape}")
    try:
        arrays = dict(zip(arrays, np.broadcast_arrays(*arrays.values()), strict=True))
    except ValueError:
        shapes = {k: v.shape for k, v in arrays.items()}
        raise ValueError(f"the inputs do not broadcast to one batch: {shapes}") from None
    arrays = {k: np.atleast_1d(np.ascontiguousarray(v)) for k, v in arrays.items()}
    kinematics = {k: arrays.pop(k) for k in ("m", "v0", "g")}
    bad = np.zeros(kinematics["m"].shape, bool)
    if invalid == "mark":
        bad = _invalid_rows(skeleton, arrays, kinematics)
    if invalid == "raise" or bad.all():  # the law's and the kinematics' own one-line errors
        _check_all(skeleton, arrays, kinematics)
        return skeleton, arrays, kinematics, bad
    if bad.any():
        good = int(np.argmin(bad))
        arrays = {k: np.where(bad, v[good], v) for k, v in arrays.items()}
        kinematics = {k: np.where(bad, v[good], v) for k, v in kinematics.items()}
    _law_of(skeleton, {k: v[:1] for k, v in arrays.items()})  # the names: unknown, missing
    return skeleton, arrays, kinematics, bad


def _law_of(skeleton, params):
    """The law of `skeleton` built from `params` (1-D arrays) by the law's own checks
    (names, values)."""
    if skeleton[0] == "law":
        return batch_law(skeleton[1], **params)
    return custom_law(skeleton[1], **params)


def _check_all(skeleton, params, kinematics):
    """Every value of a batch by the checks of the law and of `impact`: a one-line
    `ValueError` naming the first bad one."""
    _law_of(skeleton, params)
    for key, what, unit, positive in (
        ("m", "mass m", "kg", True),
        ("v0", "impact speed v0", "m/s", True),
        ("g", "gravity g", "m/s^2", False),
    ):
        (check_positive if positive else check_nonnegative)(what, kinematics[key], unit)


def _not_representable(out: dict) -> np.ndarray:
    """Rows whose computed results are not finite numbers, or separated with T <= 0 (an
    impact whose scales under- or overflow float64, e.g. v0 = 1e-300 m/s)."""
    n = next(iter(out.values())).shape[0]
    lost = np.zeros(n, bool)
    for name, values in out.items():
        if name != "status" and np.issubdtype(values.dtype, np.floating):
            lost |= ~np.isfinite(values)
    if "T" in out and "status" in out:
        lost |= (out["status"] == int(Status.separated)) & ~(out["T"] > 0)
    return lost


def _invalid_rows(skeleton, params, kinematics) -> np.ndarray:
    """Rows that `prepare_rows(invalid="raise")` would refuse."""
    if skeleton[0] == "law":
        bad = invalid_parameter_rows(skeleton[1], params)
    else:  # a user's law: its parameters must be finite
        bad = np.zeros(kinematics["m"].shape, bool)
        for value in params.values():
            bad |= ~np.isfinite(value)
    bad |= invalid_entries(kinematics["m"], lambda a: a <= 0)
    bad |= invalid_entries(kinematics["v0"], lambda a: a <= 0)
    return bad | invalid_entries(kinematics["g"], lambda a: a < 0)


class Impacts(NamedTuple):
    """What `run_impacts` computed: `out` (field -> one value per row), `lost` (the rows
    whose results float64 cannot hold), `path`, the way the batch went (`batch_path`;
    `"grid"` where the grid served every row), and `paths`, the way each row went (`"grid"`
    for the rows the grid served, the others on `path`)."""

    out: dict
    lost: np.ndarray
    path: str
    paths: np.ndarray


def run_impacts(
    skeleton,
    params: dict,
    kinematics: dict,
    *,
    separation: str = "force",
    method: str = "auto",
    fields: tuple = IMPACT_FIELDS,
    order: str = "cost",
    options: SolveOptions | None = None,
    **keywords,
) -> Impacts:
    """The impacts of rows already checked (`prepare_rows`, or a table's row checks): the
    law's structure `skeleton`, its `params` and `kinematics` (`m`, `v0`, `g`) as 1-D
    arrays of one length. No value is checked here; the options are (`impact`'s errors),
    and the path is chosen once for the batch (`choose_path`). `options`: the impacts'
    `SolveOptions` (`rtol` None: `impact`'s default, 1e-11 or a user's law 1e-12);
    `keywords`: `run_batch`'s `chunk_size`, `progress`, `devices`, `exact`, and the fields
    of `options` one by one (`rtol` by default 1e-11, `peaks`, `impact_options`), as in
    `impact_batch`."""
    run = {k: keywords.pop(k) for k in _RUN if k in keywords}
    unknown = sorted(set(keywords) - {"rtol", "peaks", *IMPACT_OPTIONS})
    if unknown:
        raise TypeError(
            f"impact_batch got an unexpected keyword argument {unknown[0]!r}; its options "
            f"for each impact are {', '.join(IMPACT_OPTIONS)} (see jaximpact.impact)"
        )
    if "rtol" not in keywords and (options is None or options.rtol is None):
        keywords["rtol"] = 1e-11
    solve = solve_options("impact_batch", options, refused=BATCH_DECIDES, **keywords)
    solve = with_defaults(solve, max_steps=4096, tau_max=1e4, rest_tol=1e-7, peaks=True)
    rtol = check_choices(separation, method, solve.rtol, table_law=skeleton[0] == "law")
    check_options(
        rtol=rtol,
        atol=solve.atol,
        rest_tol=solve.rest_tol,
        max_steps=solve.max_steps,
        tau_max=solve.tau_max,
    )
    skeleton, params = _fix_shape(skeleton, params)
    gravity = not bool(np.all(kinematics["g"] == 0.0))
    rows = {"params": params, "m": kinematics["m"], "v0": kinematics["v0"]}
    if gravity:
        rows["g"] = kinematics["g"]
    solver, peaks = solve.solver, solve.peaks
    path, plain = _member_path(
        skeleton, params, gravity, separation=separation, method=method, solver=solver, rtol=rtol
    )
    # one program over every process's devices pairs the processes' calls: each gives the
    # same rows, which a second pass over each one's own left rows would not
    spans = isinstance(run.get("devices"), str) and run["devices"] == GLOBAL
    grid = not spans and grid_serves(
        path, plain, method=method, solver=solver, rtol=rtol, gravity=gravity
    )
    options = make_options(
        path, with_tolerances(solve, rtol), separation=separation, gravity=gravity
    )
    computed = tuple(name for name in fields if name != "path")
    try:
        member = _impact_member(skeleton, computed, options, gravity)
    except TypeError:  # an option that cannot be hashed (an array): compiled for this call
        member = _impact_member.__wrapped__(skeleton, computed, options, gravity)
    label = skeleton[1] if skeleton[0] == "law" else "custom law"
    chunk_size = run.pop("chunk_size", None)
    chunk = (1024 if path.integrates else 65536) if chunk_size is None else chunk_size
    batch = dict(progress=True, devices=None, exact=True) | run
    name = _LABELS.get(path.name, path.name)
    paths = np.full(rows["m"].shape, name)
    if grid:  # every row on the grid, then the rows it did not serve integrated
        on_grid = _grid_member(skeleton, _grid_fields(computed, plain, peaks), separation)
        out = run_batch(
            on_grid,
            rows,
            chunk_size=chunk,
            cost=None,
            description=f"impacts ({label}) on the grid",
            **batch,
        )
        served = out.pop("served")
        paths = np.where(served, "grid", name)
        left = np.flatnonzero(~served)  # gathered on the host: one more batched pass
        if left.size:
            part = jax.tree.map(lambda a: a[left], rows)
            cost = None
            if order == "cost":
                kept = {k: v[left] for k, v in kinematics.items()}
                cost = cost_key(skeleton, part["params"], **kept)
            rest = run_batch(
                member,
                part,
                chunk_size=chunk,
                cost=cost,
                description=f"impacts ({label}) the grid left",
                **batch,
            )
            for key, values in rest.items():
                out[key][left] = values
        name = "grid" if served.all() else name
    else:
        cost = None
        if order == "cost" and path.integrates:
            cost = cost_key(skeleton, params, **kinematics)
        out = run_batch(
            member, rows, chunk_size=chunk, cost=cost, description=f"impacts ({label})", **batch
        )
    out = {key: out[key] for key in computed if key in out}
    if "path" in fields:
        out["path"] = paths
    return Impacts(out, _not_representable(out), name, paths)


def _grid_fields(fields: tuple, law, peaks: bool) -> tuple:
    """The `fields` the grid gives, as the integrated member gives them: without `peaks`
    no `F_max`, and `x_max`, `t_max` only for a law split at maximum compression (its row's
    `split`)."""
    dropped = set() if peaks else {"F_max"}
    if not peaks and not (law.spec and law.spec.split):
        dropped |= {"x_max", "t_max"}
    return tuple(name for name in fields if name in GRID_FIELDS and name not in dropped)


def _member_path(skeleton, params, gravity: bool, **choice):
    """`choose_path` for the law as every member of the batch sees it (one row, its
    parameters traced values, the shape that `_fix_shape` fixed as numbers), and a user's
    force function tried (`check_custom_law`): once for the batch, with no numbers. Returns
    the path and the law built from the first row's numbers (what the grid reads of it:
    `has_state`, `spec`)."""
    decided = []

    def member(row):
        law = build_law(skeleton, row["params"])
        check_custom_law(law, row["v0"])
        decided.append(choose_path(law, g=row["g"] if gravity else 0.0, **choice))
        return row["v0"]

    row = {"params": {k: v[0] for k, v in params.items()}, "v0": 1.0, "g": 1.0}
    jax.eval_shape(member, row)
    return decided[0], build_law(skeleton, row["params"])


def mark_invalid(out: dict, rows: np.ndarray) -> dict:
    """`out` with `rows` given status `Status.invalid` and NaN results."""
    marked = {}
    for name, values in out.items():
        if name == "status":
            marked[name] = np.where(rows, int(Status.invalid), values)
        elif np.issubdtype(values.dtype, np.floating):
            marked[name] = np.where(rows, np.nan, values)
        else:
            marked[name] = values
    return marked


def impact_batch(
    law, params: Mapping | None = None, *, m=None, v0=None, g=0.0, invalid="mark", **keywords
) -> dict[str, np.ndarray]:
    """Impacts of many bodies at once, arrays in and arrays out: the computation behind
    `jaximpact.impact_batch` (whose docstring has every argument), without its chunks and
    files (`_jobs`); `keywords`: `run_impacts`' (`separation`, `method`, `fields`, `order`,
    `options`, `rtol`, `peaks`, `chunk_size`, `progress`, `devices`, `exact`, and the
    `impact_options`). Returns a dict of numpy arrays, one value per row."""
    if params is not None and not isinstance(params, Mapping):
        raise TypeError(
            "params must be a mapping name -> number or 1-D array; chunks with out= are "
            "jaximpact.impact_batch's"
        )
    if m is None or v0 is None:
        raise ValueError("impact_batch needs m= (kg) and v0= (m/s): numbers or 1-D arrays")
    order = keywords.get("order", "cost")
    if order not in ("cost", "given"):
        raise ValueError(f"order must be 'cost' or 'given', got {order!r}")
    unknown = sorted(set(keywords.get("fields", IMPACT_FIELDS)) - set(_ALL_FIELDS))
    if unknown:
        raise ValueError(f"unknown fields {unknown}; choose from {_ALL_FIELDS}")
    skeleton, law_params, kinematics, bad = prepare_rows(
        law, params, m=m, v0=v0, g=g, invalid=invalid
    )
    done = run_impacts(skeleton, law_params, kinematics, **keywords)
    lost = done.lost & ~bad
    if lost.any():
        first = int(np.argmax(lost))
        message = (
            f"{int(lost.sum())} of {lost.size} rows have results that float64 cannot hold "
            f"(their scales under- or overflow, or the law gave NaN), the first at row {first}"
        )
        if invalid == "raise":
            raise ValueError(f"{message}: express the inputs in other units")
        warnings.warn(
            f"{message}: their status is Status.invalid and their results NaN",
            stacklevel=_callers_level(),
        )
    if bad.any():
        rows = np.flatnonzero(bad)
        warnings.warn(
            f"{rows.size} of {bad.size} rows have invalid inputs (not finite, or out of "
            f"range), the first at row {rows[0]}: their status is Status.invalid and their "
            "results NaN",
            stacklevel=_callers_level(),
        )
    return mark_invalid(done.out, bad | lost)


_PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _callers_level() -> int:
    """The `stacklevel` of a warning from the function that calls this one, such that it
    names the first line outside the package (the user's call, through any of its entry
    points: `jaximpact.impact_batch`, a study)."""
    frame, level = sys._getframe(1), 1
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE):
        frame, level = frame.f_back, level + 1
    return level
