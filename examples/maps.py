"""Maps of restitution e and contact duration T over stiffness and damping: the seed paper's
Fig. 1 (Kelvin-Voigt) and Fig. 7 (Maxwell), law 14, and with --all every law of LAW_NAMES.

Run: python examples/maps.py [--all] [--num 41] [--out maps]
Writes <out>/fig1_kelvin_voigt.png, <out>/fig7_maxwell.png, <out>/hertz_rate.png and, with
--all, one PNG per law plus <out>/all_laws_e.png (every law's e map on one page).
Kelvin-Voigt and (under-damped) Maxwell take their exact closed forms and run in about a
second; every other law compiles one integrated batch (10-30 s each on a busy 2-core
machine; the Hunt-Crossley variants share hunt_crossley's), so --all takes minutes.
"""

import argparse
import os
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import matplotlib  # noqa: E402

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import plot_map, restitution_map  # noqa: E402

FILES = {"kelvin_voigt": "fig1_kelvin_voigt.png", "maxwell": "fig7_maxwell.png"}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--all", action="store_true", help="every law, not only figs 1, 7, 14")
    parser.add_argument("--num", type=int, default=41, help="grid points per axis")
    parser.add_argument("--out", default="maps", help="folder for the PNGs")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    names = list(ji.LAW_NAMES) if args.all else ["kelvin_voigt", "maxwell", "hertz_rate"]
    maps = {}
    for name in names:
        start = time.perf_counter()
        rmap = restitution_map(name, num=args.num)  # m = 1 kg, v0 = 2.5 m/s, c 2e6-2e7
        seconds = time.perf_counter() - start
        maps[name] = rmap
        separated = np.mean(rmap.status == ji.Status.separated)
        print(
            f"{name:22s} {rmap.damping_name:9s} {rmap.damping[0]:8.3g}-{rmap.damping[-1]:<8.3g} "
            f"e {rmap.e.min():.3f}-{rmap.e.max():.3f}  T {1e3 * rmap.T.min():.3f}-"
            f"{1e3 * rmap.T.max():.3f} ms  separated {separated:.2f}  "
            f"({rmap.path}, {seconds:.1f} s)",
            flush=True,
        )
        path = os.path.join(args.out, FILES.get(name, f"{name}.png"))
        fig = plot_map(rmap)
        fig.savefig(path, dpi=110)
        plt.close(fig)

    if args.all:
        cols = 4
        rows = -(-len(maps) // cols)
        fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3.2 * rows), layout="constrained")
        for ax, (name, rmap) in zip(axes.flat, maps.items(), strict=False):
            x, y = np.meshgrid(rmap.damping, rmap.c, indexing="ij")
            filled = ax.contourf(x, y, rmap.e, levels=np.linspace(0, 1, 11), cmap="magma")
            ax.set_yscale("log")
            ax.set_title(name, fontsize=9)
            ax.set_xlabel(rmap.damping_name, fontsize=8)
        for ax in list(axes.flat)[len(maps) :]:
            ax.axis("off")
        fig.colorbar(filled, ax=axes, label="restitution e", shrink=0.6)
        fig.suptitle("e over (damping, c) for every law, m = 1 kg, v0 = 2.5 m/s")
        fig.savefig(os.path.join(args.out, "all_laws_e.png"), dpi=100)
    print(f"figures in {args.out}/")


if __name__ == "__main__":
    main()
