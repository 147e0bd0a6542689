"""Restitution of four balls from the instants of their impacts, heard by a phone.

Data: ../shared/data/giiulia_phyphox_bounce_impact_times.csv (measured: 85 drops of a golf
ball, a ping-pong ball, a tennis ball and a bouncy ball; read in place, never copied); without
it the SYNTHETIC examples/data/impact_times.csv (two drops of two balls, made up by
examples/data/make_samples.py from law 14 with 0.1 ms timing noise), and the output says so.
Each fit is judged by its timing residual against the data's timing noise. Each drop is fitted
alone with `fit_bounces(law, m=..., impact_times=...)`: the first impact's time and speed are
nuisance parameters, double and missed detections are found and dropped. Two laws:
Kelvin-Voigt (eq. 1: e independent of the impact speed) and law 14 (hertz_rate: e rising
slowly as the speed falls). The stiffness is held at a value giving a plausible contact time
(the audio cannot see it); e does not depend on that choice, nor on the mass (one damping group
sets e).

For comparison, the textbook estimate from the ratio of consecutive intervals,
`e_k = D_{k+1} / D_k`, which neglects the contact durations and air drag.

Run: python examples/fit_microphone_impacts.py [--per-ball 0] [--plot docs/bounces_acoustic.png]
(the default fits one drop each of the golf and ping-pong balls, in about a minute on 2 cores,
most of it compiling the models; `--balls golf pingpong tennis blue --per-ball 0` fits all 85
drops of the real data, as docs/bounces.md reports, in several minutes)
                                                [--balls golf pingpong] [--law kelvin_voigt]
"""

import argparse
import collections
import csv
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import (  # noqa: E402
    clean_impact_times,
    fit_bounces,
    interval_restitution,
)

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data"
FILE = DATA / "giiulia_phyphox_bounce_impact_times.csv"
SYNTHETIC = not FILE.exists()
if SYNTHETIC:  # the real recordings are not shipped: the synthetic sample
    FILE = Path(__file__).resolve().parent / "data" / "impact_times.csv"
# the timing noise of the data (s): the phone's detector is good to about a millisecond
# (../shared/data/README.md); the synthetic sample was made with 0.1 ms
TIMING_NOISE = 1e-4 if SYNTHETIC else 1e-3
# mass (kg; the bouncy ball's is not stated: 20 g assumed), Hertz c for a plausible contact
# time (N/m^1.5), air drag k = rho C_d A / (2 m) (1/m; the ping-pong ball only)
BALLS = {
    "golf": (0.0415, 5.5e7, None),
    "pingpong": (0.0027, 9e5, 0.14),
    "tennis": (0.056, 2.5e5, None),
    "blue": (0.02, 2e6, None),
}


def load():
    groups = collections.defaultdict(list)
    with FILE.open() as file:
        for row in csv.DictReader(file):
            key = (row["ball"], int(row["drop_height_cm"]), int(row["trial"]))
            groups[key].append((int(row["impact_index"]), float(row["event_time_s"])))
    return {k: np.array([t for _, t in sorted(v)]) for k, v in groups.items()}


def start_law(name, c):
    if name == "kelvin_voigt":
        return ji.law("kelvin_voigt", c=c, b=0.01)
    return ji.law("hertz_rate", c=c, b1=1.0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--balls", nargs="+", default=["golf", "pingpong"], choices=list(BALLS))
    parser.add_argument("--laws", nargs="+", default=["kelvin_voigt", "hertz_rate"])
    parser.add_argument(
        "--per-ball", type=int, default=1, help="drops fitted per ball (0: all of them)"
    )
    parser.add_argument(
        "--plot", default="microphone_impacts.png", help="e against impact speed, residuals"
    )
    args = parser.parse_args()
    if SYNTHETIC:
        print(
            f"data: SYNTHETIC, {FILE} (made up by examples/data/make_samples.py: law 14 "
            "contacts, air drag, 0.1 ms timing noise, one double and one missed detection; "
            "not a recording)"
        )
    else:
        print(f"data: measured, {FILE} (a phone's acoustic stopwatch, phyphox)")

    drops = load()
    results = collections.defaultdict(list)
    start = time.perf_counter()
    fitted = collections.Counter()
    for (ball, height, trial), times in drops.items():
        if ball not in args.balls or 0 < args.per_ball <= fitted[ball]:
            continue
        fitted[ball] += 1
        m, c, drag = BALLS[ball]
        cleaned = clean_impact_times(times)
        _, ratios = interval_restitution(cleaned)
        for name in args.laws:
            fit = fit_bounces(start_law(name, c), m=m, impact_times=times, drag=drag)
            results[ball, name].append(dict(height=height, trial=trial, fit=fit, ratios=ratios))
    print(f"{sum(len(v) for v in results.values())} fits in {time.perf_counter() - start:.0f} s\n")

    print(
        "| ball | drops | detections used / heard | law | e at first impact (mean ± s.e.m.) "
        "| drop-to-drop sd | median fit stderr | e at slowest impact | median timing residual "
        "| e from interval ratios (mean ± s.e.m.) |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|")
    for ball in args.balls:
        for name in args.laws:
            rows = results[ball, name]
            if not rows:
                continue
            e0 = np.array([r["fit"].e[0] for r in rows])
            e_last = np.array([r["fit"].e[-1] for r in rows])
            se = np.array([r["fit"].e_stderr[0] for r in rows])
            sigma = np.array([r["fit"].sigma for r in rows])
            used = sum(np.size(r["fit"].times) for r in rows)
            heard = sum(np.size(drops[ball, r["height"], r["trial"]]) for r in rows)
            ratios = np.concatenate([r["ratios"] for r in rows])
            sem = np.std(e0, ddof=1) / np.sqrt(e0.size) if e0.size > 1 else se[0]
            print(
                f"| {ball} | {len(rows)} | {used} / {heard} | {name} | {e0.mean():.4f} ± "
                f"{sem:.4f} | {np.std(e0, ddof=1) if e0.size > 1 else 0:.4f} | "
                f"{np.median(se):.4f} | {e_last.mean():.4f} | {np.median(sigma) * 1e3:.2f} ms | "
                f"{ratios.mean():.4f} ± {ratios.std(ddof=1) / np.sqrt(ratios.size):.4f} |"
            )

    print(
        f"\nverdict: a law that describes the drops leaves timing residuals near the data's "
        f"noise, {TIMING_NOISE * 1e3:g} ms ({'as made' if SYNTHETIC else 'about'}); larger "
        "ones mean it misses the bounces"
    )
    for ball in args.balls:
        for name in args.laws:
            rows = results[ball, name]
            if rows:
                sigma = np.median([r["fit"].sigma for r in rows])
                ratio = sigma / TIMING_NOISE
                judged = "within" if ratio < 2 else f"{ratio:.1f} times"
                print(
                    f"  {ball}, {name}: median timing residual {sigma * 1e3:.2f} ms, "
                    f"{judged} the noise"
                )

    print("\nper drop (first law):")
    name = args.laws[0]
    print(
        "| ball | cm | trial | e first | ± | e last | impact speeds (m/s) | drop height (m) "
        "| dropped | missed | timing residual |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for ball in args.balls:
        for r in results[ball, name]:
            f = r["fit"]
            print(
                f"| {ball} | {r['height']} | {r['trial']} | {f.e[0]:.4f} | {f.e_stderr[0]:.4f} | "
                f"{f.e[-1]:.4f} | {f.impact_speeds[0]:.2f} to {f.impact_speeds[-1]:.2f} | "
                f"{f.nuisance['drop_height']:.3f} | {f.dropped.tolist()} | {f.missed.tolist()} | "
                f"{f.sigma * 1e3:.2f} ms |"
            )

    if args.plot:
        plot(results, args, drops)
        print(f"\nfigure written to {args.plot}")


def plot(results, args, drops):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    balls = args.balls
    fig, axes = plt.subplots(
        2, len(balls), figsize=(4.2 * len(balls), 7.5), layout="constrained", squeeze=False
    )
    for col, ball in enumerate(balls):
        ax = axes[0, col]
        for li, name in enumerate(args.laws):
            for i, r in enumerate(results[ball, name]):
                f = r["fit"]
                ax.errorbar(
                    f.impact_speeds,
                    f.e,
                    yerr=f.e_stderr,
                    fmt="-",
                    lw=0.6,
                    color=f"C{li}",
                    alpha=0.5,
                    label=name if i == 0 else None,
                )
        # interval ratios, at the speed of the impact between the two intervals
        first = results[ball, args.laws[0]]
        for i, r in enumerate(first):
            f = r["fit"]
            k, ratios = interval_restitution(
                clean_impact_times(drops[ball, r["height"], r["trial"]])
            )
            k = k[k < f.num_impacts]
            ax.plot(
                f.impact_speeds[k],
                ratios[: k.size],
                ".",
                color="k",
                ms=3,
                label="interval ratios" if i == 0 else None,
            )
        ax.set_xlabel("impact speed (m/s)")
        ax.set_ylabel("e")
        ax.set_title(f"{ball}: e against impact speed")
        ax.legend(fontsize="x-small")
        ax = axes[1, col]
        for r in first:
            f = r["fit"]
            ax.plot(f.index, f.residuals * f.sigma * 1e3, ".-", lw=0.5, ms=3)
        ax.set_xlabel("impact number")
        ax.set_ylabel(f"residual, ms ({args.laws[0]})")
        ax.set_title(f"{ball}: impact-time residuals")
    fig.savefig(args.plot, dpi=110)


if __name__ == "__main__":
    main()
