"""Print the MuJoCo tables of docs/oblique.md ("MuJoCo's friction"): what MuJoCo realises
(its Euler step, the pyramidal cone, replicated: jaximpact/_engines/mujoco/friction.py) when
a normal law and a tangential law are exported to it, beside the laws' own e_t, for a
nearly elastic stiff contact (Kharaz's alumina sphere) and a soft, damped one.

Run: python docs/make_mujoco_friction.py
"""

import math

import jax

jax.config.update("jax_enable_x64", True)

import jaximpact as ji  # noqa: E402

R_ALUMINA = 2.5e-3
CASES = {
    "Kharaz's alumina sphere (`tsuji` c = 4.2e9, b = 15; `mindlin` G* = 13.5 GPa, "
    "mu = 0.092), 3.9 m/s": (
        ji.law("tsuji", c=4.2e9, b=15.0),
        ji.tangential_law("mindlin", G_star=1.35e10, mu=0.092),
        4000.0 * 4.0 / 3.0 * math.pi * R_ALUMINA**3,
        R_ALUMINA,
        3.9,
    ),
    "a soft ball (`kelvin_voigt` c = 3e4 N/m, b = 6 N s/m; `linear_history` kt = 2e4 N/m, "
    "mu = 0.5), 57 g, R = 33 mm, 5 m/s": (
        ji.law("kelvin_voigt", c=3e4, b=6.0),
        ji.tangential_law("linear_history", kt=2e4, mu=0.5),
        0.057,
        0.033,
        5.0,
    ),
}

if __name__ == "__main__":
    for name, (law, tangential, m, R, v0) in CASES.items():
        x = ji.export(law, "mujoco", m=m, v0=v0, radius=R, tangential=tangential, curves=False)
        damping = -x.parameters["solref"][1]
        print(
            f"\n{name}: e = {x.e:.4f}, T = {x.T:.3g} s, step {x.timestep:.3g} s, "
            f"damping x T = {damping * x.T:.2f}\n"
        )
        print("| angle (deg) | MuJoCo e_t | law's e_t | MuJoCo normal e | MuJoCo spin (rad/s) |")
        print("|---|---|---|---|---|")
        rows = zip(x.angles, x.e_t_engine, x.e_t_target, x.e_n_engine, x.omega_engine, strict=True)
        for angle, e_t, law_e_t, e_n, omega in rows:
            print(f"| {angle:g} | {e_t:.4f} | {law_e_t:.4f} | {e_n:.4f} | {omega:.4g} |")
