"""Design a bumper with law 14 (F = c x^1.5 + b1 x^0.5 v): the stiffness c and damping b1
that minimise the peak force over a range of impact speeds, with the stroke x_max under a
bound and the restitution e under a target, by optax with gradients through the solves.
Prints the designs and draws the trade-off curve of peak force against the stroke bound.

Run: python examples/bumper_design.py [--plot bumper_design.png]
"""

import argparse
import os
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import bumper_design  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", default="bumper_design.png")
    args = parser.parse_args()

    # a 1 kg body arriving at 1 to 3 m/s; strokes from 5 to 40 mm; three restitution targets
    m, speeds = 1.0, np.linspace(1.0, 3.0, 5)
    bounds = np.array([0.005, 0.01, 0.02, 0.04])
    targets = np.array([0.1, 0.2, 0.5])
    pairs_bound, pairs_target = (a.ravel() for a in np.meshgrid(bounds, targets))

    start = time.perf_counter()
    design = bumper_design(m=m, speeds=speeds, x_max_bound=pairs_bound, e_target=pairs_target)
    seconds = time.perf_counter() - start
    print(f"{len(pairs_bound)} designs optimised at once in {seconds:.1f} s (with compilation)")
    print(
        " stroke  e_target |      c (N/m^1.5)   b1 (N s/m^1.5) | F_peak (N)  F_ideal  "
        "efficiency | max x_max/bound  e(1 m/s)  feasible"
    )
    for i in range(len(pairs_bound)):
        print(
            f" {1e3 * pairs_bound[i]:4.0f} mm  {pairs_target[i]:6.2f}  | "
            f"{float(design.c[i]):14.5g} {float(design.b1[i]):14.5g}   | "
            f"{float(design.F_peak[i]):9.2f} {float(design.F_ideal[i]):8.1f}  "
            f"{float(design.F_ideal[i] / design.F_peak[i]):8.3f}   | "
            f"{float(np.max(design.x_max[i]) / pairs_bound[i]):14.5f}  "
            f"{float(design.e[i, 0]):8.4f}  {bool(design.feasible[i])}"
        )
    # an independent check of one design at rtol 1e-12
    check = ji.impact(design.law(1), m=m, v0=speeds[-1], rtol=1e-12)
    print(
        f"check, design 2 at {speeds[-1]} m/s: F_max {float(check.F_max):.4f} N "
        f"(optimiser {float(design.F_max[1, -1]):.4f}), x_max {1e3 * float(check.x_max):.5f} mm"
    )
    product = np.asarray(design.F_peak * design.x_max_bound).reshape(len(targets), len(bounds))
    print("F_peak x stroke (J) per target (constant along a row: law 14 is self-similar):")
    for target, row in zip(targets, product, strict=True):
        print(f"  e <= {target:.2f}: " + "  ".join(f"{v:.5f}" for v in row))

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(12, 4.5), layout="constrained")
        F = np.asarray(design.F_peak).reshape(len(targets), len(bounds))
        for k, target in enumerate(targets):
            axes[0].loglog(1e3 * bounds, F[k], "o-", label=f"law 14, e <= {target:g}")
        axes[0].loglog(
            1e3 * bounds, m * speeds[-1] ** 2 / (2 * bounds), "k--", label="constant force (ideal)"
        )
        axes[0].set_xlabel("stroke bound $x_{max}$ (mm)")
        axes[0].set_ylabel("lowest peak force over 1-3 m/s (N)")
        axes[0].set_title("trade-off: peak force against stroke")
        axes[0].legend()
        for k, target in enumerate(targets):  # the 10 mm designs, speed by speed
            i = k * len(bounds) + 1
            axes[1].plot(
                speeds,
                np.asarray(design.F_max[i]),
                "o-",
                label=f"e <= {target:g}: c = {float(design.c[i]):.3g}, "
                f"b1 = {float(design.b1[i]):.3g}",
            )
        axes[1].axhline(float(design.F_ideal[1]), color="k", ls="--", label="constant force")
        axes[1].set_xlabel("impact speed (m/s)")
        axes[1].set_ylabel("peak force $F_{max}$ (N)")
        axes[1].set_title("the 10 mm designs: peak force at each speed")
        axes[1].legend(fontsize="small")
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
