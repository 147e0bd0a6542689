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
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._laws.law import AbstractLaw, damping_parameter
from .._solve.bounce import (
    BounceResult,
    _chain,
    _solve_bounce,
    bounce_options,
    trajectory_from_records,
)
from .parameters import default_free, from_unbounded, law_with, to_unbounded

KINDS = ("impacts", "trajectory")
Y_AXES = ("up", "down")


# ------------------------------------------------------------------ impact-time cleaning


@dataclasses.dataclass(frozen=True)
class CleanedImpacts:
    """Impact detections sorted into real impacts, double detections and gaps.

    - `times` (s): the detections kept; `index`: the impact number (0 = first) of each, so a
      jump in `index` marks missed impacts.
    - `dropped`: positions (in the input) of detections dropped as double (too soon
      after the previous impact) or inconsistent (between two predicted impacts);
      `missed`: impact numbers with no detection.
    - `ratio`: the median ratio of consecutive intervals (about `e`).
    """

    times: np.ndarray
    index: np.ndarray
    dropped: np.ndarray
    missed: np.ndarray
    ratio: float


def clean_impact_times(
    times, *, tol: float = 0.3, window: int = 5, max_missed: int = 3
) -> CleanedImpacts:
    """Find missed and double detections in a sequence of impact times (s) of one drop.

    The times must not go backwards (a ValueError says where: two drops whose clock
    restarted must be passed apart).

    The intervals of a bouncing ball shrink nearly geometrically, `D_{k+1} = r D_k` with `r`
    about `e`. Walking along the detections, the next impacts are predicted from the last
    kept one, the last interval and the median ratio `r` of the last `window` pairs of
    consecutive intervals; a detection is kept, with the impact number of the nearest
    prediction, if it lies within `tol` times that prediction's own interval (a detection
    that skips predictions marks missed impacts); otherwise it is dropped. Of two detections
    that match the same impact the nearer is kept; at most `max_missed` impacts in a row may
    be missing. The first two detections are taken to be
    the first two impacts, unless the second comes less than half the next interval after the
    first (then it is a double detection).

    **Example**: `clean_impact_times([0, 1, 1.8, 1.83, 2.44, 3.36])` keeps 0, 1, 1.8, 2.44
    and 3.36 (as impact 5: impact 4, near 2.95 s, was missed) and drops 1.83.
    """
    t = times_in_order(times, "impact times")
    if t.size < 3:
        raise ValueError(f"need at least 3 impact times to find the intervals, got {t.size}")
    if not np.all(np.isfinite(t)):
        raise ValueError("impact times must be finite numbers (s)")
    d = np.diff(t)
    if np.any(d <= 0):
        raise ValueError("impact times must be distinct")
    ratios = d[1:] / d[:-1]
    sane = ratios[(ratios > 0.3) & (ratios < 1.0)]
    r = float(np.median(sane[:8])) if sane.size else 0.8
    dropped = []
    second = 1
    while second + 1 < t.size and t[second] - t[0] < 0.5 * (t[second + 1] - t[second]):
        dropped.append(second)
        second += 1
    kept, index = [0], [0]
    last_interval = (t[second] - t[0]) / r  # so that the first prediction is t[second]
    observed = []  # ratios of consecutive observed intervals
    previous_whole = None  # the last interval between consecutive impact numbers
    for j in range(second, t.size):
        base = t[kept[-1]]
        nxt = last_interval * r
        offsets = nxt * np.cumsum(r ** np.arange(max_missed + 1))
        local = nxt * r ** np.arange(max_missed + 1)
        errors = np.abs(t[j] - base - offsets) / local
        best = int(np.argmin(errors))
        if errors[best] > tol:
            dropped.append(j)
            continue
        if j + 1 < t.size:  # a later detection matching the same impact better wins
            ahead = np.abs(t[j + 1] - base - offsets[best]) / local[best]
            if ahead < errors[best]:
                dropped.append(j)
                continue
        gap = t[j] - base
        if best == 0:
            if previous_whole is not None:
                observed.append(gap / previous_whole)
                if len(observed) >= 3:
                    r = float(np.median(observed[-window:]))
            previous_whole = gap
            last_interval = gap
        else:
            first = gap * (1 - r) / (1 - r ** (best + 1))
            last_interval = first * r**best
            previous_whole = None
        kept.append(j)
        index.append(index[-1] + best + 1)
    kept, index = np.asarray(kept), np.asarray(index)
    pairs = np.flatnonzero(np.diff(index) == 1)
    gaps = np.diff(t[kept])
    whole = [gaps[i + 1] / gaps[i] for i in range(len(pairs) - 1) if pairs[i + 1] == pairs[i] + 1]
    return CleanedImpacts(
        times=t[kept],
        index=index.astype(int),
        dropped=np.asarray(sorted(dropped), dtype=int),
        missed=np.setdiff1d(np.arange(index.max() + 1), index),
        ratio=float(np.median(whole)) if whole else r,
    )


def times_in_order(times, what="impact times") -> np.ndarray:
    """`times` as a 1-D float array, refused (ValueError) when it is not 1-D or when it goes
    backwards: impact times of several drops concatenated (each drop's clock starting again
    at zero) must be passed apart, never sorted into one sequence."""
    try:
        t = np.asarray(times, dtype=float)
    except (TypeError, ValueError):
        raise ValueError(
            f"{what} must be numbers (s): one 1-D array for one drop, or a list of 1-D "
            "arrays, one per drop"
        ) from None
    if t.ndim != 1:
        raise ValueError(
            f"{what} must be a 1-D array (one drop), got shape {t.shape}; for several drops "
            "pass a list of 1-D arrays, one per drop"
        )
    back = np.flatnonzero(np.diff(t) < 0)
    if back.size:
        i = int(back[0]) + 1
        hint = (
            "several drops? pass them apart, impact_times=[times_1, times_2, ...] (each drop "
            "fitted on its own)"
            if "impact" in what
            else "fit one recording at a time, in time order"
        )
        raise ValueError(
            f"{what} go backwards at index {i} ({t[i]:.6g} s after {t[i - 1]:.6g} s): {hint}"
        )
    return t


def _is_list_of_drops(impact_times) -> bool:
    """A list or tuple of 1-D arrays (one per drop), rather than one drop's times."""
    if not isinstance(impact_times, (list, tuple)):
        return False
    dims = [np.ndim(x) for x in impact_times]
    if any(d >= 1 for d in dims) and not all(d == 1 for d in dims):
        raise ValueError(
            "impact_times must be one 1-D array (one drop) or a list of 1-D arrays (one per "
            "drop), not a mix of numbers and arrays"
        )
    return bool(dims) and all(d == 1 for d in dims)


def interval_restitution(cleaned: CleanedImpacts) -> tuple[np.ndarray, np.ndarray]:
    """The textbook estimate `e_k = D_{k+1} / D_k` from consecutive intervals (contact
    durations and air drag neglected), for every impact number `k` whose two neighbouring
    intervals were both observed. Returns `(k, e_k)`."""
    t, k = cleaned.times, cleaned.index
    gaps = np.diff(t)
    whole = np.diff(k) == 1
    ks, es = [], []
    for i in range(len(gaps) - 1):
        if whole[i] and whole[i + 1]:
            ks.append(k[i + 1])
            es.append(gaps[i + 1] / gaps[i])
    return np.asarray(ks, dtype=int), np.asarray(es)


# ------------------------------------------------------------------------ the model


class _Spec(eqx.Module):
    """The static part of a fit: what is fitted and how the chain is solved."""

    kind: str = eqx.field(static=True)
    free: tuple = eqx.field(static=True)
    nuisance: tuple = eqx.field(static=True)
    has_drag: bool = eqx.field(static=True)
    y_sign: float = eqx.field(static=True)
    options: object = eqx.field(static=True)


def _unpack(theta, law, data, spec):
    nf = len(spec.free)
    fitted = law_with(law, spec.free, theta[:nf])
    q = {name: theta[nf + i] for i, name in enumerate(spec.nuisance)}
    t1 = data["t1"] + q["t_impact"] * data["t_unit"]
    v1 = data["v1"] * jnp.exp(q["v_impact"])
    drag = None
    if spec.has_drag:
        drag = data["drag"] * jnp.exp(q.get("drag", 0.0))
    floor = data["floor"] + q.get("floor", 0.0) * data["y_unit"]
    scale = data["scale"] * jnp.exp(q.get("length_scale", 0.0))
    return fitted, t1, v1, drag, floor, scale


def _model(theta, law, m, g, data, spec):
    """Weighted residuals, and the chain's e, impact speeds, times and durations."""
    fitted, t1, v1, drag, floor, scale = _unpack(theta, law, data, spec)
    ts = data["t"] if spec.kind == "trajectory" else None
    start = (t1, jnp.zeros_like(t1), -v1)
    records, flight0, carry = _chain(
        fitted, m, g, drag, start, data["t_end"], data["min_flight"], ts, spec.options
    )
    if spec.kind == "impacts":
        predicted = records["t_land"][data["index"]]
        observed = data["times"]
    else:
        height = trajectory_from_records(records, flight0, carry, ts, m, g, drag)[0]
        height = jnp.where(jnp.isfinite(height), height, 0.0)
        predicted = floor + spec.y_sign * scale * height
        observed = data["y"]
    residuals = jnp.where(data["mask"], (predicted - observed) / data["sigma"], 0.0)
    aux = dict(
        predicted=predicted,
        t_land=records["t_land"],
        v_in=records["v_in"],
        T=records["T"],
        valid=records["valid"],
        status=records["status"],
    )
    return residuals, records["e"], aux


@eqx.filter_jit
def _evaluate(theta, law, m, g, data, spec):
    """`(r, e, aux)` and their Jacobians `dr/dtheta`, `de/dtheta`, in one forward pass."""

    def stacked(th):
        r, e, aux = _model(th, law, m, g, data, spec)
        return jnp.concatenate([r, e]), (r, e, aux)

    jacobian, (r, e, aux) = jax.jacfwd(stacked, has_aux=True)(theta)
    n = r.shape[0]
    return r, e, aux, jacobian[:n], jacobian[n:]


# --------------------------------------------------------------------------- the fit


class BounceFit(eqx.Module):
    """A law fitted to a bouncing ball, and how well it reproduces the measurements.

    Like `jaximpact.Fit`: `law`, `params` (SI), `stderr` (standard errors of the fitted
    parameters, law and nuisance, by name; `inf` for an undetermined one), `free` (the law
    parameters fitted), `residuals` (`(model - data) / sigma` for the data used, with the
    reported `sigma`),
    `loss` (half their sum of squares), `converged`, `iterations`, `history` (loss per
    accepted step of the last fit; `iterations` counts the steps of every stage). And:

    - `undetermined`: parameters the data cannot fix (see the module docstring); their
      values are the ones given, not estimates.
    - `nuisance`: `t_impact` (s, first impact), `v_impact` (m/s, its speed), `drop_height`
      (m, `v_impact^2 / 2g`, or its drag equivalent), `release_time` (s, when the ball was at
      that apex), and for a trajectory `floor` (y units) and `length_scale` (y units per
      metre); `drag` (1/m) when it was given or fitted.
    - `e`, `e_stderr`, `impact_speeds` (m/s), `impact_times` (s), `T` (s): the fitted
      chain, one entry per modelled impact (`num_impacts` of them).
    - `sigma`: the measurement noise used (s or y units), given or estimated from the
      residuals (then `stderr` includes that estimate, and with few data the errors
      `(estimate - truth) / stderr` follow Student's t with `dof` degrees of freedom rather
      than a normal law); `dof`: data minus parameters.
    - impact times: `times`, `index` (impact number of each used detection), `dropped`
      (positions in the input of detections not used: double, inconsistent, or
      outliers of the first fit), `missed` (impact numbers with no detection).
    - trajectory: `t`, `y`, `y_fit` (the data used and the model there), `dropped` (sample
      positions not used: before the release, or outliers).
    """

    kind: str = eqx.field(static=True)
    law: AbstractLaw
    params: dict
    stderr: dict
    free: tuple = eqx.field(static=True)
    undetermined: tuple = eqx.field(static=True)
    nuisance: dict
    e: np.ndarray
    e_stderr: np.ndarray
    impact_speeds: np.ndarray
    impact_times: np.ndarray
    T: np.ndarray
    num_impacts: int = eqx.field(static=True)
    residuals: np.ndarray
    loss: float = eqx.field(static=True)
    sigma: float = eqx.field(static=True)
    dof: int = eqx.field(static=True)
    converged: bool = eqx.field(static=True)
    iterations: int = eqx.field(static=True)
    history: np.ndarray
    times: np.ndarray | None = None
    index: np.ndarray | None = None
    missed: np.ndarray | None = None
    t: np.ndarray | None = None
    y: np.ndarray | None = None
    y_fit: np.ndarray | None = None
    dropped: np.ndarray | None = None
    m: float = eqx.field(static=True, default=1.0)
    g: float = eqx.field(static=True, default=9.81)
    separation: str = eqx.field(static=True, default="force")
    y_sign: float = eqx.field(static=True, default=1.0)

    def bounce(self, t_end=None, max_impacts: int | None = None) -> BounceResult:
        """The fitted drop as a `BounceResult`, from the first modelled impact on (its
        `height(ts)` gives the fitted motion at any times, in metres)."""
        drag = self.nuisance.get("drag")
        options = bounce_options(
            separation=self.separation,
            max_impacts=max_impacts or _round_up(self.num_impacts + 1, 16),
        )
        t1, v1 = self.nuisance["t_impact"], self.nuisance["v_impact"]
        if t_end is None:  # just past the last modelled impact
            times = self.impact_times[: self.num_impacts]
            t_end = float(times[-1]) + (
                0.5 * float(times[-1] - times[-2]) if times.size > 1 else 1e-3
            )
            if self.t is not None:
                t_end = max(t_end, float(np.max(self.t)))
        return _solve_bounce(
            self.law,
            jnp.asarray(self.m, float),
            jnp.asarray(self.g, float),
            None if drag is None else jnp.asarray(drag, float),
            (jnp.asarray(t1, float), jnp.zeros(()), -jnp.asarray(v1, float)),
            jnp.asarray(t_end, float),
            jnp.asarray(0.0, float),
            options,
        )

    def predict(self, ts) -> np.ndarray:
        """The fitted trajectory at times `ts` (s), in the data's units (trajectory fits)."""
        if self.kind != "trajectory":
            raise ValueError("predict is for trajectory fits; an impact-time fit has impact_times")
        ts = np.asarray(ts, dtype=float)
        height = np.asarray(self.bounce(t_end=float(np.max(ts))).height(ts))
        height = np.where(np.isfinite(height), height, 0.0)
        return self.nuisance["floor"] + self.y_sign * self.nuisance["length_scale"] * height


def _first_stage(law, free, nuisance):
    """What a first fit frees: the nuisance and the damping alone (a stiffness freed from the
    start can wander to a distant local minimum before the damping has settled)."""
    damping = _damping_name(law, free)
    return np.asarray([k == damping or damping is None for k in free] + [True] * len(nuisance))


def _damping_name(law, free):
    name = damping_parameter(law)
    return name if name in free else None


def _levenberg_marquardt(evaluate, theta0, active, *, max_iter, tol):
    """Minimise `|r|^2/2` over the `active` components of `theta` (numpy driver around the
    compiled `evaluate(theta) -> (r, J, extra)`). Marquardt's scaling with a floor, so a
    direction the data do not see stays where it is."""
    theta = np.array(theta0, dtype=float)
    r, J, extra = evaluate(theta)
    cost = 0.5 * float(r @ r)
    history = [cost]
    lam, converged = 1e-3, False
    active = np.asarray(active, dtype=bool)
    for _ in range(max_iter):
        if not (np.all(np.isfinite(J)) and np.all(np.isfinite(r))):
            break  # the model failed here (e.g. a contact solve ran out of steps)
        Ja = J[:, active]
        A = Ja.T @ Ja
        grad = Ja.T @ r
        diag = np.diag(A).copy()
        diag = np.maximum(diag, 1e-9 * max(diag.max(initial=0.0), 1e-300))
        if np.max(np.abs(grad) / np.sqrt(diag)) <= tol * max(math.sqrt(2 * cost), 1e-300):
            converged = True
            break
        improved = False
        while lam < 1e12:
            step = np.linalg.lstsq(A + lam * np.diag(diag), -grad, rcond=None)[0]
            trial = theta.copy()
            trial[active] += step
            r_new, J_new, extra_new = evaluate(trial)
            cost_new = 0.5 * float(r_new @ r_new) if np.all(np.isfinite(r_new)) else np.inf
            if cost_new < cost:
                improved = True
                break
            lam *= 10.0
        if not improved:
            converged = True  # no direction lowers the loss: a minimum to working precision
            break
        reduction = (cost - cost_new) / max(cost, 1e-300)
        theta, r, J, extra, cost = trial, r_new, J_new, extra_new, cost_new
        history.append(cost)
        lam = max(lam / 10.0, 1e-12)
        if reduction < tol or np.max(np.abs(step)) < tol:
            converged = True
            break
    return theta, r, J, extra, np.asarray(history), converged, len(history) - 1


def _round_up(n, multiple):
    return int(multiple * math.ceil(max(n, 1) / multiple))


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


def _prepare_impacts(impact_times, tol):
    cleaned = clean_impact_times(impact_times, tol=tol)
    if cleaned.times.size < 3:
        raise ValueError("fewer than 3 impact times left after dropping the bad detections")
    return cleaned


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
    if impact_times is not None and _is_list_of_drops(impact_times):
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


def _with_impacts(options, n):
    return type(options)(impact=options.impact, max_impacts=int(n))


def _run(law, free, nuisance, m, g, data, kind, y_sign, options, active, max_iter, tol, log):
    """One Levenberg-Marquardt fit through the compiled model; appends its number of
    accepted steps to `log`."""
    spec = _Spec(
        kind=kind,
        free=free,
        nuisance=nuisance,
        has_drag="drag" in data,
        y_sign=y_sign,
        options=options,
    )
    data = {k: jnp.asarray(v) for k, v in data.items()}
    m_, g_ = jnp.asarray(m, float), jnp.asarray(g, float)

    def evaluate(theta):
        r, e, aux, J, J_e = _evaluate(jnp.asarray(theta), law, m_, g_, data, spec)
        return (
            np.asarray(r),
            np.asarray(J),
            (np.asarray(e), np.asarray(J_e), jax.tree_util.tree_map(np.asarray, aux)),
        )

    theta0 = np.concatenate(
        [[float(to_unbounded(k, law.parameters[k])) for k in free], np.zeros(len(nuisance))]
    )
    result = _levenberg_marquardt(evaluate, theta0, active, max_iter=max_iter, tol=tol)
    log.append(result[6])
    return result


def _tune_damping(law, free, nuisance, m, g, data, kind, y_sign, options, e_target):
    """Set the damping so that the first modelled impact has restitution `e_target` (a few
    secant steps on its logarithm, through the same compiled model)."""
    damping = _damping_name(law, free)
    if damping is None:
        return law
    spec = _Spec(
        kind=kind,
        free=(damping,),
        nuisance=nuisance,
        has_drag="drag" in data,
        y_sign=y_sign,
        options=options,
    )
    jdata = {k: jnp.asarray(v) for k, v in data.items()}

    def first_e(log_value):
        theta = jnp.concatenate([jnp.asarray([log_value]), jnp.zeros(len(nuisance))])
        _, e, _, _, J_e = _evaluate(theta, law, jnp.asarray(m), jnp.asarray(g), jdata, spec)
        return float(e[0]), float(J_e[0, 0])

    x = float(to_unbounded(damping, law.parameters[damping]))
    for _ in range(30):
        e, slope = first_e(x)
        if abs(e - e_target) < 1e-4 or not np.isfinite(slope) or slope == 0:
            break
        step = np.clip((e_target - e) / slope, -2.0, 2.0)
        if e == 0.0:  # captured: far too much damping
            step = -2.0
        x += float(step)
    return law.replace(**{damping: float(from_unbounded(damping, x))})


def _statistics(theta, r, J, extra, names, sigma_given, n_data, log_params):
    """Covariance from the Jacobian at the optimum; undetermined parameters; e errors."""
    p = theta.size
    dof = max(n_data - p, 1)
    s2 = 1.0 if sigma_given else float(r @ r) / dof
    U, S, Vt = np.linalg.svd(J, full_matrices=False)
    cutoff = S.max(initial=0.0) * 1e-8
    good = S > cutoff
    inv = np.where(good, 1.0 / np.where(good, S, 1.0) ** 2, 0.0)
    cov = s2 * (Vt.T * inv) @ Vt
    null = Vt[~good]
    se_theta = np.sqrt(np.maximum(np.diag(cov), 0.0))
    undetermined = []
    for i, name in enumerate(names):
        in_null = null.size and np.max(np.abs(null[:, i])) > 1e-3
        if in_null or (log_params[i] and se_theta[i] > 1.0):
            undetermined.append(name)
            se_theta[i] = np.inf
    e, J_e, _ = extra
    cov_e = np.einsum("ki,ij,kj->k", J_e, cov, J_e)
    return dof, s2, se_theta, undetermined, e, np.sqrt(np.maximum(cov_e, 0.0))


def _finish(
    kind,
    law,
    free,
    nuisance_names,
    theta,
    r,
    J,
    extra,
    history,
    converged,
    iterations,
    data,
    sigma_used,
    sigma_given,
    n_data,
    m,
    g,
    separation,
    y_sign,
    used,
    **extra_fields,
):
    nf = len(free)
    fitted_law = law_with(law, free, jnp.asarray(theta[:nf]))
    log_params = [True] * nf + [
        name in ("v_impact", "length_scale", "drag") for name in nuisance_names
    ]
    names = list(free) + list(nuisance_names)
    dof, s2, se_theta, undetermined, e, e_se = _statistics(
        theta, r, J, extra, names, sigma_given, n_data, log_params
    )
    params = {k: float(v) for k, v in fitted_law.parameters.items()}
    stderr = {}
    for i, name in enumerate(free):
        stderr[name] = float(params[name] * se_theta[i]) if np.isfinite(se_theta[i]) else math.inf
    q = dict(zip(nuisance_names, theta[nf:], strict=True))
    t1 = float(data["t1"] + q["t_impact"] * data["t_unit"])
    v1 = float(data["v1"] * math.exp(q["v_impact"]))
    nuisance = {"t_impact": t1, "v_impact": v1}
    se_q = dict(zip(nuisance_names, se_theta[nf:], strict=True))
    stderr["t_impact"] = float(se_q["t_impact"] * data["t_unit"])
    stderr["v_impact"] = float(v1 * se_q["v_impact"])
    drag = None
    if "drag" in data:
        drag = float(data["drag"] * math.exp(q.get("drag", 0.0)))
        nuisance["drag"] = drag
        stderr["drag"] = float(drag * se_q["drag"]) if "drag" in se_q else 0.0
    # the apex the first impact fell from
    if drag is None:
        height, fall = v1**2 / (2 * g), v1 / g
    else:
        v_t = math.sqrt(g / drag)
        w = min(v1 / v_t, 1 - 1e-15)
        height, fall = -(v_t**2) / (2 * g) * math.log1p(-(w**2)), v_t / g * math.atanh(w)
    nuisance["drop_height"] = height
    nuisance["release_time"] = t1 - fall
    stderr["drop_height"] = float(2 * height * se_q["v_impact"])
    if kind == "trajectory":
        nuisance["floor"] = float(data["floor"] + q["floor"] * data["y_unit"])
        stderr["floor"] = float(se_q["floor"] * data["y_unit"])
        scale = float(data["scale"] * math.exp(q.get("length_scale", 0.0)))
        nuisance["length_scale"] = scale
        stderr["length_scale"] = (
            float(scale * se_q["length_scale"]) if "length_scale" in se_q else 0.0
        )
    aux = extra[2]
    valid = aux["valid"]
    count = int(np.sum(valid))
    if kind == "impacts":  # the impacts the detections cover
        count = min(count, int(np.max(extra_fields["index"])) + 1)
    else:
        count = min(count, int(np.sum(aux["t_land"][:count] <= np.max(extra_fields["t"]))))
    sigma = float(sigma_used * math.sqrt(s2))
    return BounceFit(
        kind=kind,
        law=fitted_law,
        params=params,
        stderr=stderr,
        free=tuple(free),
        undetermined=tuple(undetermined),
        nuisance=nuisance,
        e=np.where(valid, extra[0], np.nan)[:count],
        e_stderr=np.where(valid, e_se, np.nan)[:count],
        impact_speeds=aux["v_in"][:count],
        impact_times=aux["t_land"][:count],
        T=aux["T"][:count],
        num_impacts=count,
        residuals=r[used] / math.sqrt(s2),
        loss=float(0.5 * r @ r),
        sigma=sigma,
        dof=int(dof),
        converged=bool(converged),
        iterations=int(iterations),
        history=history,
        m=m,
        g=g,
        separation=separation,
        y_sign=y_sign,
        **extra_fields,
    )


def _outliers(r, used, threshold, sigma_given):
    """Data more than `threshold` robust standard deviations (1.4826 times the median
    absolute deviation; with a given noise, at least the given one) off the fit, at most a
    fifth of them, the worst first."""
    values = r[used]
    spread = 1.4826 * np.median(np.abs(values - np.median(values)))
    if sigma_given:
        spread = max(spread, 1.0)  # residuals are in units of the given noise
    bad = used & (np.abs(r) > threshold * max(spread, 1e-12))
    limit = max(1, int(used.sum()) // 5)
    if bad.sum() > limit:
        worst = np.argsort(-np.abs(np.where(bad, r, 0.0)))[:limit]
        bad = np.zeros_like(bad)
        bad[worst] = True
    return bad


def _assign(times, predicted, tol):
    """Give each detection the nearest predicted impact; keep it within `tol` of that
    impact's shorter neighbouring interval; of several on one impact keep the nearest."""
    gaps = np.diff(predicted)
    local = np.minimum(np.concatenate([[np.inf], gaps]), np.concatenate([gaps, [np.inf]]))
    right = np.clip(np.searchsorted(predicted, times), 1, predicted.size - 1)
    left = np.abs(times - predicted[right - 1]) <= np.abs(times - predicted[right])
    number = np.where(left, right - 1, right)
    error = np.abs(times - predicted[number]) / local[number]
    keep = error <= tol
    for k in np.unique(number[keep]):
        same = np.flatnonzero(keep & (number == k))
        keep[same[np.argsort(error[same])[1:]]] = False
    return keep, number


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
    cleaned = _prepare_impacts(raw, clean_tol)
    kept_positions = np.setdiff1d(np.arange(raw.size), cleaned.dropped)
    anomalies = np.concatenate(
        [cleaned.dropped, kept_positions[1:][np.diff(cleaned.index) > 1], [raw.size]]
    )
    prefix = kept_positions < max(int(anomalies.min()), 4)
    n_model = _round_up(int(cleaned.index.max()) + 4, 8)
    n_pad = _round_up(raw.size, 8)
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
    opts = _with_impacts(options, n_model)
    data = with_mask(data, keep, number)
    law = _tune_damping(law, free, nuisance, m, g, data, "impacts", 1.0, opts, e0)
    active = np.ones(len(free) + len(nuisance), dtype=bool)
    first = _first_stage(law, free, nuisance)
    result = _run(law, free, nuisance, m, g, data, "impacts", 1.0, opts, first, max_iter, tol, log)
    # every detection against the fitted model's impacts
    data, law = _rebase(data, law, free, nuisance, result[0])
    aux = result[3][2]
    predicted = aux["t_land"][aux["valid"]] if np.any(aux["valid"]) else aux["t_land"]
    keep, number = _assign(raw, predicted, clean_tol)
    data = with_mask(data, keep, number)
    result = _run(law, free, nuisance, m, g, data, "impacts", 1.0, opts, active, max_iter, tol, log)
    r = result[1][: raw.size]
    if keep.sum() >= 10:  # a robust spread from fewer points is itself too uncertain
        outliers = _outliers(r, keep, outlier_sigma, sigma is not None)
        if outliers.any():
            data, law = _rebase(data, law, free, nuisance, result[0])
            keep = keep & ~outliers
            data = with_mask(data, keep, number)
            result = _run(
                law, free, nuisance, m, g, data, "impacts", 1.0, opts, active, max_iter, tol, log
            )
    theta, r, J, extra, history, converged, _ = result
    iterations = sum(log)
    index = number[keep]
    return _finish(
        "impacts",
        law,
        free,
        nuisance,
        theta,
        r[: raw.size],
        J,
        extra,
        history,
        converged,
        iterations,
        {k: float(v) for k, v in data.items() if np.ndim(v) == 0},
        sigma_used,
        sigma is not None,
        int(keep.sum()),
        m,
        g,
        separation,
        1.0,
        keep,
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
    n_pad = _round_up(tu.size, 64)
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
    n_model = _round_up(min(max(bounces, 2), 64), 8)

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

    opts = _with_impacts(options, n_model)
    mask = np.ones(tu.size, dtype=bool)
    data = data_for(mask, guess["t1"], v1, y_sign * guess["floor"], scale0, drag)
    law = _tune_damping(law, free, nuisance, m, g, data, "trajectory", y_sign, opts, guess["e"])
    n_theta = len(free) + len(nuisance)
    # first the nuisance alone (the start can be far in time), then everything
    nuisance_only = np.arange(n_theta) >= len(free)
    result = _run(
        law, free, nuisance, m, g, data, "trajectory", y_sign, opts, nuisance_only, 20, 1e-6, log
    )
    data, law = _rebase(data, law, free, nuisance, result[0])
    first = _first_stage(law, free, nuisance)
    active = np.ones(n_theta, dtype=bool)
    if not first.all():
        result = _run(
            law, free, nuisance, m, g, data, "trajectory", y_sign, opts, first, max_iter, tol, log
        )
        data, law = _rebase(data, law, free, nuisance, result[0])
    result = _run(
        law, free, nuisance, m, g, data, "trajectory", y_sign, opts, active, max_iter, tol, log
    )
    r = result[1][: tu.size]
    outliers = _outliers(r, np.ones(tu.size, dtype=bool), outlier_sigma, sigma is not None)
    if outliers.any():
        data, law = _rebase(data, law, free, nuisance, result[0])
        mask = ~outliers
        data["mask"] = np.pad(mask, (0, n_pad - tu.size))
        result = _run(
            law, free, nuisance, m, g, data, "trajectory", y_sign, opts, active, max_iter, tol, log
        )
    theta, r, J, extra, history, converged, _ = result
    iterations = sum(log)
    predicted = extra[2]["predicted"][: tu.size]
    dropped = np.concatenate([positions[:keep_from], positions[keep_from:][outliers]]).astype(int)
    return _finish(
        "trajectory",
        law,
        free,
        nuisance,
        theta,
        r[: tu.size],
        J,
        extra,
        history,
        converged,
        iterations,
        {k: float(v) for k, v in data.items() if np.ndim(v) == 0},
        sigma_used,
        sigma is not None,
        int(mask.sum()),
        m,
        g,
        separation,
        y_sign,
        mask,
        t=tu[mask],
        y=yu[mask],
        y_fit=predicted[mask],
        dropped=np.sort(dropped),
    )


def _rebase(data, law, free, nuisance, theta):
    """Move the reference values of `data` and `law` to `theta` (so the next fit starts at
    zero nuisance offsets)."""
    data = dict(data)
    nf = len(free)
    q = dict(zip(nuisance, theta[nf:], strict=True))
    data["t1"] = np.asarray(float(data["t1"]) + q["t_impact"] * float(data["t_unit"]))
    data["v1"] = np.asarray(float(data["v1"]) * math.exp(q["v_impact"]))
    if "floor" in q:
        data["floor"] = np.asarray(float(data["floor"]) + q["floor"] * float(data["y_unit"]))
    if "length_scale" in q:
        data["scale"] = np.asarray(float(data["scale"]) * math.exp(q["length_scale"]))
    if "drag" in q:
        data["drag"] = np.asarray(float(data["drag"]) * math.exp(q["drag"]))
    return data, law_with(law, free, jnp.asarray(theta[:nf]))
