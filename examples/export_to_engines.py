"""From a target e and T to the engine you run: fit law 14 (F = c x^1.5 + b1 x^0.5 v) to
e = 0.75, T = 2 ms at 1 m/s (illustrative numbers, not a measurement), then export it to
MuJoCo, Drake, LAMMPS, LIGGGHTS, Yade and Chrono, each with the e and T it will realise and
its e(v) beside the fitted law's.

Run: python examples/export_to_engines.py [--plot export_to_engines.png]
"""

import argparse
import os

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import jaximpact as ji  # noqa: E402

M, V0, RADIUS = 0.05, 1.0, 0.01  # kg, m/s, m
ENGINES = ("mujoco", "drake", "lammps", "liggghts", "yade", "chrono")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--plot", default="export_to_engines.png")
    args = parser.parse_args()

    start = ji.law("hertz_rate", c=1e6, b1=100.0)
    fit = ji.calibrate(start, m=M, v0=V0, e=0.75, T=2e-3)
    print(
        f"fitted law 14: c = {fit.law.parameters['c']:.5g} N/m^1.5, "
        f"b1 = {fit.law.parameters['b1']:.5g} N s/m^1.5 (e = 0.75, T = 2 ms at 1 m/s)"
    )
    verdict = "reproduces" if bool(fit.reproduces) else "does NOT reproduce"
    print(
        f"  {verdict} the targets (two numbers, two parameters: an exact fit, not a test of "
        f"the law): e = {float(fit.e[0]):.6f}, T = {float(fit.T[0]) * 1e3:.6f} ms "
        f"(x_max = {float(fit.x_max[0]) * 1e3:.3g} mm, F_max = {float(fit.F_max[0]):.4g} N "
        f"for m = {M} kg)\n"
    )
    exports = {}
    print(f"{'engine':<9} {'e realised':>10} {'T realised (s)':>15} {'step (s)':>10}  scene")
    for engine in ENGINES:
        x = ji.export(fit, engine, m=M, v0=V0, radius=RADIUS)
        exports[engine] = x
        print(f"{engine:<9} {x.e:>10.5f} {x.T:>15.6g} {x.timestep:>10.3g}  {x.scene[:60]}...")
    print("\nMuJoCo, to paste into the MJCF:\n" + exports["mujoco"].snippet)
    print("\nLAMMPS:\n" + exports["lammps"].snippet)
    for engine, x in exports.items():
        for warning in x.warnings:
            print(f"note ({engine}): {warning}")
    plot(exports, args.plot)


def plot(exports, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4.5))
    first = next(iter(exports.values()))
    ax.semilogx(first.speeds, first.e_target, "k-", lw=3, alpha=0.4, label="fitted law 14")
    for engine, x in exports.items():
        ax.semilogx(x.speeds, x.e_engine, "o-", ms=4, label=engine)
    ax.axvline(V0, color="grey", lw=0.8, ls=":")
    ax.set_xlabel("impact speed v (m/s)")
    ax.set_ylabel("coefficient of restitution e")
    ax.set_title(
        "each engine's law, exact at v0 = 1 m/s\n(MuJoCo, LAMMPS, LIGGGHTS, Yade, "
        "Chrono: e independent of v, one flat line)",
        fontsize=10,
    )
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    print(f"\nwrote {path}")


if __name__ == "__main__":
    main()
