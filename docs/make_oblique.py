"""Write docs/oblique.png and print the tables of docs/oblique.md: Kharaz et al.'s alumina
sphere (Chung & Ooi Test 4: 5 mm, 3.9 m/s, mu = 0.092, e = 0.98, on a rigid plane), its
tangential restitution e_t, its spin after the impact and its contact point's rebound
angle against the incidence angle, from `oblique_impact` with Hertz-Mindlin (both
histories), the rigid-body theory's gross-sliding and rolling limits, Chung & Ooi's
reference curves (as Kratos stores them) and Kharaz's measurements (as Lethe and Kratos
digitised them; shared/notes/contact-physics.md, 1.3 and 4.2).

Run: python docs/make_oblique.py
"""

from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import matplotlib  # noqa: E402
import numpy as np  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact._oblique import (  # noqa: E402
    incidence,
    oblique_impact,
    rigid_oblique,
    tangential_law,
)

E, NU, RHO, R, SPEED, MU, E_N = 380e9, 0.23, 4000.0, 2.5e-3, 3.9, 0.092, 0.98
M = RHO * 4.0 / 3.0 * np.pi * R**3
C = 4.0 / 3.0 * E / (1 - NU**2) * np.sqrt(R)
G = E / (2 * (1 + NU))

# Chung & Ooi Test 4 reference (Kratos benchmark4_graph1_ref, graph2, graph3 "Al. oxide")
REF_THETA = [5.17, 10.16, 14.99, 20.06, 25.05, 30.12, 35.03, 40.02, 50, 59.98, 69.96, 80.02, 85.01]
REF_E_T = [
    0.948,
    0.687,
    0.624,
    0.616,
    0.634,
    0.684,
    0.737,
    0.781,
    0.845,
    0.893,
    0.932,
    0.966,
    0.983,
]
REF_OMEGA = [19, 213, 378, 511, 599, 617, 582, 545, 457, 357, 246, 126, 63]
REF_ANGLE = [3.8, -1.6, -5.5, -7.5, -7.5, -3.5, 3.4, 11.6, 29.4, 47.8, 64.6, 78.7, 84.5]
# Kharaz et al. 2001 (Lethe's digitisation: e_t, spin; Kratos': contact-point angle)
KH_E_T = (
    [1.84, 3.70, 9.50, 20.01, 30.13, 39.38, 49.69, 60.02],
    [0.793, 0.745, 0.673, 0.597, 0.688, 0.771, 0.848, 0.901],
)
KH_OMEGA = ([6.14, 10.99, 21.25, 31.16, 39.14, 50.35, 60.33], [136, 266, 578, 613, 595, 453, 382])
KH_ANGLE = (
    [2.10, 3.94, 9.72, 20.31, 30.16, 39.12, 49.51, 59.90, 70.46, 78.86, 84.78],
    [0.8, 0.8, -1.1, -8.5, -2.6, 9.9, 30.0, 50.0, 66.9, 78.9, 85.7],
)


def tsuji_damping(e):
    """The damping of `c x^1.5 + b x^0.25 v` whose restitution is `e` (bisection)."""
    lo, hi = 0.0, 10.0 * np.sqrt(M * C)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        found = float(ji.impact(ji.law("tsuji", c=C, b=mid), m=M, v0=SPEED).e)
        lo, hi = (mid, hi) if found > e else (lo, mid)
    return 0.5 * (lo + hi)


LAW = ji.law("tsuji", c=C, b=tsuji_damping(E_N))


def sweep(name, degrees):
    tl = tangential_law(name, G=G, nu=NU, mu=MU)

    def one(theta):
        v_n, v_t = incidence(SPEED, theta)
        r = oblique_impact(LAW, tl, m=M, R=R, v_n=v_n, v_t=v_t)
        return r.e_t, r.omega_out, r.angle_out_contact, r.num_switches

    e_t, omega, angle, switches = jax.jit(jax.vmap(one))(jnp.deg2rad(jnp.asarray(degrees)))
    return np.asarray(e_t), np.asarray(omega), np.rad2deg(np.asarray(angle)), np.asarray(switches)


def rigid(degrees):
    theta = np.deg2rad(np.asarray(degrees))
    out = rigid_oblique(mu=MU, e=E_N, v_n=SPEED * np.cos(theta), v_t=SPEED * np.sin(theta), R=R)
    slide = np.asarray(out["sliding"])
    # the two limits over the whole range: gross sliding, and rolling at the end (u_out = 0)
    v_n, v_t = SPEED * np.cos(theta), SPEED * np.sin(theta)
    sliding_e_t = 1.0 - MU * (1 + E_N) * v_n / v_t
    rolling_e_t = np.full_like(theta, 1.0 / 1.4)
    sliding_angle = np.rad2deg(np.arctan2(v_t - 3.5 * MU * (1 + E_N) * v_n, E_N * v_n))
    sliding_omega = 2.5 * MU * (1 + E_N) * v_n / R
    rolling_omega = v_t / 1.4 / R
    return dict(
        e_t=np.asarray(out["e_t"]),
        slide=slide,
        sliding_e_t=sliding_e_t,
        rolling_e_t=rolling_e_t,
        sliding_angle=sliding_angle,
        sliding_omega=sliding_omega,
        rolling_omega=rolling_omega,
    )


def main():
    degrees = np.linspace(1.0, 89.0, 89)
    curves = {name: sweep(name, degrees) for name in ("mindlin", "mindlin_force")}
    limits = rigid(degrees)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    styles = {
        "mindlin": ("C0", "-", "Hertz-Mindlin, displacement history"),
        "mindlin_force": ("C1", "--", "Hertz-Mindlin, force history"),
    }
    for name, (e_t, omega, angle, _) in curves.items():
        color, line, label = styles[name]
        axes[0].plot(degrees, e_t, line, color=color, label=label)
        axes[1].plot(degrees, omega, line, color=color, label=label)
        axes[2].plot(degrees, angle, line, color=color, label=label)
    axes[0].plot(degrees, limits["sliding_e_t"], ":", color="k", label="rigid, gross sliding")
    axes[0].plot(degrees, limits["rolling_e_t"], "-.", color="gray", label="rigid, rolling (5/7)")
    axes[1].plot(degrees, limits["sliding_omega"], ":", color="k", label="rigid, gross sliding")
    axes[1].plot(degrees, limits["rolling_omega"], "-.", color="gray", label="rigid, rolling")
    axes[2].plot(degrees, limits["sliding_angle"], ":", color="k", label="rigid, gross sliding")
    axes[2].axhline(0.0, ls="-.", color="gray", label="rigid, rolling (u' = 0)")
    ref = dict(marker="s", ls="none", mfc="none", color="C3", label="Chung & Ooi Test 4 reference")
    meas = dict(marker="o", ls="none", color="k", label="Kharaz et al. 2001, measured")
    axes[0].plot(REF_THETA, REF_E_T, **ref)
    axes[0].plot(*KH_E_T, **meas)
    axes[1].plot(REF_THETA, REF_OMEGA, **ref)
    axes[1].plot(*KH_OMEGA, **meas)
    axes[2].plot(REF_THETA, REF_ANGLE, **ref)
    axes[2].plot(*KH_ANGLE, **meas)
    axes[0].set(ylim=(0.4, 1.02), ylabel="e_t = v_t' / v_t")
    axes[1].set(ylim=(0, 1000), ylabel="spin after, omega' (rad/s)")
    axes[2].set(ylim=(-20, 90), ylabel="contact point's rebound angle (degrees)")
    for ax in axes:
        ax.set(xlabel="incidence angle (degrees)", xlim=(0, 90))
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=7, loc="lower right")
    fig.suptitle("Alumina sphere on a rigid plane, 3.9 m/s, mu = 0.092, e = 0.98")
    fig.tight_layout()
    out = Path(__file__).with_name("oblique.png")
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")

    table = {name: sweep(name, REF_THETA) for name in ("mindlin", "mindlin_force")}
    print(
        "\n| theta | e_t ref | mindlin | force | omega' ref | mindlin | force "
        "| angle ref | mindlin | force | switches |"
    )
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for k, theta in enumerate(REF_THETA):
        d, f = table["mindlin"], table["mindlin_force"]
        print(
            f"| {theta:.1f} | {REF_E_T[k]:.3f} | {d[0][k]:.3f} | {f[0][k]:.3f} "
            f"| {REF_OMEGA[k]} | {d[1][k]:.0f} | {f[1][k]:.0f} | {REF_ANGLE[k]:.1f} "
            f"| {d[2][k]:.1f} | {f[2][k]:.1f} | {d[3][k]}, {f[3][k]} |"
        )
    for name, (e_t, omega, angle, _) in table.items():
        print(
            f"{name}: max |e_t - ref| = {np.max(np.abs(e_t - REF_E_T)):.4f}, "
            f"max |omega - ref| = {np.max(np.abs(omega - REF_OMEGA)):.1f} rad/s, "
            f"max |angle - ref| = {np.max(np.abs(angle - REF_ANGLE)):.2f} degrees"
        )


if __name__ == "__main__":
    main()
