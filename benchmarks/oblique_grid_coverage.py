"""Which oblique rows the phase-angle grid serves, and how right they are: every served
row against the scipy oracle (not only every 16th, as benchmarks/oblique_batch.py), the
damped contacts the grid declines and what a finer grid would serve, and the cost of
each compiled shape of `oblique_impact_batch`'s second (integrated) pass.

1. Undamped (benchmarks/oblique.py's setting: Kharaz's alumina sphere at 3.9 m/s, Hertz,
   mu = 0.092, 1,000 rows with `v_t / v_n` 0.05 to 3): rows served, and the largest
   error of `e_t` and `R omega_out / v_t` over every served row against the oracle at
   rtol 1e-12, with the rows whose switch counts are not the oracle's.
2. Damped normal contact (tests/oblique/test_oblique_grid.py's sweep: Hunt-Crossley
   a = 0.1 s/m, 18 angles x 4 friction coefficients): rows served at 32 steps (the
   grid's `OBLIQUE_STEPS`), 48 and 64, each served row's largest relative error in e,
   v_t_out, omega_out and T against the sweep's oracle, and, at 32 steps, the true error
   of the rows declined by the error estimate alone.
3. The second pass: compile-and-run and run times of `_integrated` for chunks of 2 to 32
   `linear_history` rows.

Run: python benchmarks/oblique_grid_coverage.py (writes benchmarks/oblique_grid_coverage.md;
about 6 minutes on 2 cores).
"""

import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "tests", "oblique"))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))
from _common import load_average, machine, machine_markdown, table, write_report  # noqa: E402

STEP_COUNTS = (32, 48, 64)
CHUNKS = (2, 4, 8, 16, 32)
UNDAMPED_HEADER = ["tangential law", "rows served", "largest error (e_t, R omega / v_t)"]
UNDAMPED_HEADER += ["switches not the oracle's"]
DAMPED_HEADER = ["case", "steps", "rows served", "largest relative error"]
DAMPED_HEADER += ["switches not the oracle's"]


def _grid(law, tl, options, steps, m, R, v_n, v_t, mu=None):
    """`grid_outcome`'s dict over rows, at `steps` grid steps (a jitted vmap); `tl` a
    tangential law, or with `mu` (one per row) its name and other parameters."""
    import jax

    from jaximpact._oblique import tangential_law
    from jaximpact._oblique.grid import grid_outcome

    def one(a, b, f):
        spring_law = tl if f is None else tangential_law(tl[0], mu=f, **tl[1])
        return grid_outcome(law, spring_law, m, R, a, b, 0.0, 0.4, options, steps=steps)[2]

    if mu is None:
        return jax.jit(jax.vmap(lambda a, b: one(a, b, None)))(v_n, v_t)
    return jax.jit(jax.vmap(one))(v_n, v_t, mu)


def undamped_rows():
    import numpy as np
    from oblique import LAWS, MU, SPEED, R, _error, _oracle, _setup

    import jaximpact as ji
    from jaximpact._oblique import tangential_law
    from jaximpact._oblique.batch import batch_options

    m, c = _setup()
    law = ji.law("hunt_crossley", c=c, a=0.0)
    v_n, v_t = (np.asarray(v) for v in ji.incidence(SPEED, np.arctan(np.linspace(0.05, 3.0, 1000))))
    options = batch_options(separation="force", contact_point="surface", rtol=1e-11)
    rows = []
    for name, (params, oracle_params) in LAWS.items():
        out = _grid(law, tangential_law(name, mu=MU, **params), options, 32, m, R, v_n, v_t)
        served = np.flatnonzero(np.asarray(out["served"]))
        got = np.stack(
            [
                np.asarray(out["V_t"])[served] * v_n[served],
                np.asarray(out["W"])[served] * v_n[served] / R,
                np.asarray(out["switches"])[served],
            ],
            axis=-1,
        )
        want = _oracle(v_n[served], v_t[served], oracle_params, 1e-12)
        worst = max(
            _error(got[i : i + 1], want[i : i + 1], v_t[served][i : i + 1])
            for i in range(served.size)
        )
        rows.append(
            [name, f"{served.size} / 1000", f"{worst:.1e}", int(np.sum(got[:, 2] != want[:, 2]))]
        )
    return rows


def damped_rows():
    import numpy as np
    import test_oblique_grid as T

    import jaximpact as ji
    from jaximpact._oblique import grid as G
    from jaximpact._oblique.batch import batch_options
    from jaximpact._solve.grid import GRID_ACCEPT

    v_n, v_t, mu, _ = T._rows()
    options = batch_options(separation="force", contact_point="surface", rtol=1e-11)
    rows, declined = [], []
    for case in ("mindlin, damped normal", "linear_history, damped normal"):
        name, damping, _ = T.CASES[case]
        params, oracle_params = T.LAWS[name]
        law = ji.law("hunt_crossley", c=T.C, a=damping)
        oracle = {}

        def reference(i, oracle=oracle, damping=damping, oracle_params=oracle_params):
            if i not in oracle:
                oracle[i] = T.oblique_oracle(
                    c=T.C,
                    a=damping,
                    m=T.M,
                    R=T.R,
                    inertia=0.4,
                    v_n=float(v_n[i]),
                    v_t=float(v_t[i]),
                    omega=0.0,
                    mu=float(mu[i]),
                    **oracle_params,
                )
            return oracle[i]

        def error(out, i):
            o = reference(i)
            got = dict(
                e=out["e"][i],
                v_t_out=out["V_t"][i] * v_n[i],
                omega_out=out["W"][i] * v_n[i] / T.R,
                T=out["tau"][i] * out["t_star"][i],
            )
            return max(abs(float(got[k]) - o[k]) / abs(o[k]) for k in T.KEYS)

        for steps in STEP_COUNTS:
            out = _grid(law, (name, params), options, steps, T.M, T.R, v_n, v_t, mu)
            out = {k: np.asarray(v) for k, v in out.items()}
            served = np.flatnonzero(out["served"])
            errors = [error(out, i) for i in served]
            wrong = sum(int(out["switches"][i]) != reference(i)["switches"] for i in served)
            rows.append([case, steps, f"{served.size} / {len(v_n)}", f"{max(errors):.1e}", wrong])
            if steps == 32:
                h = 1.0 / steps
                alone = [
                    i
                    for i in np.flatnonzero(~out["served"])
                    if out["estimate"][i] > GRID_ACCEPT
                    and out["dip"][i] >= -G.DIP_TOL
                    and out["gap"][i] >= G.MIN_GAP * h
                ]
                if alone:
                    true = [error(out, i) for i in alone]
                    estimates = [out["estimate"][i] for i in alone]
                    declined.append(
                        [
                            case,
                            len(alone),
                            f"{min(estimates):.1e} - {max(estimates):.1e}",
                            f"{min(true):.1e} - {max(true):.1e}",
                        ]
                    )
    return rows, declined


def chunk_rows():
    import jax
    import jax.numpy as jnp
    import numpy as np
    from oblique import MU, SPEED, R, _setup

    import jaximpact as ji
    from jaximpact._oblique import batch as B, tangential_law
    from jaximpact._oblique.impact import ObliqueInputs

    m, c = _setup()
    law = ji.law("hunt_crossley", c=c, a=0.0)
    tl = tangential_law("linear_history", mu=MU, kt=2e7)
    v_n, v_t = (np.asarray(v) for v in ji.incidence(SPEED, np.arctan(np.linspace(0.05, 3.0, 1000))))
    options = B.batch_options(separation="force", contact_point="surface", rtol=1e-11)
    rows = []
    for size in CHUNKS:
        pick = np.arange(177, 177 + size)  # rows near v_t / v_n = 0.57, some with transitions
        inputs = ObliqueInputs(
            *(
                jnp.asarray(np.broadcast_to(np.asarray(a, float), (1000,))[pick])
                for a in (m, R, v_n, v_t, 0.0, 0.4, 0.0)
            )
        )
        start = time.perf_counter()
        jax.block_until_ready(B._integrated(law, tl, inputs, options))
        first = time.perf_counter() - start
        runs = []
        for _ in range(3):
            start = time.perf_counter()
            jax.block_until_ready(B._integrated(law, tl, inputs, options))
            runs.append(time.perf_counter() - start)
        rows.append([size, f"{first:.1f}", f"{1e3 * min(runs):.1f}"])
    return rows


def main():
    import jax

    jax.config.update("jax_enable_x64", True)
    loads = [load_average()]
    undamped = undamped_rows()
    loads.append(load_average())
    damped, declined = damped_rows()
    loads.append(load_average())
    chunks = chunk_rows()
    loads.append(load_average())
    text = "\n".join(
        [
            "# Oblique rows on the grid: coverage and accuracy",
            "",
            "Generated by `python benchmarks/oblique_grid_coverage.py` (the module docstring "
            "gives the settings). Float64, rtol 1e-11, no accelerator.",
            "",
            machine_markdown(machine(), loads),
            "",
            "## Undamped: every served row against the oracle (rtol 1e-12)",
            "",
            table(UNDAMPED_HEADER, undamped),
            "",
            "## Damped normal contact (a = 0.1 s/m): the grid at 32, 48 and 64 steps",
            "",
            table(DAMPED_HEADER, damped),
            "",
            "Rows declined at 32 steps by the error estimate alone (above `GRID_ACCEPT`), "
            "and their true errors against the oracle: most are above 1e-9, so the estimate "
            "is right to decline them as a rule.",
            "",
            table(["case", "rows", "estimate", "true error"], declined) if declined else "(none)",
            "",
            "## The second pass: one compiled shape per chunk size (`linear_history`)",
            "",
            table(["rows per call", "compile + first run s", "run ms"], chunks),
            "",
        ]
    )
    write_report(os.path.join(HERE, "oblique_grid_coverage.md"), text)


if __name__ == "__main__":
    main()
