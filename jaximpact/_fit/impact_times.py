"""Impact times as detected (by a microphone, a force plate or a video): ordered, cleaned of
double and missed detections, turned into restitutions between consecutive impacts, and
matched to a model's impacts."""

import dataclasses

import numpy as np


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
    """`times` as a 1-D float array, refused (ValueError) when it is not 1-D, not finite or
    when it goes backwards: impact times of several drops concatenated (each drop's clock
    starting again at zero) must be passed apart, never sorted into one sequence."""
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
    if not np.all(np.isfinite(t)):
        raise ValueError(f"{what} must be finite numbers (s)")
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


def is_list_of_drops(impact_times) -> bool:
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
    if not isinstance(cleaned, CleanedImpacts):
        raise TypeError(
            "interval_restitution takes what clean_impact_times returns: "
            f"interval_restitution(clean_impact_times(times)), got {type(cleaned).__name__}"
        )
    t, k = cleaned.times, cleaned.index
    gaps = np.diff(t)
    whole = np.diff(k) == 1
    ks, es = [], []
    for i in range(len(gaps) - 1):
        if whole[i] and whole[i + 1]:
            ks.append(k[i + 1])
            es.append(gaps[i + 1] / gaps[i])
    return np.asarray(ks, dtype=int), np.asarray(es)


def assign(times, predicted, tol):
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


def prepare_impacts(impact_times, tol):
    cleaned = clean_impact_times(impact_times, tol=tol)
    if cleaned.times.size < 3:
        raise ValueError("fewer than 3 impact times left after dropping the bad detections")
    return cleaned
