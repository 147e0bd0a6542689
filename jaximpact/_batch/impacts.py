"""`impact_batch`: many impacts of one law from rows of parameters, masses, speeds and
gravities, through `run_batch`, on the closed-form, curves or integrated path chosen once
for the batch; a cost key (the dimensionless groups that fix an impact's step count) orders
the integrated rows so that each chunk holds members of similar cost.
"""

import functools
import warnings
from collections.abc import Mapping

import jax
import jax.numpy as jnp
import numpy as np

from .._checks import check_nonnegative, check_positive, invalid_entries
from .._laws import LAW_NAMES, LAWS, AbstractLaw, CustomLaw, custom_law, law as make_law
from .._laws.named_law import invalid_parameter_rows, table_law
from .._progress import AbstractMeter
from .._solve.impact import CURVES_RTOL, impact, similarity_reason
from .._status import Status
from .runner import run_batch

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
)


_GROUPS = ("beta", "mu", "dry_in", "dry_out", "gamma")  # dimensionless groups, by importance


def _law_skeleton(law):
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
def _impact_member(skeleton, fields: tuple, options: tuple):
    """One row -> the requested `ImpactResult` fields; cached per law structure and options,
    so every batch of the same kind reuses one compiled program per block shape. A row
    without `g` passes `g=0.0` as a number (so that `impact` may take a closed form)."""
    keywords = dict(options)

    def member(row):
        law = build_law(skeleton, row["params"])
        result = impact(law, m=row["m"], v0=row["v0"], g=row.get("g", 0.0), **keywords)
        return {name: getattr(result, name) for name in fields if getattr(result, name) is not None}

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
    rows can be read off the universal curves (which need the shape as numbers)."""
    if skeleton[0] != "law" or not LAWS[skeleton[1]].shape_parameters:
        return skeleton, params
    shape = LAWS[skeleton[1]].shape_parameters
    if not all(np.ptp(params[k]) == 0 for k in shape):
        return skeleton, params
    fixed = tuple((k, float(params[k][0])) for k in shape)
    return (*skeleton, fixed), {k: v for k, v in params.items() if k not in shape}


def batch_path(
    law, separation, *, method="auto", rtol=1e-11, g_is_zero=True, **impact_options
) -> str:
    """The path every row of a batch of `law`'s impacts takes: `"closed_form"`,
    `"similarity"` (the universal curves) or `"integrated"` (the same choice as `impact`'s
    `method="auto"`, made once for the batch)."""
    closed = law.closed_form(separation, g_is_zero=g_is_zero)
    if method != "integrate" and closed is not None:
        return "closed_form"
    if (
        g_is_zero
        and method in ("auto", "similarity")
        and rtol >= CURVES_RTOL
        and "solver" not in impact_options
        and similarity_reason(law, separation) is None
    ):
        return "similarity"
    return "integrated"


def prepare_rows(law, params, *, m, v0, g=0.0, invalid: str = "raise"):
    """Check a batch of impacts once, eagerly, and lay it out as rows.

    Returns `(skeleton, params, kinematics, bad)`: the law's hashable structure, its
    parameters and `{"m", "v0", "g"}` as 1-D float arrays of one common length (numbers and
    arrays broadcast), and the rows whose values were refused. `invalid="raise"`: a one-line
    `ValueError` naming the first bad value (`bad` is all False); `"mark"`: bad rows are
    filled with a good row's values (so that the batch runs) and flagged in `bad`; a batch
    with no good row still raises.
    """
    if invalid not in ("raise", "mark"):
        raise ValueError(f"invalid must be 'raise' or 'mark', got {invalid!r}")
    skeleton = _law_skeleton(law)
    base = {} if isinstance(law, str) else dict(law.parameters)
    given = {**base, **(params or {})}
    if skeleton[0] == "law":
        name = skeleton[1]
        if name not in LAWS:
            raise ValueError(f"unknown law {name!r}; choose one of: {', '.join(LAW_NAMES)}")
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
        if bad.any() and not bad.all():
            good = int(np.argmin(bad))
            arrays = {k: np.where(bad, v[good], v) for k, v in arrays.items()}
            kinematics = {k: np.where(bad, v[good], v) for k, v in kinematics.items()}
    if skeleton[0] == "law":
        make_law(skeleton[1], **arrays)
    else:
        custom_law(skeleton[1], **arrays)
    for key, what, unit, positive in (
        ("m", "mass m", "kg", True),
        ("v0", "impact speed v0", "m/s", True),
        ("g", "gravity g", "m/s^2", False),
    ):
        (check_positive if positive else check_nonnegative)(what, kinematics[key], unit)
    return skeleton, arrays, kinematics, bad


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


def impact_batch(
    law,
    params: dict | None = None,
    *,
    m=None,
    v0=None,
    g=0.0,
    separation: str = "force",
    method: str = "auto",
    rtol: float = 1e-11,
    peaks: bool = True,
    fields: tuple = IMPACT_FIELDS,
    order: str = "cost",
    chunk_size: int | None = None,
    progress: bool | AbstractMeter = True,
    devices=None,
    exact: bool = True,
    invalid: str = "mark",
    out=None,
    **impact_options,
) -> dict[str, np.ndarray]:
    """Impacts of many bodies at once: `impact` over a batch, in chunks, on all local devices.

    - `law`: a law name of `LAW_NAMES` (then `params` must hold all its parameters), or a
      law from `jaximpact.law` / `custom_law` whose parameters `params` may replace.
    - `params`: parameter name -> number or 1-D array (SI units, as in `jaximpact.law`).
    - `m` (kg), `v0` (m/s), `g` (m/s^2, along the inward normal): numbers or 1-D arrays.
      Every array is broadcast against the others: `n` rows.
    - `separation`, `method`, `rtol`, `peaks` and `impact_options` (`solver`, `atol`,
      `max_steps`, `tau_max`, `rest_tol`): as in `jaximpact.impact`.
    - `fields`: which `ImpactResult` fields to return (default `e, T, x_max, F_max, status`);
      with `peaks=False` the peak fields are left out.
    - `order`: `"cost"` (default) runs the rows sorted by their dimensionless groups (which
      fix the step count; see `run_batch`) and returns them in the given order; `"given"`
      runs them as given.
    - `chunk_size`: rows per device per compiled call (default 1024 for integrated impacts,
      65536 for closed forms and the universal curves, which cost little per row);
      `progress`, `devices`, `exact`: as
      in `run_batch`.

    - `invalid`: what a row with invalid inputs (NaN, infinite, a mass, speed or stiffness
      <= 0, a negative damping) does: `"mark"` (default) gives it status `Status.invalid`
      and NaN results, with a warning, while the other rows run; `"raise"` refuses the
      batch with a `ValueError` naming the first bad value.

    Returns a dict of numpy arrays of length `n` (`status` as integers of `Status`).
    Inputs are checked once for the whole batch, before any work.

    Streaming, as `jaximpact batch` does: with `params` an iterable of chunks (mappings
    column -> array, each holding any of the law's parameters and `m`, `v0`, `g`,
    `separation`; a generator is read once) and `out` a CSV or Parquet path, each chunk is
    computed and written as it comes, and a `BatchFile` record is returned (see
    `batch_file`; `resume=True` reuses the chunks an interrupted run finished). `law` must
    then be a name.

    **Example**:
    ```python
    out = impact_batch("hertz_rate", {"c": 2e6, "b1": np.linspace(100, 2000, 10_000)},
                       m=1.0, v0=2.5)
    out["e"], out["T"]
    ```
    """
    if out is not None or not (params is None or isinstance(params, Mapping)):
        return _stream(law, params, out, m=m, v0=v0, g=g, separation=separation,
                       method=method, rtol=rtol, progress=progress, **impact_options)  # fmt: skip
    if m is None or v0 is None:
        raise ValueError("impact_batch needs m= (kg) and v0= (m/s): numbers or 1-D arrays")
    if order not in ("cost", "given"):
        raise ValueError(f"order must be 'cost' or 'given', got {order!r}")
    unknown = sorted(set(fields) - set(_ALL_FIELDS))
    if unknown:
        raise ValueError(f"unknown fields {unknown}; choose from {_ALL_FIELDS}")
    skeleton, law_params, kinematics, bad = prepare_rows(
        law, params, m=m, v0=v0, g=g, invalid=invalid
    )
    skeleton, law_params = _fix_shape(skeleton, law_params)
    zero_gravity = bool(np.all(kinematics["g"] == 0.0))
    rows = {"params": law_params, "m": kinematics["m"], "v0": kinematics["v0"]}
    if not zero_gravity:
        rows["g"] = kinematics["g"]
    options = dict(separation=separation, method=method, rtol=rtol, peaks=peaks, **impact_options)
    try:
        member = _impact_member(skeleton, tuple(fields), tuple(sorted(options.items())))
    except TypeError:  # an option that cannot be hashed (an array): compiled for this call
        member = _impact_member.__wrapped__(skeleton, tuple(fields), tuple(options.items()))
    cost = None
    first = build_law(skeleton, {k: v[:1] for k, v in law_params.items()})
    path = batch_path(
        first, separation, method=method, rtol=rtol, g_is_zero=zero_gravity, **impact_options
    )
    closed = path != "integrated"
    if order == "cost" and not closed:
        cost = cost_key(skeleton, law_params, **kinematics)
    label = skeleton[1] if skeleton[0] == "law" else "custom law"
    out = run_batch(
        member,
        rows,
        chunk_size=(65536 if closed else 1024) if chunk_size is None else chunk_size,
        progress=progress,
        devices=devices,
        cost=cost,
        exact=exact,
        description=f"impacts ({label})",
    )
    out = {name: out[name] for name in fields if name in out}
    lost = _not_representable(out) & ~bad
    if lost.any():
        first = int(np.argmax(lost))
        message = (
            f"{int(lost.sum())} of {lost.size} rows have results that float64 cannot hold "
            f"(their scales under- or overflow, or the law gave NaN), the first at row {first}"
        )
        if invalid == "raise":
            raise ValueError(f"{message}: express the inputs in other units")
        warnings.warn(
            f"{message}: their status is Status.invalid and their results NaN", stacklevel=2
        )
    if bad.any():
        rows = np.flatnonzero(bad)
        warnings.warn(
            f"{rows.size} of {bad.size} rows have invalid inputs (not finite, or out of "
            f"range), the first at row {rows[0]}: their status is Status.invalid and their "
            "results NaN",
            stacklevel=2,
        )
    for name, values in out.items():
        if name == "status":
            out[name] = np.where(bad | lost, int(Status.invalid), values)
        elif np.issubdtype(values.dtype, np.floating):
            out[name] = np.where(bad | lost, np.nan, values)
    return out


def _stream(law, chunks, out, *, m, v0, g, separation, progress, **options):
    """`impact_batch` over an iterable of chunks, written to `out` (`batch_file`)."""
    from .files import batch_file

    if not isinstance(law, str):
        raise ValueError("impact_batch with chunks and out= takes a law name (see LAW_NAMES)")
    if out is None:
        raise ValueError("impact_batch over chunks needs out= (a CSV or Parquet path)")
    if chunks is None:
        raise ValueError("impact_batch with out= needs the chunks (an iterable of mappings)")
    # impact_batch's own defaults (g = 0, "force") are not a value given for every row:
    # a chunk's g or separation column then holds (batch_file refuses a column that
    # disagrees with a value given)
    default_g = isinstance(g, (int, float)) and not isinstance(g, bool) and g == 0.0
    return batch_file(chunks, out, law, m=m, v0=v0, g=None if default_g else g,
                      separation=None if separation == "force" else separation,
                      progress=progress, **options)  # fmt: skip
