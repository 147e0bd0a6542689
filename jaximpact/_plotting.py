"""Figures of one impact, in the style of the seed paper's (Polukoshko et al. 2007, Figs. 2-11).

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
