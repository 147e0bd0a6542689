"""From scattered drops to the band an engine realises: calibrate law 14 (F = c x^1.5 +
b1 x^0.5 v) on e and T at eight speeds, sample its posterior with NUTS, print the medians
with their 90 % intervals, the bands of e and T at new speeds and the speed to measure
next, and export the posterior to MuJoCo with the 5-95 % band of what MuJoCo realises.

The data are SYNTHETIC: this script first writes them to drops_synthetic.csv (law 14 with
c = 2e6 N/m^1.5, b1 = 800 N s/m^1.5 for 1 kg, the seed paper's Fig. 10, with noise 0.01
in e and 2 % in T); replace that file by your measurements (columns v0,e,T,sigma_e,sigma_T,
SI units) and the rest runs as it is.

Run: python examples/posterior_to_engine.py [--data drops_synthetic.csv] [--draws 2000]
     [--band-draws 40] [--plot posterior.png]
"""

import argparse
import csv
import os
import time
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402

M = 1.0  # kg
COLUMNS = ("v0", "e", "T", "sigma_e", "sigma_T")  # SI units
TRUTH = {"c": 2e6, "b1": 800.0}  # N/m^1.5, N s/m^1.5: what the synthetic data are made of


def make_synthetic_data(path: Path):
    """Eight drops from 0.5 to 3 m/s of law 14 at `TRUTH`, e with noise 0.01 and T with
    noise 2 % (fixed seed), written as CSV with their sigmas."""
    law = ji.law("hertz_rate", **TRUTH)
    v0 = np.linspace(0.5, 3.0, 8)
    exact = [ji.impact(law, m=M, v0=float(v)) for v in v0]
    rng = np.random.default_rng(7)
    e = np.array([float(r.e) for r in exact]) + 0.01 * rng.normal(size=v0.size)
    T_exact = np.array([float(r.T) for r in exact])
    T = T_exact * (1.0 + 0.02 * rng.normal(size=v0.size))
    lines = [
        f"# SYNTHETIC data made by examples/{Path(__file__).name}: law 14 with c = 2e6 "
        "N/m^1.5, b1 = 800 N s/m^1.5, m = 1 kg, noise 0.01 in e and 2 % in T; not a measurement",
        ",".join(COLUMNS),
        *(
            f"{a:.4f},{b:.5f},{c:.6e},0.01,{0.02 * d:.3e}"
            for a, b, c, d in zip(v0, e, T, T_exact, strict=True)
        ),
    ]
    path.write_text("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", default="drops_synthetic.csv", help="CSV: v0,e,T,sigma_e,sigma_T")
    parser.add_argument("--draws", type=int, default=2000, help="NUTS draws per chain (4 chains)")
    parser.add_argument("--band-draws", type=int, default=40, help="draws exported to MuJoCo")
    parser.add_argument("--plot", default="posterior.png", help="pairs plot and bands (PNG)")
    args = parser.parse_args()

    path = Path(args.data)
    if not path.exists():
        make_synthetic_data(path)
        print(f"data: SYNTHETIC, written to {path} by this script (law 14 at c = 2e6, b1 = 800)")
    else:
        print(f"data: {path}")
    lines = [line for line in path.read_text().splitlines() if not line.startswith("#")]
    rows = {k: np.array([float(r[k]) for r in csv.DictReader(lines)]) for k in COLUMNS}
    v0, e, T = rows["v0"], rows["e"], rows["T"]

    start = ji.law("hertz_rate", c=1e6, b1=100.0)  # a rough guess
    fit = ji.calibrate(
        start, m=M, v0=v0, e=e, T=T, sigma_e=rows["sigma_e"], sigma_T=rows["sigma_T"]
    )
    print(
        f"fit: c = {float(fit.params['c']):.4g} N/m^1.5, b1 = {float(fit.params['b1']):.4g} "
        f"N s/m^1.5, reduced chi-square {float(fit.reduced_chi2):.2f} ({int(fit.n_data)} data)"
    )

    t0 = time.perf_counter()
    post = ji.posterior(
        fit,
        prior={"c": ("loguniform", 1e5, 1e8), "b1": ("loguniform", 10.0, 1e5)},
        method="nuts",
        num_samples=args.draws,
        key=jax.random.key(0),
    )
    print(f"\nNUTS: {time.perf_counter() - t0:.1f} s (compiling included)")
    print(post.summary())
    for k, (lo, hi) in post.interval(0.9).items():
        inside = "inside" if lo < TRUTH[k] < hi else "OUTSIDE"
        print(f"  {k}: the synthetic truth {TRUTH[k]:g} is {inside} the 90 % interval")

    print()
    print(post.predict(v0=[0.3, 1.0, 2.0, 5.0]).summary())
    nm = ji.next_measurement(post, v0=np.linspace(0.2, 8.0, 14))
    print(f"the speed to measure next: {nm.v0[0]:.3g} m/s ({nm.gain[0]:.3g} nats expected)")

    t0 = time.perf_counter()
    x = ji.export(post, "mujoco", m=M, v0=2.0, band_draws=args.band_draws, progress=False)
    print(
        f"\nMuJoCo at 2 m/s, the law at the medians: e = {x.e:.4f}, T = {1e3 * x.T:.3f} ms "
        f"(timestep {x.timestep:.3g} s)"
    )
    print(
        f"  what MuJoCo realises over {x.band_draws} posterior draws (5-95 %): "
        f"e {x.e_band[0]:.4f} to {x.e_band[1]:.4f}, T {1e3 * x.T_band[0]:.3f} to "
        f"{1e3 * x.T_band[1]:.3f} ms ({time.perf_counter() - t0:.1f} s)"
    )
    print("  solref/solimp at the medians:\n" + x.snippet)

    if args.plot:
        post.plot(args.plot)
        print(f"\nwrote {args.plot}")


if __name__ == "__main__":
    main()
