"""e(v) where it comes from a contact state: a steel ball that yields (Thornton's law, from
E, nu, R and a yield stress) and an adhesive microsphere that sticks below a speed (JKR,
from the surface energy). The yield stress is fitted back from SYNTHETIC e(v) (made by the
law with noise), and a ranking of laws tells the plastic law from damping laws on it.

Run: python examples/plastic_and_sticky.py [--noise 0.005] [--plot plastic_and_sticky.png]
"""

import argparse
import math
import os

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--noise", type=float, default=0.005, help="sigma of e (synthetic)")
    parser.add_argument("--plot", default="plastic_and_sticky.png")
    args = parser.parse_args()

    # 1. a 5 mm steel ball on a rigid flat, yield stress 1 GPa (p_y = 1.6 Y)
    E, nu, R, Y = 2.1e11, 0.3, 5e-3, 1e9  # Pa, -, m, Pa
    m = 7800.0 * 4.0 / 3.0 * math.pi * R**3  # kg
    c = ji.hertz_stiffness(E=E, nu=nu, R=R, E2=math.inf)
    steel = ji.law("thornton", c=c, x_y=ji.yield_overlap(E=E, nu=nu, R=R, Y=Y, E2=math.inf))
    v_y = float(steel.yield_speed(m))
    print(f"steel ball: {steel!r}, m = {m * 1e3:.3g} g")
    print(f"  yield speed v_y = {v_y * 1e3:.1f} mm/s: impacts above it are plastic")
    speeds = np.array([0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0])  # m/s
    e = np.asarray(jax.vmap(lambda v: ji.impact(steel, m=m, v0=v).e)(speeds))
    for v, e_v in zip(speeds, e, strict=True):
        print(
            f"  v0 = {v:4g} m/s: e = {e_v:.4f}  (Thornton's 1.185 (v_y/v0)^(1/4) = "
            f"{1.185 * (v_y / v) ** 0.25:.4f})"
        )

    # the yield stress back from SYNTHETIC e(v): the law's, plus noise
    rng = np.random.default_rng(0)
    measured = e + rng.normal(0.0, args.noise, e.size)
    fit = ji.calibrate(
        steel.replace(x_y=1e-6),
        m=m,
        v0=speeds,
        e=measured,
        sigma_e=np.full(e.size, args.noise),
        free=("x_y",),
    )
    p_y = ji.yield_pressure(float(fit.params["x_y"]), E=E, nu=nu, R=R, E2=math.inf)
    print(
        f"  fitted to SYNTHETIC e(v) (sigma {args.noise:g}): yield stress Y = p_y / 1.6 = "
        f"{p_y / 1.6 / 1e9:.3f} GPa (made with {Y / 1e9:g}), reduced chi-square "
        f"{float(fit.reduced_chi2):.2f}"
    )
    ranking = ji.compare_laws(
        m=m,
        v0=speeds,
        e=measured,
        sigma_e=np.full(e.size, args.noise),
        laws=("thornton", "hertz_rate", "hunt_crossley", "kelvin_voigt"),
        progress=False,
    )
    print(
        "  ranked by AIC: "
        + ", ".join(f"{r.name} (reduced chi-square {float(r.reduced_chi2):.3g})" for r in ranking)
    )

    # 2. an ammonium fluorescein microsphere on silicon (Thornton & Ning's particle)
    Rp, rho, w = 2.45e-6, 1350.0, 0.2  # m, kg/m^3, J/m^2 (the work of adhesion)
    mp = rho * 4.0 / 3.0 * math.pi * Rp**3
    cp = ji.hertz_stiffness(E=1.2e9, nu=0.3, R=Rp, E2=182e9, nu2=0.3)
    sticky = ji.law("jkr", c=cp, R=Rp, w=w)
    V_s = float(sticky.sticking_speed(mp))
    print(f"\nmicrosphere: {sticky!r}, m = {mp:.3g} kg")
    print(f"  sticking speed V_s = {V_s:.3f} m/s: slower impacts stay stuck (e = 0)")
    fast = np.array([0.3, 0.6, 1.0, 2.0, 5.0])
    impacts = jax.vmap(lambda v: ji.impact(sticky, m=mp, v0=v))(fast)
    for v, e_v, status in zip(fast, np.asarray(impacts.e), np.asarray(impacts.status), strict=True):
        exact = math.sqrt(max(1.0 - (V_s / v) ** 2, 0.0))
        print(
            f"  v0 = {v:3g} m/s: e = {e_v:.4f} ({ji.Status(int(status)).name}; "
            f"JKR's (1 - (V_s/v0)^2)^(1/2) = {exact:.4f})"
        )

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.8), layout="constrained")
        dense = np.geomspace(0.6 * v_y, 10.0, 80)
        fitted = jax.vmap(lambda v: ji.impact(fit.law, m=m, v0=v).e)(dense)
        left.semilogx(dense, fitted, "-", label="Thornton, fitted")
        left.errorbar(speeds, measured, yerr=args.noise, fmt="o", label="synthetic data")
        left.axvline(v_y, color="0.6", ls=":", label="yield speed")
        left.set_xlabel("impact speed v0 (m/s)")
        left.set_ylabel("restitution e")
        left.set_title("5 mm steel ball, Y = 1 GPa")
        left.legend(fontsize=8)
        dense = np.geomspace(0.5 * V_s, 20.0 * V_s, 80)
        right.semilogx(dense, jax.vmap(lambda v: ji.impact(sticky, m=mp, v0=v).e)(dense), "-")
        right.axvline(V_s, color="0.6", ls=":", label="sticking speed")
        right.set_xlabel("impact speed v0 (m/s)")
        right.set_ylabel("restitution e")
        right.set_title("2.45 um microsphere on silicon, w = 0.2 J/m^2")
        right.legend(fontsize=8)
        fig.savefig(args.plot, dpi=120)
        print(f"\nplot written to {args.plot}")


if __name__ == "__main__":
    main()
