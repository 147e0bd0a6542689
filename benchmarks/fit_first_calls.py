"""A fit's first call: the optimiser driven from Python around one compiled program (the
default for an eager `calibrate`, `optimizer="auto"`, i.e. Levenberg-Marquardt) against the
optimiser inside the compiled fit (`optimizer="lbfgs"`, the default before issue 35, which
compiles the solve three times: the loss's, the Jacobian's, the final one with the peaks).

Each row runs in a fresh Python process without JAX's persistent compilation cache, so the
first call holds tracing and XLA's compiling; the second call (new targets, same shapes) is
the run time. Both optimisers of a row see the same law, start and data, and the table gives
how far apart their answers are (the largest relative difference of the fitted parameters).

Run: python benchmarks/fit_first_calls.py [CASE ...] (writes benchmarks/fit_first_calls.md).
"""

import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from _common import fresh_process, load_average, machine, machine_markdown, table, write_report  # noqa: E402

CHILD = r"""
import json, sys, time, warnings
import jax
jax.config.update("jax_enable_x64", True)
import numpy as np
import jaximpact as ji
from jaximpact._fit.model_choice import starting_law
warnings.simplefilter("ignore")
case, optimizer = sys.argv[1], sys.argv[2]
v4 = np.array([0.5, 1.0, 2.0, 3.0])
v6 = np.array([0.5, 1.0, 1.5, 2.0, 2.5, 3.0])
e6 = np.array([0.9, 0.87, 0.85, 0.83, 0.82, 0.81])


def user_law(p_c=2e6, p_b1=800.0):
    force = lambda x, v, p: p["c"] * x**1.5 + p["b1"] * x**0.5 * v * (1 + 0.1 * v)
    return ji.custom_law(force, c=p_c, b1=p_b1)


def targets(law, v0, m):
    rows = [ji.impact(law, m=m, v0=float(v)) for v in v0]
    return np.array([float(r.e) for r in rows]), np.array([float(r.T) for r in rows])


if case == "user law":  # a user's Hunt-Crossley form, e and T at 4 speeds
    start = user_law()
    e, T = targets(user_law(3e6, 600.0), v4, 0.05)
    e2 = e * (1 - 1e-3)
    call = lambda e: ji.calibrate(start, m=0.05, v0=v4, e=e, T=T, optimizer=optimizer)
elif case in ("hertz_rate", "bingham", "maxwell"):  # a table law, e and T at 4 speeds
    start = starting_law(case, m=0.05, v0=1.5, e=0.85, T=1e-3)
    e, T = targets(start.replace(c=1.3 * float(start.params["c"])), v4, 0.05)
    e2 = e * (1 - 1e-3)
    call = lambda e: ji.calibrate(start, m=0.05, v0=v4, e=e, T=T, optimizer=optimizer)
else:  # compare_laws over the seed paper's laws, e at 6 speeds
    e, e2 = e6, e6 * (1 - 1e-3)
    call = lambda e: ji.compare_laws(m=0.05, v0=v6, e=e, progress=False, warn=False,
                                     optimizer=optimizer)
out = {}
for key, target in (("first", e), ("second", e2)):
    t0, c0 = time.perf_counter(), time.process_time()
    result = call(target)
    out[key] = time.perf_counter() - t0
    out[key + "_cpu"] = time.process_time() - c0
fits = [r.fit for r in result] if isinstance(result, list) else [result]
out["params"] = {f.law.name + ":" + k: float(v) for f in fits for k, v in f.params.items()}
out["losses"] = {f.law.name: float(f.loss) for f in fits}
out["converged"] = all(bool(f.converged) for f in fits)
out["optimizer"] = sorted({f.optimizer for f in fits})
print(json.dumps(out))
"""
QUICK = (
    "Since stop 42 `auto`'s program on a closed form or the curves (`hertz_rate`, `bingham`, "
    "`maxwell`, 10 of `compare_laws`' 11 laws) compiles without XLA's CPU fusion emitters "
    "(`jaximpact/_compiling.py`); `lbfgs` and the integrated `user law` keep XLA's defaults. "
    "Since stop 50 `auto`'s Jacobian batches the solve once, over (impact, direction) pairs "
    "of a `jax.jvp` (`_fit/forward_jacobian.rows_value_and_jacobian`), not `jax.jacfwd` of "
    "the batch of impacts: the run before (commit e67b1a1, load 1.5-2.6) gave `auto` first "
    "calls of 12.0 / 13.9 (user law), 1.0 / 1.3 (hertz_rate), 4.0 / 4.9 (bingham), "
    "3.0 / 3.5 (maxwell) and 37.9 / 33.8 (compare_laws) wall / CPU s."
)
CASES = ("user law", "hertz_rate", "bingham", "maxwell", "compare_laws")
NOTE = (
    "With e alone, several of the paper's laws leave a parameter undetermined (a stiffness, "
    "or a yield force: `Fit.undetermined`), where the two optimisers stop at different "
    "values of the same loss: `compare_laws`' parameters are far apart where its losses "
    "are not."
)


def child(case, optimizer):
    return fresh_process(CHILD, case, optimizer)


def largest_difference(a: dict, b: dict) -> float:
    return max(abs(a[k] - b[k]) / max(abs(b[k]), 1e-300) for k in a)


def main():
    only = sys.argv[1:] or CASES
    loads, rows = [load_average()], []
    started = time.strftime("%Y-%m-%d %H:%M:%S UTC", time.gmtime())
    for case in only:
        host, graph = child(case, "auto"), child(case, "lbfgs")
        rows.append(
            [
                case,
                f"{host['first']:.1f} / {host['first_cpu']:.1f}",
                f"{graph['first']:.1f} / {graph['first_cpu']:.1f}",
                f"{graph['first_cpu'] / host['first_cpu']:.1f}x",
                f"{host['second'] * 1e3:.0f} / {graph['second'] * 1e3:.0f}",
                f"{largest_difference(host['params'], graph['params']):.1e}",
                f"{max(abs(host['losses'][k] - graph['losses'][k]) for k in host['losses']):.1e}",
                f"{host['converged']} / {graph['converged']}",
            ]
        )
        print(" | ".join(rows[-1]), flush=True)
        loads.append(load_average())
    text = "\n".join(
        [
            "# A fit's first call: one compiled program, the optimiser in Python",
            "",
            f"Generated by `python benchmarks/fit_first_calls.py`, {started}. Each cell is one "
            "fresh process without the persistent cache (median of 1: the rows are minutes "
            "each). `auto`: the default of an eager `calibrate` since issue 35, "
            "Levenberg-Marquardt (`jaximpact/_least_squares.py`) driven from Python around "
            "one compiled program of the residuals, the peaks and their forward-mode Jacobian; "
            "`lbfgs`: optax L-BFGS inside the compiled fit (the default before). `user law`: "
            "`c x^1.5 + b1 sqrt(x) v (1 + 0.1 v)`, e and T at 4 speeds (integrated); "
            "`hertz_rate` (on the curves), `bingham` and `maxwell` (closed forms): e and T at "
            "4 speeds; `compare_laws`: the seed paper's 11 laws, e at 6 speeds (threads, one "
            "per core). Seconds as wall / CPU (the process's user + system time, which load "
            "affects less); the second call is new targets of the same shapes.",
            "",
            QUICK,
            "",
            NOTE,
            "",
            machine_markdown(machine(), loads),
            "",
            table(
                [
                    "fit",
                    "first call, auto: wall / CPU s",
                    "first call, lbfgs: wall / CPU s",
                    "CPU saved (lbfgs / auto)",
                    "second call ms, auto / lbfgs",
                    "parameters apart (relative)",
                    "losses apart",
                    "converged, auto / lbfgs",
                ],
                rows,
            ),
            "",
        ]
    )
    write_report(os.path.join(HERE, "fit_first_calls.md"), text)


if __name__ == "__main__":
    main()
