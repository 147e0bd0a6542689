"""Write docs/plastic_adhesive.png: the restitution of Thornton's elastic-plastic law against
v0/v_y and of the JKR adhesive contact against v0/V_s, from jaximpact's closed forms (lines)
and its integrated path (points), with the published formulas (Thornton 1997; the JKR energy
balance, shared/notes/contact-physics.md, 2.1 and 3.1).

Run: python docs/make_plastic_adhesive.py
"""

import math
from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact._laws.thornton import thornton_restitution  # noqa: E402

# steel ball, R = 5 mm, on a rigid flat, yield stress 1 GPa (p_y = 1.6 Y)
R, M = 5e-3, 4.0 / 3.0 * math.pi * 5e-3**3 * 7800.0
PLASTIC = ji.law(
    "thornton",
    c=ji.hertz_stiffness(E=2.1e11, nu=0.3, R=R, E2=math.inf),
    x_y=ji.yield_overlap(E=2.1e11, nu=0.3, R=R, Y=1e9, E2=math.inf),
)
# ammonium fluorescein on silicon (Thornton & Ning 1998), w = 0.2 J/m^2
R_A = 2.45e-6
M_A = 4.0 / 3.0 * math.pi * R_A**3 * 1350.0
E_A = 1.0 / ((1 - 0.3**2) / 1.2e9 + (1 - 0.3**2) / 182e9)
ADHESIVE = ji.law("jkr", c=4.0 / 3.0 * E_A * math.sqrt(R_A), R=R_A, w=0.2)


def restitutions(law, m, speeds, method):
    return jax.vmap(lambda v: ji.impact(law, m=m, v0=v, method=method, throw=False).e)(speeds)


def main(path=None):
    path = Path(__file__).with_name("plastic_adhesive.png") if path is None else path
    v_y, v_s = float(PLASTIC.yield_speed(M)), float(ADHESIVE.sticking_speed(M_A))
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4))
    ratio = jnp.logspace(-0.5, 4, 300)
    left.semilogx(
        ratio, restitutions(PLASTIC, M, ratio * v_y, "auto"), label="jaximpact, closed form"
    )
    points = jnp.logspace(-0.3, 3.8, 12)
    left.semilogx(
        points,
        restitutions(PLASTIC, M, points * v_y, "integrate"),
        "o",
        mfc="none",
        label="jaximpact, integrated",
    )
    left.semilogx(ratio, thornton_restitution(ratio), "k:", label="Thornton (1997), formula")
    tail = ratio[ratio > 3]
    left.semilogx(tail, 1.185 * tail**-0.25, "--", color="gray", label="1.185 (v_y/v0)^(1/4)")
    left.set(xlabel="v0 / v_y", ylabel="e", title="elastic-plastic (steel, R = 5 mm)")
    left.legend(fontsize=8)
    ratio = jnp.logspace(-0.5, 2, 300)
    right.semilogx(
        ratio, restitutions(ADHESIVE, M_A, ratio * v_s, "auto"), label="jaximpact, closed form"
    )
    points = jnp.logspace(-0.4, 1.9, 12)
    right.semilogx(
        points,
        restitutions(ADHESIVE, M_A, points * v_s, "integrate"),
        "o",
        mfc="none",
        label="jaximpact, integrated",
    )
    right.semilogx(
        ratio, jnp.sqrt(jnp.clip(1 - ratio**-2, 0, 1)), "k:", label="(1 - (V_s/v0)^2)^(1/2)"
    )
    right.set(xlabel="v0 / V_s", ylabel="e", title="JKR adhesive (R = 2.45 µm, w = 0.2 J/m²)")
    right.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    print(f"wrote {path}: v_y = {v_y:.4g} m/s, V_s = {v_s:.4g} m/s")


if __name__ == "__main__":
    main()
