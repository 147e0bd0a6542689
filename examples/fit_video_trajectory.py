"""Restitution of a glass marble on stacks of paper, from video tracks.

Data: ../shared/data/marble_on_paper_video/A5_glass_marble/<trial>-<sheets>-B-A5.csv (ImageJ
MTrack2 exports, measured, read in place, never copied; without them the two SYNTHETIC tracks
of examples/data/marble_video, made up by examples/data/make_samples.py with 0.3 px noise,
and the output says which): pixel rows pointing down, no frame rate, no pixel
scale. Each track is fitted with `fit_bounces(law, m=..., t=..., y=..., y_axis="down",
length_scale="fit")`: the pixel scale is fitted with g known, the floor row, the first
impact's time and speed too; frames before the release (the marble in the hand) and tracking
glitches are dropped. The frame rate is not recorded: time is taken as frames / 240 (the scale
then absorbs the choice). The contact lasts about a frame, so the stiffness is held; since it is
held in SI units, the assumed frame rate changes the contact's length in frames and e a little
(the script refits at 120 frames/s, with c as held and with c scaled as the frame rate squared,
which reproduces the 240 frames/s fit exactly).

Run: python examples/fit_video_trajectory.py [--sheets 1 50] [--trials 1] [--plot FILE]
(the defaults, two tracks, take about a minute on 2 cores, most of it compiling the model;
docs/bounces.md reports `--sheets 1 10 50 100 200 340 --trials 1 2 3`)
"""

import argparse
import time
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import fit_bounces, read_recording  # noqa: E402

DATA = Path(__file__).resolve().parents[1].parent / "shared" / "data" / "marble_on_paper_video"
SYNTHETIC = not DATA.exists()
if SYNTHETIC:  # the real tracks are not shipped: two synthetic ones
    DATA = Path(__file__).resolve().parent / "data" / "marble_video"
MASS = 0.0055  # kg, a 16 mm glass marble
FPS = 240.0  # assumed; not recorded


def track(path):
    t, y = read_recording(path).groups["track 1"]
    return np.asarray(t, dtype=float), np.asarray(y, dtype=float)


def fit(path, fps=FPS, c=2000.0):
    t, y = track(path)
    law = ji.law("kelvin_voigt", c=c, b=0.5)
    return fit_bounces(law, m=MASS, t=t / fps, y=y, y_axis="down", length_scale="fit")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sheets", nargs="+", type=int, default=[1, 50])
    parser.add_argument("--trials", nargs="+", type=int, default=[1])
    parser.add_argument(
        "--plot", default="video_trajectory.png", help="tracked against fitted tracks"
    )
    args = parser.parse_args()
    if SYNTHETIC:
        print(
            f"data: SYNTHETIC, {DATA} (made up by examples/data/make_samples.py: 240 frames/s, "
            "0.3 px tracking noise; not a video)"
        )
    else:
        print(f"data: measured, {DATA} (video tracks, ImageJ MTrack2)")

    start = time.perf_counter()
    fits = {}
    for sheets in args.sheets:
        for trial in args.trials:
            path = DATA / "A5_glass_marble" / f"{trial}-{sheets}-B-A5.csv"
            if path.exists():
                try:
                    fits[sheets, trial] = fit(path)
                except ValueError as error:
                    print(f"{path.name}: {error}")
    print(f"{len(fits)} tracks fitted in {time.perf_counter() - start:.0f} s\n")

    print(
        "| sheets | trial | e (1st impact) | ± | e (2nd) | ± | impact speed (m/s at 240 fps) "
        "| scale (px/m at 240 fps) | g (px/frame^2) | residual (px) | dropped frames |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for (sheets, trial), f in fits.items():
        g_px = 9.81 * f.nuisance["length_scale"] / FPS**2
        second = f"{f.e[1]:.3f} | {f.e_stderr[1]:.3f}" if f.num_impacts > 1 else "- | -"
        print(
            f"| {sheets} | {trial} | {f.e[0]:.3f} | {f.e_stderr[0]:.3f} | {second} | "
            f"{f.impact_speeds[0]:.3f} | {f.nuisance['length_scale']:.0f} | {g_px:.3f} | "
            f"{f.sigma:.2f} | {np.size(f.dropped)} |"
        )

    if SYNTHETIC:
        worst = max(f.sigma for f in fits.values())
        print(
            f"\nverdict: residuals up to {worst:.2f} px against the 0.3 px noise the tracks "
            f"were made with: {'the model follows them' if worst < 0.6 else 'the model misses'}"
        )
    else:
        print(
            "\nverdict: the residual (px) is the tracker's noise plus the model's misfit; a "
            "model that missed the bounces would leave residuals of several pixels with a "
            "pattern (the plot's lower row)"
        )

    first = next(iter(fits))
    path = DATA / "A5_glass_marble" / f"{first[1]}-{first[0]}-B-A5.csv"
    same_c = fit(path, fps=120.0)
    scaled_c = fit(path, fps=120.0, c=2000.0 * (120.0 / FPS) ** 2)
    print(
        f"\nframe rate check ({path.name}): e = {fits[first].e[0]:.5f} at 240 fps; at 120 fps "
        f"{same_c.e[0]:.5f} with the same c, {scaled_c.e[0]:.5f} with c scaled by (120/240)^2"
    )
    if args.plot:
        plot(fits, args.plot)
        print(f"figure written to {args.plot}")


def plot(fits, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    chosen = list(fits)[:3]
    fig, axes = plt.subplots(
        2, len(chosen), figsize=(4.6 * len(chosen), 7), layout="constrained", squeeze=False
    )
    for col, key in enumerate(chosen):
        f = fits[key]
        ts = np.linspace(f.t.min(), f.t.max(), 2000)
        ax = axes[0, col]
        ax.plot(f.t * FPS, f.y, ".", ms=2.5, label="tracked")
        ax.plot(ts * FPS, f.predict(ts), "-", lw=1, label="fitted")
        ax.invert_yaxis()
        ax.set_xlabel("frame")
        ax.set_ylabel("pixel row (down)")
        ax.set_title(f"{key[0]} sheets, trial {key[1]}: e = {f.e[0]:.3f} ± {f.e_stderr[0]:.3f}")
        ax.legend(fontsize="small")
        ax = axes[1, col]
        ax.plot(f.t * FPS, f.y - f.y_fit, ".", ms=2.5)
        ax.set_xlabel("frame")
        ax.set_ylabel("residual (px)")
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
