"""`jaximpact.impact_batch`: arrays in, arrays out (`_batch.impact_batch`), or chunks in and a
file out (`batch_file`), as `jaximpact batch` does."""

from collections.abc import Mapping

import numpy as np

from .._batch import IMPACT_FIELDS, IMPACT_OPTIONS, impacts
from .._laws import AbstractLaw
from .._progress import AbstractMeter
from .._solve.options import BATCH_DECIDES, SolveOptions, solve_options
from .job import BatchFile, batch_file


def impact_batch(
    law,
    params=None,
    *,
    m=None,
    v0=None,
    g=0.0,
    separation: str = "force",
    method: str = "auto",
    rtol: float | None = None,
    peaks: bool = True,
    fields: tuple = IMPACT_FIELDS,
    order: str = "cost",
    chunk_size: int | None = None,
    progress: bool | AbstractMeter = True,
    devices=None,
    exact: bool = True,
    invalid: str = "mark",
    out=None,
    options: SolveOptions | None = None,
    **impact_options,
) -> dict[str, np.ndarray] | BatchFile:
    """Impacts of many bodies at once: `impact` over a batch, in chunks, on all local devices.

    - `law`: a law name of `LAW_NAMES` (then `params` must hold all its parameters), or a
      law from `jaximpact.law` / `custom_law` whose parameters `params` may replace.
    - `params`: parameter name -> number or 1-D array (SI units, as in `jaximpact.law`).
    - `m` (kg), `v0` (m/s), `g` (m/s^2, along the inward normal): numbers or 1-D arrays.
      Every array is broadcast against the others: `n` rows.
    - `separation`, `method`, `rtol`, `peaks` and `impact_options` (`solver`, `atol`,
      `max_steps`, `tau_max`, `rest_tol`): as in `jaximpact.impact` (`rtol` by default
      1e-11; to a file, `impact`'s: 1e-11, a user's law 1e-12).
    - `fields`: which `ImpactResult` fields to return (default `e, T, x_max, F_max, status`);
      with `peaks=False` the peak fields are left out. `"path"` adds each row's path, a
      string: an integrated batch of a law whose force is a function of `(x, v)` (a user's
      law, a law of the table off the curves) without gravity, at `method="auto"` and the
      default tolerances, runs every row on a fixed grid of the contact's phase-plane angle
      first (no event search; `"grid"` where it served the row to 1e-9), then integrates
      only the rows it could not serve (heavy damping, a force that pulls, a body held),
      with their path `"integrated"`; `method="integrate"` integrates every row.
    - `order`: `"cost"` (default) runs the rows sorted by their dimensionless groups (which
      fix the step count; see `run_batch`) and returns them in the given order; `"given"`
      runs them as given.
    - `chunk_size`: rows per device per compiled call (default 1024 for integrated impacts,
      65536 for closed forms and the universal curves, which cost little per row);
      `progress`, `devices`, `exact`: as
      in `run_batch`.

    - `options`: a `SolveOptions` holding `rtol`, `peaks` and any of `impact_options` as
      one record (`throw` stays None: a batch reports each row's status); a keyword that
      sets one of them to another value than the record does is refused (`ValueError`).

    - `invalid`: what a row with invalid inputs (NaN, infinite, a mass, speed or stiffness
      <= 0, a negative damping) does: `"mark"` (default) gives it status `Status.invalid`
      and NaN results, with a warning, while the other rows run; `"raise"` refuses the
      batch with a `ValueError` naming the first bad value.

    Returns a dict of numpy arrays of length `n` (`status` as integers of `Status`).
    Inputs are checked once for the whole batch, before any work (`_batch.prepare_rows`).

    Streaming, as `jaximpact batch` does: with `params` an iterable of chunks (mappings
    column -> array, each holding any of the law's parameters and `m`, `v0`, `g`,
    `separation`; a generator is read once) and `out` a CSV or Parquet path, each chunk is
    computed and written as it comes, and a `BatchFile` record is returned (see
    `batch_file`; `resume=True` reuses the chunks an interrupted run finished). `law` is
    then a name, or a law (`jaximpact.law`, `custom_law`) whose parameters are the values
    every row takes unless a chunk's column gives them.

    **Example**:
    ```python
    out = impact_batch("hertz_rate", {"c": 2e6, "b1": np.linspace(100, 2000, 10_000)},
                       m=1.0, v0=2.5)
    out["e"], out["T"]
    ```
    """
    if options is not None:  # the record whole, each of its fields given once
        given = {k: impact_options.pop(k) for k in IMPACT_OPTIONS if k in impact_options}
        options = solve_options(
            impact_batch, options, refused=BATCH_DECIDES, rtol=rtol, peaks=peaks, **given
        )
    if out is None and (params is None or isinstance(params, Mapping)):
        settings = dict(
            m=m,
            v0=v0,
            g=g,
            separation=separation,
            method=method,
            fields=fields,
            order=order,
            chunk_size=chunk_size,
            progress=progress,
            devices=devices,
            exact=exact,
            invalid=invalid,
        )
        if options is not None:
            return impacts.impact_batch(law, params, **settings, options=options, **impact_options)
        return impacts.impact_batch(
            law,
            params,
            **settings,
            rtol=1e-11 if rtol is None else rtol,
            peaks=peaks,
            **impact_options,
        )
    if options is not None:  # a file's options are keywords (its resume key)
        rtol = options.rtol
        given = {k: getattr(options, k) for k in IMPACT_OPTIONS}
        impact_options.update({k: v for k, v in given.items() if v is not None})
    if not isinstance(law, (str, AbstractLaw)):
        raise ValueError(
            "impact_batch with chunks and out= takes a law name (see LAW_NAMES), a law from "
            f"jaximpact.law or a user's law from custom_law, got {type(law).__name__}"
        )
    if out is None:
        raise ValueError("impact_batch over chunks needs out= (a CSV or Parquet path)")
    if params is None:
        raise ValueError("impact_batch with out= needs the chunks (an iterable of mappings)")
    # impact_batch's own defaults (g = 0, "force") are not a value given for every row:
    # a chunk's g or separation column then holds (batch_file refuses a column that
    # disagrees with a value given); the options of arrays (peaks, fields, order, ...)
    # do not apply to a file, whose columns are fixed
    default_g = isinstance(g, (int, float)) and not isinstance(g, bool) and g == 0.0
    return batch_file(
        params,
        out,
        law,
        m=m,
        v0=v0,
        g=None if default_g else g,
        separation=None if separation == "force" else separation,
        progress=progress,
        method=method,
        **({} if rtol is None else {"rtol": rtol}),
        **impact_options,
    )
