"""The figure of a posterior: a pairs plot of the draws and the bands over the data."""

import numpy as np

from .._plotting import new_figure, save_figure


def plot_posterior(post, path=None, *, v0=None, level=0.9):
    """Pairs plot of `post`'s draws (histograms on the diagonal, log axes for positive
    parameters spanning more than a factor of 3) and, with a forward model, the `level`
    bands of e and T over the measured data (error bars: the given sigmas)."""
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
        measured = np.asarray(model.v0)
        lo, hi = measured.min(), measured.max()
        speeds = np.linspace(0.5 * lo, 1.5 * hi, 40) if v0 is None else np.asarray(v0, float)
        b = post.predict(speeds, level=level)
        half = max(d // 2, 1)
        for row, (what, med, blo, bhi, data, sig) in enumerate(
            (
                ("e", b.e, b.e_lo, b.e_hi, model.e, model.sigma_e),
                ("T (s)", b.T, b.T_lo, b.T_hi, model.T, model.sigma_T),
            )
        ):
            span = slice(0, half) if row == 0 else slice(half, d)
            if row == 1 and d < 2:
                break
            ax = fig.add_subplot(grid[span, d])
            band = f"{100 * level:g} % band"
            ax.fill_between(speeds, blo, bhi, color="C1", alpha=0.3, label=band)
            ax.plot(speeds, med, color="C1", label="median")
            if data is not None:
                ax.errorbar(measured, data, yerr=sig, fmt="o", color="k", ms=3, label="data")
            ax.set_ylabel(what)
            ax.set_xlabel("v0 (m/s)")
            if row == 0:
                ax.legend(fontsize=7)
    fig.suptitle(f"Posterior of {post.law_name} ({post.method})")
    if path is not None:
        save_figure(fig, path)
    return fig


def _label(name, post, log):
    unit = post.units.get(name, "")
    text = f"{name} ({unit})" if unit else name
    return f"log10 {text}" if log else text
