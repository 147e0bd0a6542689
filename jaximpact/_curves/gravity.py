"""Universal curves with a second group, tabulated in two dimensions on top of the
one-group curves: gravity `gamma = g x*/v0^2` (drops, bounces), or a dry force
`pi = P/(c x*^n)` against the motion (Bingham-modified, eq. 8: `F = c x + b1 x v + P
sgn(v)`, whose impact without gravity depends on `(beta, pi)` alone). The module speaks of
gravity; a dry table (`group="dry"`) is the same with `pi` for `gamma`, keyed by its
separation criterion (the dry force makes the criteria differ where `n = p`), and its
threshold is the sticking one (`X_max^n <= pi`: held at maximum compression).

With gravity pushing in, `X'' = -X^n - beta X^p X' + gamma`, every output `f` depends on
`(beta, gamma)`. `f(beta, 0)` is the one-group curve (`similarity.curve_values`); what is
tabulated here is the smooth correction

    Q(beta, gamma) = [ln f(beta, gamma) - ln f(beta, 0)] / gamma,

so that `f = f(beta, 0) exp(gamma Q)`: exact at `gamma = 0` (the one-group path), and an
absolute error `dQ` in the table is a relative error `gamma dQ` in `f`. `Q` is a tensor
Chebyshev series per piece of `s = ln beta` (degree `DEGREE` in `s`, `GAMMA_DEGREE` in
`u = gamma / G_k`, `0 <= u <= 1`), where each piece `k` has its own upper bound `G_k`: a
`GAMMA_FRACTION` of the smallest `gamma` at which gravity holds the body in the surface
(capture, found by a scan on the piece), at most `GAMMA_MAX`. A pair `(beta, gamma)`
outside the table (`gamma > G_k`, `beta` above the table's end) is not served: `impact`
integrates it (`in_range` below). Below `BETA_LO` the correction is that at `BETA_LO`
(its change there is below `BETA_LO gamma |dQ/dbeta|`, 1e-10 relative).

`build_gravity(key)` tabulates one shape (reference impacts of `reference.reference_impact`
with `gamma`, Dopri8 at rtol 1e-13; a few seconds to a minute); `python -m
jaximpact._curves.gravity` rebuilds the shipped files `gravity.npz` (`SHIPPED`) and
`dry.npz` (`SHIPPED_DRY`).
"""

import dataclasses
import functools
import hashlib
import math
import os
import tempfile
import time
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from .._progress import metered
from . import chebyshev
from .curve import DEGREE, OUTPUTS
from .shapes import CurveKey, curve_key
from .store import read_groups

GAMMA_DEGREE = 15  # Chebyshev degree in u = gamma / G_k
GAMMA_MAX = 1.0  # the largest gamma tabulated
GAMMA_FRACTION = 0.5  # of the capture threshold: G_k <= GAMMA_FRACTION gamma_c
GAMMA_FLOOR = 1e-3  # a piece whose G_k would fall below this ends the table
BETA_LO = 1e-10  # below: the correction at BETA_LO
BETA_HI = 30.0  # above: not tabulated (T under the force criterion is ill-conditioned)
TAIL_TOL = 1e-10  # largest of the last two coefficients (times G_k) in s and in u
# a dry table's reference impacts (two phases, the force criterion's event on the force
# itself) are noisier: at beta = 1e-10 its tails stay at 1.5e-10 as G_k is halved three
# times, the reference's own scatter divided by gamma at the first Chebyshev node
TAIL_TOLS = {"gravity": TAIL_TOL, "dry": 4e-10}
MIN_WIDTH = 0.25  # narrowest piece in ln(beta)
FORMAT = 1
SHIPPED_FILE = Path(__file__).with_name("gravity.npz")
# the Hertz shapes of the law table whose impacts always separate without gravity
SHIPPED = (
    curve_key(1.5, 0.5, "force"),  # the paper's law 14 (hertz_rate)
    curve_key(1.5, 1.5, "force"),  # hunt_crossley (n = 1.5), its variants; either criterion
    curve_key(1.5, 1.0, "force"),  # hertz_modified
    curve_key(1.5, 0.5, "penetration"),
    curve_key(1.5, 0.0, "force"),  # hertz_viscous (law 12)
)
SHIPPED_DRY_FILE = Path(__file__).with_name("dry.npz")
# Bingham-modified (eq. 8) under each criterion: n = p = 1, the dry force in both phases
SHIPPED_DRY = (CurveKey(1.0, 1.0, "force"), CurveKey(1.0, 1.0, "penetration"))
GROUPS = ("gravity", "dry")
# not shipped: (1.5, 1, penetration), whose build ran past 40 minutes on two shared cores
_CHUNK = 256


@dataclasses.dataclass(frozen=True)
class WithGravity:
    """The static choice `impact` makes for a one-group law with gravity: the shape's
    key, read off the two-dimensional table where `(beta, gamma)` lies in it."""

    key: CurveKey
    group = "gravity"


@dataclasses.dataclass(frozen=True)
class WithDryForce(WithGravity):
    """The same choice for a law with a dry force in both phases and no gravity
    (Bingham-modified): the table of `(beta, pi)` under `key.separation`."""

    group = "dry"


@dataclasses.dataclass(frozen=True, eq=False)
class GravityTable:
    """`Q` of the five `OUTPUTS` for one shape: `breaks` (K + 1,) in `ln beta`,
    `gamma_max` (K,) the `G_k`, `coefficients` (K, DEGREE + 1, GAMMA_DEGREE + 1, 5) (in
    `s`, in `u`, output), `tail` (K, 5) the error estimate (times `G_k`) per piece,
    `capture` (K,) the capture threshold found on each piece (a lower bound)."""

    key: CurveKey
    breaks: np.ndarray
    gamma_max: np.ndarray
    coefficients: np.ndarray
    tail: np.ndarray
    capture: np.ndarray
    group: str = "gravity"

    @property
    def beta_max(self) -> float:
        return math.exp(self.breaks[-1])


# --- reference impacts ----------------------------------------------------------------


@functools.lru_cache(maxsize=16)
def _reference_function(key: CurveKey, max_steps: int, group: str | None, tau_max: float):
    from .reference import reference_impact  # diffrax: only when building

    def one(pair):
        r = reference_impact(
            pair[0],
            n=key.n,
            p=key.p,
            separation="penetration" if key.separation == "either" else key.separation,
            max_steps=max_steps,
            tau_max=tau_max,
            gamma=pair[1] if group == "gravity" else None,
            dry=pair[1] if group == "dry" else None,
        )
        return jnp.stack([r[name] for name in OUTPUTS]), r["separated"], r["peak_at_touch"]

    return jax.jit(lambda pairs: jax.lax.map(one, pairs))


def reference_values(
    key: CurveKey, betas, gammas, *, group="gravity", max_steps=100_000, tau_max=1e7
):
    """Outputs `(N, 5)`, `separated` and `peak_at_touch` `(N,)` at the pairs (float64);
    `gammas=None`: without the second group (`group`: `"gravity"` or `"dry"`). A solve
    that runs out of `max_steps` or `tau_max` does not count as separated."""
    group = None if gammas is None else group
    gammas = 0.0 if gammas is None else gammas
    pairs = np.stack(np.broadcast_arrays(np.asarray(betas, float), np.asarray(gammas, float)), 1)
    run = _reference_function(key, max_steps, group, tau_max)
    out = [[], [], []]
    for start in range(0, len(pairs), _CHUNK):
        chunk = pairs[start : start + _CHUNK]
        padded = np.concatenate([chunk, np.tile([[0.1, 0.0]], (_CHUNK - len(chunk), 1))])
        for store, value in zip(out, run(jnp.asarray(padded)), strict=True):
            store.append(np.asarray(value)[: len(chunk)])
    return tuple(np.concatenate(o) for o in out)


def capture_thresholds(key: CurveKey, betas, *, steps: int = 16, group="gravity") -> np.ndarray:
    """For each `beta`, a lower bound of the smallest `gamma` at which gravity holds the
    body (bisection in `ln gamma` on [1e-6, GAMMA_MAX / GAMMA_FRACTION], `steps` halvings;
    the top where none is captured). A solve that runs out of its short budget counts as
    captured (a body creeping to rest never reaches V = 0): the bound stays a lower one."""
    betas = np.asarray(betas, float)
    low = np.full(len(betas), math.log(1e-6))
    high = np.full(len(betas), math.log(GAMMA_MAX / GAMMA_FRACTION))
    budget = dict(group=group, max_steps=2_000, tau_max=1e3)
    _, top_ok, _ = reference_values(key, betas, np.exp(high), **budget)
    for _ in range(steps):
        mid = 0.5 * (low + high)
        _, ok, _ = reference_values(key, betas, np.exp(mid), **budget)
        low, high = np.where(ok, mid, low), np.where(ok, high, mid)
    return np.where(top_ok, np.exp(high), np.where(low > math.log(1e-6), np.exp(low), 0.0))


# --- building ---------------------------------------------------------------------------


def _fit_piece(key, a, b, G, zero_cache, group):
    """Coefficients `(D + 1, M + 1, 5)` of `Q` on `[a, b] x [0, G]`, and whether every
    reference impact there separated with its force peak after first touch."""
    s = chebyshev.nodes(a, b, DEGREE)
    u = chebyshev.nodes(0.0, 1.0, GAMMA_DEGREE)
    betas = np.exp(s)
    if (a, b) not in zero_cache:
        zero_cache[(a, b)] = reference_values(key, betas, None)
    f0, ok0, touch0 = zero_cache[(a, b)]
    bb, uu = np.meshgrid(betas, u, indexing="ij")
    f, ok, touch = reference_values(key, bb.ravel(), G * uu.ravel(), group=group)
    f = f.reshape(len(s), len(u), len(OUTPUTS))
    good = (
        (ok.all() and ok0.all() and not touch.any() and not touch0.any())
        and np.all(f > 0)
        and np.all(f0 > 0)
    )
    if not good:
        return None, False
    q = (np.log(f) - np.log(f0)[:, None, :]) / (G * uu)[..., None]
    D, M, P = q.shape
    c = chebyshev.fit(q.reshape(D, M * P)).reshape(D, M, P)  # along s
    c = np.moveaxis(chebyshev.fit(np.moveaxis(c, 1, 0).reshape(M, D * P)).reshape(M, D, P), 0, 1)
    return c, True


def build_gravity(key: CurveKey, *, progress=True, group="gravity") -> GravityTable:
    """Tabulate `key`'s correction `Q` (see the module's docstring) for the second group
    `group` (`"gravity"` or `"dry"`). `progress`: `True` reports on the default meter (and
    prints a summary at the end), `False` says nothing, or any `jaximpact.AbstractMeter`."""
    started = time.perf_counter()
    tail_tol = TAIL_TOLS[group]
    s_lo, s_hi = math.log(BETA_LO), math.log(BETA_HI)
    # the capture threshold on a grid of beta (it falls with beta): a piece's G is a
    # fraction of the least threshold on the grid points around it
    scan_s = np.linspace(s_lo, s_hi, int((s_hi - s_lo) / math.log(10) * 8) + 2)
    thresholds = capture_thresholds(key, np.exp(scan_s), group=group)
    h = scan_s[1] - scan_s[0]

    def capture_on(a, b):
        inside = (scan_s >= a - h) & (scan_s <= b + h)
        return float(thresholds[inside].min())

    edges = np.linspace(s_lo, s_hi, 9)
    pending = [(a, b, np.inf) for a, b in zip(edges[:-1], edges[1:], strict=True)]
    accepted, end, zero_cache = {}, s_hi, {}
    with metered(progress, 1, f"building {group} table {key.name}") as bar:
        while pending:
            bar.total += 1
            split = []
            for a, b, parent_tail in pending:
                if a >= end:
                    continue
                capture = capture_on(a, b)
                G = min(GAMMA_MAX, GAMMA_FRACTION * capture)
                halves = [(a, 0.5 * (a + b), parent_tail), (0.5 * (a + b), b, parent_tail)]
                if G < GAMMA_FLOOR:  # the capture comes too soon: a narrower piece, or
                    if b - a >= 2 * MIN_WIDTH:  # the table ends here
                        split += halves
                    else:
                        end = min(end, a)
                    continue
                if (
                    b - a >= 2 * MIN_WIDTH
                    and min(GAMMA_MAX, GAMMA_FRACTION * capture_on(a, 0.5 * (a + b))) >= 2 * G
                ):  # the capture falls steeply across the piece: halves reach further
                    split += halves
                    continue
                while True:
                    c, good = _fit_piece(key, a, b, G, zero_cache, group)
                    if not good:
                        break
                    tail_u = G * np.abs(c[:, -2:]).max(axis=(0, 1))
                    if tail_u.max() <= tail_tol or G / 2 < GAMMA_FLOOR:
                        break
                    G /= 2  # gamma nearer the capture needs a shorter interval
                if not good or tail_u.max() > tail_tol:
                    if b - a >= 2 * MIN_WIDTH:
                        split += halves
                    else:
                        end = min(end, a)
                    continue
                tail_s = G * np.abs(c[-2:]).max(axis=(0, 1))
                tail = np.maximum(tail_s, tail_u)
                noise = 1e-8 > tail_s.max() > parent_tail / 100
                if tail_s.max() <= tail_tol or noise or b - a < MIN_WIDTH:
                    accepted[(a, b)] = (c, tail, G, capture)
                else:
                    m = 0.5 * (a + b)
                    split += [(a, m, tail_s.max()), (m, b, tail_s.max())]
            pending = split
            bar.update(1, f"{len(accepted)} pieces")
    order = sorted(piece for piece in accepted if piece[1] <= end)
    if not order or order[0][0] > s_lo:
        raise RuntimeError(f"{key.name}: no gravity table from beta = {BETA_LO:g} on")
    # the table must be contiguous from BETA_LO: stop at the first gap
    kept = [order[0]]
    for piece in order[1:]:
        if abs(piece[0] - kept[-1][1]) > 1e-12:
            break
        kept.append(piece)
    table = GravityTable(
        key,
        breaks=np.array([a for a, _ in kept] + [kept[-1][1]]),
        gamma_max=np.array([accepted[p][2] for p in kept]),
        coefficients=np.stack([accepted[p][0] for p in kept]),
        tail=np.stack([accepted[p][1] for p in kept]),
        capture=np.array([accepted[p][3] for p in kept]),
        group=group,
    )
    if progress:
        print(
            f"{key.name}: {len(kept)} pieces up to beta = {table.beta_max:.4g}, G from "
            f"{table.gamma_max.min():.3g} to {table.gamma_max.max():.3g}, largest tail "
            f"{table.tail.max():.1e}, {time.perf_counter() - started:.0f} s",
            flush=True,
        )
    return table


# --- storing ----------------------------------------------------------------------------


def _arrays(table: GravityTable) -> dict:
    return dict(
        breaks=table.breaks,
        gamma_max=table.gamma_max,
        coefficients=table.coefficients,
        tail=table.tail,
        capture=table.capture,
        meta=np.array([FORMAT, table.key.n, table.key.p, GAMMA_DEGREE, DEGREE]),
    )


def _digest(name: str, arrays: dict) -> str:
    sha = hashlib.sha256(f"gravity:{FORMAT}:{name}".encode())
    for field in sorted(arrays):
        sha.update(field.encode())
        sha.update(np.ascontiguousarray(arrays[field], dtype=float).tobytes())
    return sha.hexdigest()


def save(tables, path: Path):
    """Write tables to `path` atomically (a temporary file renamed into place)."""
    content = {}
    for table in tables:
        arrays, name = _arrays(table), table.key.name
        content.update({f"{name}/{field}": value for field, value in arrays.items()})
        content[f"{name}/sha256"] = np.array(_digest(name, arrays))
    handle, temporary = tempfile.mkstemp(dir=path.parent, suffix=".npz")
    os.close(handle)
    np.savez(temporary, **content)
    os.chmod(temporary, 0o644)
    os.replace(temporary, path)


def load(path: Path, group: str = "gravity") -> dict:
    """`{CurveKey: GravityTable}` of the second group `group` (one file per group); a
    `ValueError` if anything does not check."""
    grouped = read_groups(path, ValueError, "gravity table file")
    tables = {}
    for name, arrays in grouped.items():
        digest = str(arrays.pop("sha256"))
        if digest != _digest(name, arrays):
            raise ValueError(f"gravity table {name}: checksum mismatch")
        version, n, p, gamma_degree, degree = arrays["meta"]
        key = CurveKey(float(n), float(p), name.rsplit(",", 1)[-1])
        pieces = arrays["breaks"].shape[0] - 1
        shape = (pieces, DEGREE + 1, GAMMA_DEGREE + 1, len(OUTPUTS))
        if (
            version != FORMAT
            or key.name != name
            or (gamma_degree, degree) != (GAMMA_DEGREE, DEGREE)
            or arrays["coefficients"].shape != shape
            or arrays["gamma_max"].shape != (pieces,)
            or not np.all(np.diff(arrays["breaks"]) > 0)
        ):
            raise ValueError(f"gravity table {name}: arrays of the wrong form")
        tables[key] = GravityTable(
            key,
            arrays["breaks"],
            arrays["gamma_max"],
            arrays["coefficients"],
            arrays["tail"],
            arrays["capture"],
            group,
        )
    return tables


def _shipped_file(group: str) -> Path:
    return SHIPPED_FILE if group == "gravity" else SHIPPED_DRY_FILE


@functools.cache
def shipped(group: str = "gravity") -> dict:
    path = _shipped_file(group)
    return load(path, group) if path.exists() else {}


def table_for(key: CurveKey, group: str = "gravity") -> GravityTable | None:
    """The shipped table of `key` for `group`, or `None` (then the impact is integrated)."""
    return shipped(group).get(key)


# --- evaluating -------------------------------------------------------------------------


def gravity_correction(table: GravityTable, beta, gamma, outputs: tuple[int, ...]):
    """`(in_range, Q)`: whether `(beta, gamma)` lies in the table, and `Q` of `outputs`
    there (elsewhere `Q` at the nearest point of the table: finite, not to be used);
    differentiable in both, NaN-free for every `beta, gamma >= 0`."""
    breaks = jnp.asarray(table.breaks)
    s_lo, s_hi = float(table.breaks[0]), float(table.breaks[-1])
    s = jnp.clip(jnp.log(jnp.where(beta > BETA_LO, beta, BETA_LO)), s_lo, s_hi)
    last = breaks.shape[0] - 2
    k = jnp.clip(jnp.searchsorted(breaks, s, side="right", method="compare_all") - 1, 0, last)
    G = jnp.asarray(table.gamma_max)[k]
    in_range = (jnp.log(jnp.where(beta > BETA_LO, beta, BETA_LO)) <= s_hi) & (gamma <= G)
    u = jnp.clip(gamma / G, 0.0, 1.0)
    c = table.coefficients[..., list(outputs)]
    K, D, M, P = c.shape
    in_u = chebyshev.evaluate(table.breaks, c.reshape(K, D, M * P), s).reshape(M, P)
    t = 2.0 * u - 1.0

    def step(carry, j):
        b1, b2 = carry
        return (2.0 * t * b1 - b2 + in_u[j], b1), None

    zero = jnp.zeros(P, dtype=t.dtype)
    (b1, b2), _ = jax.lax.scan(step, (zero, zero), jnp.arange(M - 1, 0, -1))
    return in_range, t * b1 - b2 + in_u[0]


def gravity_fields(
    dynamics, key: CurveKey, *, m, v0, g, peaks: bool, group: str = "gravity"
) -> tuple[dict, object]:
    """`ImpactResult` fields from the table of `group` (`f(beta, 0) exp(gamma Q)`, with
    `pi` for `gamma` in a dry table), the penetration at separation (m), and `in_range`
    (where it is False the fields are not the impact's: the caller integrates those)."""
    from .similarity import curve_values, fields_from_values
    from .store import curves_for

    outputs = (0, 1, 2, 3, 4) if peaks else (0, 1)
    beta = dynamics.beta
    # a constant force alike in both phases (DMT's adhesion, dry_in = dry_out < 0) pulls
    # in as gravity does
    second = dynamics.gamma - dynamics.dry_in if group == "gravity" else dynamics.dry_in
    in_range, q = gravity_correction(table_for(key, group), beta, second, outputs)
    base = curve_values(curves_for(curve_key(key.n, key.p, key.separation)), beta, outputs)
    values = base * jnp.exp(jnp.where(in_range, second, 0.0) * q)
    if peaks and group == "gravity":  # the table's F_max is that of X^n + beta X^p V
        values = values.at[4].add(dynamics.dry_in)
    e = values[0]
    if key.separation == "force" and group == "dry":
        # x^n (1 + beta V) = pi where the force criterion ends contact (n = p, V = -e)
        x_end = dynamics.x_star * jnp.power(
            second / jnp.maximum(1.0 - beta * e, 1e-300), 1.0 / key.n
        )
    elif key.separation == "force" and key.n != key.p:
        # where the force criterion ends contact: x^(n - p) + beta V = 0 (p < n)
        x_end = dynamics.x_star * jnp.power(jnp.maximum(beta * e, 1e-300), 1.0 / (key.n - key.p))
        x_end = jnp.where(beta > 0, x_end, 0.0)
    else:
        x_end = jnp.zeros_like(e)
    # a damping that only dissipates keeps e^2 <= 1 + 2 gamma x_end/x* (gravity's work over
    # a contact that ends inside the surface, under the force criterion, can put e above 1:
    # Hertz viscous at beta = 0.005, gamma = 0.66 gives e = 1.0007); the series' own error
    # could put e just above that bound: clamped, with the slope kept
    bound = jnp.sqrt(1.0 + 2.0 * dynamics.gamma * x_end / dynamics.x_star)
    e = e - jax.lax.stop_gradient(jnp.maximum(e - bound, 0.0))
    fields = fields_from_values(dynamics, values, e, m=m, v0=v0, gravity_work=m * g * x_end)
    return fields, x_end, in_range


def main(argv=None):
    """`python -m jaximpact._curves.gravity [--all | NAME ...]`: build the shipped tables
    that the files lack (all with `--all`, and those named, e.g. `n=1.5,p=0.5,force` or
    `dry:n=1,p=1,force`), writing a file after each table, so an interrupted run keeps
    what it built."""
    import sys

    jax.config.update("jax_enable_x64", True)
    argv = sys.argv[1:] if argv is None else argv
    started = time.perf_counter()
    for group, keys in (("gravity", SHIPPED), ("dry", SHIPPED_DRY)):
        path = _shipped_file(group)
        prefix = "" if group == "gravity" else "dry:"
        done = {} if "--all" in argv or not path.exists() else load(path, group)
        done = {k: t for k, t in done.items() if prefix + k.name not in argv}
        for key in keys:
            if key in done:
                continue
            done[key] = build_gravity(key, group=group)
            save([done[k] for k in keys if k in done], path)
        size = path.stat().st_size
        print(f"written {path} ({size / 1e6:.2f} MB, {time.perf_counter() - started:.0f} s)")


if __name__ == "__main__":
    main()
