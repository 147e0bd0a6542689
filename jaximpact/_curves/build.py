"""Building a shape's curves: reference impacts at Chebyshev nodes in `s = ln beta`, pieces
split until the series' last coefficients fall below the tolerance.

Every output is tabulated as a logarithm (`ln e`, `ln(T/t*)`, ...), so an absolute error
in the series is a relative error in the value, down to the smallest `e`. The curves run
from `beta = 1e-18` (below it every output is its elastic limit plus the first-order slope,
to better than 1e-12) to `BETA_MAX = 1e4`, or to the last `beta` whose reference impact
still separates within the step budget (`Curves.beta_max`).
"""

import functools
import math

import jax
import jax.numpy as jnp
import numpy as np

from .._progress import metered
from . import chebyshev
from .curve import BETA_MAX, BETA_MIN, DEGREE, OUTPUTS, Curves
from .reference import reference_impact
from .shapes import CurveKey

TAIL_TOL = 2e-11  # largest of the last two coefficients of ln(output), per piece
MIN_WIDTH = 0.5  # narrowest piece in ln(beta); one that still fails is kept with its tail
_CHUNK = 128  # reference impacts per compiled call (padded), so one program serves all


@functools.lru_cache(maxsize=8)
def _reference_function(key: CurveKey, max_steps: int):
    """One compiled program per shape and step budget, shared by every round."""

    def one(beta):
        r = reference_impact(
            beta,
            n=key.n,
            p=key.p,
            separation="penetration" if key.separation == "either" else key.separation,
            max_steps=max_steps,
        )
        return jnp.stack([r[name] for name in OUTPUTS]), r["separated"], r["peak_at_touch"]

    # `lax.map`, not `vmap`: under `vmap` diffrax placed the force-zero event of Kelvin-Voigt
    # at beta = 1e-6 at x = 0 instead of x = beta (T 3e-7 high, measured); one impact after
    # the other gives the unbatched answer, and no member waits for the slowest
    return jax.jit(lambda betas: jax.lax.map(one, betas))


def reference_values(key: CurveKey, betas, *, max_steps: int, flags: bool = False):
    """Reference outputs `(len(betas), 5)` and `separated` at `betas` (float64), and with
    `flags` whether the force peaks at first touch."""
    betas = np.asarray(betas, dtype=float)
    run = _reference_function(key, max_steps)
    values, separated, at_touch = [], [], []
    for start in range(0, len(betas), _CHUNK):
        chunk = betas[start : start + _CHUNK]
        padded = np.concatenate([chunk, np.full(_CHUNK - len(chunk), 1.0)])
        out, ok, touch = run(jnp.asarray(padded))
        values.append(np.asarray(out)[: len(chunk)])
        separated.append(np.asarray(ok)[: len(chunk)])
        at_touch.append(np.asarray(touch)[: len(chunk)])
    result = np.concatenate(values), np.concatenate(separated)
    return (*result, np.concatenate(at_touch)) if flags else result


def _peak_switches(key: CurveKey, beta_max: float, max_steps: int) -> list[float]:
    """`ln beta` where `F_max` switches between the force at first touch and a later peak
    (a kink), each to 1e-13 relative by bisection."""
    grid = np.logspace(-6, math.log10(beta_max), 241)
    *_, touch = reference_values(key, grid, max_steps=max_steps, flags=True)
    switches = []
    for i in np.flatnonzero(touch[1:] != touch[:-1]):
        low, high = math.log(grid[i]), math.log(grid[i + 1])
        while high - low > 1e-13:
            mid = 0.5 * (low + high)
            *_, t = reference_values(key, [math.exp(mid)], max_steps=max_steps, flags=True)
            low, high = (mid, high) if t[0] == touch[i] else (low, mid)
        switches.append(0.5 * (low + high))
    return switches


def _valid(values, separated):
    return separated & np.all(np.isfinite(values), axis=1) & np.all(values > 0, axis=1)


def _table_end(key: CurveKey, max_steps: int) -> tuple[float, float | None]:
    """The largest `beta <= BETA_MAX` up to which impacts separate (a scan in quarter
    decades), and the capture threshold (bisection to 1e-12 relative) where one exists."""
    scan = np.logspace(-2, math.log10(BETA_MAX), 4 * (2 + int(math.log10(BETA_MAX))) + 1)
    values, separated = reference_values(key, scan, max_steps=max_steps)
    ok = _valid(values, separated)
    if ok.all():
        return BETA_MAX, None
    first_bad = int(np.argmin(ok))
    if first_bad == 0:
        raise RuntimeError(f"{key.name}: the reference impact fails at beta = {scan[0]:g}")
    low, high = scan[first_bad - 1], scan[first_bad]
    # a member that only ran out of steps is not a capture: the table then ends where the
    # step budget does (a few halvings suffice); a capture is found to 1e-12 relative
    _, long_run = reference_values(key, [high], max_steps=10 * max_steps)
    capture = not long_run[0]
    for _ in range(45 if capture else 8):
        mid = math.sqrt(low * high)
        v, s = reference_values(key, [mid], max_steps=max_steps)
        if _valid(v, s)[0]:
            low = mid
        else:
            high = mid
    return (low * (1 - 1e-3), high) if capture else (low, None)


def build_curves(key: CurveKey, *, progress: bool = True, max_steps: int = 40_000) -> Curves:
    """Tabulate `key`'s impacts (a few thousand reference impacts: tens of seconds).

    Pieces are halved until the last two coefficients of every `ln(output)` fall below
    `TAIL_TOL`, or until halving stops shrinking them (or they are `MIN_WIDTH` wide): there
    the reference itself is noisy (heavy damping under the force criterion, where the force
    stays near zero while the body creeps out and `T` is ill-conditioned), and the piece
    keeps its tail as its error estimate. `max_steps` bounds each reference impact: the
    table ends where heavy damping under the penetration criterion needs more (the shipped
    shapes are built with 400 000, a shape built on first use with 40 000)."""
    with metered(progress, 1, f"building curves {key.name}") as bar:
        beta_max, capture = _table_end(key, max_steps)
        s_lo, s_hi = math.log(BETA_MIN), math.log(beta_max)
        edges = np.linspace(s_lo, s_hi, 13)
        kinks = _peak_switches(key, beta_max, max_steps)
        edges = np.unique(np.concatenate([edges, kinks]))
        edges = edges[np.concatenate([[True], np.diff(edges) > 1e-3])]
        pending = [(a, b, np.inf) for a, b in zip(edges[:-1], edges[1:], strict=True)]
        accepted, end = {}, s_hi
        while pending:
            bar.total += 1
            nodes = np.stack([chebyshev.nodes(a, b, DEGREE) for a, b, _ in pending])
            values, separated = reference_values(key, np.exp(nodes.ravel()), max_steps=max_steps)
            valid = _valid(values, separated).reshape(len(pending), DEGREE + 1)
            logs = np.log(np.where(values > 0, values, 1.0))
            logs = logs.reshape(len(pending), DEGREE + 1, len(OUTPUTS))
            split = []
            for (a, b, parent_tail), piece, ok in zip(pending, logs, valid, strict=True):
                if not ok.all():  # out of steps at heavy damping: the table ends below
                    if a < math.log(1e-2):
                        raise RuntimeError(
                            f"{key.name}: the reference fails at beta = {math.exp(a):g}"
                        )
                    end = min(end, a)
                    continue
                coefficients = chebyshev.fit(piece)
                tail = np.max(np.abs(coefficients[-2:]), axis=0)
                # halving a smooth piece divides a degree-20 tail by about 2^20: a small
                # one (below 1e-8) that shrinks less than 100-fold is the reference's noise
                noise = 1e-8 > tail.max() > parent_tail / 100
                if tail.max() <= TAIL_TOL or noise or b - a < MIN_WIDTH:
                    accepted[(a, b)] = (coefficients, tail)
                else:
                    middle = 0.5 * (a + b)
                    split += [(a, middle, tail.max()), (middle, b, tail.max())]
            pending = split
            bar.update(1, f"{len(accepted)} pieces")
    order = sorted(piece for piece in accepted if piece[1] <= end)
    breaks = np.array([a for a, _ in order] + [order[-1][1]])
    beta_max = math.exp(breaks[-1])
    coefficients = np.stack([accepted[piece][0] for piece in order])
    tail = np.stack([accepted[piece][1] for piece in order])
    return Curves(key, breaks, coefficients, beta_max, capture, tail)
