"""Calibrate the seed paper's law 14 (Hertz with x^0.5 damping) from a restitution and a
contact duration, and check the fit with an independent re-simulation.

The targets (e = 0.85, T = 7.8 ms at 2.5 m/s for 1 kg) are illustrative numbers, not a
measurement. Two numbers fix law 14's two parameters exactly, so the fit reproducing them
says nothing about whether the law suits a material: that needs more speeds (see
examples/pick_a_law.py, which judges each law by its reduced chi-square).

Run: python examples/calibrate_e_and_T.py [--plot calibration.png]
"""

import argparse
import os
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import jaximpact as ji  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--plot", default="calibration.png", help="the fitted force-displacement loop (PNG)"
    )
    args = parser.parse_args()

    # A 1 kg body hits a surface at 2.5 m/s with e = 0.85 and T = 7.8 ms (illustrative).
    m, v0, e, T = 1.0, 2.5, 0.85, 7.8e-3
    start = ji.law("hertz_rate", c=1e6, b1=100.0)  # a rough guess: F = c x^1.5 + b1 x^0.5 v

    t0 = time.perf_counter()
    fit = ji.calibrate(start, m=m, v0=v0, e=e, T=T)
    first = time.perf_counter() - t0
    t0 = time.perf_counter()
    fit = ji.calibrate(start, m=m, v0=v0, e=e, T=T)
    again = time.perf_counter() - t0

    c, b1 = float(fit.params["c"]), float(fit.params["b1"])
    print("law 14: F = c x^1.5 + b1 x^0.5 v, fitted to e = 0.85, T = 7.8 ms at v0 = 2.5 m/s")
    print(f"  c  = {c:.6e} N/m^1.5")
    print(f"  b1 = {b1:.6e} N s/m^1.5")
    print(
        f"  optimiser converged: {bool(fit.converged)} after {int(fit.iterations)} "
        f"iterations, loss {float(fit.loss):.2e}"
    )
    print(
        f"  reproduces the targets to 1e-6: {bool(fit.reproduces)} ({int(fit.n_data)} data, "
        f"{len(fit.free)} parameters: {int(fit.dof)} degrees of freedom, an exact fit)"
    )
    print(
        f"  implied at v0: x_max = {1e3 * float(fit.x_max[0]):.4f} mm, "
        f"F_max = {float(fit.F_max[0]):.1f} N for m = {m:g} kg (a mass in the wrong unit "
        "shows here)"
    )
    print(
        f"  time: {first:.1f} s for the first fit (includes compilation), "
        f"{1e3 * again:.1f} ms for the next"
    )

    # an independent check: the fitted law integrated (not read off the curves) at rtol 1e-12,
    # with the time histories for the plot from the same solve
    ts = jax.numpy.linspace(0.0, 1.05 * T, 600)
    check = ji.impact(fit.law, m=m, v0=v0, method="integrate", rtol=1e-12, ts=ts)
    print("re-simulated (integrated, rtol 1e-12):")
    print(
        f"  e = {float(check.e):.10f} (target {e}), T = {1e3 * float(check.T):.8f} ms "
        f"(target {1e3 * T} ms)"
    )
    print(f"  x_max = {1e3 * float(check.x_max):.4f} mm, F_max = {float(check.F_max):.1f} N")
    if args.plot:
        figure = ji.plot_impact(check, fit.law, title="law 14 fitted to e = 0.85, T = 7.8 ms")
        figure.savefig(args.plot, dpi=120)
        print(f"plot written to {args.plot}")


if __name__ == "__main__":
    main()
