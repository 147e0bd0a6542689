"""Sensitivities and uncertainty of law 14 (the seed paper's Fig. 10: c = 2e6 N/m^1.5,
b1 = 800 N s/m^1.5, m = 1 kg, v0 = 2.5 m/s): maps of d e/d param and d T/d param over
(b1, c), and the spread of e and T from scattered c, b1 and v0, to first order (J Sigma J^T)
and by Monte Carlo (vmap), with the Monte Carlo sampling error that says whether they agree.

Run: python examples/uncertainty_propagation.py [--samples 20000] [--plot uncertainty.png]
"""

import argparse
import os
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import plot_sensitivity, propagate_uncertainty, sensitivity_map  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=20_000)
    parser.add_argument("--plot", default="uncertainty.png")
    args = parser.parse_args()
    c, b1, m, v0 = 2e6, 800.0, 1.0, 2.5
    law = ji.law("hertz_rate", c=c, b1=b1)

    start = time.perf_counter()
    smap = sensitivity_map("hertz_rate", num=21, m=m, v0=v0)
    print(f"sensitivity map, 21 x 21 points: {time.perf_counter() - start:.1f} s")
    for output in ("e", "T"):
        for parameter in ("c", "damping"):
            values = smap.elasticity(output, parameter)
            print(
                f"  d ln {output} / d ln {parameter:7s}: {values.min():+.4f} to {values.max():+.4f}"
            )

    scatter = {"c": 0.05 * c, "b1": 0.10 * b1, "v0": 0.02 * v0}  # 5 %, 10 %, 2 %
    start = time.perf_counter()
    u = propagate_uncertainty(law, m=m, v0=v0, scatter=scatter, n_samples=args.samples)
    print(
        f"uncertainty ({args.samples:,} Monte Carlo samples): {time.perf_counter() - start:.1f} s"
    )
    print(
        f"  scatter (1 sigma): c 5 %, b1 10 %, v0 2 %; nominal e = {u.nominal[0]:.6f}, "
        f"T = {1e3 * u.nominal[1]:.6f} ms"
    )
    print("  Jacobian d(e, T)/d(c, b1, v0):")
    for row, name in zip(u.jacobian, ("e", "T"), strict=True):
        print(f"    {name}: " + "  ".join(f"{v:+.6e}" for v in row))
    print("                 first order       Monte Carlo       MC std error   z = (lin - MC)/se")
    for k, (name, scale, unit) in enumerate((("e", 1.0, ""), ("T", 1e6, "us"))):
        print(
            f"  std {name} {unit:2s}   {scale * u.std_linear[k]:14.6g}  "
            f"{scale * u.std_mc[k]:14.6g}  {scale * u.std_mc_error[k]:14.3g}   {u.z_std[k]:+.2f}"
        )
    print(
        f"  mean e: nominal {u.nominal[0]:.6f}, MC {u.mean_mc[0]:.6f} +- {u.mean_mc_error[0]:.1e}"
    )
    print(
        f"  mean T: nominal {1e3 * u.nominal[1]:.6f} ms, MC {1e3 * u.mean_mc[1]:.6f} "
        f"+- {1e3 * u.mean_mc_error[1]:.1e} ms (T is convex in c: the second-order shift of "
        "the mean is what first order leaves out)"
    )
    corr_lin = u.cov_linear[0, 1] / np.sqrt(u.cov_linear[0, 0] * u.cov_linear[1, 1])
    corr_mc = u.cov_mc[0, 1] / np.sqrt(u.cov_mc[0, 0] * u.cov_mc[1, 1])
    print(f"  correlation of e and T: first order {corr_lin:+.4f}, MC {corr_mc:+.4f}")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig = plot_sensitivity(smap)
        base, ext = os.path.splitext(args.plot)
        fig.savefig(f"{base}_sensitivity{ext}", dpi=110)
        out = {"e": u.samples[0], "T": u.samples[1]}
        fig, axes = plt.subplots(1, 3, figsize=(14, 4.2), layout="constrained")
        for k, (name, scale, unit) in enumerate((("e", 1.0, ""), ("T", 1e3, " (ms)"))):
            values = np.stack([out["e"], out["T"]])[k] * scale
            axes[k].hist(values, bins=80, density=True, color="C0", alpha=0.6, label="Monte Carlo")
            grid = np.linspace(values.min(), values.max(), 300)
            mu, sd = u.nominal[k] * scale, u.std_linear[k] * scale
            axes[k].plot(
                grid,
                np.exp(-0.5 * ((grid - mu) / sd) ** 2) / (sd * np.sqrt(2 * np.pi)),
                "k",
                label="first order (normal)",
            )
            axes[k].set_xlabel(name + unit)
            axes[k].legend()
        axes[2].plot(out["e"][:3000], 1e3 * out["T"][:3000], ".", ms=2, alpha=0.4)
        axes[2].set_xlabel("e")
        axes[2].set_ylabel("T (ms)")
        axes[2].set_title(f"correlation: first order {corr_lin:+.3f}, MC {corr_mc:+.3f}")
        fig.suptitle("law 14, c 5 %, b1 10 %, v0 2 % scatter")
        fig.savefig(args.plot, dpi=110)
        print(f"plots: {args.plot}, {base}_sensitivity{ext}")


if __name__ == "__main__":
    main()
