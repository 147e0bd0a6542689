"""The paper's figures redrawn: a force-displacement loop and its velocity beside the
paper's Euler, a bounce sequence, and the maps of Figs. 1 and 7.
"""

from pathlib import Path

import numpy as np

from .cases import CRITERIA, DROP_DURATION, DROP_HEIGHT, V0, M, PaperCase, figure_numbers
from .tables import format_parameters


def plot_loop(row, law, histories, path: Path):
    """The paper's loop figure: force (and its elastic part) and velocity against the
    penetration, converged (force criterion) and Euler as printed."""
    from .._plotting import elastic_part, new_figure

    fig = new_figure(figsize=(11, 4.2), layout="constrained")
    ax_force, ax_speed = fig.subplots(1, 2)
    exact = histories["force"]
    contact = np.asarray(exact.ts) <= row["T_force"]
    x, v, F = (np.asarray(a)[contact] for a in (exact.x, exact.v, exact.F))
    euler = histories["paper"]
    inside = (euler.t >= euler.impact_times[0]) & (euler.t <= euler.release_times[0])
    xe, ve, Fe = -euler.height[inside], -euler.velocity[inside], euler.force[inside]
    ax_force.plot(x * 1e3, F, color="C0", lw=1.8, label=f"converged, e = {row['e_force']:.3f}")
    ax_force.plot(
        xe * 1e3, Fe, color="C1", lw=0.9, label=f"paper's Euler 2e-5 s, e = {row['e_paper']:.3f}"
    )
    elastic = elastic_part(law, x)
    if elastic is not None:
        ax_force.plot(elastic[0] * 1e3, elastic[1], "--", color="0.4", lw=1.0, label=elastic[2])
    ax_speed.plot(x * 1e3, v, color="C0", lw=1.8, label="converged")
    ax_speed.plot(xe * 1e3, ve, color="C1", lw=0.9, label="paper's Euler 2e-5 s")
    for ax, label in ((ax_force, "force $N$ (N)"), (ax_speed, "velocity $v$ (m/s)")):
        ax.axhline(0.0, color="0.7", lw=0.8)
        ax.set_xlabel("penetration $x$ (mm)")
        ax.set_ylabel(label)
        ax.legend(fontsize="small")
    printed = "" if row["printed"] is None else f"; printed e = {row['printed']:.2f}"
    params = format_parameters(row["params"])
    fig.suptitle(
        f"Fig. {row['figure']}: {row['law']} ({params}), m = {M:g} kg, v0 = {V0:g} m/s{printed}"
    )
    from .._plotting import save_figure

    save_figure(fig, path)


def plot_bounce(row, drops, out_dir: Path) -> list[Path]:
    """Figs. 13-15 (or 16-18, 19-21): height, velocity and force against time, converged
    (force criterion) beside the paper's Euler, one file each."""
    from .._plotting import new_figure, save_figure

    drop, euler = drops["force"], drops["paper"]
    grid = np.linspace(0.0, DROP_DURATION, 6000)
    count = int(drop.num_impacts)
    inside = [  # a dense grid inside each contact, so the force pulses are drawn
        np.linspace(t, t + T, 40)
        for t, T in zip(
            np.asarray(drop.impact_times)[:count], np.asarray(drop.T)[:count], strict=True
        )
        if np.isfinite(t) and np.isfinite(T)
    ]
    grid = np.unique(np.concatenate([grid, *inside]))
    exact = [np.asarray(a) for a in drop.trajectory(grid)]
    paths = []
    quantities = (
        ("height above the floor $y$ (m)", euler.height),
        ("velocity, upward (m/s)", euler.velocity),
        ("contact force $N$ (N)", euler.force),
    )
    params = format_parameters(row["params"])
    for number, (label, reference), series in zip(
        figure_numbers(row["figure"]), quantities, exact, strict=True
    ):
        fig = new_figure(figsize=(9, 3.6), layout="constrained")
        ax = fig.subplots()
        ax.plot(euler.t, reference, color="C1", lw=0.8, label="paper's Euler, 2e-5 s")
        ax.plot(grid, series, color="C0", lw=0.9, ls="--", label="converged (jaximpact.bounce)")
        ax.set_xlabel("time $t$ (s)")
        ax.set_ylabel(label)
        ax.legend(fontsize="small")
        ax.set_title(f"Fig. {number}: {row['law']} ({params}), dropped from {DROP_HEIGHT:g} m")
        path = out_dir / f"fig{number}.png"
        save_figure(fig, path)
        paths.append(path)
    return paths


def plot_maps(case: PaperCase, out_dir: Path) -> list[Path]:
    from .._plotting import new_figure, save_figure
    from .._studies.maps import plot_map, restitution_map

    paths = []
    for criterion in CRITERIA:
        rmap = restitution_map(case.law, m=M, v0=V0, separation=criterion)
        fig = new_figure(figsize=(11, 4.4), layout="constrained")
        plot_map(
            rmap,
            fig=fig,
            title=f"Fig. {case.figure}: {case.law}, m = {M:g} kg, "
            f"v0 = {V0:g} m/s, {criterion} separation ({rmap.path})",
        )
        path = out_dir / f"fig{case.figure}_{criterion}.png"
        save_figure(fig, path)
        paths.append(path)
    return paths
