"""Write the small synthetic sample files the examples and the README's commands read when the
real measurements (../shared/data, not part of the repository: no licence) are not there.

They are made up, in the real files' formats (numpy, and `jaximpact.impact` for the
restitution and duration of each contact of the impact-time samples):

- `rebound_heights.csv`: rebound heights of three balls dropped from several heights, ten
  repeats each (the format of giiulia_method1_rebound_heights.csv), from an `e` falling
  linearly with the impact speed, with 1 % scatter;
- `drops.csv`: `v0,e,sigma_e` of the ping-pong ball from those heights (for
  `jaximpact calibrate --law all --data`);
- `impact_times.csv`: impact times of a golf ball and a ping-pong ball, two drops each (the
  format of giiulia_phyphox_bounce_impact_times.csv): each contact's `e` and duration from
  law 14 (hertz_rate, the law the example fits), closed-form flights with quadratic air drag,
  0.1 ms timing noise, one double detection and one missed impact;
- `marble_video/A5_glass_marble/1-{1,50}-B-A5.csv`: a marble dropped on 1 and 50 sheets of
  paper, tracked at 240 frames per second in pixels, y pointing down (ImageJ MTrack2's
  format), held for 10 frames before the release.

Run `python examples/data/make_samples.py` to write them again (they are committed); the
output is the same on every run (fixed seeds).
"""

import csv
import math
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
G = 9.81
SOURCE = "synthetic (examples/data/make_samples.py)"


def restitution(v, e0, slope):
    """The made-up law of the samples: e falling linearly with the impact speed (m/s)."""
    return e0 - slope * v


# ------------------------------------------------------------------ rebound heights

BALLS_REBOUND = {  # ball: (drop heights in cm, e at 0 m/s, slope per m/s)
    "pingpong": ([5, 7.5, 10, 18, 30, 45], 0.965, 0.025),
    "golf": ([20, 40, 60, 80, 100], 0.86, 0.03),
    "tennis": ([30, 60, 90, 120], 0.82, 0.025),
}


def rebound_heights(rng):
    rows, drops = [], []
    for ball, (heights, e0, slope) in BALLS_REBOUND.items():
        for h0 in heights:
            v0 = math.sqrt(2 * G * h0 / 100)
            e = restitution(v0, e0, slope)
            h1 = e**2 * h0 * (1 + 0.01 * rng.standard_normal(10))
            rows.append([ball, "synthetic", f"{h0:g}", " ".join(f"{h:.2f}" for h in h1)])
            if ball == "pingpong":
                e_k = np.sqrt(h1 / h0)
                drops.append((v0, e_k.mean(), e_k.std(ddof=1) / math.sqrt(e_k.size)))
    with open(HERE / "rebound_heights.csv", "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(
            ["ball", "surface", "drop_height_h0_cm", "rebound_heights_h1_cm (10 repeats)"]
        )
        writer.writerows(rows)
    with open(HERE / "drops.csv", "w") as handle:
        handle.write(f"# ping-pong ball, m = 0.0027 kg: e from rebound_heights.csv ({SOURCE})\n")
        handle.write("v0,e,sigma_e\n")
        for v0, e, se in drops:
            handle.write(f"{v0:.4f},{e:.5f},{se:.5f}\n")


# ---------------------------------------------------------------------- impact times


def rise(u, k):
    """Time to the apex and its height, launched up at `u` (m/s) with drag `k` (1/m)."""
    if k == 0:
        return u / G, u * u / (2 * G)
    vt = math.sqrt(G / k)
    return vt / G * math.atan(u / vt), vt * vt / (2 * G) * math.log1p((u / vt) ** 2)


def fall(h, k):
    """Time to fall `h` (m) from rest with drag `k`, and the landing speed."""
    if k == 0:
        return math.sqrt(2 * h / G), math.sqrt(2 * G * h)
    vt = math.sqrt(G / k)
    return vt / G * math.acosh(math.exp(h * G / vt**2)), vt * math.sqrt(
        -math.expm1(-2 * G * h / vt**2)
    )


BALLS_AUDIO = {  # ball: (drop height cm, drag 1/m, mass kg, law 14's c and b1)
    "golf": (60, 0.0, 0.0415, 5.5e7, 700.0),
    "pingpong": (30, 0.14, 0.0027, 9e5, 40.0),
}


def contact(m, c, b1):
    """`v -> (e, T)` of law 14 (`jaximpact.impact`, float64)."""
    import jax

    jax.config.update("jax_enable_x64", True)
    import jaximpact as ji

    solve = jax.jit(lambda v: ji.impact(ji.law("hertz_rate", c=c, b1=b1), m=m, v0=v))

    def e_and_T(v):
        r = solve(v)
        return float(r.e), float(r.T)

    return e_and_T


def impact_times(rng):
    rows = []
    for ball, (h_cm, k, m, c, b1) in BALLS_AUDIO.items():
        e_and_T = contact(m, c, b1)
        for trial in (1, 2):
            t = 0.4 + 0.3 * rng.random()  # the release, some time into the recording
            dt, v = fall(h_cm / 100, k)
            t += dt
            times = []
            while len(times) < 25:
                times.append(t)
                e, duration = e_and_T(v)
                u = e * v
                t_up, h = rise(u, k)
                t_down, v = fall(h, k)
                if t_up + t_down < 0.02:
                    break
                t += duration + t_up + t_down
            times = np.array(times) + 1e-4 * rng.standard_normal(len(times))
            if trial == 1:  # a double detection 3 ms after the fourth impact
                times = np.sort(np.append(times, times[3] + 3e-3))
            else:  # the sixth impact not heard
                times = np.delete(times, 5)
            for index, time in enumerate(times, start=1):
                rows.append([ball, "synthetic", h_cm, trial, SOURCE, index, f"{time:.6f}"])
    with open(HERE / "impact_times.csv", "w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(
            [
                "ball",
                "surface",
                "drop_height_cm",
                "trial",
                "source_file",
                "impact_index",
                "event_time_s",
            ]
        )
        writer.writerows(rows)


# ----------------------------------------------------------------------- video track


def marble_track(rng, sheets, e, path):
    fps, scale, floor_px, h0 = 240.0, 2500.0, 680.0, 0.25  # scale in px/m, h0 in m
    frames = np.arange(1, 241)
    t = (frames - 11) / fps  # released at frame 11
    height = np.full(t.shape, h0)
    # flights as parabolas, contacts as instants (a marble's contact is far below a frame)
    t_land, v = math.sqrt(2 * h0 / G), math.sqrt(2 * G * h0)
    landings = []
    while v > 0.05 and t_land < t[-1]:
        landings.append((t_land, v))
        u = e * v
        t_land += 2 * u / G
        v = u
    released = t >= 0
    height[released] = 0.0
    previous_t, previous_u = 0.0, 0.0
    start_height = h0
    for t_k, v_k in [(0.0, None)] + landings:
        if v_k is not None:
            previous_t, previous_u, start_height = t_k, e * v_k, 0.0
        segment = released & (t >= previous_t)
        s = t[segment] - previous_t
        height[segment] = np.maximum(start_height + previous_u * s - 0.5 * G * s * s, 0.0)
    y = floor_px - scale * height + 0.3 * rng.standard_normal(t.size)
    x = 136.0 + 0.3 * rng.standard_normal(t.size)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as handle:
        handle.write("Frame\tX1\tY1\tFlag1\tX2\tY2\tFlag2\n")
        handle.write("Tracks 1 to 2\n")
        for frame, xi, yi in zip(frames, x, y, strict=True):
            handle.write(f"{frame}\t{xi:.5f}\t{yi:.5f}\t \t12.5\t633.4\t \n")


def main():
    rng = np.random.default_rng(20240607)
    rebound_heights(rng)
    impact_times(rng)
    folder = HERE / "marble_video" / "A5_glass_marble"
    for sheets, e in ((1, 0.62), (50, 0.48)):
        marble_track(rng, sheets, e, folder / f"1-{sheets}-B-A5.csv")
    for path in sorted(HERE.rglob("*.csv")):
        print(f"{path.relative_to(HERE)}: {path.stat().st_size} bytes")


if __name__ == "__main__":
    main()
