"""Requested vs realised e and T in the real engines (MuJoCo, LAMMPS, Drake), for
docs/engines.md. Run: python benchmarks/engines_table.py > benchmarks/engines_table.md"""

import jax

jax.config.update("jax_enable_x64", True)

import jaximpact as ji  # noqa: E402
from jaximpact._engines import drake, lammps, mujoco  # noqa: E402

PHASES = (0.05, 0.3, 0.55, 0.8, 0.95)
print("| engine | asked e | asked T (s) | promised e | engine e (5 start phases) | "
      "promised T (s) | engine T (s) | step (s) |")
print("|---|---|---|---|---|---|---|---|")
for e, T in [(0.95, 0.02), (0.75, 0.01), (0.5, 2e-3), (0.2, 5e-3), (0.05, 1e-3)]:
    x = ji.export(None, "mujoco", m=0.05, v0=1.0, e=e, T=T, curves=False)
    es, Ts = mujoco.simulate(x.parameters, 1.0, m=0.05, phases=PHASES)
    print(f"| MuJoCo {__import__('mujoco').__version__} | {e} | {T:g} | {x.e:.5f} | "
          f"{es.min():.5f} to {es.max():.5f} | {x.T:.5g} | {Ts.min():.5g} to {Ts.max():.5g} | "
          f"{x.timestep:g} |")
for e, T, limit in [(0.9, 1e-3, False), (0.5, 5e-4, False), (0.1, 1e-4, False),
                    (0.8, 5e-4, True), (0.3, 2e-4, True)]:
    x = ji.export(None, "lammps", m=0.004, v0=1.0, radius=0.005, e=e, T=T, limit_damping=limit,
                  curves=False)
    es, Ts = lammps.simulate(x.parameters, m=0.004, v0=1.0, radius=0.005, phases=PHASES)
    name = "LAMMPS 22Jul2025" + (" limit_damping" if limit else "")
    print(f"| {name} | {e} | {T:g} | {x.e:.5f} | {es.min():.5f} to {es.max():.5f} | "
          f"{x.T:.5g} | {Ts.min():.5g} to {Ts.max():.5g} | {x.timestep:g} |")
try:
    import pydrake

    for e, T in [(0.8, 1e-3), (0.5, 5e-3), (0.3, 2e-3)]:
        x = ji.export(None, "drake", m=0.05, v0=1.0, e=e, T=T, curves=False)
        e_d, T_d = drake.simulate(x.parameters, m=0.05, v0=1.0)
        print(f"| Drake {pydrake.__version__ if hasattr(pydrake, '__version__') else ''} "
              f"continuous | {e} | {T:g} | {x.e:.5f} | {e_d:.5f} | {x.T:.5g} | {T_d:.5g} | 0 |")
except ImportError as error:
    print(f"\nDrake not run: {error}")
# the requested-vs-realised gap of LAMMPS's own formulas (what users meet)
print("\n| LAMMPS input | coefficient given | realised e (LAMMPS) |")
print("|---|---|---|")
for damping, limit in [("coeff_restitution", ""), ("coeff_restitution", " limit_damping"),
                       ("tsuji", ""), ("tsuji", " limit_damping")]:
    for cor in (0.1, 0.5, 0.9):
        params = dict(pair_style="pair_style granular", timestep="timestep 2e-8", timestep_s=2e-8,
                      pair_coeff=f"pair_coeff * * hertz/material 1e8 {cor} 0.3 damping {damping} "
                      f"tangential linear_nohistory 0 0{limit}")
        es, _ = lammps.simulate(params, m=0.004, v0=1.0, radius=0.005, phases=(0.5,))
        print(f"| {damping}{limit} | {cor} | {es[0]:.4f} |")
