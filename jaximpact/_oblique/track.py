"""Rebounds read off a video track of a ball bouncing across a floor with spin:
`track_rebounds`, each impact's speeds and spin before and after, ready for `fit_oblique`
(and the normal ones for `calibrate`).

Between two contacts the ball flies: its centre's `x` moves at a constant speed, its height
`y` on a parabola of the known `g`, and a mark's angle `phi` at a constant spin (no drag:
a short flight of a dense ball). Each flight is one least-squares fit, `x = a + v_x t`,
`y + g t^2/2 = b + v_y0 t`, `phi = c + phi' t`, over its frames away from the contacts;
an impact is where the parabolas before and after it meet (`t_c`), its speeds the flights'
there. Signs follow DESIGN.md ("Oblique impacts"): `v_n > 0` approaching, `v_t = v_x`,
and `omega = -phi'` for `phi` counterclockwise in the image with `y` up (a ball rolling
to +x turns clockwise: `omega = v_t / R`), so that the contact point slips at
`u = v_t - R omega`. The contact's own duration (well under a frame for a hard ball) is
not resolved: both sides are evaluated at `t_c`, which shifts the normal speeds by `g T`.
"""

import dataclasses
import math

import numpy as np

from .._checks import check_positive
from .._format import format_fields, format_value, jsonable

# the fields as `summary()` shows them, with units
_SHOWN = (
    ("t_impact", "s"),
    ("v_n", "m/s"),
    ("v_t", "m/s"),
    ("omega", "rad/s"),
    ("v_n_out", "m/s"),
    ("v_t_out", "m/s"),
    ("omega_out", "rad/s"),
    ("e", ""),
    ("e_t", ""),
    ("sigma_e_t", ""),
    ("sigma_omega_out", "rad/s"),
)


@dataclasses.dataclass(frozen=True)
class TrackRebounds:
    """Each impact of a track (arrays, one entry per impact, SI units): `t_impact` (s),
    the speeds before, `v_n` (> 0, approaching), `v_t`, `omega` (rad/s), and after,
    `v_n_out`, `v_t_out`, `omega_out`; `e = v_n_out / v_n`, `e_t = v_t_out / v_t`; their
    standard errors from the flights' fits, `sigma_e`, `sigma_e_t`, `sigma_omega_out`
    (`omega`, `omega_out` and their errors are NaN without a spin track); `flights`: the
    frames `(first, last)` of each flight fitted;
    `g_track` (m/s^2): the fall acceleration the flights show when it is left free (a check
    of the units)."""

    t_impact: np.ndarray
    v_n: np.ndarray
    v_t: np.ndarray
    omega: np.ndarray
    v_n_out: np.ndarray
    v_t_out: np.ndarray
    omega_out: np.ndarray
    e: np.ndarray
    e_t: np.ndarray
    sigma_e: np.ndarray
    sigma_e_t: np.ndarray
    sigma_omega_out: np.ndarray
    flights: tuple[tuple[int, int], ...]
    g_track: float

    def fit_inputs(self) -> dict:
        """The keywords of `fit_oblique` that the track gives: the speeds and spin before,
        `e_t` and `omega_out`, with their standard errors. A track without the spin (no
        `phi`) cannot give the spin before each impact: a one-line ValueError."""
        if not np.all(np.isfinite(self.omega)):
            raise ValueError(
                "the track has no spin (phi): the spin before each impact is unknown; track "
                "a mark on the ball, or give fit_oblique the spins (omega=) yourself"
            )
        return dict(
            v_n=self.v_n,
            v_t=self.v_t,
            omega=self.omega,
            e_t=self.e_t,
            omega_out=self.omega_out,
            sigma_e_t=self.sigma_e_t,
            sigma_omega=self.sigma_omega_out,
        )

    def to_dict(self) -> dict:
        return {f.name: jsonable(getattr(self, f.name)) for f in dataclasses.fields(self)}

    def summary(self) -> str:
        """The impacts as text, every number with its unit."""
        shown = [*_SHOWN, ("g_track", "m/s^2")]
        rows = [(name, format_value(getattr(self, name), unit)) for name, unit in shown]
        return format_fields(f"Rebounds of a track ({len(self.v_n)} impacts; SI units)", rows)

    def __repr__(self) -> str:
        return self.summary()


def _slope_sigma(covariance) -> float:
    """The standard error of a line's slope from its fit's covariance."""
    return math.sqrt(max(float(covariance[1, 1]), 0.0))


def _line(t, values):
    """Least-squares `values = p0 + p1 t`: `(p, covariance)`, the covariance from the
    residuals' own scatter (at least one degree of freedom)."""
    design = np.stack([np.ones_like(t), t], axis=1)
    p, residuals, _, _ = np.linalg.lstsq(design, values, rcond=None)
    dof = max(len(t) - 2, 1)
    scatter = float(residuals[0]) / dof if residuals.size else 0.0
    return p, scatter * np.linalg.inv(design.T @ design)


def _contacts(y, min_gap: int) -> list[int]:
    """Frames of the lowest points between flights: local minima of `y` in the lower fifth
    of its range, those closer than `min_gap` frames merged (the lowest kept)."""
    low = y.min() + 0.2 * (y.max() - y.min())
    candidates = [
        i for i in range(1, len(y) - 1) if y[i] <= y[i - 1] and y[i] < y[i + 1] and y[i] < low
    ]
    merged: list[int] = []
    for i in candidates:
        if merged and i - merged[-1] < min_gap:
            if y[i] < y[merged[-1]]:
                merged[-1] = i
            continue
        merged.append(i)
    return merged


def _array(name, values, n=None):
    out = np.asarray(values, dtype=float)
    if out.ndim != 1 or (n is not None and len(out) != n):
        raise ValueError(
            f"{name} must be a 1-D array of {n or 'the'} samples, got shape {out.shape}"
        )
    if not np.all(np.isfinite(out)):
        raise ValueError(f"{name} holds NaN or infinite values: drop those frames first")
    return out


def track_rebounds(t, x, y, phi=None, *, g=9.81, skip: int = 2, min_points: int = 5):
    """The impacts of a ball's track: times `t` (s, increasing), its centre's `x` and `y`
    (m; `y` up, the floor below), and optionally a mark's angle `phi` (rad, counterclockwise,
    unwrapped or not) for the spin; `g` (m/s^2). `skip`: frames left out on each side of a
    contact (its frames show the ball touching, not flying); `min_points`: the fewest frames
    a flight's fit takes. Returns `TrackRebounds` (see the module's docstring for the
    method and the signs).

    One-line ValueErrors: arrays of different lengths or with NaN, times not increasing,
    fewer than two flights, a flight with too few frames, or a track whose fall
    acceleration is not `g` (positions in mm or px: give them in m).

    **Example**: `r = track_rebounds(t, x, y, phi); fit_oblique(law, tangential, m=m, R=R,
    **r.fit_inputs())`.
    """
    t = _array("t", t)
    n = len(t)
    x, y = _array("x", x, n), _array("y", y, n)
    if phi is not None:
        phi = np.unwrap(_array("phi", phi, n))
    g = check_positive("g", g, "m/s^2")
    if n < 2 * min_points or not np.all(np.diff(t) > 0):
        raise ValueError("t must increase from frame to frame, with enough frames for two flights")
    contacts = _contacts(y, min_gap=2 * skip + 2)
    if not contacts:
        raise ValueError(
            "no impact found in the track: y must come down to the floor and go back up "
            "(y up, in m)"
        )
    edges = [0, *contacts, n - 1]
    flights = []
    for k in range(len(edges) - 1):
        first = edges[k] + (skip if k > 0 else 0)
        last = edges[k + 1] - (skip if k < len(edges) - 2 else 0)
        flights.append((first, last))
    fits = []
    g_free = []
    scatter = {"x": [], "y": []}  # the fits' residuals: a flight's y is a parabola of g
    for first, last in flights:
        if last - first + 1 < min_points:
            raise ValueError(
                f"the flight over frames {first}-{last} has {last - first + 1} frames, fewer "
                f"than min_points={min_points}: a faster camera, or a smaller skip"
            )
        s = t[first : last + 1]
        fit = {
            "x": _line(s, x[first : last + 1]),
            "y": _line(s, y[first : last + 1] + 0.5 * g * s**2),
        }
        if phi is not None:
            fit["phi"] = _line(s, phi[first : last + 1])
        fits.append(fit)
        for name, values in (("x", x), ("y", y + 0.5 * g * t**2)):
            p_fit, _ = fit[name]
            scatter[name].append(values[first : last + 1] - p_fit[0] - p_fit[1] * s)
        if len(s) >= 4:
            g_free.append(-2.0 * np.polyfit(s, y[first : last + 1], 2)[0])
    g_track = float(np.median(g_free)) if g_free else math.nan
    if not (0.7 * g < g_track < 1.3 * g):
        raise ValueError(
            f"the track falls at {g_track:.4g} (its y units per s^2), not g = {g:g} m/s^2: "
            "give the positions in metres, with y up"
        )
    rms = {k: float(np.sqrt(np.mean(np.concatenate(v) ** 2))) for k, v in scatter.items()}
    if rms["y"] > 5.0 * rms["x"] + 1e-6 * (y.max() - y.min()):
        raise ValueError(
            f"the heights between the impacts found are not parabolas of g (residuals "
            f"{rms['y']:.3g} against {rms['x']:.3g} along x): give y up, in m, with the "
            "floor below"
        )
    rebounds = _rebounds(fits, g, flights, g_track, spin=phi is not None)
    gaps = [(t[b[1]], t[a[0]]) for b, a in zip(flights[:-1], flights[1:], strict=True)]
    for k, (t_c, (end, start)) in enumerate(zip(rebounds.t_impact, gaps, strict=True)):
        bounce = rebounds.v_n[k] > 0 and rebounds.v_n_out[k] > 0
        if not (bounce and end - 1e-9 <= t_c <= start + 1e-9):
            raise ValueError(
                f"the track near t = {t_c:.4g} s is not a bounce (the ball coming down to "
                "the floor and going back up between two flights): give y up, in m"
            )
    return rebounds


def _rebounds(fits, g, flights, g_track, *, spin: bool) -> TrackRebounds:
    """Each impact between consecutive flights' fits."""
    rows = []
    for before, after in zip(fits[:-1], fits[1:], strict=True):
        (b1, vy1), cov_y1 = before["y"]
        (b2, vy2), cov_y2 = after["y"]
        t_c = (b2 - b1) / (vy1 - vy2)  # where the two parabolas meet
        v_n, v_n_out = -(vy1 - g * t_c), vy2 - g * t_c

        # a speed at t_c, p1 - g t_c, carries its slope's error (t_c held)
        s_n, s_n_out = _slope_sigma(cov_y1), _slope_sigma(cov_y2)
        (_, v_t), cov_x1 = before["x"]
        (_, v_t_out), cov_x2 = after["x"]
        s_t, s_t_out = _slope_sigma(cov_x1), _slope_sigma(cov_x2)
        if spin:
            (_, spin1), _ = before["phi"]
            (_, spin2), cov_phi2 = after["phi"]
            omega, omega_out = -spin1, -spin2
            s_omega_out = _slope_sigma(cov_phi2)
        else:  # not tracked: unknown, not assumed
            omega, omega_out, s_omega_out = math.nan, math.nan, math.nan
        e, e_t = v_n_out / v_n, v_t_out / v_t
        rows.append(
            (
                t_c,
                v_n,
                v_t,
                omega,
                v_n_out,
                v_t_out,
                omega_out,
                e,
                e_t,
                abs(e) * math.hypot(s_n_out / v_n_out, s_n / v_n),
                abs(e_t) * math.hypot(s_t_out / v_t_out, s_t / v_t),
                s_omega_out,
            )
        )
    columns = [np.array(c) for c in zip(*rows, strict=True)]
    return TrackRebounds(*columns, flights=tuple(flights), g_track=g_track)
