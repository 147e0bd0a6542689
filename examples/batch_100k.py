"""100 000 impacts at once: a Monte Carlo over a population of bodies (law 14), run through
`impact_batch` in chunks with a progress bar, written to a table and summarised in a plot.

Run: python examples/batch_100k.py [--n 100000] [--table batch_100k.csv] [--plot batch_100k.png]
"""

import argparse
import os
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import impact_batch, write_table  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=100_000)
    parser.add_argument(
        "--table", default="batch_100k.csv", help=".csv or .json ('' for none; git ignores it)"
    )
    parser.add_argument("--plot", default="batch_100k.png")
    args = parser.parse_args()

    # Granules of scattered size and stiffness hitting a plate: mass log-normal around 10 g,
    # Hertz stiffness and damping of law 14 scattered by 20 % and 30 %, speeds 0.5-5 m/s.
    rng = np.random.default_rng(0)
    n = args.n
    m = 0.01 * rng.lognormal(0.0, 0.3, n)
    params = {
        "c": 5e8 * rng.lognormal(0.0, 0.2, n),  # N/m^1.5
        "b1": 2e4 * rng.lognormal(0.0, 0.3, n),  # N s/m^1.5
    }
    v0 = rng.uniform(0.5, 5.0, n)

    start = time.perf_counter()
    out = impact_batch("hertz_rate", params, m=m, v0=v0)  # progress bar on stderr
    seconds = time.perf_counter() - start
    start = time.perf_counter()
    impact_batch("hertz_rate", params, m=m, v0=v0, progress=False)
    again = time.perf_counter() - start

    separated = out["status"] == ji.Status.separated
    print(f"{n:,} impacts of law 14 on {len(jax.local_devices())} device(s):")
    print(
        f"  first run {seconds:.1f} s (with compilation), again {again:.2f} s "
        f"({n / again:,.0f} impacts/s)"
    )
    print(f"  separated: {separated.mean():.4f}")
    for key, unit, scale in (
        ("e", "", 1),
        ("T", "us", 1e6),
        ("x_max", "um", 1e6),
        ("F_max", "N", 1),
    ):
        q = np.percentile(out[key][separated] * scale, [5, 50, 95])
        print(f"  {key:6s} 5/50/95 %: {q[0]:.4g} / {q[1]:.4g} / {q[2]:.4g} {unit}")
    if args.table:
        path = write_table(args.table, {"m": m, "v0": v0, **params, **out})
        print(f"  table: {path} ({os.path.getsize(path) / 1e6:.1f} MB)")
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 3, figsize=(13, 4), layout="constrained")
        axes[0].hist(out["e"][separated], bins=100, color="C0")
        axes[0].set_xlabel("restitution e")
        axes[1].hexbin(v0[separated], out["e"][separated], gridsize=60, bins="log", cmap="viridis")
        axes[1].set_xlabel("impact speed $v_0$ (m/s)")
        axes[1].set_ylabel("restitution e")
        axes[2].hexbin(
            out["x_max"][separated] * 1e6,
            out["F_max"][separated],
            gridsize=60,
            bins="log",
            cmap="magma",
            xscale="log",
            yscale="log",
        )
        axes[2].set_xlabel("maximum compression $x_{max}$ (um)")
        axes[2].set_ylabel("peak force $F_{max}$ (N)")
        fig.suptitle(f"{n:,} impacts of law 14 (one run_batch call, {again:.1f} s)")
        fig.savefig(args.plot, dpi=110)
        print(f"  plot: {args.plot}")


if __name__ == "__main__":
    main()
