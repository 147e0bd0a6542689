"""The seed paper's section 7, done right and done its way.

A 1 kg ball dropped from 0.6 m onto a floor (Polukoshko et al. 2007, system (17), figs. 13-21)
with three contact laws: law 14 (c = 1e6, b1 = 1350), law 1 (c = 2e6, b = 480) and law 6
(c = 2e6, b1 = 8e5). The paper integrated flight and contact together with explicit Euler at
2e-5 s and printed e = 0.64, 0.64 and 0.54. Here: `jaximpact.bounce` (closed-form flights,
converged contacts with gravity, both separation criteria) against the paper's Euler scheme as
printed (the force lagging one step) and textbook Euler, at the paper's step and, for the first
contact, at 2e-7 s.

Run: python examples/bounce_paper_section7.py [--plot docs/bounce_section7.png]
"""

import argparse

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402

LAWS = {
    "hertz_rate": (dict(c=1e6, b1=1350.0), "14", 0.64),
    "kelvin_voigt": (dict(c=2e6, b=480.0), "1", 0.64),
    "kelvin_voigt_modified": (dict(c=2e6, b1=8e5), "6", 0.54),
}
M, H0, G, T_END = 1.0, 0.6, 9.81, 3.0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--plot", default="bounce_section7.png", help="figures 13-21: position, velocity, force"
    )
    args = parser.parse_args()

    rows, drops = [], {}
    for name, (params, eq, printed) in LAWS.items():
        law = ji.law(name, **params)
        converged = {
            sep: ji.bounce(law, m=M, h0=H0, t_end=T_END, separation=sep, max_impacts=32)
            for sep in ("force", "penetration")
        }
        drops[name] = converged
        euler = {
            ("paper", 2e-5): ji.euler_bounce(law, m=M, h0=H0, t_end=T_END),
            ("euler", 2e-5): ji.euler_bounce(law, m=M, h0=H0, t_end=T_END, scheme="euler"),
            ("euler", 2e-7): ji.euler_bounce(law, m=M, h0=H0, t_end=0.4, scheme="euler", dt=2e-7),
        }
        drops[name, "euler"] = euler["paper", 2e-5]
        for k in range(4):
            row = dict(law=f"{name} (eq. {eq})", bounce=k + 1, printed=printed if k == 0 else None)
            for sep, b in converged.items():
                row[sep] = float(b.e[k])
                row[f"t_{sep}"] = float(b.impact_times[k])
            for (scheme, dt), r in euler.items():
                row[f"{scheme} {dt:g}"] = float(r.e[k]) if k < r.e.size else float("nan")
            rows.append(row)
        b = converged["force"]
        print(
            f"{name}: {int(b.num_impacts)} contacts, status {b.status_name} at "
            f"{float(b.t_rest):.3f} s (force criterion); penetration: "
            f"{int(converged['penetration'].num_impacts)} contacts, "
            f"{converged['penetration'].status_name}"
        )

    print()
    print(
        "| law | bounce | printed | Euler as printed, 2e-5 s | Euler, 2e-5 s | Euler, 2e-7 s "
        "| converged, penetration | converged, force | impact time (force), s |"
    )
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        printed = "" if r["printed"] is None else f"{r['printed']:.2f}"
        print(
            f"| {r['law']} | {r['bounce']} | {printed} | {r['paper 2e-05']:.4f} | "
            f"{r['euler 2e-05']:.4f} | {r['euler 2e-07']:.4f} | {r['penetration']:.6f} | "
            f"{r['force']:.6f} | {r['t_force']:.6f} |"
        )

    if args.plot:
        plot(drops, args.plot)
        print(f"\nfigure written to {args.plot}")


def plot(drops, path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 3, figsize=(14, 10), layout="constrained")
    ts = np.sort(np.concatenate([np.linspace(0.0, 2.0, 4000)]))
    for row, name in enumerate(LAWS):
        b = drops[name]["force"]
        # a dense grid inside every contact too, so the force pulses are drawn
        inside = [
            np.linspace(float(t), float(t + T), 60)
            for t, T in zip(
                b.impact_times[: int(b.num_impacts)], b.T[: int(b.num_impacts)], strict=True
            )
            if float(t) < 2.0
        ]
        grid = np.unique(np.concatenate([ts, *inside]))
        y, u, F = (np.asarray(a) for a in b.trajectory(jnp.asarray(grid)))
        euler = drops[name, "euler"]
        keep = euler.t <= 2.0
        for col, (series, ref, label) in enumerate(
            [
                (y, euler.height, "height above floor (m)"),
                (u, euler.velocity, "velocity, upward (m/s)"),
                (F, euler.force, "contact force (N)"),
            ]
        ):
            ax = axes[row, col]
            ax.plot(euler.t[keep], ref[keep], color="C1", lw=0.8, label="paper's Euler, 2e-5 s")
            ax.plot(grid, series, color="C0", lw=0.9, ls="--", label="jaximpact.bounce")
            ax.set_xlabel("time (s)")
            ax.set_ylabel(label)
            if col == 0:
                ax.set_title(
                    f"{name}: " + ", ".join(f"{k} = {v:g}" for k, v in LAWS[name][0].items())
                )
        axes[row, 0].legend(fontsize="small")
    fig.savefig(path, dpi=110)


if __name__ == "__main__":
    main()
