"""`jacobian_batch`, `sensitivity_map`: `de/dparam` and `dT/dparam` over a batch or a grid
(forward-mode derivatives through the event-terminated solve), and their contour plot.
"""

import functools

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._batch import build_law, cost_key, prepare_rows, run_batch
from .._format import PrintedFields
from .._laws import LAWS
from .._progress import AbstractMeter
from .._solve.impact import impact
from .maps import C_RANGE, axis, axis_unit, held_fixed


@functools.lru_cache(maxsize=32)
def _jacobian_member(skeleton, wrt: tuple, options: tuple):
    """One row -> `e`, `T`, `status` and their forward-mode derivatives with respect to
    `wrt` (law parameters, `m`, `v0`); cached so that batches of one kind compile once."""
    keywords = dict(options)

    def member(row):
        def solve(theta):
            params = {**row["params"], **{k: v for k, v in theta.items() if k in row["params"]}}
            result = impact(
                build_law(skeleton, params),
                m=theta.get("m", row["m"]),
                v0=theta.get("v0", row["v0"]),
                g=row.get("g", 0.0),
                peaks=False,
                **keywords,
            )
            values = jnp.stack([result.e, result.T])
            return values, (values, result.status)

        theta = {k: row["params"][k] if k in row["params"] else row[k] for k in wrt}
        jac, (values, status) = jax.jacfwd(solve, has_aux=True)(theta)
        out = {"e": values[0], "T": values[1], "status": status}
        for k in wrt:
            out[f"de_d{k}"], out[f"dT_d{k}"] = jac[k][0], jac[k][1]
        return out

    return member


def jacobian_batch(
    law,
    params: dict | None = None,
    *,
    wrt,
    m,
    v0,
    g=0.0,
    separation: str = "force",
    rtol: float = 1e-10,
    progress: bool | AbstractMeter = False,
    **batch_options,
) -> dict[str, np.ndarray]:
    """`e`, `T` and their derivatives with respect to `wrt` for a batch of impacts.

    `law`, `params`, `m`, `v0`, `g`, `separation`, `rtol`: as in `impact_batch`; `wrt`:
    names of law parameters and/or `"m"`, `"v0"`. Returns numpy arrays `e`, `T`, `status`
    and `de_d<name>`, `dT_d<name>` for each name (SI units: `dT_dc` in s per N/m^n).
    Forward mode (`jax.jacfwd` with diffrax's `ForwardMode`), about 2-4 solves per row.
    """
    wrt = tuple(wrt)
    skeleton, law_params, kinematics, _ = prepare_rows(law, params, m=m, v0=v0, g=g)
    for name in wrt:
        if name not in law_params and name not in ("m", "v0"):
            raise ValueError(
                f"cannot differentiate with respect to {name!r}: the law's parameters are "
                f"{', '.join(law_params)} (or m, v0)"
            )
    rows = {"params": law_params, "m": kinematics["m"], "v0": kinematics["v0"]}
    if np.any(kinematics["g"] != 0):
        rows["g"] = kinematics["g"]
    options = tuple(sorted(dict(separation=separation, rtol=rtol).items()))
    member = _jacobian_member(skeleton, wrt, options)
    cost = cost_key(skeleton, law_params, **kinematics)  # rows of similar step counts together
    return run_batch(
        member, rows, progress=progress, cost=cost, description="derivatives", **batch_options
    )


class SensitivityMap(PrintedFields, eqx.Module):
    """`e`, `T` and their derivatives over a grid (rows: `damping`, columns: `c`).

    `de_dc`, `de_ddamping`, `dT_dc`, `dT_ddamping` in SI units; `elasticity(which)` gives
    the dimensionless `d ln y / d ln p` (the relative change of `y` per relative change of
    `p`), e.g. `elasticity("e", "c")`.
    """

    _TITLE = "SensitivityMap (SI units; rows follow damping, columns c)"
    _SHOWN = (
        ("law", None),
        ("damping_name", None),
        ("c", lambda r: axis_unit(r, "c")),
        ("damping", lambda r: axis_unit(r, r.damping_name)),
        ("e", ""),
        ("T", "s"),
        ("de_dc", ""),
        ("de_ddamping", ""),
        ("dT_dc", ""),
        ("dT_ddamping", ""),
        ("m", "kg"),
        ("v0", "m/s"),
    )

    law: str = eqx.field(static=True)
    damping_name: str = eqx.field(static=True)
    c: np.ndarray
    damping: np.ndarray
    e: np.ndarray
    T: np.ndarray
    de_dc: np.ndarray
    de_ddamping: np.ndarray
    dT_dc: np.ndarray
    dT_ddamping: np.ndarray
    m: float
    v0: float
    fixed: dict

    def elasticity(self, output: str, parameter: str) -> np.ndarray:
        """`d ln output / d ln parameter` over the grid (`output` "e" or "T", `parameter`
        "c" or "damping")."""
        grids = np.meshgrid(self.damping, self.c, indexing="ij")
        value = {"damping": grids[0], "c": grids[1]}[parameter]
        derivative = getattr(self, f"d{output}_d{parameter}")
        return derivative * value / getattr(self, output)


def sensitivity_map(
    law_name: str,
    *,
    c=None,
    damping=None,
    m=1.0,
    v0=2.5,
    fixed: dict | None = None,
    num: int = 31,
    rtol: float = 1e-10,
    progress: bool | AbstractMeter = False,
    **batch_options,
) -> SensitivityMap:
    """`de/dc`, `de/d(damping)`, `dT/dc`, `dT/d(damping)` of `law_name` over the grid
    `damping x c`; the grid's defaults are those of `restitution_map` (the law's row:
    `damping`, `map_range`, `map_fixed`).

    **Example**: `s = sensitivity_map("hertz_rate"); s.elasticity("e", "damping")`.
    """
    spec = LAWS[law_name]
    damping_name = spec.damping
    fixed = held_fixed(spec, fixed, damping_name)
    c = axis(c, C_RANGE, num, log=True)
    damping = axis(damping, spec.map_range, num, log=False)
    d_grid, c_grid = np.meshgrid(damping, c, indexing="ij")
    params = {**fixed, "c": c_grid.ravel(), damping_name: d_grid.ravel()}
    out = jacobian_batch(
        law_name,
        params,
        wrt=("c", damping_name),
        m=m,
        v0=v0,
        rtol=rtol,
        progress=progress,
        **batch_options,
    )
    shape = d_grid.shape
    grid = {k: np.asarray(v).reshape(shape) for k, v in out.items()}
    return SensitivityMap(
        law=law_name,
        damping_name=damping_name,
        c=c,
        damping=damping,
        e=grid["e"],
        T=grid["T"],
        de_dc=grid["de_dc"],
        de_ddamping=grid[f"de_d{damping_name}"],
        dT_dc=grid["dT_dc"],
        dT_ddamping=grid[f"dT_d{damping_name}"],
        m=float(m),
        v0=float(v0),
        fixed=fixed,
    )


def plot_sensitivity(smap: SensitivityMap, *, fig=None, levels: int = 12, title=None):
    """Four contour plots of the elasticities `d ln e / d ln c`, `d ln e / d ln damping`,
    `d ln T / d ln c`, `d ln T / d ln damping` over the grid; returns the Figure."""
    import matplotlib.pyplot as plt

    if fig is None:
        fig = plt.figure(figsize=(11, 8), layout="constrained")
    axes = fig.subplots(2, 2)
    x, y = np.meshgrid(smap.damping, smap.c, indexing="ij")
    for row, output in enumerate(("e", "T")):
        for col, parameter in enumerate(("c", "damping")):
            ax = axes[row, col]
            values = smap.elasticity(output, parameter)
            filled = ax.contourf(x, y, values, levels=levels, cmap="coolwarm")
            lines = ax.contour(x, y, values, levels=filled.levels, colors="k", linewidths=0.4)
            ax.clabel(lines, lines.levels[::2], fontsize=7, fmt="%.3g")
            name = smap.damping_name if parameter == "damping" else "c"
            fig.colorbar(filled, ax=ax, label=f"d ln {output} / d ln {name}")
            ax.set_yscale("log")
            ax.set_xlabel(smap.damping_name)
            ax.set_ylabel("stiffness $c$")
            ax.set_title(f"$\\partial \\ln {output} / \\partial \\ln {name}$")
    if title is None:
        title = f"{smap.law}: sensitivities of e and T (m = {smap.m:g} kg, v0 = {smap.v0:g} m/s)"
    fig.suptitle(title)
    return fig
