"""Drop design: the drop height and mass of a ball that give a wanted sequence of bounce
apexes on a floor with law 14 (c = 1e6 N/m^1.5, b1 = 1350 N s/m^1.5: the seed paper's
section 7), by Levenberg-Marquardt with forward-mode derivatives through jaximpact.bounce
(closed-form flights, one impact solve with gravity per contact).

Run: python examples/drop_design.py [--apexes 0.30 0.165 0.095 0.055] [--plot drop_design.png]
"""

import argparse
import os
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import drop_design  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--apexes", type=float, nargs="+", default=[0.30, 0.165, 0.095, 0.055])
    parser.add_argument("--plot", default="drop_design.png")
    args = parser.parse_args()
    law = ji.law("hertz_rate", c=1e6, b1=1350.0)

    start = time.perf_counter()
    d = drop_design(law, apexes=args.apexes, h0_guess=1.0, m_guess=0.3)
    print(
        f"drop design in {time.perf_counter() - start:.1f} s (with compilation), "
        f"{d.iterations} Levenberg-Marquardt iterations, converged: {d.converged}"
    )
    print(f"  drop height h0 = {d.h0:.5f} m, mass m = {d.m:.5f} kg")
    print("  bounce   wanted (cm)   achieved (cm)   difference (mm)")
    for k, (want, got) in enumerate(zip(d.target, d.apexes, strict=True)):
        print(
            f"  {k + 1:6d}   {100 * want:10.3f}   {100 * got:13.3f}   {1e3 * (got - want):+12.3f}"
        )
    print(
        f"  rms log residual {np.sqrt(np.mean(d.residuals**2)):.2e} (0 if the sequence is "
        "exactly reachable; law 14 fixes how e changes with speed and mass)"
    )

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        # the flights are parabolas: drawn from the apexes (contacts, ~1 ms, as instants)
        g = 9.81
        speeds = np.sqrt(2 * g * np.concatenate([[d.h0], d.apexes]))  # at each landing
        landings = np.cumsum(np.concatenate([[speeds[0] / g], 2 * speeds[1:-1] / g]))
        fig, axes = plt.subplots(1, 2, figsize=(12, 4.2), layout="constrained")
        ts = np.linspace(0.0, landings[-1] + 2 * speeds[-1] / g, 3000)
        k = np.searchsorted(landings, ts)  # flight k starts at landing k - 1
        start = np.where(k > 0, landings[np.maximum(k - 1, 0)], 0.0)
        up = np.where(k > 0, speeds[np.minimum(k, len(speeds) - 1)], 0.0)
        height = np.where(
            k > 0, up * (ts - start) - 0.5 * g * (ts - start) ** 2, d.h0 - 0.5 * g * ts**2
        )
        axes[0].plot(ts, 100 * height, lw=1.2, label="designed drop")
        apex_times = landings + speeds[1:] / g
        axes[0].plot(apex_times, 100 * d.target, "rx", ms=9, label="wanted apexes")
        axes[0].set_xlabel("time (s)")
        axes[0].set_ylabel("height (cm)")
        axes[0].set_title(f"h0 = {d.h0:.3f} m, m = {d.m:.3f} kg")
        axes[0].legend()
        axes[1].semilogy(np.arange(len(d.history)), d.history, "o-")
        axes[1].set_xlabel("iteration")
        axes[1].set_ylabel("loss (half the squared log residuals)")
        fig.savefig(args.plot, dpi=110)
        print(f"plot: {args.plot}")


if __name__ == "__main__":
    main()
