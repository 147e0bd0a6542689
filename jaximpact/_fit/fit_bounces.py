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

How the work is shared: `fit_bounces` checks the input, keeps its options in `Settings` and
starts a `BounceProblem` (law, mass, gravity, kind of data, the chain's options);
`_fit_impacts` and `_fit_trajectory` give it its data and run its stages (`run_stage`, each a
`Stage`); `finish(problem, stage, measurements)` turns the last stage into a `BounceFit`.
"""

import dataclasses
import math

import diffrax as dfx
import numpy as np

from .._laws import AbstractLaw
from .._solve.bounce import bounce_options
from .._solve.options import FIT_DECIDES, SolveOptions, solve_options
from .._xla_log import quietly_compiled
from .bounce_fit import BounceFit, Measurements, find_outliers, finish
from .bounce_model import (
    BounceProblem,
    Stage,
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


@dataclasses.dataclass(frozen=True)
class Settings:
    """How `fit_bounces` fits, checked on creation (ValueError).

    - `sigma`: the measurement noise (s for impact times, y units for a trajectory), or
      None: estimated from the residuals.
    - `drag`: quadratic air drag in flight (1/m), held or the start of `fit_drag`; None: none.
    - `fit_drag`: whether the drag is fitted.
    - `clean_tol`: how far (a fraction of the neighbouring interval) a detection may lie
      from its impact.
    - `outlier_sigma`: how far (robust standard deviations) a datum may lie off the fit.
    - `max_iter`, `tol`: each Levenberg-Marquardt stage's step budget and (relative)
      tolerance.
    """

    sigma: float | None
    drag: float | None
    fit_drag: bool
    clean_tol: float
    outlier_sigma: float
    max_iter: int
    tol: float

    def __post_init__(self):
        for name in ("sigma", "clean_tol", "tol", "outlier_sigma"):
            value = getattr(self, name)
            if value is not None and not (np.ndim(value) == 0 and 0 < float(value) < math.inf):
                raise ValueError(f"{name} must be a finite number > 0, got {value!r}")
        n = self.max_iter
        if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 1:
            raise ValueError(f"max_iter must be a positive integer, got {n!r}")
        if self.fit_drag and self.drag is None:
            raise ValueError("fit_drag needs a starting value: drag=k (1/m)")
        if self.drag is not None and not (np.isfinite(self.drag) and self.drag > 0):
            raise ValueError(f"drag must be a finite number > 0 (1/m), got {self.drag}")

    @property
    def sigma_given(self) -> bool:
        """Whether the noise was given (else it is estimated from the residuals)."""
        return self.sigma is not None

    def capped(self, v1, g):
        """An impact speed `v1` (m/s) kept below nine tenths of the terminal speed (m/s)
        under gravity `g` (m/s^2) and the drag, if any."""
        return v1 if self.drag is None else min(v1, 0.9 * math.sqrt(g / self.drag))

    def stage(self, problem: BounceProblem, active, before: Stage | None = None) -> Stage:
        """`run_stage` of `problem`'s `active` parameters with these step budget and
        tolerance, counting on from the stage `before`."""
        return run_stage(problem, active, max_iter=self.max_iter, tol=self.tol, before=before)


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


@quietly_compiled
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
    rtol: float | None = None,
    max_steps: int = 4096,
    options: SolveOptions | None = None,
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
    - `rtol`, `max_steps`: each contact's solve (`rtol` as `bounce`'s: by default 1e-11
      for a law of the table, 1e-12 for a user's law); `max_iter`, `tol`: the optimiser.
    - `options`: a `SolveOptions` for each contact's solve, whole: `rtol`, `max_steps` (a
      keyword that sets one of them otherwise is refused), `atol`, `tau_max`, `rest_tol`,
      `solver` (as `bounce`'s); the fit differentiates in forward mode and leaves out the
      peaks, so `adjoint`, `peaks` and `throw` stay None.
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
            m=m,
            free=free,
            g=g,
            separation=separation,
            drag=drag,
            fit_drag=fit_drag,
            sigma=sigma,
            clean_tol=clean_tol,
            outlier_sigma=outlier_sigma,
            max_iter=max_iter,
            tol=tol,
            rtol=rtol,
            max_steps=max_steps,
            options=options,
        )
        for i, times in enumerate(impact_times):  # every drop checked before any is fitted
            try:
                prepare_impacts(times_in_order(times, "impact_times"), clean_tol)
            except ValueError as error:
                raise ValueError(f"drop {i} of impact_times: {error}") from None
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
    settings = Settings(
        sigma=sigma,
        drag=drag,
        fit_drag=fit_drag,
        clean_tol=clean_tol,
        outlier_sigma=outlier_sigma,
        max_iter=max_iter,
        tol=tol,
    )
    free = default_free(law, stiffness=False) if free is None else tuple(free)
    unknown = [k for k in free if k not in law.parameters]
    if unknown:
        raise ValueError(
            f"cannot fit {', '.join(unknown)}: the law's parameters are {', '.join(law.parameters)}"
        )
    kind = "impacts" if impact_times is not None else "trajectory"
    solve = solve_options(fit_bounces, options, rtol=rtol, max_steps=max_steps, refused=FIT_DECIDES)
    solve = dataclasses.replace(solve, adjoint=dfx.ForwardMode(), peaks=False)
    options = bounce_options(law, solve, separation=separation, max_impacts=8)
    problem = BounceProblem(
        law=law,
        free=free,
        m=float(m),
        g=float(g),
        kind=kind,
        y_sign=-1.0 if kind == "trajectory" and y_axis == "down" else 1.0,
        options=options,
    )
    if kind == "impacts":
        return _fit_impacts(problem, impact_times, settings)
    return _fit_trajectory(problem, t, y, length_scale, settings)


def _refit(problem: BounceProblem, stage: Stage, settings: Settings, mask, index=None):
    """The next stage: `problem` moved to `stage`'s optimum (`rebase`), fitting the data
    where `mask` holds (impact times: detections of impacts number `index`), every
    parameter free. Returns the new problem and its stage."""
    problem = rebase(problem, stage.theta).masked(mask, index)
    return problem, settings.stage(problem, np.ones(problem.size, dtype=bool), stage)


def _fit_impacts(problem: BounceProblem, impact_times, settings: Settings) -> BounceFit:
    """Three fits with one compiled model: on the detections before the first anomaly that
    `clean_impact_times` finds; on every detection within `clean_tol` of the fitted
    model's impacts; without the outliers of that fit."""
    raw = times_in_order(impact_times, "impact_times")
    problem = _impacts_problem(problem, raw, settings)
    stage = settings.stage(problem, first_stage(problem))
    # every detection against the fitted model's impacts
    aux = stage.chain
    predicted = aux["t_land"][aux["valid"]] if np.any(aux["valid"]) else aux["t_land"]
    keep, number = assign(raw, predicted, settings.clean_tol)
    problem, stage = _refit(problem, stage, settings, keep, number)
    if keep.sum() >= 10:  # a robust spread from fewer points is itself too uncertain
        r = stage.residuals[: raw.size]
        outliers = find_outliers(r, keep, settings.outlier_sigma, settings.sigma_given)
        if outliers.any():
            keep = keep & ~outliers
            problem, stage = _refit(problem, stage, settings, keep, number)
    index = number[keep]
    fields = dict(
        times=raw[keep],
        index=index,
        missed=np.setdiff1d(np.arange(index.max() + 1), index),
        dropped=np.flatnonzero(~keep),
    )
    return finish(problem, stage, Measurements(keep, settings.sigma_given, fields))


def _impacts_problem(problem: BounceProblem, raw, settings: Settings) -> BounceProblem:
    """`problem` set up for the detections `raw` (s, in order): the nuisance, the data
    and the model's size; its starting values (first impact at the first detection, its
    speed from the first interval and the intervals' ratio as e); the detections before
    the first anomaly that `clean_impact_times` finds masked in, and the damping set so
    that the first impact's e is that ratio."""
    g = problem.g
    cleaned = prepare_impacts(raw, settings.clean_tol)
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
    v1 = settings.capped(v1, g)
    nuisance = ("t_impact", "v_impact") + (("drag",) if settings.fit_drag else ())
    data = dict(
        times=np.pad(raw, (0, n_pad - raw.size), constant_values=raw[-1]),
        sigma=np.asarray(float(settings.sigma) if settings.sigma_given else 1e-3),
        t1=np.asarray(raw[0]),
        t_unit=np.asarray(1e-3),
        v1=np.asarray(v1),
        floor=np.asarray(0.0),
        y_unit=np.asarray(1.0),
        scale=np.asarray(1.0),
        t_end=np.asarray(np.inf),
        min_flight=np.asarray(0.0),
    )
    if settings.drag is not None:
        data["drag"] = np.asarray(float(settings.drag))
    number = np.zeros(raw.size, dtype=int)
    number[kept_positions] = cleaned.index
    keep = np.zeros(raw.size, dtype=bool)
    keep[kept_positions[prefix]] = True
    options = with_impacts(problem.options, n_model)
    problem = dataclasses.replace(problem, nuisance=nuisance, data=data, options=options)
    problem = problem.masked(keep, number)
    return dataclasses.replace(problem, law=tune_damping(problem, e0))


def _fit_trajectory(problem: BounceProblem, t, y, length_scale, settings: Settings) -> BounceFit:
    """Fits of a track `t` (s), `y` (y units): the nuisance alone first (the start can be
    far in time), then the damping with it (if more is free), then everything, then
    everything without the outliers of that fit."""
    t = np.asarray(t, dtype=float)
    y = np.asarray(y, dtype=float)
    if t.ndim != 1 or t.shape != y.shape or t.size < 8:
        raise ValueError("t and y must be 1-D arrays of the same length (at least 8 samples)")
    good = np.isfinite(t) & np.isfinite(y)
    positions = np.flatnonzero(good)
    times_in_order(t[positions], "the times t of a trajectory")
    t, y = t[positions], y[positions]
    guess = _guess_trajectory(t, problem.y_sign * y, problem.g)
    problem = _trajectory_problem(problem, t, y, guess, length_scale, settings)
    keep_from = guess["release"]
    tu, yu = t[keep_from:], y[keep_from:]
    nuisance_only = np.arange(problem.size) >= len(problem.free)
    stage = run_stage(problem, nuisance_only, max_iter=20, tol=1e-6)
    problem = rebase(problem, stage.theta)
    first = first_stage(problem)
    if not first.all():
        stage = settings.stage(problem, first, stage)
        problem = rebase(problem, stage.theta)
    stage = settings.stage(problem, np.ones(problem.size, dtype=bool), stage)
    r = stage.residuals[: tu.size]
    outliers = find_outliers(
        r, np.ones(tu.size, dtype=bool), settings.outlier_sigma, settings.sigma_given
    )
    mask = ~outliers
    if outliers.any():
        problem, stage = _refit(problem, stage, settings, mask)
    predicted = stage.chain["predicted"][: tu.size]
    dropped = np.concatenate([positions[:keep_from], positions[keep_from:][outliers]]).astype(int)
    fields = dict(t=tu[mask], y=yu[mask], y_fit=predicted[mask], dropped=np.sort(dropped))
    return finish(problem, stage, Measurements(mask, settings.sigma_given, fields))


def _trajectory_problem(
    problem: BounceProblem, t, y, guess, length_scale, settings: Settings
) -> BounceProblem:
    """`problem` set up for the track `t` (s), `y` (y units) from the release on, from the
    first look at it (`guess`, see `_guess_trajectory`): the nuisance, the data, the
    model's size (enough contacts for the record: flights shrink as e^2 ... down to the
    sample spacing) and the damping set so that the first impact's e is the guessed one."""
    g = problem.g
    fit_scale = isinstance(length_scale, str)
    if fit_scale and length_scale != "fit":
        raise ValueError(f"length_scale must be a number, None or 'fit', got {length_scale!r}")
    scale0 = guess["scale"] if fit_scale else (1.0 if length_scale is None else float(length_scale))
    v1 = settings.capped(guess["v1"] * guess["scale"] / scale0, g)
    dt = float(np.median(np.diff(t)))
    tu, yu = t[guess["release"] :], y[guess["release"] :]
    n_pad = round_up(tu.size, 64)
    span = float(np.ptp(yu)) or 1.0
    nuisance = ("t_impact", "v_impact", "floor") + (("length_scale",) if fit_scale else ())
    nuisance += ("drag",) if settings.fit_drag else ()
    e = guess["e"]
    bounces = int(np.ceil(np.log(max(dt / (2 * e * v1 / g), 1e-12)) / np.log(max(e, 0.05)))) + 2
    data = dict(
        t=np.pad(tu, (0, n_pad - tu.size), constant_values=tu[-1]),
        y=np.pad(yu, (0, n_pad - tu.size), constant_values=yu[-1]),
        sigma=np.asarray(float(settings.sigma) if settings.sigma_given else 1e-3 * span),
        t1=np.asarray(guess["t1"]),
        t_unit=np.asarray(dt),
        v1=np.asarray(v1),
        floor=np.asarray(problem.y_sign * guess["floor"]),
        y_unit=np.asarray(0.01 * span),
        scale=np.asarray(scale0),
        t_end=np.asarray(float(tu[-1])),
        min_flight=np.asarray(0.5 * dt),
    )
    if settings.drag is not None:
        data["drag"] = np.asarray(float(settings.drag))
    options = with_impacts(problem.options, round_up(min(max(bounces, 2), 64), 8))
    problem = dataclasses.replace(problem, nuisance=nuisance, data=data, options=options)
    problem = problem.masked(np.ones(tu.size, dtype=bool))
    return dataclasses.replace(problem, law=tune_damping(problem, e))
