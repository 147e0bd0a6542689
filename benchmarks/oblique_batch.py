"""Oblique impacts at batch speed: `oblique_impact_batch` (the phase-angle grid, then the
rows it did not serve integrated) against a jitted `jax.vmap` of `oblique_impact` (the
event-terminated diffrax solve, before) and the scipy oracle, per impact in a batch of
1,000.

The setting is benchmarks/oblique.py's: Kharaz's alumina sphere at 3.9 m/s, Hertz normal
law, mu = 0.092, `mindlin` and `linear_history` (kt = 2e7 N/m), `v_t / v_n` from 0.05 to
3 over 1,000 rows (sticking, micro-slip reversals, gross sliding). The oracle
(`tests/oblique/oblique_oracle.py`: scipy's DOP853 with event-handled transitions; nothing
of jaximpact) runs one impact at a time on every 16th row (63 rows), at the loosest rtol
whose results are within 1e-9 of its own rtol-1e-12 solution there; its time is per
impact. Errors: the largest error in `e_t` and in `R omega_out / v_t` against the oracle
at rtol 1e-12 on those rows; `grid vs before`: the largest such difference between the
two jaximpact paths over all 1,000 rows. Every time is measured in this one process,
the median of 3 rounds after a first (compiling) call.

Run: python benchmarks/oblique_batch.py (writes benchmarks/oblique_batch.md).
"""

import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "tests", "oblique"))
from _common import load_average, machine, machine_markdown, table, time_call, write_report  # noqa: E402
from oblique import LAWS, MU, SPEED, R, _error, _loosest, _oracle, _setup  # noqa: E402

N = 1000
EVERY = 16


def _rows(name, params, oracle_params):
    import jax
    import jax.numpy as jnp
    import numpy as np

    import jaximpact as ji
    from jaximpact._oblique import oblique_impact_batch

    m, c = _setup()
    law = ji.law("hunt_crossley", c=c, a=0.0)
    tl = ji.tangential_law(name, mu=MU, **params)
    angles = np.arctan(np.linspace(0.05, 3.0, N))
    v_n, v_t = (np.asarray(v) for v in ji.incidence(SPEED, angles))

    def one(a, b):
        r = ji.oblique_impact(law, tl, m=m, R=R, v_n=a, v_t=b)
        return jnp.stack([r.v_t_out, r.omega_out, r.num_switches.astype(float)], axis=-1)

    before = jax.jit(jax.vmap(one))

    def after():
        r = oblique_impact_batch(law, tl, m=m, R=R, v_n=v_n, v_t=v_t)
        out = np.stack([r.v_t_out, r.omega_out, r.num_switches.astype(float)], axis=-1)
        return out, r.path

    start = time.perf_counter()
    got_before = np.asarray(jax.block_until_ready(before(jnp.asarray(v_n), jnp.asarray(v_t))))
    compile_before = time.perf_counter() - start
    start = time.perf_counter()
    got_after, path = after()
    compile_after = time.perf_counter() - start
    t_before = time_call(before, jnp.asarray(v_n), jnp.asarray(v_t))[0] / N
    t_after = time_call(after)[0] / N
    served = sum(p == "grid" for p in path)

    pick = np.arange(0, N, EVERY)
    reference = _oracle(v_n[pick], v_t[pick], oracle_params, 1e-12)
    rtol, oerr, t_oracle = _loosest(v_n[pick], v_t[pick], oracle_params, reference)
    err_before = _error(got_before[pick], reference, v_t[pick])
    err_after = _error(got_after[pick], reference, v_t[pick])
    apart = _error(got_after, got_before, v_t)
    same = int(np.sum(got_after[pick, 2] == reference[:, 2]))
    return [
        [
            f"{name}: before, `jax.vmap` of `oblique_impact`",
            f"{t_before * 1e6:.0f} µs, max error {err_before:.1e}",
            f"{t_oracle / t_before:.0f}x",
            f"{compile_before:.0f} s",
        ],
        [
            f"{name}: after, `oblique_impact_batch` ({served}/{N} rows on the grid; "
            f"switches as the oracle's {same}/{pick.size}; grid vs before {apart:.1e})",
            f"{t_after * 1e6:.1f} µs, max error {err_after:.1e}",
            f"{t_oracle / t_after:.0f}x",
            f"{compile_after:.0f} s",
        ],
        [
            f"{name}: scipy oracle, DOP853 rtol {rtol:g}",
            f"{t_oracle * 1e6:.0f} µs, max error {oerr:.1e}",
            "1x",
            "-",
        ],
    ]


def main():
    import warnings

    import jax

    jax.config.update("jax_enable_x64", True)
    warnings.filterwarnings("ignore", "overflow encountered", RuntimeWarning)
    info = machine()
    loads = [load_average()]
    rows = []
    for name, (params, oracle_params) in LAWS.items():
        rows += _rows(name, params, oracle_params)
        loads.append(load_average())
    busy = max(float(load.split(",")[0]) for load in loads) > 1.5
    note = (
        [
            "**The machine was loaded by other jobs during this run** (1-minute load "
            "average above 1.5 on its 2 CPUs): absolute times are slower than on an idle "
            "machine; every row ran in this process, so the ratios are less affected, "
            "but they vary by about 2x between runs under such load.",
            "",
        ]
        if busy
        else []
    )
    text = "\n".join(
        [
            "# Oblique impacts at batch speed: the grid against the integrated solve",
            "",
            "Generated by `python benchmarks/oblique_batch.py` (the module docstring gives "
            "the setting). Per impact in a batch of 1,000 incidence angles (`v_t / v_n` "
            "0.05 to 3) of Kharaz's alumina sphere at 3.9 m/s, Hertz normal law, mu = "
            "0.092, every default (rtol 1e-11), float64, no accelerator. Errors: the "
            "largest error in `e_t` and in `R omega_out / v_t` against the scipy oracle "
            "at rtol 1e-12 on every 16th row. Ratio: the oracle's time per impact over "
            "the row's, all measured in this one process.",
            "",
            *note,
            machine_markdown(info, loads),
            "",
            table(["what", "per impact", "scipy / row", "first call"], rows),
            "",
        ]
    )
    write_report(os.path.join(HERE, "oblique_batch.md"), text)
    print(text)


if __name__ == "__main__":
    main()
