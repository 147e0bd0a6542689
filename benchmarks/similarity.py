"""The similarity path (universal curves) against the integrated path and scipy.

For each law at the seed paper's conditions (m = 1 kg, v0 = 2.5 m/s, force criterion):
the error in e and T of `impact` on the curves and integrated (both at their defaults)
against the reference (closed form, or scipy DOP853 at rtol 1e-13), the time of one jitted
impact and per impact in a vmapped batch, and scipy DOP853 at the loosest rtol whose error
in e is at most 1e-9, timed alternately in the same process (`jaximpact._bench`). Then
`calibrate` from (e, T) at one speed after its first call against scipy's least_squares
over solve_ivp (benchmarks/calibrate.py's), and cold-process times: a bare JAX process,
`import jaximpact` plus one impact, a cold `jaximpact simulate`, the README's main job.

Run: `python benchmarks/similarity.py` (about five minutes; `--quick` for a smoke run).
"""

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
import numpy as np  # noqa: E402
from _common import fmt, load_average, machine, machine_markdown, table, write_report  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import _bench  # noqa: E402

CASES = {
    "hertz_rate": dict(c=2e6, b1=800.0),
    "hunt_crossley": dict(c=2e6, a=0.1),
    "hertz_viscous": dict(c=2e6, b=40.0),
}
M, V0 = _bench.M, _bench.V0
REPORT = os.path.join(HERE, "similarity.md")


def solve_function(name, method):
    def solve(params, v0):
        r = ji.impact(ji.law(name, **params), m=M, v0=v0, method=method)
        return r.e, r.T

    return solve


def measure_case(name, params, *, batch, rounds, min_round_s):
    ref = _bench.reference(name, params)
    args = ({k: jnp.asarray(v) for k, v in params.items()}, jnp.asarray(V0))
    speeds = V0 * np.exp(np.random.default_rng(0).uniform(np.log(0.8), np.log(1.25), batch))
    speeds[0] = V0
    rtol, scipy_err, scipy_fn = _bench.loosest_scipy(name, params, e_ref=ref["e"])
    rows = []
    for method, size in (("similarity", batch), ("integrate", min(batch, 1000))):
        solve = solve_function(name, method)
        single = jax.jit(solve)
        compile_s, (e, T) = _bench.first_call(single, *args)
        batched = jax.jit(jax.vmap(solve, in_axes=(None, 0)))
        bargs = (args[0], jnp.asarray(speeds[:size]))
        _bench.first_call(batched, *bargs)
        times = dict(single=[], batch=[], scipy=[])
        for _ in range(rounds):
            times["scipy"].append(_bench.seconds_per_call(scipy_fn, min_round_s=min_round_s))
            times["single"].append(_bench.seconds_per_call(single, *args, min_round_s=min_round_s))
            times["batch"].append(
                _bench.seconds_per_call(batched, *bargs, min_round_s=min_round_s) / size
            )
        median = {k: statistics.median(v) for k, v in times.items()}
        ratios_single = [s / t for s, t in zip(times["scipy"], times["single"], strict=True)]
        ratios_batch = [s / t for s, t in zip(times["scipy"], times["batch"], strict=True)]
        rows.append(
            dict(
                law=name,
                path=ji.impact(ji.law(name, **params), m=M, v0=V0, method=method).path,
                err_e=_bench.relative_error(e, ref["e"]),
                err_T=_bench.relative_error(T, ref["T"]),
                reference=ref["source"],
                single_s=median["single"],
                batch_s=median["batch"],
                batch_size=size,
                compile_s=compile_s,
                scipy_s=median["scipy"],
                scipy_rtol=rtol,
                scipy_err_e=scipy_err,
                ratio_single=statistics.median(ratios_single),
                ratio_batch=statistics.median(ratios_batch),
            )
        )
        print(rows[-1], flush=True)
    return rows


def measure_calibrate(rounds):
    """`calibrate` of law 14 from (e, T) at 2.5 m/s, after its first call, on the curves and
    integrated, against scipy least_squares (trf) over solve_ivp DOP853 at rtol 1e-10."""
    from calibrate import scipy_fit

    truth = dict(c=2e6, b1=800.0)
    ref = _bench.reference("hertz_rate", truth)
    start = ji.law("hertz_rate", c=1e6, b1=100.0)
    rows = []
    scipy_times = []
    for _ in range(rounds):
        out = scipy_fit(
            "hertz_rate", dict(c=1e6, b1=100.0), (V0,), [ref["e"]], [ref["T"]], 1e-10, "trf"
        )
        scipy_times.append(out["seconds"])
    scipy_s = statistics.median(scipy_times)
    for method in ("similarity", "integrate"):

        def run(method=method):
            return ji.calibrate(start, m=M, v0=V0, e=ref["e"], T=ref["T"], method=method)

        first_s, fit = _bench.first_call(run)
        seconds, _ = _bench.time_call(run, rounds=max(rounds, 3), min_round_s=0.05, max_total_s=10)
        err = max(abs(float(fit.params[k]) / truth[k] - 1) for k in truth)
        rows.append(
            dict(
                method=method,
                first_s=first_s,
                seconds=seconds,
                iterations=int(fit.iterations),
                param_err=err,
                scipy_s=scipy_s,
                scipy_params_err=max(abs(out["params"][k] / truth[k] - 1) for k in truth),
                ratio=scipy_s / seconds,
            )
        )
        print(rows[-1], flush=True)
    return rows


def _wall(command, env=None, repeats=3):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        subprocess.run(command, env=env, check=True, capture_output=True, cwd=ROOT)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def measure_cold(repeats):
    """Wall seconds of fresh processes: cold = an empty compilation cache each run."""
    python = sys.executable
    bare = [python, "-c", "import jax; jax.numpy.ones(3).block_until_ready()"]
    one = [
        python,
        "-c",
        "import jax; jax.config.update('jax_enable_x64', True); import jaximpact as ji; "
        "ji.impact(ji.law('hertz_rate', c=2e6, b1=800.0), m=1.0, v0=2.5).e.block_until_ready()",
    ]
    cli = [
        python,
        "-m",
        "jaximpact._cli",
        "simulate",
        "--law",
        "hertz_rate",
        "--param",
        "c=2e6",
        "b1=800",
        "--v0",
        "2.5",
        "--mass",
        "1",
    ]
    main_job = [
        python,
        "examples/calibrate_e_and_T.py",
        "--plot",
        os.path.join(tempfile.gettempdir(), "similarity_bench.png"),
    ]
    rows = []
    for label, command in (
        ("bare JAX process, one array", bare),
        ("import jaximpact, one impact (curves)", one),
        ("jaximpact simulate (curves)", cli),
        ("README main job (examples/calibrate_e_and_T.py)", main_job),
    ):
        for cache in ("cold", "warm"):
            with tempfile.TemporaryDirectory() as directory:
                env = {**os.environ, "JAXIMPACT_CACHE_DIR": directory if cache == "warm" else ""}
                if cache == "warm":
                    subprocess.run(command, env=env, check=True, capture_output=True, cwd=ROOT)
                seconds = _wall(command, env=env, repeats=repeats)
            rows.append(dict(process=label, cache=cache, seconds=seconds))
            print(rows[-1], flush=True)
    return rows


def report(info, loads, cases, fits, cold):
    bare = {r["cache"]: r["seconds"] for r in cold if r["process"].startswith("bare")}
    lines = [
        "# Similarity path: universal curves against integration and scipy",
        "",
        "Written by `python benchmarks/similarity.py`. Seed-paper conditions (m = 1 kg, "
        "v0 = 2.5 m/s, force criterion). Errors against the reference column; scipy is DOP853 "
        "at the loosest rtol whose error in e is at most 1e-9, timed alternately with jaximpact "
        "in the same process (ratios are medians of per-round ratios).",
        "",
        table(
            [
                "law",
                "path",
                "error in e",
                "error in T",
                "one impact",
                "per impact in a batch",
                "scipy",
                "ratio single",
                "ratio batch",
                "first call",
                "reference",
            ],
            [
                [
                    r["law"],
                    r["path"],
                    fmt(r["err_e"]),
                    fmt(r["err_T"]),
                    f"{r['single_s'] * 1e6:.3g} µs",
                    f"{r['batch_s'] * 1e9:.3g} ns (of {r['batch_size']})",
                    f"{r['scipy_s'] * 1e3:.3g} ms (rtol {fmt(r['scipy_rtol'])})",
                    f"{r['ratio_single']:.0f}x",
                    f"{r['ratio_batch']:.0f}x",
                    f"{r['compile_s']:.2f} s",
                    r["reference"],
                ]
                for r in cases
            ],
        ),
        "",
        "Targets (issue 13): one impact at least 300x scipy, a vmapped batch at least 10,000x per "
        "impact, both at an error of at most 1e-9.",
        "",
        "## calibrate from (e, T) at one speed, after its first call",
        "",
        table(
            [
                "method",
                "time per fit",
                "first call",
                "iterations",
                "largest parameter error",
                "scipy least_squares (trf) over solve_ivp",
                "ratio",
            ],
            [
                [
                    r["method"],
                    f"{r['seconds'] * 1e3:.3g} ms",
                    f"{r['first_s']:.2f} s",
                    r["iterations"],
                    fmt(r["param_err"]),
                    f"{r['scipy_s'] * 1e3:.3g} ms (error {fmt(r['scipy_params_err'])})",
                    f"{r['ratio']:.0f}x",
                ]
                for r in fits
            ],
        ),
        "",
        "Target: at least 1000x scipy.",
        "",
        "## Fresh processes (wall time, median of repeats)",
        "",
        "cold: no persistent compilation cache (`JAXIMPACT_CACHE_DIR=`); warm: the cache filled "
        "by one earlier run.",
        "",
        table(
            ["process", "cache", "seconds", "more than the bare JAX process"],
            [
                [
                    r["process"],
                    r["cache"],
                    f"{r['seconds']:.2f}",
                    f"{r['seconds'] - bare[r['cache']]:+.2f}",
                ]
                for r in cold
            ],
        ),
        "",
        "Targets: one impact in a fresh process at most 1 s more than the bare JAX process, a "
        "cold `jaximpact simulate` at most 1.5 s more, the README's main job under 5 s.",
        "",
        "## Machine",
        "",
        machine_markdown(info, loads),
        "",
    ]
    write_report(REPORT, "\n".join(lines))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small batches, few rounds")
    args = parser.parse_args()
    batch, rounds, min_round = (2000, 2, 0.02) if args.quick else (100_000, 5, 0.1)
    info = machine()
    loads = [load_average()]
    cases = []
    for name, params in CASES.items():
        cases += measure_case(name, params, batch=batch, rounds=rounds, min_round_s=min_round)
        loads.append(load_average())
    fits = measure_calibrate(rounds)
    loads.append(load_average())
    cold = measure_cold(1 if args.quick else 3)
    loads.append(load_average())
    report(info, loads, cases, fits, cold)


if __name__ == "__main__":
    main()
