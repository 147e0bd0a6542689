"""Work against precision: error in e and T against the time per impact.

For five laws at the seed paper's parameters (m = 1 kg, v0 = 2.5 m/s, force criterion):
Kelvin-Voigt and Maxwell (closed-form references), Hertz with linear damping (eq. 12) and
the paper's law 14 (scipy DOP853 at rtol 1e-13), Hunt-Crossley (e from its closed form, T
from scipy at 1e-13). Compared:

- jaximpact (`impact(..., method="integrate")`), diffrax Tsit5, Dopri5, Dopri8 and the
  implicit Kvaerno5 at rtol 1e-6 ... 1e-13, with `peaks=True` (the default: three phases,
  x_max and F_max found) and `peaks=False` (one phase: e and T only), as one jitted impact
  and per impact in a `jax.vmap`-ed batch of 1000 (100 for Kvaerno5);
- jaximpact's closed-form fast path (Kelvin-Voigt, the default there) and its default call;
- scipy `solve_ivp` (RK45, DOP853, LSODA, Radau) with a terminal event, half-decade rtols;
- the seed paper's explicit Euler at fixed steps (2e-5 s is the paper's), jitted in JAX.

Derivative costs (`jax.jacfwd`, `jax.jacrev` of (e, T) with respect to the law's parameters)
at the default tolerance are measured too. Timings are medians of several rounds after
compilation; compile times are separate. Results go to benchmarks/work_precision.json, the
report to benchmarks/work_precision.md and the plot to docs/work_precision.png.

Run: `python benchmarks/work_precision.py` (about an hour on 2 cores; `--quick` for a short
run; `--report` to rebuild the report from the JSON; `--laws`, `--solvers` to restrict).
"""

import argparse
import json
import math
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(ROOT, "tests"))

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")  # XLA's harmless "circular simplification" notes

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import diffrax as dfx  # noqa: E402
import jax.numpy as jnp  # noqa: E402
from _common import (  # noqa: E402
    PAPER_CASES,
    first_call,
    fmt,
    load_average,
    machine,
    machine_markdown,
    table,
    time_call,
    us,
)
from scipy.integrate import solve_ivp  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact import closed_forms  # noqa: E402
from jaximpact._bench import scipy_problem, scipy_solver  # noqa: E402, F401

M, V0 = 1.0, 2.5
CASES = PAPER_CASES
DAMPING = {
    "kelvin_voigt": "b",
    "maxwell": "b",
    "hertz_viscous": "b",
    "hertz_rate": "b1",
    "hunt_crossley": "a",
}
# (n, p) of F = c x^n + b x^p v (Hunt-Crossley: b = 1.5 a c, p = n)
FAMILY = {"kelvin_voigt": (1, 0), "hertz_viscous": (1.5, 0), "hertz_rate": (1.5, 0.5)}
SOLVERS = {
    "Tsit5": dfx.Tsit5,
    "Dopri5": dfx.Dopri5,
    "Dopri8": dfx.Dopri8,
    "Kvaerno5": dfx.Kvaerno5,
}
RTOLS = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13]
# Dopri5 tracks Tsit5 closely and Kvaerno5 is slow: a sparser grid for those
SPARSE_RTOLS = {"Dopri5": [1e-6, 1e-8, 1e-10, 1e-12, 1e-13], "Kvaerno5": [1e-6, 1e-8, 1e-10, 1e-12]}
SCIPY_METHODS = ["RK45", "DOP853", "LSODA", "Radau"]
SCIPY_RTOLS = [10.0 ** (-k / 2) for k in range(12, 27)]  # 1e-6 ... 1e-13, half decades
EULER_DTS = [1e-4, 5e-5, 2e-5, 1e-5, 5e-6, 2e-6, 1e-6, 5e-7, 2e-7, 1e-7]
BATCH = 1000
BATCH_IMPLICIT = 100
DEFAULT = dict(solver="Tsit5", rtol=1e-10, peaks=True)  # jaximpact.impact's defaults
TARGET_ERROR = 1e-9

JSON_PATH = os.path.join(HERE, "work_precision.json")
MD_PATH = os.path.join(HERE, "work_precision.md")
PNG_PATH = os.path.join(ROOT, "docs", "work_precision.png")


# ------------------------------------------------------------------------ references


def _lienard_scipy(name, params, rtol=1e-13):
    """Second, independent reference: the nondimensional Lienard form (no x^0.5 in the
    right-hand side), scipy DOP853. Returns (e, T) or None where it does not apply."""
    if name == "maxwell" or name == "kelvin_voigt":
        return None
    c = params["c"]
    if name == "hunt_crossley":
        n, p, b = 1.5, 1.5, 1.5 * params["a"] * c
    else:
        n, p = FAMILY[name]
        b = params[DAMPING[name]]
    x_star = (M * V0**2 / c) ** (1 / (n + 1))
    beta = b * x_star ** (p + 1) / (M * V0)

    def pos(x, q):
        return max(x, 0.0) ** q

    def velocity(y):
        return y[1] - beta * pos(y[0], p + 1) / (p + 1)

    def rhs(t, y):
        return [velocity(y), -pos(y[0], n)]

    def gap(t, y):
        if name == "hunt_crossley":
            return y[0]
        if p == 0:
            return pos(y[0], n) + beta * velocity(y)
        return min(y[0], pos(y[0], n - p) + beta * velocity(y))

    gap.terminal, gap.direction = True, -1
    sol = solve_ivp(
        rhs, (0, 1e3), [0.0, 1.0], method="DOP853", rtol=rtol, atol=rtol * 1e-2, events=[gap]
    )
    tau, state = sol.t_events[0][0], sol.y_events[0][0]
    return -velocity(state), tau * x_star / V0


def reference(name, params):
    """Reference (e, T), a second independent value of each, and where they come from."""
    from reference import reference_impact

    scipy_ref = reference_impact(name, params, m=M, v0=V0, separation="force", rtol=1e-13)
    alt = _lienard_scipy(name, params)
    if name == "kelvin_voigt":
        cf = closed_forms.kelvin_voigt(params["c"], params["b"], M, V0, "force")
        return dict(
            e=float(cf["e"]),
            T=float(cf["T"]),
            e_alt=scipy_ref["e"],
            T_alt=scipy_ref["T"],
            source="closed form (alt: scipy DOP853 1e-13)",
        )
    if name == "maxwell":
        cf = closed_forms.maxwell(params["c"], params["b"], M, V0)
        return dict(
            e=float(cf["e"]),
            T=float(cf["T"]),
            e_alt=scipy_ref["e"],
            T_alt=scipy_ref["T"],
            source="closed form (alt: scipy DOP853 1e-13)",
        )
    if name == "hunt_crossley":
        e = float(closed_forms.hunt_crossley_restitution(1.5 * params["a"] * V0))
        return dict(
            e=e,
            T=scipy_ref["T"],
            e_alt=alt[0],
            T_alt=alt[1],
            source="e closed form, T scipy DOP853 1e-13 (alt: Lienard DOP853 1e-13)",
        )
    return dict(
        e=scipy_ref["e"],
        T=scipy_ref["T"],
        e_alt=alt[0],
        T_alt=alt[1],
        source="scipy DOP853 1e-13 (alt: Lienard DOP853 1e-13)",
    )


def rel(value, ref):
    value = float(value)
    if not math.isfinite(value):
        return float("nan")
    return abs(value - ref) / abs(ref)


# ------------------------------------------------------------------------ scipy


# `scipy_problem(name, params)` and `scipy_solver(name, params, method, rtol)`: the
# dimensional problem with its force event, as a scipy user writes it, shared with
# `jaximpact bench` (imported above; m = 1 kg and v0 = 2.5 m/s are its defaults, M and V0).


# ------------------------------------------------------------------------ Euler


def euler_function(name):
    """The seed paper's scheme (sect. 5): `x += v dt; v += -F(x, v)/m dt` at a fixed step,
    from first touch, stopped at the first step where the contact no longer pushes
    (x < 0, or v < 0 with F <= 0: the force criterion). No interpolation of the end."""

    def force(params, x, v, s):
        xp = jnp.maximum(x, 0.0)
        if name == "kelvin_voigt":
            return params["c"] * x + params["b"] * v
        if name == "maxwell":
            return s
        if name == "hertz_viscous":
            return params["c"] * xp**1.5 + params["b"] * v
        if name == "hertz_rate":
            return params["c"] * xp**1.5 + params["b1"] * jnp.sqrt(xp) * v
        return params["c"] * xp**1.5 * (1.0 + 1.5 * params["a"] * v)

    def run(params, dt):
        def ended(state):
            n, x, v, s = state
            f = force(params, x, v, s)
            return (n > 0) & ((x < 0) | ((v < 0) & (f <= 0)))

        def body(state):
            n, x, v, s = state
            f = force(params, x, v, s)
            s_new = s + params["c"] * (v - s / params["b"]) * dt if name == "maxwell" else s
            return n + 1, x + v * dt, v - f / M * dt, s_new

        state = (jnp.asarray(0), jnp.asarray(0.0), jnp.asarray(V0), jnp.asarray(0.0))
        n, x, v, s = jax.lax.while_loop(lambda st: ~ended(st) & (st[0] < 100_000_000), body, state)
        return -v / V0, n * dt, n

    return jax.jit(run)


# ------------------------------------------------------------------------ jaximpact


def impact_function(name, solver, rtol, peaks, max_steps, method="integrate"):
    def solve(params, m, v0):
        r = ji.impact(
            ji.law(name, **params),
            m=m,
            v0=v0,
            method=method,
            solver=solver,
            rtol=rtol,
            peaks=peaks,
            max_steps=max_steps,
        )
        return r.e, r.T, r.num_steps, r.status

    return solve


def batch_params(name, size, seed=0):
    """Member 0 is the nominal case; the others vary c and the damping by up to +-10%."""
    rng = np.random.default_rng(seed)
    params = {}
    for key, value in CASES[name].items():
        spread = np.exp(rng.uniform(np.log(0.9), np.log(1.1), size))
        spread[0] = 1.0
        params[key] = jnp.asarray(value * spread)
    return params


def scalar_params(name):
    return {k: jnp.asarray(v) for k, v in CASES[name].items()}


def measure_jaximpact(name, solver_name, rtol, peaks, ref, batch=True):
    solver = SOLVERS[solver_name]()
    implicit = solver_name == "Kvaerno5"
    max_steps = 65536 if implicit else 4096
    solve = impact_function(name, solver, rtol, peaks, max_steps)
    single = jax.jit(solve)
    args = (scalar_params(name), jnp.asarray(M), jnp.asarray(V0))
    compile_s, (e, T, steps, status) = first_call(single, *args)
    median, best = time_call(single, *args)
    row = dict(
        kind="jaximpact",
        law=name,
        solver=solver_name,
        rtol=rtol,
        peaks=peaks,
        err_e=rel(e, ref["e"]),
        err_T=rel(T, ref["T"]),
        steps=int(steps),
        status=int(status),
        single_s=median,
        single_min_s=best,
        compile_s=compile_s,
    )
    if batch:
        size = BATCH_IMPLICIT if implicit else BATCH
        batched = jax.jit(jax.vmap(solve, in_axes=(0, None, None)))
        bargs = (batch_params(name, size), jnp.asarray(M), jnp.asarray(V0))
        bcompile, (be, bT, bsteps, bstatus) = first_call(batched, *bargs)
        bmedian, bbest = time_call(batched, *bargs, rounds=5, max_total_s=30.0)
        row.update(
            batch_size=size,
            batch_s=bmedian / size,
            batch_min_s=bbest / size,
            batch_compile_s=bcompile,
            batch_max_steps=int(np.max(bsteps)),
            batch_all_separated=bool(np.all(np.asarray(bstatus) == 0)),
            batch_err_e=rel(be[0], ref["e"]),
        )
    return row


def measure_default_calls(name, ref):
    """`impact(law, m, v0)` as a user calls it (eager, defaults) and its jitted form."""
    law = ji.law(name, **CASES[name])
    eager = lambda: ji.impact(law, m=M, v0=V0).e  # noqa: E731
    compile_s, e = first_call(eager)
    median, best = time_call(eager, rounds=7)

    def solve(params, m, v0):
        r = ji.impact(ji.law(name, **params), m=m, v0=v0)
        return r.e, r.T

    single = jax.jit(solve)
    args = (scalar_params(name), jnp.asarray(M), jnp.asarray(V0))
    jcompile, (je, jT) = first_call(single, *args)
    jmedian, jbest = time_call(single, *args)
    batched = jax.jit(jax.vmap(solve, in_axes=(0, None, None)))
    bargs = (batch_params(name, BATCH), jnp.asarray(M), jnp.asarray(V0))
    bcompile, _ = first_call(batched, *bargs)
    bmedian, _ = time_call(batched, *bargs, rounds=5)
    path = ji.impact(law, m=M, v0=V0).path
    return dict(
        kind="default",
        law=name,
        path=path,
        err_e=rel(je, ref["e"]),
        err_T=rel(jT, ref["T"]),
        eager_s=median,
        eager_min_s=best,
        eager_first_s=compile_s,
        single_s=jmedian,
        single_min_s=jbest,
        compile_s=jcompile,
        batch_s=bmedian / BATCH,
        batch_compile_s=bcompile,
    )


def measure_maxwell_closed_form(ref):
    """The Maxwell closed form (under-damped), which `impact` does not use yet."""
    c, b = CASES["maxwell"]["c"], CASES["maxwell"]["b"]
    single = jax.jit(lambda c, b: (lambda r: (r["e"], r["T"]))(closed_forms.maxwell(c, b, M, V0)))
    compile_s, (e, T) = first_call(single, jnp.asarray(c), jnp.asarray(b))
    median, best = time_call(single, jnp.asarray(c), jnp.asarray(b))
    return dict(
        kind="closed_form_function",
        law="maxwell",
        err_e=rel(e, ref["e_alt"]),
        err_T=rel(T, ref["T_alt"]),
        single_s=median,
        single_min_s=best,
        compile_s=compile_s,
    )


def measure_derivatives(name, solver_name="Tsit5", rtol=1e-10):
    """d(e, T)/d(params) at the default tolerance, `peaks=False` (what fitting uses)."""

    def solve(params, m, v0):
        r = ji.impact(
            ji.law(name, **params),
            m=m,
            v0=v0,
            method="integrate",
            rtol=rtol,
            peaks=False,
            solver=SOLVERS[solver_name](),
        )
        return jnp.stack([r.e, r.T])

    args = (scalar_params(name), jnp.asarray(M), jnp.asarray(V0))
    rows = []
    for mode, transform in (("jacfwd (ForwardMode)", jax.jacfwd), ("jacrev (RCA)", jax.jacrev)):
        single = jax.jit(transform(solve))
        compile_s, _ = first_call(single, *args)
        median, _ = time_call(single, *args)
        batched = jax.jit(jax.vmap(transform(solve), in_axes=(0, None, None)))
        bargs = (batch_params(name, BATCH), jnp.asarray(M), jnp.asarray(V0))
        bcompile, _ = first_call(batched, *bargs)
        bmedian, _ = time_call(batched, *bargs, rounds=5)
        rows.append(
            dict(
                kind="derivative",
                law=name,
                solver=solver_name,
                rtol=rtol,
                mode=mode,
                single_s=median,
                compile_s=compile_s,
                batch_s=bmedian / BATCH,
                batch_compile_s=bcompile,
            )
        )
    forward = jax.jit(solve)
    first_call(forward, *args)
    rows.append(
        dict(
            kind="derivative",
            law=name,
            solver=solver_name,
            rtol=rtol,
            mode="value only",
            single_s=time_call(forward, *args)[0],
        )
    )
    return rows


# ------------------------------------------------------------------------ targets, interleaved


def measure_targets(results, threshold=TARGET_ERROR, rounds=9):
    """The target ratios, timed in alternation so that scipy and jaximpact see the same load.

    Per law: scipy DOP853 at its loosest half-decade rtol with e error <= `threshold`; the
    fastest jaximpact configuration of the sweep reaching it (single and batch, chosen on
    the sweep's medians) and the default solver with peaks at the rtol it needs. Each round
    times all of them once (each call repeated for >= 0.1 s); the ratio is the median over
    rounds of the per-round ratios.
    """
    rows = results["rows"]
    out = []
    for name in results["references"]:
        dop = loosest(
            [
                r
                for r in rows
                if r["kind"] == "scipy" and r["law"] == name and r["method"] == "DOP853"
            ],
            threshold,
        )
        jx = [r for r in rows if r["kind"] == "jaximpact" and r["law"] == name and r["status"] == 0]
        if dop is None or not jx:
            continue
        picks = {
            "fastest single": fastest(jx, threshold, time="single_s"),
            "fastest batch": fastest(jx, threshold, time="batch_s"),
            "fastest with peaks, single": fastest([r for r in jx if r["peaks"]], threshold),
            "Tsit5 with peaks, single": fastest(
                [r for r in jx if r["peaks"] and r["solver"] == "Tsit5"], threshold
            ),
        }
        scipy_fn = scipy_solver(name, CASES[name], "DOP853", dop["rtol"])
        timers = {}
        for label, pick in picks.items():
            if pick is None:
                continue
            solver = SOLVERS[pick["solver"]]()
            max_steps = 65536 if pick["solver"] == "Kvaerno5" else 4096
            solve = impact_function(name, solver, pick["rtol"], pick["peaks"], max_steps)
            if "batch" in label:
                size = BATCH_IMPLICIT if pick["solver"] == "Kvaerno5" else BATCH
                fn = jax.jit(jax.vmap(solve, in_axes=(0, None, None)))
                args = (batch_params(name, size), jnp.asarray(M), jnp.asarray(V0))
            else:
                size = 1
                fn = jax.jit(solve)
                args = (scalar_params(name), jnp.asarray(M), jnp.asarray(V0))
            first_call(fn, *args)
            timers[label] = (fn, args, size, pick)
        per_round = {label: [] for label in timers}
        scipy_times = []
        for _ in range(rounds):
            t_scipy = time_call(scipy_fn, rounds=1, min_round_s=0.1)[0]
            scipy_times.append(t_scipy)
            for label, (fn, args, size, _) in timers.items():
                t = time_call(fn, *args, rounds=1, min_round_s=0.1)[0] / size
                per_round[label].append((t, t_scipy / t))
        entry = dict(
            law=name,
            scipy_rtol=dop["rtol"],
            scipy_err_e=dop["err_e"],
            scipy_s=float(np.median(scipy_times)),
            load=load_average(),
            picks={},
        )
        for label, (fn, args, size, pick) in timers.items():
            times = [t for t, _ in per_round[label]]
            ratios = [r for _, r in per_round[label]]
            entry["picks"][label] = dict(
                config=f"{pick['solver']} {pick['rtol']:.0e} peaks={pick['peaks']}",
                err_e=pick["err_e"],
                s=float(np.median(times)),
                ratio=float(np.median(ratios)),
                ratio_min=float(np.min(ratios)),
                ratio_max=float(np.max(ratios)),
                batch=size > 1,
            )
        out.append(entry)
        print("target", entry, flush=True)
    return out


# ------------------------------------------------------------------------ the run


def key(row):
    return (
        row["kind"],
        row["law"],
        row.get("mode") or row.get("solver") or row.get("method"),
        row.get("rtol") or row.get("dt"),
        row.get("peaks"),
    )


def run(args):
    results = dict(machine=machine(), loads=[], references={}, rows=[])
    if os.path.exists(JSON_PATH) and args.resume:
        with open(JSON_PATH) as f:
            results = json.load(f)
    done = {key(r) for r in results["rows"]}

    def save():
        with open(JSON_PATH, "w") as f:
            json.dump(results, f, indent=1)

    def add(row):
        results["rows"].append(row)
        done.add(key(row))
        save()

    laws = args.laws or list(CASES)
    solvers = args.solvers or list(SOLVERS)
    rtols = [1e-6, 1e-8, 1e-10, 1e-12] if args.quick else RTOLS
    results["loads"].append(load_average())
    for name in laws:
        ref = reference(name, CASES[name])
        results["references"][name] = ref
        print(f"== {name}: reference {ref}", flush=True)
        save()
        # scipy
        for method in SCIPY_METHODS:
            for rtol in SCIPY_RTOLS[:: 4 if args.quick else 1]:
                row = dict(kind="scipy", law=name, method=method, rtol=rtol)
                if key(row) in done:
                    continue
                fn = scipy_solver(name, CASES[name], method, rtol)
                e, T, nfev = fn()
                median, best = time_call(fn, rounds=5, min_round_s=0.1, max_total_s=6.0)
                row.update(
                    err_e=rel(e, ref["e"]),
                    err_T=rel(T, ref["T"]),
                    nfev=int(nfev),
                    single_s=median,
                    single_min_s=best,
                )
                add(row)
                print(f"scipy {method} {rtol:.0e} e {row['err_e']:.1e} {us(median)} us", flush=True)
        # Euler
        euler = euler_function(name)
        params = scalar_params(name)
        for dt in EULER_DTS[: 5 if args.quick else None]:
            row = dict(kind="euler", law=name, dt=dt)
            if key(row) in done:
                continue
            compile_s, (e, T, n) = first_call(euler, params, jnp.asarray(dt))
            median, best = time_call(euler, params, jnp.asarray(dt), rounds=5)
            row.update(
                err_e=rel(e, ref["e"]),
                err_T=rel(T, ref["T"]),
                steps=int(n),
                single_s=median,
                single_min_s=best,
                compile_s=compile_s,
            )
            add(row)
            print(f"euler {dt:.0e} e {row['err_e']:.1e} {us(median)} us", flush=True)
        # defaults, closed forms, derivatives
        row = dict(kind="default", law=name)
        if key(row) not in done:
            add(measure_default_calls(name, ref))
            print("default", results["rows"][-1], flush=True)
        if name == "maxwell" and key(dict(kind="closed_form_function", law=name)) not in done:
            add(measure_maxwell_closed_form(ref))
        if (
            not args.no_derivatives
            and key(dict(kind="derivative", law=name, mode="value only", rtol=1e-10)) not in done
        ):
            for r in measure_derivatives(name):
                add(r)
        # jaximpact
        for solver_name in solvers:
            for rtol in rtols if args.quick else SPARSE_RTOLS.get(solver_name, rtols):
                for peaks in (False, True):
                    row = dict(
                        kind="jaximpact", law=name, solver=solver_name, rtol=rtol, peaks=peaks
                    )
                    if key(row) in done:
                        continue
                    row = measure_jaximpact(name, solver_name, rtol, peaks, ref)
                    add(row)
                    print(
                        f"{name} {solver_name} {rtol:.0e} peaks={peaks} steps {row['steps']} "
                        f"e {row['err_e']:.1e} T {row['err_T']:.1e} single {us(row['single_s'])} us "
                        f"batch {us(row['batch_s'])} us compile {row['compile_s']:.1f}s "
                        f"load {load_average()}",
                        flush=True,
                    )
        results["loads"].append(load_average())
        save()
    if not args.no_targets:
        results["targets"] = measure_targets(results)
        results["loads"].append(load_average())
        save()
    return results


# ------------------------------------------------------------------------ report


def loosest(rows, threshold, what="err_e"):
    """The row with the loosest tolerance whose error is at most `threshold`."""
    ok = [r for r in rows if r[what] == r[what] and r[what] <= threshold]
    return max(ok, key=lambda r: r["rtol"]) if ok else None


def fastest(rows, threshold, what="err_e", time="single_s"):
    ok = [r for r in rows if r[what] == r[what] and r[what] <= threshold and r.get(time)]
    return min(ok, key=lambda r: r[time]) if ok else None


def targets(results, threshold=TARGET_ERROR):
    """Per law: scipy DOP853 at its loosest rtol with err_e <= threshold, against the
    fastest jaximpact configuration reaching the same error (single and batch), against the
    default configuration, and against the fastest peaks=False one."""
    out = []
    rows = results["rows"]
    for name in results["references"]:
        dop = loosest(
            [
                r
                for r in rows
                if r["kind"] == "scipy" and r["law"] == name and r["method"] == "DOP853"
            ],
            threshold,
        )
        jx = [r for r in rows if r["kind"] == "jaximpact" and r["law"] == name and r["status"] == 0]
        if dop is None or not jx:
            continue
        entry = dict(
            law=name, scipy_rtol=dop["rtol"], scipy_err_e=dop["err_e"], scipy_s=dop["single_s"]
        )
        for label, subset in (
            ("any", jx),
            ("peaks", [r for r in jx if r["peaks"]]),
            ("default_solver", [r for r in jx if r["solver"] == "Tsit5" and r["peaks"]]),
        ):
            single = fastest(subset, threshold, time="single_s")
            batch = fastest(subset, threshold, time="batch_s")
            entry[label] = dict(
                single=None
                if single is None
                else dict(
                    config=f"{single['solver']} {single['rtol']:.0e} peaks={single['peaks']}",
                    err_e=single["err_e"],
                    s=single["single_s"],
                    ratio=dop["single_s"] / single["single_s"],
                ),
                batch=None
                if batch is None
                else dict(
                    config=f"{batch['solver']} {batch['rtol']:.0e} peaks={batch['peaks']}",
                    err_e=batch["err_e"],
                    s=batch["batch_s"],
                    ratio=dop["single_s"] / batch["batch_s"],
                ),
            )
        out.append(entry)
    return out


def verdict(ratio, goal):
    if ratio >= goal:
        return f"met [>= {goal}]"
    return f"MISSED by {goal / ratio:.1f}x [>= {goal}]"


def report(results):
    rows = results["rows"]
    refs = results["references"]
    lines = [
        "# Work against precision",
        "",
        "Generated by `python benchmarks/work_precision.py` (data in `work_precision.json`, plot in "
        "`docs/work_precision.png`). Error = relative error `|x - x_ref| / x_ref` of the "
        "restitution e and the contact duration T; time = seconds per impact after compilation "
        "(median of several rounds), compile time apart. m = 1 kg, v0 = 2.5 m/s (the seed paper's), "
        'g = 0, `separation="force"`, float64. jaximpact rows use `method="integrate"`; '
        "**the library default** (Tsit5, rtol 1e-10, peaks=True; the closed form for "
        "Kelvin-Voigt) is marked with **bold** / `<- default`.",
        "",
        machine_markdown(results["machine"], results["loads"]),
        "",
        "## References",
        "",
        table(
            ["law", "parameters", "e_ref", "T_ref (s)", "source", "rel. diff. of the alt. e / T"],
            [
                [
                    n,
                    ", ".join(f"{k}={v:g}" for k, v in CASES[n].items()),
                    f"{r['e']:.15f}",
                    f"{r['T']:.15e}",
                    r["source"],
                    f"{fmt(rel(r['e_alt'], r['e']))} / {fmt(rel(r['T_alt'], r['T']))}",
                ]
                for n, r in refs.items()
            ],
        ),
        "",
        "Errors below the last column's level are at the references' own noise floor.",
        "",
    ]
    # targets
    tg = targets(results)
    lines += [
        "## Targets (error in e <= 1e-9)",
        "",
        "scipy DOP853 at its loosest (half-decade) rtol reaching e error <= 1e-9, against the "
        "fastest jaximpact configuration reaching it: one jitted impact (target: >= 50x) and "
        "per impact in a vmapped batch of 1000 (target: >= 1000x). `any` = best over solvers, "
        "rtols and `peaks`; `peaks` = best with `peaks=True` (x_max, F_max too); `Tsit5` = "
        "the default solver with peaks, at the rtol it needs.",
        "",
    ]
    trows = []
    for t in tg:
        for label in ("any", "peaks", "default_solver"):
            s, b = t[label]["single"], t[label]["batch"]
            trows.append(
                [
                    t["law"],
                    f"{t['scipy_rtol']:.1e}: {fmt(t['scipy_err_e'])}, {us(t['scipy_s'])} us",
                    {"any": "any", "peaks": "peaks", "default_solver": "Tsit5+peaks"}[label],
                    "-" if s is None else f"{s['config']}: {fmt(s['err_e'])}, {us(s['s'])} us",
                    "-"
                    if s is None
                    else f"**{s['ratio']:.0f}x** {'met' if s['ratio'] >= 50 else 'MISSED'}",
                    "-" if b is None else f"{b['config']}: {us(b['s'])} us",
                    "-"
                    if b is None
                    else f"**{b['ratio']:.0f}x** {'met' if b['ratio'] >= 1000 else 'MISSED'}",
                ]
            )
    if results.get("targets"):
        irows = []
        for t in results["targets"]:
            for label, pk in t["picks"].items():
                goal = 1000 if pk["batch"] else 50
                irows.append(
                    [
                        t["law"],
                        f"{t['scipy_rtol']:.1e}: {fmt(t['scipy_err_e'])}, {us(t['scipy_s'])} us",
                        label,
                        f"{pk['config']}: {fmt(pk['err_e'])}, {us(pk['s'])} us"
                        + ("/impact" if pk["batch"] else ""),
                        f"**{pk['ratio']:.0f}x** ({pk['ratio_min']:.0f}-{pk['ratio_max']:.0f}) "
                        + verdict(pk["ratio"], goal),
                        t["load"],
                    ]
                )
        lines += [
            "Timed in alternation (9 rounds, scipy then each jaximpact configuration, each "
            "call repeated >= 0.1 s per round); the ratio is the median of the per-round "
            "ratios (range in parentheses). Configurations chosen from the sweep below.",
            "",
            table(
                [
                    "law",
                    "DOP853 rtol: err e, time",
                    "jaximpact",
                    "config: err e, time",
                    "ratio to DOP853 [target]",
                    "load avg",
                ],
                irows,
            ),
            "",
            "The same from the sweep's medians (each measured at a different moment):",
            "",
        ]
    lines += [
        table(
            [
                "law",
                "DOP853 rtol: err e, time",
                "set",
                "jaximpact single: err e, time",
                "single ratio (>= 50)",
                "jaximpact batch: time/impact",
                "batch ratio (>= 1000)",
            ],
            trows,
        ),
        "",
    ]
    # defaults
    defaults = [r for r in rows if r["kind"] == "default"]
    if defaults:
        lines += [
            "## The default call",
            "",
            "`impact(law, m=1, v0=2.5)` with every default: eager (as typed at a prompt, Python "
            "overhead included), inside `jax.jit`, and per impact in a vmapped batch of 1000.",
            "",
            table(
                [
                    "law",
                    "path",
                    "err e",
                    "err T",
                    "eager us",
                    "first eager call s",
                    "jit us",
                    "jit compile s",
                    "batch us/impact",
                    "batch compile s",
                ],
                [
                    [
                        r["law"],
                        r["path"],
                        fmt(r["err_e"]),
                        fmt(r["err_T"]),
                        us(r["eager_s"]),
                        f"{r['eager_first_s']:.1f}",
                        us(r["single_s"]),
                        f"{r['compile_s']:.1f}",
                        us(r["batch_s"]),
                        f"{r['batch_compile_s']:.1f}",
                    ]
                    for r in defaults
                ],
            ),
            "",
        ]
    cff = [r for r in rows if r["kind"] == "closed_form_function"]
    if cff:
        r = cff[0]
        lines += [
            f"Maxwell's closed form (`closed_forms.maxwell`, not used by `impact`): "
            f"{us(r['single_s'])} us jitted, error against scipy 1e-13 {fmt(r['err_e'])} in e, "
            f"{fmt(r['err_T'])} in T.",
            "",
        ]
    deriv = [r for r in rows if r["kind"] == "derivative"]
    if deriv:
        lines += [
            "## Derivatives",
            "",
            "d(e, T)/d(law parameters), Tsit5, rtol 1e-10, `peaks=False` (what a fit evaluates); "
            "the adjoint is jaximpact's automatic choice (ForwardMode under `jacfwd`, "
            "RecursiveCheckpointAdjoint under `jacrev`).",
            "",
            table(
                [
                    "law",
                    "mode",
                    "single us",
                    "x value",
                    "compile s",
                    "batch us/impact",
                    "batch compile s",
                ],
                [
                    [
                        r["law"],
                        r["mode"],
                        us(r["single_s"]),
                        fmt(
                            r["single_s"]
                            / next(
                                d["single_s"]
                                for d in deriv
                                if d["law"] == r["law"] and d["mode"] == "value only"
                            )
                        ),
                        fmt(r.get("compile_s")),
                        us(r.get("batch_s")),
                        fmt(r.get("batch_compile_s")),
                    ]
                    for r in deriv
                ],
            ),
            "",
        ]
    # per law
    for name in refs:
        lines += [f"## {name}", ""]
        jx = [r for r in rows if r["kind"] == "jaximpact" and r["law"] == name]
        by = {}
        for r in jx:
            by[(r["solver"], r["rtol"], r["peaks"])] = r
        trs = []
        for solver in SOLVERS:
            for rtol in RTOLS:
                a, b = by.get((solver, rtol, False)), by.get((solver, rtol, True))
                if a is None and b is None:
                    continue
                is_default = solver == DEFAULT["solver"] and rtol == DEFAULT["rtol"]
                mark = " <- default" if is_default and name != "kelvin_voigt" else ""

                def cells(r, bold=False):
                    if r is None:
                        return ["-"] * 6
                    wrap = (lambda s: f"**{s}**") if bold else (lambda s: s)
                    status = "" if r["status"] == 0 else f" (status {r['status']})"
                    return [
                        f"{r['steps']}{status}",
                        wrap(fmt(r["err_e"])),
                        fmt(r["err_T"]),
                        wrap(us(r["single_s"])),
                        us(r.get("batch_s")),
                        f"{r['compile_s']:.1f}",
                    ]

                trs.append([f"{solver} {rtol:.0e}{mark}"] + cells(a) + cells(b, bold=bool(mark)))
        lines += [
            "jaximpact, `peaks=False` | `peaks=True`: steps, error in e and T, µs per jitted "
            f"impact, µs per impact in a vmapped batch ({BATCH}; {BATCH_IMPLICIT} for Kvaerno5), "
            "compile s (single).",
            "",
            table(
                ["solver rtol", "steps", "err e", "err T", "single us", "batch us", "compile s"]
                + ["steps (peaks)", "err e", "err T", "single us", "batch us", "compile s"],
                trs,
            ),
            "",
        ]
        sc = [r for r in rows if r["kind"] == "scipy" and r["law"] == name]
        if sc:
            lines += [
                "scipy `solve_ivp`, terminal event, one phase (rtol; atol = rtol x the contact's "
                "natural scales):",
                "",
                table(
                    ["method", "rtol", "nfev", "err e", "err T", "us per impact"],
                    [
                        [
                            r["method"],
                            f"{r['rtol']:.1e}",
                            r["nfev"],
                            fmt(r["err_e"]),
                            fmt(r["err_T"]),
                            us(r["single_s"]),
                        ]
                        for r in sc
                    ],
                ),
                "",
            ]
        eu = [r for r in rows if r["kind"] == "euler" and r["law"] == name]
        if eu:
            lines += [
                "The seed paper's explicit Euler (fixed step dt; jitted JAX loop):",
                "",
                table(
                    ["dt (s)", "steps", "err e", "err T", "us per impact"],
                    [
                        [
                            f"{r['dt']:.0e}" + (" (paper)" if r["dt"] == 2e-5 else ""),
                            r["steps"],
                            fmt(r["err_e"]),
                            fmt(r["err_T"]),
                            us(r["single_s"]),
                        ]
                        for r in eu
                    ],
                ),
                "",
            ]
    with open(MD_PATH, "w") as f:
        f.write("\n".join(lines) + "\n")
    plot(results)


def plot(results):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    rows = results["rows"]
    laws = list(results["references"])
    fig, axes = plt.subplots(2, len(laws), figsize=(4.2 * len(laws), 8), squeeze=False)
    colors = {
        "Tsit5": "C0",
        "Dopri5": "C1",
        "Dopri8": "C2",
        "Kvaerno5": "C3",
        "RK45": "C4",
        "DOP853": "C5",
        "LSODA": "C6",
        "Radau": "C7",
        "Euler": "k",
    }
    floor = 1e-16
    for j, name in enumerate(laws):
        for i, what in enumerate(("err_e", "err_T")):
            ax = axes[i, j]
            for solver in SOLVERS:
                for peaks, style in ((False, "-"), (True, "--")):
                    rs = sorted(
                        [
                            r
                            for r in rows
                            if r["kind"] == "jaximpact"
                            and r["law"] == name
                            and r["solver"] == solver
                            and r["peaks"] == peaks
                        ],
                        key=lambda r: r["rtol"],
                    )
                    if not rs:
                        continue
                    ys = [max(r[what], floor) for r in rs]
                    ax.loglog(
                        [r["single_s"] for r in rs],
                        ys,
                        style,
                        marker="o",
                        ms=3,
                        color=colors[solver],
                        label=f"jaximpact {solver}" + (" peaks" if peaks else "")
                        if j == 0 and i == 0
                        else None,
                    )
                    if not peaks:
                        ax.loglog(
                            [r["batch_s"] for r in rs],
                            ys,
                            ":",
                            marker=".",
                            ms=3,
                            color=colors[solver],
                            label=f"jaximpact {solver} batch/impact" if j == 0 and i == 0 else None,
                        )
            for method in SCIPY_METHODS:
                rs = sorted(
                    [
                        r
                        for r in rows
                        if r["kind"] == "scipy" and r["law"] == name and r["method"] == method
                    ],
                    key=lambda r: r["rtol"],
                )
                if rs:
                    ax.loglog(
                        [r["single_s"] for r in rs],
                        [max(r[what], floor) for r in rs],
                        "-.",
                        marker="s",
                        ms=3,
                        color=colors[method],
                        label=f"scipy {method}" if j == 0 and i == 0 else None,
                    )
            rs = sorted(
                [r for r in rows if r["kind"] == "euler" and r["law"] == name],
                key=lambda r: -r["dt"],
            )
            if rs:
                ax.loglog(
                    [r["single_s"] for r in rs],
                    [max(r[what], floor) for r in rs],
                    "-",
                    marker="x",
                    ms=4,
                    color="k",
                    label="Euler (paper)" if j == 0 and i == 0 else None,
                )
                paper = [r for r in rs if r["dt"] == 2e-5]
                for r in paper:
                    ax.annotate("dt=2e-5", (r["single_s"], max(r[what], floor)), fontsize=7)
            d = [
                r
                for r in rows
                if r["kind"] == "jaximpact"
                and r["law"] == name
                and r["solver"] == DEFAULT["solver"]
                and r["rtol"] == DEFAULT["rtol"]
                and r["peaks"] == DEFAULT["peaks"]
            ]
            if name == "kelvin_voigt":
                d = [r for r in rows if r["kind"] == "default" and r["law"] == name]
            for r in d:
                ax.loglog(
                    [r["single_s"]],
                    [max(r[what], floor)],
                    "*",
                    ms=14,
                    color="gold",
                    markeredgecolor="k",
                    label="default" if (i, j) == (0, 0) else None,
                )
            ax.axhline(TARGET_ERROR, color="grey", lw=0.5)
            ax.set_title(f"{name}: error in {what[-1]}")
            ax.set_xlabel("seconds per impact")
            if j == 0:
                ax.set_ylabel(f"relative error in {what[-1]}")
            ax.grid(True, which="major", alpha=0.3)
    fig.legend(loc="lower center", ncol=6, fontsize=8)
    fig.tight_layout(rect=(0, 0.1, 1, 1))
    os.makedirs(os.path.dirname(PNG_PATH), exist_ok=True)
    fig.savefig(PNG_PATH, dpi=110)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer tolerances and steps")
    parser.add_argument("--report", action="store_true", help="rebuild the report from the JSON")
    parser.add_argument("--resume", action="store_true", help="keep the rows already in the JSON")
    parser.add_argument("--laws", nargs="*", choices=list(CASES))
    parser.add_argument("--solvers", nargs="*", choices=list(SOLVERS))
    parser.add_argument("--no-derivatives", action="store_true")
    parser.add_argument("--no-targets", action="store_true", help="skip the interleaved timing")
    parser.add_argument("--targets", action="store_true", help="only redo the interleaved timing")
    args = parser.parse_args()
    if args.report or args.targets:
        with open(JSON_PATH) as f:
            results = json.load(f)
        if args.targets:
            results["loads"].append(load_average())
            results["targets"] = measure_targets(results)
            results["loads"].append(load_average())
            with open(JSON_PATH, "w") as f:
                json.dump(results, f, indent=1)
    else:
        start = time.perf_counter()
        results = run(args)
        print(f"total {time.perf_counter() - start:.0f} s")
    report(results)


if __name__ == "__main__":
    main()
