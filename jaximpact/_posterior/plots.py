"""The figure of a posterior: a pairs plot of the draws and the bands over the data."""

import numpy as np

from .._plotting import new_figure, save_figure
from .oblique_model import ObliqueModel


def plot_posterior(post, path=None, *, v0=None, angle=None, level=0.9):
    """Pairs plot of `post`'s draws (histograms on the diagonal, log axes for positive
    parameters spanning more than a factor of 3) and, with a forward model, the `level`
    bands over the measured data (error bars: the given sigmas): of e and T over the
    speeds `v0`, or of an oblique fit's e_t and spin over the incidence angles `angle`
    (rad)."""
    names = list(post.names)
    d = len(names)
    model = post.model
    bands = model is not None
    ncols = d + (1 if bands else 0)
    fig = new_figure(figsize=(2.6 * ncols, 2.6 * d), layout="constrained")
    grid = fig.add_gridspec(d, ncols)
    draws = {k: np.asarray(post.samples[k]) for k in names}
    log = {k: bool(np.all(draws[k] > 0) and draws[k].max() > 3 * draws[k].min()) for k in names}
    shown = {k: np.log10(draws[k]) if log[k] else draws[k] for k in names}
    thin = slice(None, None, max(1, len(draws[names[0]]) // 4000))
    for i, ki in enumerate(names):
        for j, kj in enumerate(names[: i + 1]):
            ax = fig.add_subplot(grid[i, j])
            if i == j:
                ax.hist(shown[ki], bins=40, color="C0", alpha=0.8)
                ax.set_yticks([])
            else:
                ax.plot(shown[kj][thin], shown[ki][thin], ".", ms=1.5, alpha=0.3, color="C0")
            if i == d - 1:
                ax.set_xlabel(_label(kj, post, log[kj]))
            if j == 0 and i > 0:
                ax.set_ylabel(_label(ki, post, log[ki]))
    if bands:
        if isinstance(model, ObliqueModel):
            x_label, measured, x, panels = _oblique_panels(post, angle, level)
        else:
            x_label, measured, x, panels = _speed_panels(post, v0, level)
        half = max(d // 2, 1)
        for row, (what, med, blo, bhi, data, sig) in enumerate(panels):
            span = slice(0, half) if row == 0 else slice(half, d)
            if row == 1 and d < 2:
                break
            ax = fig.add_subplot(grid[span, d])
            band = f"{100 * level:g} % band"
            ax.fill_between(x, blo, bhi, color="C1", alpha=0.3, label=band)
            ax.plot(x, med, color="C1", label="median")
            if data is not None:
                ax.errorbar(measured, data, yerr=sig, fmt="o", color="k", ms=3, label="data")
            ax.set_ylabel(what)
            ax.set_xlabel(x_label)
            if row == 0:
                ax.legend(fontsize=7)
    fig.suptitle(f"Posterior of {post.law_name} ({post.method})")
    if path is not None:
        save_figure(fig, path)
    return fig


def _speed_panels(post, v0, level):
    """The bands of e and T over the speeds (default: around the measured ones)."""
    model = post.model
    measured = np.asarray(model.v0)
    lo, hi = measured.min(), measured.max()
    speeds = np.linspace(0.5 * lo, 1.5 * hi, 40) if v0 is None else np.asarray(v0, float)
    b = post.predict(speeds, level=level)
    panels = (
        ("e", b.e, b.e_lo, b.e_hi, model.e, model.sigma_e),
        ("T (s)", b.T, b.T_lo, b.T_hi, model.T, model.sigma_T),
    )
    return "v0 (m/s)", measured, speeds, panels


# an oblique fit's bands: at most this many angles and draws (each a solve with events)
OBLIQUE_ANGLES = 24
OBLIQUE_DRAWS = 200


def _oblique_panels(post, angle, level):
    """The bands of e_t and the spin over incidence angles (degrees on the axis; default:
    over the measured angles), the measured kinds first, at the fit's median speed."""
    problem = post.model.problem
    measured = np.degrees(np.arctan2(np.asarray(problem.v_t), np.asarray(problem.v_n)))
    if angle is None:
        lo, hi = max(0.5 * measured.min(), 0.5), min(measured.max() + 5.0, 89.0)
        angle = np.deg2rad(np.linspace(lo, hi, OBLIQUE_ANGLES))
    b = post.predict(angle=angle, level=level, max_draws=OBLIQUE_DRAWS)

    def data(kind, has):
        return np.asarray(getattr(problem, kind)) if has else None

    def sigma(given, has):
        return None if given is None or not has else np.asarray(given)

    e_t = ("e_t", b.e_t, b.e_t_lo, b.e_t_hi, data("e_t", problem.has_e))
    e_t += (sigma(post.model.sigma_e_t, problem.has_e),)
    spin = ("omega_out (rad/s)", b.omega_out, b.omega_out_lo, b.omega_out_hi)
    spin += (data("omega_out", problem.has_w), sigma(post.model.sigma_omega, problem.has_w))
    panels = (e_t, spin) if problem.has_e or not problem.has_w else (spin, e_t)
    return "incidence (deg)", measured, np.degrees(np.asarray(b.angle)), panels


def _label(name, post, log):
    unit = post.units.get(name, "")
    text = f"{name} ({unit})" if unit else name
    return f"log10 {text}" if log else text
