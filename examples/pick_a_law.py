"""Which contact law do the measurements support? Restitution at several impact speeds,
from drops of a ping-pong ball on parquet (rebound heights read off video, 10 repeats per
drop height), fitted by every law of the seed paper and ranked by AIC.

Data: ../shared/data/giiulia_method1_rebound_heights.csv (read in place, never copied) when it
is there, else the synthetic examples/data/rebound_heights.csv (made by
examples/data/make_samples.py; the numbers below are the real data's).
With no air drag, `e = sqrt(h1 / h0)` and `v0 = sqrt(2 g h0)`; the spread of the ten repeats
gives the standard error of each e. Three laws whose restitutions depend on the impact speed
in three ways, each through one dimensionless group: not at all (Kelvin-Voigt, eq. 1), through
`b1 v0^(1/5)` (law 14, the seed paper's proposal) and through `a v0` (Hunt-Crossley). This
ball's e falls from about 0.95 at 1 m/s to 0.91 at 2.4 m/s, faster than law 14 can follow:
Hunt-Crossley wins by a wide margin (the AIC differences are printed). The contact duration
is not measured, so only that group is determined, not c and the damping separately.

Run: python examples/pick_a_law.py [--ball pingpong] [--plot pick_a_law.png]
"""

import argparse
import csv
import os
from pathlib import Path

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402

SHARED = Path(__file__).resolve().parents[2] / "shared" / "data"
SAMPLES = Path(__file__).resolve().parent / "data"  # synthetic, made by data/make_samples.py
MASS = {"pingpong": 0.0027, "golf": 0.0415, "tennis": 0.056}  # kg (data README)
G = 9.81


def restitutions(ball):
    """(v0 in m/s, e, standard error of e) per drop height of `ball`."""
    path = SHARED / "giiulia_method1_rebound_heights.csv"
    if not path.exists():  # the real measurements are not shipped: the synthetic sample
        path = SAMPLES / "rebound_heights.csv"
    print(f"data: {path}")
    rows = []
    with open(path) as handle:
        for row in csv.reader(handle):
            if row[0] != ball:
                continue
            h0 = float(row[2]) / 100
            e = np.sqrt(np.asarray(row[3].split(), dtype=float) / 100 / h0)
            rows.append((np.sqrt(2 * G * h0), e.mean(), e.std(ddof=1) / np.sqrt(e.size)))
    return np.asarray(sorted(rows)).T


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ball", choices=sorted(MASS), default="pingpong")
    parser.add_argument("--plot", default="pick_a_law.png")
    args = parser.parse_args()

    v0, e, sigma = restitutions(args.ball)
    m = MASS[args.ball]
    print(f"{args.ball}: m = {m * 1e3:g} g, {v0.size} drop heights")
    for row in zip(v0, e, sigma, strict=True):
        print("  v0 = {:.3f} m/s   e = {:.4f} +- {:.4f}".format(*row))

    laws = ("kelvin_voigt", "hertz_rate", "hunt_crossley")
    ranking = ji.compare_laws(m=m, v0=v0, e=e, sigma_e=sigma, laws=laws)
    print("\nlaw                      chi2     AIC   fitted parameters")
    for r in ranking:
        params = ", ".join(f"{k} = {float(v):.4g}" for k, v in r.fit.params.items())
        print(f"{r.name:<24} {r.chi2:7.1f} {r.aic:7.1f}   {params}")
    best = ranking[0]
    print(
        f"\nbest: {best.name} (AIC {best.aic:.1f}; the next is "
        f"{ranking[1].aic - best.aic:.1f} higher)"
    )

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2), layout="constrained")
    ax.errorbar(v0, e, yerr=sigma, fmt="ko", ms=4, label="measured (10 repeats each)")
    speeds = np.linspace(0.9 * v0.min(), 1.1 * v0.max(), 40)
    for r in ranking[:3]:
        model = ji.impact_batch(r.fit.law, m=m, v0=speeds, fields=("e",), progress=False)
        ax.plot(speeds, model["e"], label=f"{r.name} (AIC {r.aic:.1f})")
    ax.set_xlabel("impact speed $v_0$ (m/s)")
    ax.set_ylabel("restitution $e$")
    ax.set_title(f"{args.ball} ball: e against impact speed, three laws fitted")
    ax.legend(fontsize="small")
    fig.savefig(args.plot, dpi=110)
    print(f"plot written to {args.plot}")


if __name__ == "__main__":
    main()
