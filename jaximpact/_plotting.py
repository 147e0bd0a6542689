"""Figures: one impact, in the style of the seed paper's (Polukoshko et al. 2007, Figs. 2-11),
and those of the command line's `--plot FILE` (a fit against the impact speed, a sweep, oblique
rebounds, recorded bounces, the benchmark's ratios).

matplotlib is imported inside the functions only, so `import jaximpact` never needs it.
"""

import numpy as np

# axis units: SI quantity times the factor gives the plotted number
_MM, _MS = 1e3, 1e3


def elastic_part(law, x):
    """The elastic part `c x^n` (N) of a law of the power family over the penetrations
    `x` (m) reached, as `(x grid, force, legend label)`; `None` for laws without one
    (Maxwell, a user's own law)."""
    family = None if law is None else law.coefficients(1.0)  # c and n never depend on v0
    if family is None:
        return None
    c, n, *_ = family
    c, n = float(c), float(n)
    x = np.linspace(0.0, max(float(np.max(x, initial=0.0)), 0.0), 200)
    power = "" if n == 1 else f"^{{{n:g}}}"
    return x, c * x**n, f"elastic part $c\\,x{power}$"


def plot_impact(result, law=None, *, fig=None, axes=None, title: str | None = None):
    """Draw one impact in three panels and return the matplotlib Figure.

    1. The force-displacement loop: the contact force `F` (N) against the penetration `x`
       (mm) over the contact, with the law's elastic part `c x^n` where it has one (the
       area between the loading and unloading branches is the energy dissipated).
    2. `F` (N) against time (ms), with the contact duration `T` and the peak `F_max`.
    3. The velocity `v` (m/s) against time (ms), with `t_max` (maximum compression, v = 0)
       and the rebound speed `e v0`.

    - `result`: an `ImpactResult` with histories, from `impact(..., ts=...)`; a grid
      reaching a little past the contact shows the separation, e.g.
      `ts = np.linspace(0, 1.05 * T, 600)` with `T` from a first call without `ts`.
    - `law`: the law that produced it, for the elastic part and the title (optional).
    - `fig`: a Figure to draw into (three panels side by side); `axes`: three Axes to
      draw into instead; neither: a new `pyplot` figure.
    - `title`: the figure's title; default: the law's name, e and T.

    **Example**:
    ```python
    law = ji.law("hertz_rate", c=2e6, b1=800.0)
    T = float(ji.impact(law, m=1.0, v0=2.5).T)
    r = ji.impact(law, m=1.0, v0=2.5, ts=np.linspace(0, 1.05 * T, 600))
    ji.plot_impact(r, law).savefig("impact.png")
    ```
    """
    if result.ts is None:
        raise ValueError(
            "plot_impact needs the time histories: pass ts= to impact, e.g. "
            "impact(law, m=..., v0=..., ts=np.linspace(0, 1.05 * T, 600))"
        )
    ts, x, v, force = (
        np.asarray(a, dtype=float) for a in (result.ts, result.x, result.v, result.F)
    )
    if ts.ndim != 1:
        raise ValueError(f"plot_impact draws one impact; got histories of shape {ts.shape}")
    e, T = float(result.e), float(result.T)
    status = _status_name(result)

    if axes is not None:
        axes = list(axes)
        if len(axes) != 3:
            raise ValueError(f"plot_impact needs 3 axes, got {len(axes)}")
        fig = axes[0].figure
    else:
        if fig is None:
            import matplotlib.pyplot as plt

            fig = plt.figure(figsize=(13.5, 4.2), layout="constrained")
        axes = list(fig.subplots(1, 3))
    ax_loop, ax_force, ax_speed = axes

    # 1. force-displacement loop over the contact
    contact = (ts >= 0.0) & (ts <= T)
    ax_loop.plot(x[contact] * _MM, force[contact], color="C0", lw=1.8, label="contact force $F$")
    elastic = None if law is None else elastic_part(law, x[contact])
    if elastic is not None:
        x_el, f_el, label = elastic
        ax_loop.plot(x_el * _MM, f_el, "--", color="C1", lw=1.4, label=label)
    _arrows(ax_loop, x[contact] * _MM, force[contact])
    ax_loop.axhline(0.0, color="0.6", lw=0.8)
    ax_loop.set_xlabel("penetration $x$ (mm)")
    ax_loop.set_ylabel("force (N)")
    ax_loop.set_title("force-displacement loop")
    ax_loop.legend(loc="best", fontsize="small")

    # 2. force against time
    ax_force.plot(ts * _MS, force, color="C0", lw=1.8)
    ax_force.axhline(0.0, color="0.6", lw=0.8)
    ax_force.axvline(T * _MS, color="k", ls=":", lw=1.0, label=f"$T$ = {T * _MS:.4g} ms")
    if result.F_max is not None:
        F_max = float(result.F_max)
        k = int(np.argmax(force))
        ax_force.plot(
            ts[k] * _MS, F_max, "o", color="C3", ms=5, label=f"$F_{{max}}$ = {F_max:.4g} N"
        )
    ax_force.set_xlabel("time $t$ (ms)")
    ax_force.set_ylabel("contact force $F$ (N)")
    ax_force.set_title("force")
    ax_force.legend(loc="best", fontsize="small")

    # 3. velocity against time
    ax_speed.plot(ts * _MS, v, color="C2", lw=1.8)
    ax_speed.axhline(0.0, color="0.6", lw=0.8)
    ax_speed.axvline(T * _MS, color="k", ls=":", lw=1.0, label=f"$T$ = {T * _MS:.4g} ms")
    if result.t_max is not None:
        t_max = float(result.t_max)
        ax_speed.axvline(
            t_max * _MS, color="C3", ls="--", lw=1.0, label=f"$t_{{max}}$ = {t_max * _MS:.4g} ms"
        )
    if status == "separated":
        v_out = float(result.v_out)
        ax_speed.axhline(v_out, color="C1", ls="--", lw=1.0, label=f"$-e\\,v_0$, e = {e:.4g}")
    ax_speed.set_xlabel("time $t$ (ms)")
    ax_speed.set_ylabel("velocity $v = dx/dt$ (m/s)")
    ax_speed.set_title("velocity (positive into the surface)")
    ax_speed.legend(loc="best", fontsize="small")

    if title is None:
        name = None if law is None else law.name
        title = (f"{name}: " if name else "") + f"e = {e:.4g}, T = {T * _MS:.4g} ms"
        if status != "separated":
            title += f" ({status})"
    if title:
        fig.suptitle(title)
    return fig


def _status_name(result) -> str:
    from ._status import Status

    return Status(int(result.status)).name


def _arrows(ax, x, y, count: int = 2):
    """Arrowheads along a curve showing the direction of travel (loading, then unloading)."""
    n = len(x)
    if n < 8:
        return
    for k in np.linspace(0, n - 1, count + 2)[1:-1].astype(int):
        if x[k + 1] == x[k] and y[k + 1] == y[k]:
            continue
        ax.annotate(
            "",
            xy=(x[k + 1], y[k + 1]),
            xytext=(x[k], y[k]),
            arrowprops=dict(arrowstyle="-|>", color="C0", lw=1.2, mutation_scale=14),
        )


def plain_log_axis(axis):
    """A log-scaled axis (`ax.xaxis`) labelled with plain numbers at 1, 2 and 5 of each
    decade (`0.3`, `2`, not `3x10^-1`, whose minor labels ran into each other over a short
    range)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.set_minor_formatter(NullFormatter())


def new_figure(**kwargs):
    """A matplotlib Figure drawn by the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    return Figure(**kwargs)


def save_figure(fig, path):
    """Write `fig` to `path` (format from the extension; a temporary name renamed into
    place, `_files.atomic_output`); an `OSError` that names the file if that fails."""
    from ._files import atomic_output

    try:
        with atomic_output(path) as temporary:  # never a half-written figure under `path`
            fig.savefig(temporary, dpi=150, bbox_inches="tight")
    except OSError as error:
        raise OSError(f"cannot write {path}: {error.strerror or error}") from None


# ---------------------------------------------------------------- the commands' figures


def plot_fitted_speeds(path, data, speeds, curves, title: str):
    """e (and T, ms) against the impact speed on a log axis, written to `path`: the
    measured points of `data` (`v0`, `e`, `T` or None, `sigma_e`, `sigma_T`: lists, T NaN
    where not measured) with error bars from the sigmas, and one line per `(name, e, T)`
    of `curves` at `speeds` (m/s), the first drawn heavier (`jaximpact calibrate`)."""
    v0 = np.asarray(data["v0"])
    has_T = data["T"] is not None
    fig = new_figure(figsize=(11.0 if has_T else 5.8, 4.2), layout="constrained")
    axes = fig.subplots(1, 2 if has_T else 1, squeeze=False)[0]
    for k, (name, es, Ts) in enumerate(curves):
        style = dict(lw=2.0 if k == 0 else 1.2, ls="-" if k == 0 else "--")
        axes[0].plot(speeds, es, label=f"{name} (fit)", **style)
        if has_T:
            axes[1].plot(speeds, 1e3 * np.asarray(Ts), label=f"{name} (fit)", **style)
    e_err = None if data["sigma_e"] is None else data["sigma_e"]
    axes[0].errorbar(
        v0, data["e"], yerr=e_err, fmt="o", color="k", ms=5, capsize=3, label="measured", zorder=5
    )
    axes[0].set_ylabel("coefficient of restitution e")
    if has_T:
        T = np.asarray(data["T"], dtype=float)
        T_err = None if data["sigma_T"] is None else 1e3 * np.asarray(data["sigma_T"])
        if T_err is not None:
            T_err = np.where(np.isnan(T), 0.0, T_err)
        axes[1].errorbar(
            v0, 1e3 * T, yerr=T_err, fmt="o", color="k", ms=5, capsize=3, label="measured", zorder=5
        )
        axes[1].set_ylabel("contact duration T [ms]")
    for ax in axes:
        ax.set_xscale("log")
        plain_log_axis(ax.xaxis)
        ax.set_xlabel("impact speed v0 [m/s]")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    save_figure(fig, path)


def plot_speed_sweep(path, v0, e, T, title: str):
    """e and T (ms) against the impact speeds `v0` (m/s), one point each, written to
    `path` (`jaximpact simulate --v0 ...`)."""
    fig = new_figure(figsize=(9.0, 3.6), layout="constrained")
    ax_e, ax_T = fig.subplots(1, 2)
    ax_e.plot(v0, e, "o-")
    ax_e.set_xlabel("impact speed v0 (m/s)")
    ax_e.set_ylabel("restitution e")
    ax_T.plot(v0, [1e3 * t for t in T], "o-")
    ax_T.set_xlabel("impact speed v0 (m/s)")
    ax_T.set_ylabel("contact duration T (ms)")
    fig.suptitle(title)
    save_figure(fig, path)


def plot_oblique(path, theta, fitted, measured=None):
    """e_t and the spin after impact (rad/s) against the incidence `theta` (degrees),
    written to `path`: `fitted` (`{"e_t": [...], "omega_out": [...]}`, a fit's or a sweep's)
    as a line, and where given the `measured` points (`jaximpact fit-oblique`, `simulate
    --tangential`)."""
    fig = new_figure(figsize=(9, 3.6))
    order = np.argsort(theta)
    for k, (name, label) in enumerate((("e_t", "e_t"), ("omega_out", "spin after [rad/s]"))):
        ax = fig.add_subplot(1, 2, k + 1)
        line = np.asarray(fitted[name], dtype=float)[order]
        ax.plot(np.asarray(theta)[order], line, "-" if measured else "o-", label="fit")
        if measured:
            ax.plot(theta, measured[name], "o", label="measured")
            ax.legend()
        ax.set_xlabel("incidence from the normal [deg]")
        ax.set_ylabel(label)
    save_figure(fig, path)


def plot_bounce_fits(path, fits: dict, trajectory: bool):
    """The fits of recorded bounces (`fit_bounces`, name -> `BounceFit`) in three panels,
    written to `path`: a `trajectory`'s heights measured and fitted with their residuals
    (its first fit), or the impact intervals and the impact-time residuals of each; then
    the fitted e against the impact speed (`jaximpact fit`)."""
    fig = new_figure(figsize=(13.5, 4.2), layout="constrained")
    axes = fig.subplots(1, 3)
    if trajectory:
        name, fit = next(iter(fits.items()))
        ts = np.linspace(float(np.min(fit.t)), float(np.max(fit.t)), 1500)
        axes[0].plot(fit.t, fit.y, ".", ms=3, label="measured")
        axes[0].plot(ts, fit.predict(ts), "-", lw=1.2, label="fitted")
        if fit.y_sign < 0:
            axes[0].invert_yaxis()
        axes[0].set_xlabel("time (s)")
        axes[0].set_ylabel("height (data units)")
        axes[0].set_title(f"{name}: measured and fitted")
        axes[0].legend(fontsize="small")
        axes[1].plot(fit.t, fit.y - fit.y_fit, ".", ms=3)
        axes[1].set_xlabel("time (s)")
        axes[1].set_ylabel("residual (data units)")
        axes[1].set_title("residuals")
    else:
        for name, fit in fits.items():
            gaps = np.diff(fit.times)
            whole = np.diff(fit.index) == 1
            model = np.diff(fit.impact_times)
            axes[0].plot(fit.index[:-1][whole], gaps[whole], "o", ms=3)
            axes[0].plot(np.arange(model.size), model, "-", lw=1, color="0.3")
            axes[1].plot(fit.times, fit.residuals * fit.sigma * 1e3, ".", ms=4, label=name)
        axes[0].set_xlabel("impact number")
        axes[0].set_ylabel("interval (s)")
        axes[0].set_title("intervals: measured (dots), fitted (lines)")
        axes[1].set_xlabel("time (s)")
        axes[1].set_ylabel("residual (ms)")
        axes[1].set_title("impact-time residuals")
    for fit in fits.values():
        axes[2].errorbar(fit.impact_speeds, fit.e, yerr=fit.e_stderr, fmt="o-", ms=3, lw=0.8)
    axes[2].set_xlabel("impact speed (m/s)")
    axes[2].set_ylabel("restitution e")
    axes[2].set_title("fitted e against impact speed")
    save_figure(fig, path)


def plot_bench(path, data, targets):
    """Grouped bars of a benchmark's single and batch ratios per law (`data["rows"]`, log
    scale), the `targets` (`{"single": x, "batch": x}`) as dashed lines, written to `path`
    (`jaximpact bench`)."""
    import math

    fig = new_figure(figsize=(1.6 + 1.5 * max(len(data["rows"]), 1), 4.0))
    ax = fig.add_subplot()
    names = [r["case"].replace(" (", "\n(") for r in data["rows"]]
    width = 0.38
    colors = {"single": "tab:blue", "batch": "tab:orange"}
    for k, kind in enumerate(("single", "batch")):
        values = [r[f"ratio_{kind}"] or float("nan") for r in data["rows"]]
        xs = [i + (k - 0.5) * width for i in range(len(values))]
        ax.bar(xs, values, width, color=colors[kind], label=f"{kind} (scipy / jaximpact)")
        for x, value in zip(xs, values, strict=True):
            if math.isfinite(value):
                label = f"{value:.0f}x" if value >= 100 else f"{value:.3g}x"
                ax.annotate(label, (x, value), ha="center", va="bottom", fontsize=7)
        ax.axhline(
            targets[kind],
            color=colors[kind],
            ls="--",
            lw=1,
            label=f"{kind} target {targets[kind]:.0f}x",
        )
    ax.set_xticks(range(len(names)), names, fontsize=8)
    ax.set_yscale("log")
    ax.set_ylabel("scipy DOP853 time / jaximpact time")
    machine = data["machine"]
    ax.set_title(
        f"jaximpact bench: {machine['cpu_count']} CPUs, {machine['backend']}, "
        f"load {machine['load_average']}",
        fontsize=9,
    )
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.0, 1.0))
    save_figure(fig, path)
