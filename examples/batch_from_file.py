"""A table of bodies from a file: write a CSV of 20,000 bodies (synthetic: law 14 with a
spread of stiffness, damping, mass and speed; a fifth of them dropped under gravity), run
`batch_file` over it in chunks, then do the same from a script's own chunks (a generator),
interrupted on purpose after two chunks and finished by `resume=True`, and plot e against
law 14's one damping group.

Run: python examples/batch_from_file.py [--rows 20000] [--out impacts.csv]
     (the same as: jaximpact batch bodies.csv --law hertz_rate --out impacts.csv)
"""

import argparse
import os
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402


def write_bodies(path, rows, seed=0):
    """A synthetic table: c (N/m^1.5), b1 (N s/m^1.5), m (kg), v0 (m/s), g (m/s^2)."""
    rng = np.random.default_rng(seed)
    columns = dict(
        c=rng.uniform(1e6, 3e6, rows),
        b1=rng.uniform(100.0, 2000.0, rows),
        m=rng.uniform(0.5, 2.0, rows),
        v0=rng.uniform(0.2, 5.0, rows),
        g=np.where(rng.random(rows) < 0.2, 9.81, 0.0),
    )
    table = np.column_stack(list(columns.values()))
    np.savetxt(path, table, delimiter=",", header=",".join(columns), comments="", fmt="%.17g")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=20_000)
    parser.add_argument("--bodies", default="bodies.csv")
    parser.add_argument("--out", default="impacts.csv")
    parser.add_argument("--plot", default="batch_from_file.png")
    args = parser.parse_args()

    write_bodies(args.bodies, args.rows)
    start = time.perf_counter()
    run = ji.batch_file(args.bodies, args.out, "hertz_rate", chunk_rows=5_000)
    seconds = time.perf_counter() - start
    print(
        f"{run.rows:,} impacts in {run.chunks} chunks, {seconds:.1f} s "
        f"({run.rows / seconds:,.0f} rows/s, compiling included) -> {run.path}"
    )
    print("statuses:", {k: v for k, v in run.statuses.items() if v})

    # the same rows made by a script, chunk by chunk; stopped after two chunks, then resumed
    table = np.genfromtxt(args.bodies, delimiter=",", names=True)

    def chunks(stop_after=None):
        for k, first in enumerate(range(0, len(table), 5_000)):
            if k == stop_after:
                raise KeyboardInterrupt("stopped on purpose")
            yield {name: table[name][first : first + 5_000] for name in table.dtype.names}

    streamed = "streamed_" + os.path.basename(args.out)
    try:
        ji.impact_batch("hertz_rate", chunks(stop_after=2), out=streamed, progress=False)
    except KeyboardInterrupt:
        print(f"interrupted after 2 chunks: {streamed} not written, its finished chunks kept")
    again = ji.impact_batch("hertz_rate", chunks(), out=streamed, resume=True, progress=False)
    print(f"resume=True: {again.reused} chunks reused, {again.computed} computed")
    out = np.genfromtxt(args.out, delimiter=",", names=True, dtype=None, encoding="utf-8")
    other = np.genfromtxt(streamed, delimiter=",", names=True, dtype=None, encoding="utf-8")
    same = all(np.array_equal(out[k], other[k]) for k in ("e", "T", "x_max", "F_max"))
    print(f"the file's run and the script's interrupted-and-resumed run agree bit for bit: {same}")
    for path in np.unique(out["path"]):
        rows = out["path"] == path
        print(
            f"path {path}: {rows.sum():,} rows, e from {out['e'][rows].min():.3f} to "
            f"{out['e'][rows].max():.3f}"
        )
    plot(out, args.plot)


def plot(out, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    for name, colour in (("similarity", "tab:blue"), ("integrated", "tab:orange")):
        rows = out["path"] == name
        label = {
            "similarity": "no gravity (universal curves)",
            "integrated": "g = 9.81 m/s^2 (integrated)",
        }[name]
        # law 14, F = c x^1.5 + b1 x^0.5 v: at the scale x* = (m v0^2/c)^(2/5) the damping
        # term over the elastic one is b1 v0 / (c x*) = b1 v0^0.2 / (c^0.6 m^0.4)
        c, b1, m, v0 = (out[k][rows] for k in ("c", "b1", "m", "v0"))
        group = b1 * v0**0.2 / (c**0.6 * m**0.4)
        ax.scatter(group, out["e"][rows], s=2, alpha=0.4, color=colour, label=label)
    ax.set_xscale("log")
    ax.set_xlabel("damping group b1 v0^0.2 / (c^0.6 m^0.4) (dimensionless)")
    ax.set_ylabel("coefficient of restitution e")
    ax.set_title(
        f"law 14, {len(out):,} bodies from a file: without gravity e depends on one group alone",
        fontsize=10,
    )
    ax.legend(markerscale=5)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
