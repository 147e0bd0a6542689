"""Fitting a contact law to a bouncing ball: a sampled trajectory, or the impact times alone.

The model is `jaximpact.bounce`'s chain (closed-form flights, one impact solve per contact,
gravity inside each contact), started at the first observed impact: its time and speed are
nuisance parameters, as are the floor level and the length scale of a video track. The law's
free parameters and the nuisance parameters are fitted by Levenberg-Marquardt on residuals
whose Jacobian comes from one forward-mode pass through the chain (`jax.jacfwd` with diffrax's
`ForwardMode`; shared/notes, sections 0.5 and 6), compiled once per law, data kind and size
bucket.

What the data can and cannot say:
- Impact times: each interval is a contact plus a flight, `T_k + 2 e_k v_k / g` without drag,
  so the intervals carry `e` and its speed dependence; the contact durations enter only as a
  small offset per interval, so the stiffness is held fixed by default; freed, the Jacobian
  decides (short contacts against the timing noise: undetermined).
- A trajectory carries the same plus the drop height; a contact shows as a delay between two
  parabolas, and samples that fall inside a contact are modelled by that contact's own
  solution.
- Parameters whose standard error in log space exceeds 1 (a factor e), or that lie in a null
  direction of the Jacobian, are listed in `undetermined` with an infinite standard error.
"""

import dataclasses
import math

import diffrax as dfx
import numpy as np

from .._laws import AbstractLaw
from .._solve.bounce import bounce_options
from .bounce_fit import BounceFit, find_outliers, finish
from .bounce_model import (
    BounceProblem,
    first_stage,
    rebase,
    round_up,
    run_stage,
    tune_damping,
    with_impacts,
)
from .impact_times import assign, is_list_of_drops, prepare_impacts, times_in_order
from .parameters import default_free

KINDS = ("impacts", "trajectory")
Y_AXES = ("up", "down")


def _guess_trajectory(t, h, g):
    """First impact, release, scale, speed and restitution from a track (`h` upward, data
    units). Returns a dict, or raises ValueError when no bounce is visible."""
    span = float(np.percentile(h, 98) - np.percentile(h, 2))
    if not span > 0:
        raise ValueError("the trajectory does not move")
    floor = float(np.percentile(h, 1))
    low = h <= floor + 0.1 * span
    minima = [i for i in range(1, len(h) - 1) if low[i] and h[i] <= h[i - 1] and h[i] <= h[i + 1]]
    if not minima:
        raise ValueError(
            "no bounce found in the trajectory (no low point with rises on both sides)"
        )
    first = minima[0]
    top = float(np.percentile(h[: first + 1], 95))
    near_top = np.flatnonzero(h[:first] >= top - 0.03 * (top - floor))
    release = int(near_top[-1]) if near_top.size else 0
    fall = np.arange(release, first)
    if fall.size < 4:
        raise ValueError("the first fall is too short to estimate (fewer than 4 samples)")
    c2, c1, c0 = np.polyfit(t[fall], h[fall], 2)
    if c2 >= 0:
        raise ValueError("the first fall is not a downward parabola: is --y-axis right?")
    floor0 = float(h[first])
    disc = c1**2 - 4 * c2 * (c0 - floor0)
    t1 = float((-c1 - math.sqrt(max(disc, 0.0))) / (2 * c2))
    slope = abs(c1 + 2 * c2 * t1)  # data units per second
    scale = -2.0 * c2 / g
    later = [i for i in minima if t[i] > t[first] + 0.05 * (t[first] - t[release])]
    e0 = 0.5
    if later:
        gap = t[later[0]] - t1
        e0 = float(np.clip(g * gap * scale / (2 * slope), 0.05, 0.98))
    return dict(release=release, t1=t1, v1=slope / scale, scale=scale, floor=floor0, e=e0)


def fit_bounces(
    law: AbstractLaw,
    *,
    m,
    t=None,
    y=None,
    impact_times=None,
    free=None,
    g: float = 9.81,
    separation: str = "force",
    drag=None,
    fit_drag: bool = False,
    length_scale=None,
    y_axis: str = "up",
    sigma=None,
    clean_tol: float = 0.3,
    outlier_sigma: float = 5.0,
    max_iter: int = 100,
    tol: float = 1e-10,
    rtol: float = 1e-8,
    max_steps: int = 4096,
) -> BounceFit:
    """Fit `law` to a bouncing ball of mass `m` (kg): a sampled trajectory `(t, y)` or the
    instants of its impacts `impact_times` (s, e.g. from a microphone).

    - Trajectory: `t` (s) and `y` (height, any length unit; `y_axis="down"` for image rows).
      `length_scale`: units of `y` per metre (None: `y` is in metres; `"fit"`: fitted,
      with `g` known, as for a video with no scale in it). Fitted nuisance: first impact
      time and speed (hence drop height and release time), floor level, the scale if asked.
      Samples before the release (a hand holding the ball) are dropped, and samples more
      than `outlier_sigma` robust standard deviations off the first fit (tracking glitches)
      are dropped before a second fit.
    - Impact times: detections are sorted out by `clean_impact_times` (`clean_tol`): double
      and inconsistent ones are dropped, missed impacts left as gaps, and all are reported;
      then outliers of the first fit, as above. Nuisance: first impact time and speed.
      The times of one drop must not go backwards (ValueError, with the index where they
      do). Several drops: pass a list of 1-D arrays, `impact_times=[times_1, times_2]`;
      each drop is fitted on its own (its own first impact, speed and noise) and the result
      is a list of `BounceFit`, one per drop, in order: compare their `params` and `e`
      to see the spread between drops.
    - `free`: the law's parameters to fit (default: its damping parameter; the stiffness is
      then held at the value in `law`, which the data rarely fix). The values in `law` are the
      starting point and the values of everything held.
    - `drag` (1/m): quadratic air drag in flight, `k = rho C_d A / (2 m)`; `fit_drag=True`
      fits it starting from that value.
    - `sigma`: measurement noise (s for impact times, y units for a trajectory); default:
      estimated from the residuals.
    - `rtol`, `max_steps`: each contact's solve; `max_iter`, `tol`: the optimiser.
    Eager (it sorts data and chooses the model's size), with a compiled core: the chain
    and its forward-mode Jacobian, compiled once per law, data kind and size bucket.

    **Example**:
    ```python
    fit = fit_bounces(law("hertz_rate", c=1e7, b1=100.0), m=0.0415, impact_times=times)
    fit.e[:5], fit.e_stderr[:5], fit.dropped, fit.missed
    ```
    """
    if not isinstance(law, AbstractLaw):
        raise TypeError("fit_bounces needs a law from jaximpact.law(...) or custom_law(...)")
    if impact_times is not None and is_list_of_drops(impact_times):
        if t is not None or y is not None:
            raise ValueError(
                "give either a trajectory (t=..., y=...) or impact_times=..., not both"
            )
        options = dict(
            m=m, free=free, g=g, separation=separation, drag=drag, fit_drag=fit_drag,
            sigma=sigma, clean_tol=clean_tol, outlier_sigma=outlier_sigma, max_iter=max_iter,
            tol=tol, rtol=rtol, max_steps=max_steps,
        )  # fmt: skip
        return [fit_bounces(law, impact_times=times, **options) for times in impact_times]
    if (impact_times is None) == (t is None and y is None):
        raise ValueError("give either a trajectory (t=..., y=...) or impact_times=..., not both")
    if impact_times is None and (t is None or y is None):
        raise ValueError("a trajectory needs both t (s) and y")
    if y_axis not in Y_AXES:
        raise ValueError(f"y_axis must be one of {Y_AXES}, got {y_axis!r}")
    if not (np.isfinite(m) and m > 0):
        raise ValueError(f"mass m must be a finite number > 0 kg, got {m}")
    if not (np.isfinite(g) and g > 0):
        raise ValueError(f"gravity g must be a finite number > 0 m/s^2, got {g}")
    for name, value in (("sigma", sigma), ("clean_tol", clean_tol), ("tol", tol),
                        ("outlier_sigma", outlier_sigma)):  # fmt: skip
        if value is not None and not (np.ndim(value) == 0 and 0 < float(value) < math.inf):
            raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) or max_iter < 1:
        raise ValueError(f"max_iter must be a positive integer, got {max_iter!r}")
    if fit_drag and drag is None:
        raise ValueError("fit_drag needs a starting value: drag=k (1/m)")
    if drag is not None and not (np.isfinite(drag) and drag > 0):
        raise ValueError(f"drag must be a finite number > 0 (1/m), got {drag}")
    free = default_free(law, stiffness=False) if free is None else tuple(free)
    unknown = [k for k in free if k not in law.parameters]
    if unknown:
        raise ValueError(
            f"cannot fit {', '.join(unknown)}: the law's parameters are {', '.join(law.parameters)}"
        )
    kind = "impacts" if impact_times is not None else "trajectory"
    options = bounce_options(
        separation=separation,
        max_impacts=8,
        rtol=rtol,
        max_steps=max_steps,
        adjoint=dfx.ForwardMode(),
        peaks=False,
    )
    m = float(m)
    g = float(g)
    if kind == "impacts":
        return _fit_impacts(
            law,
            free,
            m,
            g,
            impact_times,
            drag,
            fit_drag,
            sigma,
            clean_tol,
            outlier_sigma,
            max_iter,
            tol,
            options,
            separation,
        )
    return _fit_trajectory(
        law,
        free,
        m,
        g,
        t,
        y,
        drag,
        fit_drag,
        length_scale,
        y_axis,
        sigma,
        outlier_sigma,
        max_iter,
        tol,
        options,
        separation,
    )


def _fit_impacts(
    law,
    free,
    m,
    g,
    impact_times,
    drag,
    fit_drag,
    sigma,
    clean_tol,
    outlier_sigma,
    max_iter,
    tol,
    options,
    separation,
):
    """Three fits with one compiled model: on the detections before the first anomaly that
    `clean_impact_times` finds; on every detection within `clean_tol` of the fitted
    model's impacts; without the outliers of that fit."""
    log = []  # accepted steps of each fit
    raw = times_in_order(impact_times, "impact_times")
    cleaned = prepare_impacts(raw, clean_tol)
    kept_positions = np.setdiff1d(np.arange(raw.size), cleaned.dropped)
    anomalies = np.concatenate(
        [cleaned.dropped, kept_positions[1:][np.diff(cleaned.index) > 1], [raw.size]]
    )
    prefix = kept_positions < max(int(anomalies.min()), 4)
    n_model = round_up(int(cleaned.index.max()) + 4, 8)
    n_pad = round_up(raw.size, 8)
    e0 = float(np.clip(cleaned.ratio, 0.05, 0.99))
    v1 = g * float(raw[1] - raw[0]) / (2 * e0) if 1 not in cleaned.dropped else None
    if v1 is None:
        consecutive = np.flatnonzero(np.diff(cleaned.index) == 1)[0]
        gap = cleaned.times[consecutive + 1] - cleaned.times[consecutive]
        v1 = g * gap / (2 * e0 ** (cleaned.index[consecutive] + 1))
    if drag is not None:
        v1 = min(v1, 0.9 * math.sqrt(g / drag))
    sigma_used = float(sigma) if sigma is not None else 1e-3
    nuisance = ("t_impact", "v_impact") + (("drag",) if fit_drag else ())
    data = dict(
        times=np.pad(raw, (0, n_pad - raw.size), constant_values=raw[-1]),
        sigma=np.asarray(sigma_used),
        t1=np.asarray(raw[0]),
        t_unit=np.asarray(1e-3),
        v1=np.asarray(v1),
        floor=np.asarray(0.0),
        y_unit=np.asarray(1.0),
        scale=np.asarray(1.0),
        t_end=np.asarray(np.inf),
        min_flight=np.asarray(0.0),
    )
    if drag is not None:
        data["drag"] = np.asarray(float(drag))

    def with_mask(data, keep, number):
        data = dict(data)
        data["index"] = np.pad(np.minimum(number, n_model - 1), (0, n_pad - raw.size))
        data["mask"] = np.pad(keep, (0, n_pad - raw.size))
        return data

    number = np.zeros(raw.size, dtype=int)
    number[kept_positions] = cleaned.index
    keep = np.zeros(raw.size, dtype=bool)
    keep[kept_positions[prefix]] = True
    opts = with_impacts(options, n_model)
    problem = BounceProblem(
        law, free, nuisance, m, g, with_mask(data, keep, number), "impacts", 1.0, opts
    )
    problem = dataclasses.replace(problem, law=tune_damping(problem, e0))
    active = np.ones(len(free) + len(nuisance), dtype=bool)
    first = first_stage(problem.law, free, nuisance)
    result = run_stage(problem, first, max_iter=max_iter, tol=tol, log=log)
    # every detection against the fitted model's impacts
    problem = rebase(problem, result.theta)
    aux = result.extra[2]
    predicted = aux["t_land"][aux["valid"]] if np.any(aux["valid"]) else aux["t_land"]
    keep, number = assign(raw, predicted, clean_tol)
    problem = dataclasses.replace(problem, data=with_mask(problem.data, keep, number))
    result = run_stage(problem, active, max_iter=max_iter, tol=tol, log=log)
    r = result.residuals[: raw.size]
    if keep.sum() >= 10:  # a robust spread from fewer points is itself too uncertain
        outliers = find_outliers(r, keep, outlier_sigma, sigma is not None)
        if outliers.any():
            problem = rebase(problem, result.theta)
            keep = keep & ~outliers
            problem = dataclasses.replace(problem, data=with_mask(problem.data, keep, number))
            result = run_stage(problem, active, max_iter=max_iter, tol=tol, log=log)
    law, data = problem.law, problem.data
    theta, r, J, extra = result.theta, result.residuals, result.jacobian, result.extra
    history, converged = result.history, result.converged
    iterations = sum(log)
    index = number[keep]
    return finish(
        kind="impacts",
        law=law,
        free=free,
        nuisance_names=nuisance,
        theta=theta,
        r=r[: raw.size],
        J=J,
        extra=extra,
        history=history,
        converged=converged,
        iterations=iterations,
        data={k: float(v) for k, v in data.items() if np.ndim(v) == 0},
        sigma_used=sigma_used,
        sigma_given=sigma is not None,
        n_data=int(keep.sum()),
        m=m,
        g=g,
        separation=separation,
        y_sign=1.0,
        used=keep,
        times=raw[keep],
        index=index,
        missed=np.setdiff1d(np.arange(index.max() + 1), index),
        dropped=np.flatnonzero(~keep),
    )


def _fit_trajectory(
    law,
    free,
    m,
    g,
    t,
    y,
    drag,
    fit_drag,
    length_scale,
    y_axis,
    sigma,
    outlier_sigma,
    max_iter,
    tol,
    options,
    separation,
):
    log = []  # accepted steps of each fit
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.ndim != 1 or t.shape != y.shape or t.size < 8:
        raise ValueError("t and y must be 1-D arrays of the same length (at least 8 samples)")
    good = np.isfinite(t) & np.isfinite(y)
    positions = np.flatnonzero(good)
    times_in_order(t[positions], "the times t of a trajectory")
    t, y = t[positions], y[positions]
    y_sign = 1.0 if y_axis == "up" else -1.0
    guess = _guess_trajectory(t, y_sign * y, g)
    fit_scale = isinstance(length_scale, str)
    if fit_scale and length_scale != "fit":
        raise ValueError(f"length_scale must be a number, None or 'fit', got {length_scale!r}")
    scale0 = guess["scale"] if fit_scale else (1.0 if length_scale is None else float(length_scale))
    v1 = guess["v1"] * guess["scale"] / scale0
    if drag is not None:
        v1 = min(v1, 0.9 * math.sqrt(g / drag))
    keep_from = guess["release"]
    used = np.arange(t.size) >= keep_from
    dt = float(np.median(np.diff(t)))
    tu, yu = t[used], y[used]
    n_pad = round_up(tu.size, 64)
    span = float(np.ptp(yu)) or 1.0
    sigma_used = float(sigma) if sigma is not None else 1e-3 * span
    nuisance = ("t_impact", "v_impact", "floor") + (("length_scale",) if fit_scale else ())
    nuisance += ("drag",) if fit_drag else ()
    # enough contacts for the record: flights shrink as e^2 ... down to the sample spacing
    bounces = (
        int(
            np.ceil(
                np.log(max(dt / (2 * guess["e"] * v1 / g), 1e-12)) / np.log(max(guess["e"], 0.05))
            )
        )
        + 2
    )
    n_model = round_up(min(max(bounces, 2), 64), 8)

    def data_for(mask, t1, v1_, floor, scale, drag_):
        data = dict(
            t=np.pad(tu, (0, n_pad - tu.size), constant_values=tu[-1]),
            y=np.pad(yu, (0, n_pad - tu.size), constant_values=yu[-1]),
            mask=np.pad(mask, (0, n_pad - tu.size)),
            sigma=np.asarray(sigma_used),
            t1=np.asarray(t1),
            t_unit=np.asarray(dt),
            v1=np.asarray(v1_),
            floor=np.asarray(floor),
            y_unit=np.asarray(0.01 * span),
            scale=np.asarray(scale),
            t_end=np.asarray(float(tu[-1])),
            min_flight=np.asarray(0.5 * dt),
        )
        if drag_ is not None:
            data["drag"] = np.asarray(float(drag_))
        return data

    opts = with_impacts(options, n_model)
    mask = np.ones(tu.size, dtype=bool)
    data = data_for(mask, guess["t1"], v1, y_sign * guess["floor"], scale0, drag)
    problem = BounceProblem(law, free, nuisance, m, g, data, "trajectory", y_sign, opts)
    problem = dataclasses.replace(problem, law=tune_damping(problem, guess["e"]))
    n_theta = len(free) + len(nuisance)
    # first the nuisance alone (the start can be far in time), then everything
    nuisance_only = np.arange(n_theta) >= len(free)
    result = run_stage(problem, nuisance_only, max_iter=20, tol=1e-6, log=log)
    problem = rebase(problem, result.theta)
    first = first_stage(problem.law, free, nuisance)
    active = np.ones(n_theta, dtype=bool)
    if not first.all():
        result = run_stage(problem, first, max_iter=max_iter, tol=tol, log=log)
        problem = rebase(problem, result.theta)
    result = run_stage(problem, active, max_iter=max_iter, tol=tol, log=log)
    r = result.residuals[: tu.size]
    outliers = find_outliers(r, np.ones(tu.size, dtype=bool), outlier_sigma, sigma is not None)
    if outliers.any():
        problem = rebase(problem, result.theta)
        mask = ~outliers
        data = {**problem.data, "mask": np.pad(mask, (0, n_pad - tu.size))}
        problem = dataclasses.replace(problem, data=data)
        result = run_stage(problem, active, max_iter=max_iter, tol=tol, log=log)
    law, data = problem.law, problem.data
    theta, r, J, extra = result.theta, result.residuals, result.jacobian, result.extra
    history, converged = result.history, result.converged
    iterations = sum(log)
    predicted = extra[2]["predicted"][: tu.size]
    dropped = np.concatenate([positions[:keep_from], positions[keep_from:][outliers]]).astype(int)
    return finish(
        kind="trajectory",
        law=law,
        free=free,
        nuisance_names=nuisance,
        theta=theta,
        r=r[: tu.size],
        J=J,
        extra=extra,
        history=history,
        converged=converged,
        iterations=iterations,
        data={k: float(v) for k, v in data.items() if np.ndim(v) == 0},
        sigma_used=sigma_used,
        sigma_given=sigma is not None,
        n_data=int(mask.sum()),
        m=m,
        g=g,
        separation=separation,
        y_sign=y_sign,
        used=mask,
        t=tu[mask],
        y=yu[mask],
        y_fit=predicted[mask],
        dropped=np.sort(dropped),
    )
