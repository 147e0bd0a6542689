"""Calibration: time per fit, iterations and accuracy, against scipy, in a batch, and the first fit.

Problems: the seed paper's parameter sets (m = 1 kg) for law 14 (`hertz_rate`), Kelvin-Voigt and
Hunt-Crossley, fitted to e and T at one speed (2.5 m/s) and at five speeds (0.5 ... 10 m/s),
targets from the scipy reference integrator (tests/reference.py, DOP853 at rtol 1e-13). Each
problem is solved from two starts: every free parameter 10 times too large (`init="given"`),
and the nondimensional-table start (`init="auto"`, the default), by

- `jaximpact.calibrate` with `optimizer="lbfgs"` (optax L-BFGS, the default) and `"lm"`
  (optimistix Levenberg-Marquardt): time per fit after compilation (the public call, Python
  overhead included; median of several rounds), iterations, largest relative parameter error;
- `scipy.optimize.least_squares` (trust-region reflective, finite-difference Jacobian) over
  `scipy.integrate.solve_ivp` (DOP853 with a terminal event), on the same residuals in the same
  log-parameters from the same start, at the loosest rtol whose e and T are as accurate as
  jaximpact's default solve (rtol 1e-10) on that problem; same run, same machine.

Then a batch of fits under `jax.vmap` (law 14, each body its own mass, stiffness, damping and
targets: `jax.jit(jax.vmap(lambda m, e, T: calibrate(start, m=m, v0=2.5, e=e, T=T)))`), and the
first fit's time in a fresh process (compilation included): through the library and through the
CLI, with a cold and a warm persistent compilation cache.

Run: `python benchmarks/calibrate.py` (about 20 minutes on the 2-core machine; `--quick` for
a short run, `--batch N` for the batch size, `--report` to rebuild calibrate.md from the JSON).
"""

import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tests"))

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # XLA's harmless "circular simplification" notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import jax.numpy as jnp  # noqa: E402
from _common import first_call, fmt, load_average, machine, machine_markdown, table, time_call  # noqa: E402
from reference import reference_impact  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402
from scipy.optimize import least_squares  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact._fit import calibrate as _calibrate  # noqa: E402
from jaximpact._fit.calibrate import _fit, _initial_law  # noqa: E402

M = 1.0
SPEEDS = (0.5, 1.0, 2.5, 5.0, 10.0)
TRUE = {
    "hertz_rate": dict(c=2e6, b1=800.0),
    "kelvin_voigt": dict(c=2e6, b=400.0),
    "hunt_crossley": dict(c=2e6, a=0.1),
}
FREE = {"hertz_rate": ("c", "b1"), "kelvin_voigt": ("c", "b"), "hunt_crossley": ("c", "a")}
PROBLEMS = [
    ("hertz_rate", (2.5,)),
    ("kelvin_voigt", (2.5,)),
    ("hunt_crossley", (2.5,)),
    ("hertz_rate", SPEEDS),
    ("hunt_crossley", SPEEDS),
]
SCIPY_RTOLS = (1e-8, 3e-9, 1e-9, 3e-10, 1e-10, 3e-11, 1e-11, 3e-12, 1e-12)
JSON = os.path.join(HERE, "calibrate.json")
REPORT = os.path.join(HERE, "calibrate.md")
LOADS = []


def note_load():
    LOADS.append(load_average())


# ------------------------------------------------------------------ scipy side


def scipy_impact(name, params, v0, rtol):
    """(e, T, nfev) of one impact by DOP853 with a terminal separation event (force
    criterion), in (x, v) with absolute tolerances scaled by the contact's own x* and v0."""
    c = params["c"]
    if name == "hunt_crossley":
        n, p, b = 1.5, 1.5, 1.5 * params["a"] * c
    elif name == "kelvin_voigt":
        n, p, b = 1.0, 0.0, params["b"]
    else:
        n, p, b = 1.5, 0.5, params["b1"]
    x_star = (M * v0**2 / c) ** (1 / (n + 1))

    def pos(x, q):
        return x if q == 1 else (1.0 if q == 0 else max(x, 0.0) ** q)

    def rhs(t, y):
        x, v = y
        return [v, -(c * pos(x, n) + b * pos(x, p) * v) / M]

    if n == p:  # Hunt-Crossley: the force vanishes at x = 0 only

        def event(t, y):
            return y[0] / x_star

    elif p == 0:  # the force itself crosses zero

        def event(t, y):
            return (c * pos(y[0], n) + b * y[1]) / (c * x_star**n)

    else:  # F = x^p (c x^(n-p) + b v): the first zero of x or of the bracket

        def event(t, y):
            return min(y[0] / x_star, (c * pos(y[0], n - p) + b * y[1]) / (c * x_star ** (n - p)))

    event.terminal, event.direction = True, -1
    atol = rtol * np.array([x_star, v0])
    sol = solve_ivp(
        rhs,
        (0.0, 1e3 * x_star / v0),
        [0.0, v0],
        method="DOP853",
        rtol=rtol,
        atol=atol,
        events=[event],
    )
    if not sol.t_events[0].size:
        return math.nan, math.nan, sol.nfev
    return -sol.y_events[0][0][1] / v0, sol.t_events[0][0], sol.nfev


def scipy_fit(name, start, speeds, e, T, rtol, method):
    """least_squares (`method` "trf" or "lm", MINPACK) over scipy_impact on calibrate's
    residuals, in log-parameters."""
    free = FREE[name]
    counts = dict(solves=0)

    def residuals(theta):
        params = dict(start)
        params.update({k: math.exp(t) for k, t in zip(free, theta, strict=True)})
        r_e, r_T = [], []
        for v, e_t, T_t in zip(speeds, e, T, strict=True):
            e_f, T_f, _ = scipy_impact(name, params, v, rtol)
            counts["solves"] += 1
            r_e.append(e_f - e_t)
            r_T.append((T_f - T_t) / T_t)
        return np.array(r_e + r_T)

    theta0 = np.log([start[k] for k in free])
    t0 = time.perf_counter()
    sol = least_squares(
        residuals,
        theta0,
        method=method,
        diff_step=2e-6,
        xtol=1e-12,
        ftol=1e-12,
        gtol=1e-12,
        max_nfev=500,
    )
    seconds = time.perf_counter() - t0
    params = {k: math.exp(t) for k, t in zip(free, sol.x, strict=True)}
    return dict(
        method=method,
        seconds=seconds,
        nfev=int(sol.nfev),
        njev=int(sol.njev or 0),
        solves=counts["solves"],
        params=params,
        max_residual=float(np.max(np.abs(sol.fun))),
        status=int(sol.status),
    )


def scipy_rtol_for(name, speeds, jax_error):
    """The loosest DOP853 rtol whose e and T error (against tests/reference at 1e-13) is at
    most jaximpact's at its default rtol 1e-10, on this problem's speeds."""
    for rtol in SCIPY_RTOLS:
        worst = 0.0
        for v in speeds:
            ref = reference_impact(name, TRUE[name], m=M, v0=v, rtol=1e-13)
            e, T, _ = scipy_impact(name, TRUE[name], v, rtol)
            worst = max(worst, abs(e / ref["e"] - 1), abs(T / ref["T"] - 1))
        if worst <= jax_error:
            return rtol, worst
    return SCIPY_RTOLS[-1], worst


# ------------------------------------------------------------------ problems


def targets(name, speeds):
    rows = [reference_impact(name, TRUE[name], m=M, v0=v, rtol=1e-13) for v in speeds]
    return np.array([r["e"] for r in rows]), np.array([r["T"] for r in rows])


def jax_solve_error(name, speeds, e, T):
    """jaximpact's default solve (as calibrate runs it: Tsit5, rtol 1e-10, one phase) at the
    true parameters, against the reference."""
    law = ji.law(name, **TRUE[name])
    worst = 0.0
    for v, e_t, T_t in zip(speeds, e, T, strict=True):
        r = ji.impact(law, m=M, v0=v, method="integrate", peaks=False)
        worst = max(worst, abs(float(r.e) / e_t - 1), abs(float(r.T) / T_t - 1))
    return worst


def compiled_arguments(fit):
    """The arguments `calibrate` passes to its compiled core `_fit` (after its checks and
    the table start), to time the core alone."""
    captured = []

    def capture(*args):
        captured.append(args)
        return _fit(*args)

    _calibrate._fit = capture
    try:
        fit()
    finally:
        _calibrate._fit = _fit
    return captured[0]


def param_error(params, name):
    return max(abs(float(params[k]) / TRUE[name][k] - 1) for k in FREE[name])


def run_problems(quick):
    results = []
    problems = PROBLEMS[:1] + PROBLEMS[3:4] if quick else PROBLEMS
    for name, speeds in problems:
        note_load()
        e, T = targets(name, speeds)
        jax_error = jax_solve_error(name, speeds, e, T)
        rtol, scipy_error = scipy_rtol_for(name, speeds, jax_error)
        far = {k: v * 10.0 for k, v in TRUE[name].items()}
        table_start = _initial_law(
            ji.law(name, **far),
            FREE[name],
            m=jnp.asarray(M),
            v0=jnp.asarray(speeds),
            e=jnp.asarray(e),
            T=jnp.asarray(T),
            separation="force",
        )
        table_start = {k: float(v) for k, v in table_start.parameters.items()}
        label = f"{name}, {len(speeds)} speed{'s' if len(speeds) > 1 else ''}"
        print(
            f"{label}: jaximpact solve error {jax_error:.1e}; scipy rtol {rtol:g} "
            f"({scipy_error:.1e})",
            flush=True,
        )
        for start_name, start, init in (("x10", far, "given"), ("table", table_start, "auto")):
            row = dict(
                problem=label,
                law=name,
                speeds=len(speeds),
                start=start_name,
                jax_solve_error=jax_error,
                scipy_rtol=rtol,
                scipy_solve_error=scipy_error,
            )
            for optimizer in ("lbfgs", "lm"):
                law = ji.law(name, **start)
                fit_kwargs = dict(m=M, v0=np.asarray(speeds), e=e, T=T, free=FREE[name])

                def fit(law=law, kwargs=fit_kwargs, init=init, optimizer=optimizer):
                    return ji.calibrate(law, init=init, optimizer=optimizer, **kwargs)

                compile_s, out = first_call(fit)
                median, best = time_call(fit, rounds=7, max_total_s=10.0)
                core = time_call(_fit, *compiled_arguments(fit), rounds=7, max_total_s=5.0)[0]
                row[optimizer] = dict(
                    core=core,
                    seconds=median,
                    best=best,
                    compile_s=compile_s,
                    iterations=int(out.iterations),
                    converged=bool(out.converged),
                    param_error=param_error(out.params, name),
                    loss=float(out.loss),
                )
                print(
                    f"  {start_name:5s} {optimizer:5s} {1e3 * median:8.2f} ms "
                    f"({int(out.iterations)} it, err {row[optimizer]['param_error']:.1e}, "
                    f"compile {compile_s:.1f} s)",
                    flush=True,
                )
            runs = [
                scipy_fit(name, start, speeds, e, T, rtol, method)
                for method in ("trf", "lm")
                for _ in range(2)
            ]
            best_run = min(runs, key=lambda r: r["seconds"])
            best_run["param_error"] = param_error(best_run["params"], name)
            row["scipy"] = best_run
            print(
                f"  {start_name:5s} scipy {best_run['method']} "
                f"{1e3 * best_run['seconds']:8.1f} ms "
                f"({best_run['nfev']} nfev + {best_run['njev']} njev, {best_run['solves']} "
                f"solves, err {best_run['param_error']:.1e})",
                flush=True,
            )
            results.append(row)
    return results


# ------------------------------------------------------------------ batch


def run_batch(n, chunk):
    """`n` bodies of law 14 (mass 0.2-5 kg, c and b1 within a factor 3 of the paper's),
    their e and T from jaximpact at rtol 1e-12, fitted under jax.vmap."""
    note_load()
    rng = np.random.default_rng(0)
    masses = np.exp(rng.uniform(np.log(0.2), np.log(5.0), n))
    cs = 2e6 * np.exp(rng.uniform(-math.log(3), math.log(3), n))
    b1s = 800.0 * np.exp(rng.uniform(-math.log(3), math.log(3), n))

    @jax.jit
    @jax.vmap
    def simulate(m, c, b1):
        r = ji.impact(ji.law("hertz_rate", c=c, b1=b1), m=m, v0=2.5, rtol=1e-12, peaks=False)
        return r.e, r.T

    es, Ts = jax.block_until_ready(simulate(masses, cs, b1s))
    start = ji.law("hertz_rate", c=1e6, b1=100.0)
    out = {}
    for optimizer in ("lbfgs", "lm"):

        def one(m, e, T, optimizer=optimizer):
            return ji.calibrate(start, m=m, v0=2.5, e=e, T=T, optimizer=optimizer)

        batch = jax.jit(jax.vmap(one))
        compile_s, fits = first_call(batch, masses[:chunk], es[:chunk], Ts[:chunk])
        note_load()
        t0 = time.perf_counter()
        parts = []
        for i in range(0, n, chunk):
            parts.append(
                jax.block_until_ready(
                    batch(masses[i : i + chunk], es[i : i + chunk], Ts[i : i + chunk])
                )
            )
        seconds = time.perf_counter() - t0
        c_fit = np.concatenate([np.asarray(p.params["c"]) for p in parts])
        b_fit = np.concatenate([np.asarray(p.params["b1"]) for p in parts])
        converged = np.concatenate([np.asarray(p.converged) for p in parts])
        iterations = np.concatenate([np.asarray(p.iterations) for p in parts])
        err = np.maximum(np.abs(c_fit / cs - 1), np.abs(b_fit / b1s - 1))
        out[optimizer] = dict(
            n=n,
            chunk=chunk,
            seconds=seconds,
            per_fit=seconds / n,
            compile_s=compile_s,
            converged=float(np.mean(converged)),
            max_param_error=float(np.max(err)),
            median_iterations=float(np.median(iterations)),
            max_iterations=int(iterations.max()),
        )
        print(
            f"batch {optimizer}: {n} fits in {seconds:.1f} s ({1e3 * seconds / n:.2f} ms/fit), "
            f"compile {compile_s:.1f} s, converged {np.mean(converged):.4f}, "
            f"max param err {np.max(err):.1e}",
            flush=True,
        )
    return out


# ------------------------------------------------------------------ first fit


LIBRARY_FIRST_FIT = """
import time
t0 = time.perf_counter()
import jax
jax.config.update("jax_enable_x64", True)
import jaximpact as ji
t1 = time.perf_counter()
fit = ji.calibrate(ji.law("hertz_rate", c=1e6, b1=100.0), m=1.0, v0=2.5, e=0.85, T=7.8e-3,
                   optimizer="{optimizer}")
jax.block_until_ready(fit)
t2 = time.perf_counter()
fit = ji.calibrate(ji.law("hertz_rate", c=1e6, b1=100.0), m=1.0, v0=2.5, e=0.85, T=7.8e-3,
                   optimizer="{optimizer}")
jax.block_until_ready(fit)
t3 = time.perf_counter()
print(t1 - t0, t2 - t1, t3 - t2)
"""

CLI = ["calibrate", "--law", "hertz_rate", "--mass", "1", "--v0", "2.5", "--e", "0.85"]
CLI += ["--T", "7.8e-3"]


def run_first_fits():
    env = dict(os.environ, TF_CPP_MIN_LOG_LEVEL="3")
    out = {}
    for optimizer in ("lbfgs", "lm"):
        note_load()
        done = subprocess.run(
            [sys.executable, "-c", LIBRARY_FIRST_FIT.replace("{optimizer}", optimizer)],
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
        imports, first, second = map(float, done.stdout.split())
        out[f"library {optimizer}"] = dict(imports=imports, first=first, second=second)
        print(
            f"library {optimizer}: import {imports:.1f} s, first fit {first:.1f} s, "
            f"second {1e3 * second:.1f} ms",
            flush=True,
        )
    script = os.path.join(os.path.dirname(sys.executable), "jaximpact")
    command = [script] if os.path.exists(script) else [sys.executable, "-m", "jaximpact._cli"]
    for label, extra in (("CLI", {}), ("CLI, EQX_ON_ERROR=nan", {"EQX_ON_ERROR": "nan"})):
        with tempfile.TemporaryDirectory() as cache:
            for state in ("cold", "warm"):
                note_load()
                t0 = time.perf_counter()
                subprocess.run(
                    command + CLI,
                    capture_output=True,
                    text=True,
                    check=True,
                    env=dict(env, JAXIMPACT_CACHE_DIR=cache, **extra),
                )
                seconds = time.perf_counter() - t0
                out[f"{label}, {state} cache"] = dict(wall=seconds)
                print(f"{label}, {state} cache: {seconds:.1f} s", flush=True)
    return out


# ------------------------------------------------------------------ report


def ms(seconds):
    return f"{1e3 * seconds:.3g}"


def report(results):
    p = results["problems"]
    lines = [
        "# Calibration: time per fit, against scipy, in a batch, and the first fit",
        "",
        "Generated by `python benchmarks/calibrate.py` (data in `calibrate.json`). m = 1 kg, "
        "the seed paper's parameter sets (law 14: c = 2e6, b1 = 800; Kelvin-Voigt: c = 2e6, "
        "b = 400; Hunt-Crossley: c = 2e6, a = 0.1), force criterion, targets e and T from the "
        "scipy reference (DOP853, rtol 1e-13) at 2.5 m/s or at 0.5, 1, 2.5, 5, 10 m/s. Both "
        "free parameters fitted (c and the damping). Times are per fit after compilation, "
        "median of several rounds, through the public `calibrate` call (Python overhead "
        "included; in brackets the compiled core `_fit` alone, without `calibrate`'s checks, "
        "conversions and table start, which run eagerly); compile times apart.",
        "",
        machine_markdown(results["machine"], results["loads"]),
        "",
        "The machine is shared: other sessions' jobs kept the load average well above its two "
        "cores during the run, so every absolute time here is pessimistic (by about 2-4x, "
        "judging from the same calls on a quieter machine) and ratios measured in the same "
        "minute are the reliable part.",
        "",
        "## Time per fit: jaximpact against scipy",
        "",
        '`x10`: every free parameter 10 times too large, `init="given"`; `table`: the '
        'nondimensional-table start (`init="auto"`, the default), given to scipy too. '
        "err = largest relative error of the fitted parameters. scipy: `least_squares` "
        "(the faster of trf and MINPACK lm, 2-point Jacobian, `diff_step=2e-6`, tolerances "
        "1e-12; nfev + njev: residual evaluations for steps and for Jacobians, solves: "
        "impact solves in all) over `solve_ivp` DOP853 "
        "with a terminal event, at the loosest rtol as accurate as jaximpact's solve "
        "(column `scipy rtol`: rtol, and its e/T error against the 1e-13 reference; "
        "jaximpact's is in `jax solve err`). Ratio = scipy time / jaximpact time, "
        "for the faster jaximpact optimizer and for L-BFGS (the default).",
        "",
    ]
    header = [
        "problem",
        "start",
        "L-BFGS ms (core)",
        "it",
        "err",
        "LM ms (core)",
        "it",
        "err",
        "scipy ms",
        "nfev+njev (solves)",
        "err",
        "jax solve err",
        "scipy rtol",
        "ratio best",
        "ratio L-BFGS",
    ]
    rows = []
    for r in p:
        lb, lm, sp = r["lbfgs"], r["lm"], r["scipy"]
        best = min(lb["seconds"], lm["seconds"])
        rows.append(
            [
                r["problem"],
                r["start"],
                f"{ms(lb['seconds'])} ({ms(lb['core'])})",
                lb["iterations"],
                fmt(lb["param_error"]),
                f"{ms(lm['seconds'])} ({ms(lm['core'])})",
                lm["iterations"],
                fmt(lm["param_error"]),
                f"{ms(sp['seconds'])} ({sp['method']})",
                f"{sp['nfev']}+{sp['njev']} ({sp['solves']})",
                fmt(sp["param_error"]),
                fmt(r["jax_solve_error"]),
                f"{r['scipy_rtol']:g} ({fmt(r['scipy_solve_error'])})",
                f"**{sp['seconds'] / best:.0f}x**",
                f"{sp['seconds'] / lb['seconds']:.0f}x",
            ]
        )
    lines.append(table(header, rows))
    lines += [
        "",
        "Compile time of each configuration (first call, s): "
        + "; ".join(
            f"{r['problem']} {r['start']}: L-BFGS {r['lbfgs']['compile_s']:.0f}, "
            f"LM {r['lm']['compile_s']:.0f}"
            for r in p
            if r["start"] == "x10"
        )
        + " (the table start reuses the compiled fit).",
        "",
    ]
    if "batch" in results:
        b = results["batch"]
        lines += [
            "## A batch of fits under `jax.vmap`",
            "",
            "Law 14 at 2.5 m/s, each body its own mass (0.2-5 kg), c and b1 (within a factor 3 "
            "of the paper's) and targets (jaximpact at rtol 1e-12), started from "
            'c = 1e6, b1 = 100 with `init="auto"`:',
            "",
            "```python",
            "fits = jax.jit(jax.vmap(lambda m, e, T: ji.calibrate(start, m=m, v0=2.5, e=e, T=T)))",
            "batch = fits(masses, es, Ts)   # one Fit, every field with a leading batch axis",
            "```",
            "",
        ]
        header = [
            "optimizer",
            "fits",
            "chunk",
            "total s",
            "ms / fit",
            "compile s",
            "converged",
            "max param err",
            "iterations (median, max)",
        ]
        rows = [
            [
                name,
                v["n"],
                v["chunk"],
                f"{v['seconds']:.1f}",
                f"{1e3 * v['per_fit']:.2f}",
                f"{v['compile_s']:.0f}",
                f"{100 * v['converged']:.2f}%",
                fmt(v["max_param_error"]),
                f"{v['median_iterations']:.0f}, {v['max_iterations']}",
            ]
            for name, v in b.items()
        ]
        lines += [table(header, rows), ""]
    if "first" in results:
        f = results["first"]
        lines += [
            "## The first fit, compilation included",
            "",
            "A fresh process fitting law 14 to e = 0.85, T = 7.8 ms (the README's example). "
            "Library: `import jaximpact` then two `calibrate` calls. CLI: the wall time of "
            "`jaximpact calibrate --law hertz_rate --mass 1 --v0 2.5 --e 0.85 --T 7.8e-3`, "
            "first with an empty persistent compilation cache (cold), then again (warm).",
            "",
        ]
        rows = []
        for label, v in f.items():
            if "imports" in v:
                rows.append(
                    [
                        label,
                        f"{v['imports']:.1f}",
                        f"{v['first']:.1f}",
                        f"{1e3 * v['second']:.1f} ms",
                    ]
                )
            else:
                rows.append([label, "-", f"{v['wall']:.1f} (whole command)", "-"])
        lines += [table(["run", "import s", "first fit s", "second fit"], rows), ""]
    lines += ["## Reading", "", results.get("reading", "").strip(), ""]
    return "\n".join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two problems, batch of 1000")
    parser.add_argument("--batch", type=int, default=10_000, help="fits in the vmap batch")
    parser.add_argument("--chunk", type=int, default=10_000, help="fits per vmapped call")
    parser.add_argument("--no-first", action="store_true", help="skip the fresh-process runs")
    parser.add_argument("--report", action="store_true", help="rebuild the report from JSON")
    args = parser.parse_args()
    if args.report:
        with open(JSON) as f:
            results = json.load(f)
    else:
        results = dict(machine=machine())
        results["problems"] = run_problems(args.quick)
        n = 1000 if args.quick else args.batch
        results["batch"] = run_batch(n, min(args.chunk, n))
        if not args.no_first:
            results["first"] = run_first_fits()
        note_load()
        results["loads"] = LOADS
        if os.path.exists(JSON):  # keep the reading written by hand
            with open(JSON) as f:
                results["reading"] = json.load(f).get("reading", "")
        with open(JSON, "w") as f:
            json.dump(results, f, indent=1)
    with open(REPORT, "w") as f:
        f.write(report(results))
    print(f"written {REPORT}")


if __name__ == "__main__":
    main()
