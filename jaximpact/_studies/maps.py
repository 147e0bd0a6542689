"""Maps of restitution `e` and contact duration `T` over a grid of stiffness and damping.

The seed paper draws `T(b, c)` and `e(b, c)` for Kelvin-Voigt (its Fig. 1: m = 1 kg,
c from 2e6 to 2e7 N/m, b from 200 to 1000 N s/m) and for Maxwell (its Fig. 7);
`restitution_map` computes the same for every law of `LAW_NAMES`, vectorised over the grid
(through `impact_batch`), and `plot_map` draws the two contour plots.
"""

import equinox as eqx
import numpy as np

from .._batch import batch_path, impact_batch
from .._choices import unknown_name
from .._format import PrintedFields, concrete_units
from .._laws import LAW_NAMES, LAWS, law
from .._laws.closed_forms import exact_batch
from .._laws.named_law import batch_law
from .._progress import AbstractMeter
from .._status import Status

# the stiffness axis of every map (N/m^n); the damping axis is the law's row's `map_range`
C_RANGE = (2e6, 2e7)


class RestitutionMap(PrintedFields, eqx.Module):
    """`e` and `T` of one law over a grid: rows follow `damping`, columns follow `c`.

    - `law`: the law's name; `damping_name`: the parameter along the first axis.
    - `c` (N/m^n), `damping` (its units): the grid's axes (1-D).
    - `e`, `T` (s), `status` (`Status` integers): arrays of shape `(len(damping), len(c))`;
      `e` is 0 and `T` the time to rest where the body did not separate.
    - `m` (kg), `v0` (m/s), `separation`, `fixed` (the other parameters), `path`: how the
      values were computed (`"integrated"` or `"closed_form"`).
    """

    _TITLE = "RestitutionMap (SI units; rows follow damping, columns c)"
    _SHOWN = (
        ("law", None),
        ("damping_name", None),
        ("c", lambda r: axis_unit(r, "c")),
        ("damping", lambda r: axis_unit(r, r.damping_name)),
        ("e", ""),
        ("T", "s"),
        ("m", "kg"),
        ("v0", "m/s"),
        ("separation", None),
        ("path", None),
    )

    law: str = eqx.field(static=True)
    damping_name: str = eqx.field(static=True)
    c: np.ndarray
    damping: np.ndarray
    e: np.ndarray
    T: np.ndarray
    status: np.ndarray
    m: float
    v0: float
    separation: str = eqx.field(static=True)
    fixed: dict
    path: str = eqx.field(static=True)


def axis_unit(result, name: str) -> str:
    """The unit of a map's axis `name` (a parameter of the law `result.law`)."""
    unit = concrete_units(LAWS[result.law], result.fixed).get(name, "-")
    return "" if unit == "-" else unit


def held_fixed(spec, fixed, damping_name) -> dict:
    """The parameters a map holds fixed: the row's `map_fixed` (less the grid's damping
    parameter), then the user's `fixed` over them."""
    defaults = {k: v for k, v in spec.map_fixed.items() if k != damping_name}
    return {**defaults, **(fixed or {})}


def axis(values, default, num, log):
    if values is None:
        lo, hi = default
        return np.geomspace(lo, hi, num) if log else np.linspace(lo, hi, num)
    values = np.asarray(values, dtype=float)
    if values.ndim != 1 or values.size < 2:
        raise ValueError(f"grid axes must be 1-D with at least 2 values, got shape {values.shape}")
    return values


def restitution_map(
    law_name: str,
    *,
    c=None,
    damping=None,
    m=1.0,
    v0=2.5,
    separation: str = "force",
    fixed: dict | None = None,
    damping_name: str | None = None,
    method: str = "auto",
    num: int = 41,
    rtol: float = 1e-10,
    progress: bool | AbstractMeter = False,
    **batch_options,
) -> RestitutionMap:
    """`e` and `T` of the law `law_name` over the grid `damping x c`, all at once.

    - `c`: stiffnesses (N/m^n, 1-D); default `num` values log-spaced over 2e6 to 2e7.
    - `damping`: values of the law's damping parameter (1-D); default `num` values over the
      range of the law's row, `LAWS[name].map_range` (for Kelvin-Voigt 200 to 1000 N s/m,
      the paper's Fig. 1).
    - `damping_name`: which parameter varies along `damping` (default: the row's `damping`,
      e.g.
      `b` for Kelvin-Voigt, `b1` for law 14, `a` for Hunt-Crossley, `P` for eq. 9,
      `e_nominal` for the published Hunt-Crossley variants).
    - `fixed`: the law's other parameters (added to the row's `map_fixed`, e.g. `P = 400 N` for
      Bingham); `m` (kg), `v0` (m/s), `separation` as in `impact`.
    - `method`: `"auto"` takes an exact closed form where it holds on the whole grid
      (Kelvin-Voigt; Maxwell when every point is under-damped, `4 b^2 > m c`, under the
      force criterion); `"integrate"` always integrates.
    - `num`, `rtol`, `progress` and `batch_options` (`chunk_size`, `devices`, ...): as in
      `impact_batch`.

    The published Hunt-Crossley variants (`lankarani_nikravesh`, `flores`, ...) are the
    Hunt-Crossley equation with a damping set from `e_nominal` and `v0`: they are solved
    through `hunt_crossley` with `a = D / 1.5`, so all of them share one compilation.

    **Example** (the paper's Fig. 1):
    `plot_map(restitution_map("kelvin_voigt")).savefig("fig1.png")`.
    """
    if law_name not in LAWS:
        raise ValueError(unknown_name("law", law_name, LAW_NAMES))
    spec = LAWS[law_name]
    damping_name = spec.damping if damping_name is None else damping_name
    fixed = held_fixed(spec, fixed, damping_name)
    if damping_name not in spec.parameters or damping_name == "c":
        raise ValueError(
            f"law {law_name!r} has no damping parameter {damping_name!r}; "
            f"its parameters are {', '.join(spec.parameters)}"
        )
    if {"c", damping_name} & set(fixed):
        raise ValueError("fixed must not hold c or the damping parameter: they are the grid")
    missing = [k for k in spec.geometry if k not in fixed]
    if missing:  # a radius is the user's, never guessed
        raise ValueError(
            f"law {law_name!r} needs its geometry held fixed: pass fixed={{"
            + ", ".join(f"{k!r}: ... (m)" for k in missing)
            + "}"
        )
    c = axis(c, C_RANGE, num, log=True)
    damping = axis(damping, spec.map_range, num, log=False)
    m, v0 = float(m), float(v0)

    damping_grid, c_grid = np.meshgrid(damping, c, indexing="ij")
    flat = {"c": c_grid.ravel(), damping_name: damping_grid.ravel()}
    params = {**fixed, **flat}
    name = law_name
    if spec.nominal is not None and damping_name == "e_nominal":
        # the same equation as hunt_crossley, with a = D / 1.5: one compiled solve for all
        factor = spec.nominal(params.pop("e_nominal"), v0)
        params["a"] = np.asarray(factor, dtype=float) / 1.5
        name = "hunt_crossley"

    made = batch_law(name, **params)  # one law, its parameters the grid's arrays
    out = exact_batch(made, m=m, v0=v0, separation=separation) if method == "auto" else None
    path = "closed_form"
    if out is None:
        out = impact_batch(
            name,
            params,
            m=m,
            v0=v0,
            separation=separation,
            method=method,
            rtol=rtol,
            peaks=False,
            fields=("e", "T", "status"),
            progress=progress,
            **batch_options,
        )
        first = law(name, **{k: np.asarray(v).ravel()[0] for k, v in params.items()})
        path = batch_path(first, separation, method=method, rtol=rtol, **batch_options)
    shape = damping_grid.shape
    return RestitutionMap(
        law=law_name,
        damping_name=damping_name,
        c=c,
        damping=damping,
        e=np.asarray(out["e"], dtype=float).reshape(shape),
        T=np.asarray(out["T"], dtype=float).reshape(shape),
        status=np.asarray(out["status"]).astype(int).reshape(shape),
        m=m,
        v0=v0,
        separation=separation,
        fixed=fixed,
        path=path,
    )


_UNITS = {"b": "N s/m", "b1": "N s/m$^{p+1}$", "a": "s/m", "P": "N", "e_nominal": "-"}


def plot_map(rmap: RestitutionMap, *, fig=None, axes=None, levels: int = 12, title=None):
    """Contour plots of `T` (ms) and `e` over the grid of a `RestitutionMap`; returns the
    matplotlib Figure.

    The damping parameter runs along x, the stiffness `c` (log scale) along y, as the seed
    paper's Figs. 1 and 7 read. Grid points where the body did not separate (stuck or
    captured) are hatched. `fig`: a Figure to draw into (two panels side by side); `axes`:
    two Axes instead; `title`: default the law, `m` and `v0`.

    **Example**: `plot_map(restitution_map("maxwell")).savefig("fig7.png")`.
    """
    import matplotlib.pyplot as plt

    if axes is not None:
        axes = list(axes)
        if len(axes) != 2:
            raise ValueError(f"plot_map needs 2 axes, got {len(axes)}")
        fig = axes[0].figure
    else:
        if fig is None:
            fig = plt.figure(figsize=(11, 4.4), layout="constrained")
        axes = list(fig.subplots(1, 2))
    x, y = np.meshgrid(rmap.damping, rmap.c, indexing="ij")
    unit = _UNITS.get(rmap.damping_name, "")
    stuck = rmap.status != Status.separated
    panels = (
        (rmap.T * 1e3, "contact duration $T$ (ms)", "viridis"),
        (rmap.e, "restitution $e$", "magma"),
    )
    for ax, (values, label, cmap) in zip(axes, panels, strict=True):
        filled = ax.contourf(x, y, values, levels=levels, cmap=cmap)
        lines = ax.contour(x, y, values, levels=filled.levels, colors="k", linewidths=0.5)
        ax.clabel(lines, lines.levels[::2], fontsize=7, fmt="%.3g")
        if np.any(stuck):
            ax.contourf(x, y, stuck.astype(float), levels=[0.5, 1.5], colors="none", hatches=["//"])
        fig.colorbar(filled, ax=ax, label=label)
        ax.set_yscale("log")
        ax.set_xlabel(f"{rmap.damping_name} ({unit})" if unit else rmap.damping_name)
        ax.set_ylabel("stiffness $c$ (N/m$^n$)")
        ax.set_title(label)
    if title is None:
        extra = "".join(f", {k} = {v:g}" for k, v in rmap.fixed.items())
        title = (
            f"{rmap.law}: m = {rmap.m:g} kg, v0 = {rmap.v0:g} m/s{extra} "
            f"({rmap.separation} separation, {rmap.path})"
        )
    if title:
        fig.suptitle(title)
    return fig
