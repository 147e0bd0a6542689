"""Oblique rebounds of a 5 mm alumina sphere on glass at 3.9 m/s (Kharaz, Gorham & Salman
2001's experiment, Chung & Ooi's test 4): the tangential restitution, the spin and the
rebound angle against the incidence with Hertz-Mindlin; the friction coefficient and the
tangential modulus G* fitted back from SYNTHETIC rebounds (made here by the same law with
noise: Kharaz's measured points are not shipped), with their standard errors; and the
tangential law exported to LAMMPS with the e_t LAMMPS realises at its time step.

Run: python examples/oblique_rebounds.py [--noise 0.01] [--plot oblique_rebounds.png]
"""

import argparse
import math
import os
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # hide XLA's compiler notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402

# the sphere and its contact, as the DEM codes set Kharaz's case up (notes 4.2)
M, R, SPEED = 2.618e-4, 2.5e-3, 3.9  # kg, m, m/s
E_STAR = 1 / ((1 - 0.23**2) / 3.8e11 + (1 - 0.25**2) / 7.0e10)  # alumina on glass, Pa
G_STAR, MU = 1.35e10, 0.092  # Pa, the codes' values


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--noise", type=float, default=0.01, help="sigma of e_t (synthetic)")
    parser.add_argument("--plot", default="oblique_rebounds.png")
    args = parser.parse_args()
    law = ji.law("hunt_crossley", c=4.0 / 3.0 * E_STAR * math.sqrt(R), a=0.0)  # Hertz, N/m^1.5
    truth = ji.tangential_law("mindlin", G_star=G_STAR, mu=MU)
    print(f"normal {law!r}\ntangential {truth!r}")
    print(f"sphere m = {M * 1e3:g} g, R = {R * 1e3:g} mm, speed {SPEED:g} m/s")

    # 1. the rebound against the incidence: one compiled vmap over 35 angles
    degrees = np.linspace(2.0, 87.0, 35)
    v_n, v_t = ji.incidence(SPEED, np.deg2rad(degrees))

    def one(law, tangential, v_n, v_t):
        return ji.oblique_impact(law, tangential, m=M, R=R, v_n=v_n, v_t=v_t)

    start = time.perf_counter()
    curve = jax.vmap(one, in_axes=(None, None, 0, 0))(law, truth, v_n, v_t)
    seconds = time.perf_counter() - start
    print(f"\n35 oblique impacts (one vmap, compiling included): {seconds:.1f} s")
    print("angle (deg)   e_t      spin after (rad/s)   rebound angle of the contact point (deg)")
    for k in range(0, 35, 5):
        print(
            f"{degrees[k]:8.1f}   {float(curve.e_t[k]):7.4f}   {float(curve.omega_out[k]):12.1f}"
            f"   {math.degrees(float(curve.angle_out_contact[k])):14.2f}"
        )

    # 2. mu and G* back from SYNTHETIC e_t at 8 angles (the law's, plus noise)
    rng = np.random.default_rng(1)
    chosen = np.array([5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0, 60.0])
    vn8, vt8 = ji.incidence(SPEED, np.deg2rad(chosen))
    made = jax.vmap(one, in_axes=(None, None, 0, 0))(law, truth, vn8, vt8)
    e_t = np.asarray(made.e_t) + rng.normal(0.0, args.noise, chosen.size)
    start = time.perf_counter()
    # started from the materials' G* and a guessed mu; start_scan=0: no grid of starts (a
    # start far off may stop in another phase's minimum: leave the default scan on then)
    fit = ji.fit_oblique(
        law,
        truth.replace(mu=0.15),
        m=M,
        R=R,
        v_n=vn8,
        v_t=vt8,
        e_t=e_t,
        sigma_e_t=np.full(chosen.size, args.noise),
        free=("G_star", "mu"),
        start_scan=0,
    )
    print(
        f"\nfit to SYNTHETIC e_t at {chosen.size} angles (sigma {args.noise:g}), started from "
        f"G* = 13.5 GPa, mu = 0.15: {time.perf_counter() - start:.1f} s"
    )
    for name, true in (("G_star", G_STAR), ("mu", MU)):
        value, error = float(fit.params[name]), float(fit.stderr[name])
        print(
            f"  {name:6s} = {value:.4g} +- {error:.2g} (made with {true:.4g}: "
            f"{(value - true) / error:+.1f} standard errors off)"
        )
    print(
        f"  rms of e_t {float(fit.rms_e_t):.4f}, reduced chi-square {float(fit.reduced_chi2):.2f}"
    )

    # 3. to LAMMPS: the same Mindlin law, and the e_t LAMMPS realises at its step
    x = ji.export(
        law, "lammps", m=M, v0=SPEED, radius=R, geometry="wall", tangential=fit.tangential
    )
    print(f"\nLAMMPS: {x.parameters['fix_wall']}")
    print("angle (deg)   law's e_t   LAMMPS realises")
    for angle, want, got in zip(x.angles, x.e_t_target, x.e_t_engine, strict=True):
        print(f"{angle:8.1f}    {want:9.4f}   {got:9.4f}")

    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), layout="constrained")
        fitted = jax.vmap(one, in_axes=(None, None, 0, 0))(law, fit.tangential, v_n, v_t)
        axes[0].plot(degrees, curve.e_t, "-", label="G* = 13.5 GPa, mu = 0.092")
        axes[0].plot(degrees, fitted.e_t, "--", label="fitted")
        axes[0].errorbar(chosen, e_t, yerr=args.noise, fmt="o", label="synthetic data")
        axes[0].plot(x.angles, x.e_t_engine, "s", mfc="none", label="LAMMPS realises")
        axes[0].set_xlabel("incidence from the normal (deg)")
        axes[0].set_ylabel("tangential restitution e_t")
        axes[0].legend(fontsize=8)
        axes[1].plot(degrees, curve.omega_out, "-")
        axes[1].set_xlabel("incidence from the normal (deg)")
        axes[1].set_ylabel("spin after impact (rad/s)")
        fig.suptitle("5 mm alumina sphere on glass, 3.9 m/s (Hertz-Mindlin; data synthetic)")
        fig.savefig(args.plot, dpi=120)
        print(f"\nplot written to {args.plot}")


if __name__ == "__main__":
    main()
