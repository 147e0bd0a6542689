"""Which contact law do the data support, and does any fit them? Restitution at several impact
speeds, fitted by three laws of the seed paper, ranked by AIC and each judged by its reduced
chi-square.

Data, said at the top of the output:
- measured, when ../shared/data/giiulia_method1_rebound_heights.csv is there (read in place,
  never copied): a ping-pong ball dropped on parquet in a first-year lab, rebound heights read
  off video, 10 repeats per drop height;
- otherwise synthetic (a fresh clone): examples/data/rebound_heights.csv, made up by
  examples/data/make_samples.py in the same format, with `e = e0 - slope v0` (for the
  ping-pong ball 0.965 - 0.025 v0, a straight line that none of these laws follows) and 1 %
  scatter on the rebound heights. Such data show what the ranking and the verdict do; they
  are not a measurement of any ball.
With no air drag, `e = sqrt(h1 / h0)` and `v0 = sqrt(2 g h0)`; the spread of the ten repeats
gives the standard error of each e, which weights the fit. The three laws' restitutions depend
on the impact speed in three ways, each through one dimensionless group: not at all
(Kelvin-Voigt, eq. 1), through `b1 v0^(1/5)` (law 14, the seed paper's proposal) and through
`a v0` (Hunt-Crossley). The contact duration is not measured, so only that group is
determined: the stiffness c is held at a start value and is not an estimate.

The smallest AIC only names the least bad law. The verdict says whether it fits: a reduced
chi-square near 1 (p above 0.001) means it describes the data within their standard errors;
far above 1, no law tried does (`jaximpact.compare_laws` warns, and this script says so).

Run: python examples/pick_a_law.py [--ball pingpong] [--plot pick_a_law.png]
"""

import argparse
import csv
import os
import warnings
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
LAWS = ("kelvin_voigt", "hertz_rate", "hunt_crossley")
UNITS = {  # the parameters' SI units, per law (F = c x^n + damping; `jaximpact laws`)
    "kelvin_voigt": {"c": "N/m", "b": "N s/m"},
    "hertz_rate": {"c": "N/m^1.5", "b1": "N s/m^1.5"},
    "hunt_crossley": {"c": "N/m^1.5", "a": "s/m", "n": ""},
}


def restitutions(ball):
    """(v0 in m/s, e, standard error of e) per drop height of `ball`, and what the data are."""
    path = SHARED / "giiulia_method1_rebound_heights.csv"
    if path.exists():
        what = f"measured: {path} (video, 10 repeats per drop height)"
    else:  # the real measurements are not shipped: the synthetic sample
        path = SAMPLES / "rebound_heights.csv"
        what = (
            f"SYNTHETIC: {path}, made up by examples/data/make_samples.py "
            "(e falling linearly with v0, 1 % scatter on the heights; not a measurement)"
        )
    print(f"data: {what}")
    rows, surfaces = [], set()
    with open(path) as handle:
        for row in csv.reader(handle):
            if row[0] != ball:
                continue
            surfaces.add(row[1])
            h0 = float(row[2]) / 100
            e = np.sqrt(np.asarray(row[3].split(), dtype=float) / 100 / h0)
            rows.append((np.sqrt(2 * G * h0), e.mean(), e.std(ddof=1) / np.sqrt(e.size)))
    synthetic = "synthetic" in surfaces
    return (*np.asarray(sorted(rows)).T, synthetic)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ball", choices=sorted(MASS), default="pingpong")
    parser.add_argument("--plot", default="pick_a_law.png")
    args = parser.parse_args()

    v0, e, sigma, synthetic = restitutions(args.ball)
    source = "synthetic" if synthetic else "measured"
    m = MASS[args.ball]
    print(f"{args.ball} ball ({source} data): m = {m * 1e3:g} g, {v0.size} drop heights")
    for row in zip(v0, e, sigma, strict=True):
        print("  v0 = {:.3f} m/s   e = {:.4f} +- {:.4f}".format(*row))

    with warnings.catch_warnings():  # its warning on a bad best fit: the verdict below
        warnings.filterwarnings("ignore", message="the best law")
        ranking = ji.compare_laws(m=m, v0=v0, e=e, sigma_e=sigma, laws=LAWS)
    dof = ranking[0].dof
    print(f"\n{v0.size} restitutions, {dof} degrees of freedom per law (one damping group)")
    print("law             chi2/dof        p      AIC   fitted (c held, not measured)")
    for r in ranking:
        units = UNITS[r.name]
        params = ", ".join(
            f"{k} = {float(v):.4g} {units.get(k, '')}".rstrip()
            for k, v in r.fit.params.items()
            if k in r.fit.free
        )
        print(f"{r.name:<15} {r.reduced_chi2:8.2f} {r.p_value:8.2g} {r.aic:8.1f}   {params}")
    best = ranking[0]
    print(
        f"\nsmallest AIC: {best.name} (the next is {ranking[1].aic - best.aic:.1f} higher; "
        "AIC = chi2 + 2k, chi2 the sum of squared normalised residuals)"
    )
    if best.p_value < 1e-3:  # what compare_laws calls fitting badly (its docstring)
        print(
            f"verdict: {best.name} does NOT fit these data: reduced chi-square "
            f"{best.reduced_chi2:.1f} with {best.dof} degrees of freedom (p = "
            f"{best.p_value:.1g}), its residuals are {np.sqrt(best.reduced_chi2):.1f} "
            "standard errors on average. It is only the least bad of these laws"
            + (
                ": the synthetic e falls linearly with v0, which none of them follows."
                if synthetic
                else "."
            )
        )
    else:
        print(
            f"verdict: {best.name} fits within the standard errors (reduced chi-square "
            f"{best.reduced_chi2:.2f}, p = {best.p_value:.2g})."
        )
    c = best.fit.params["c"]
    print(
        f"note: c = {float(c):.4g} {UNITS[best.name]['c']} is a start value held fixed: without "
        "a measured contact duration only the damping group is determined."
    )

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.2), layout="constrained")
    ax.errorbar(v0, e, yerr=sigma, fmt="ko", ms=4, label=f"{source} (10 repeats each)")
    speeds = np.linspace(0.9 * v0.min(), 1.1 * v0.max(), 40)
    for r in ranking[:3]:
        model = ji.impact_batch(r.fit.law, m=m, v0=speeds, fields=("e",), progress=False)
        ax.plot(speeds, model["e"], label=f"{r.name} (chi2/dof {r.reduced_chi2:.1f})")
    ax.set_xlabel("impact speed $v_0$ (m/s)")
    ax.set_ylabel("restitution $e$")
    ax.set_title(f"{args.ball} ball, {source} data: e against impact speed, three laws fitted")
    ax.legend(fontsize="small")
    fig.savefig(args.plot, dpi=110)
    print(f"plot written to {args.plot}")


if __name__ == "__main__":
    main()
