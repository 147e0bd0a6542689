"""A short speed-against-scipy benchmark: jaximpact's default `impact` against `solve_ivp`.

At the seed paper's conditions (m = 1 kg, v0 = 2.5 m/s, `separation="force"`, g = 0), for
each law of `CASES`:

- the relative error in e and T of `jaximpact.impact(law, m=m, v0=v0)` (every default, or
  `method="integrate"` for the second Kelvin-Voigt row) against a reference: the closed
  form where `jaximpact.closed_forms` has one (Kelvin-Voigt, Maxwell; e of Hunt-Crossley),
  else scipy's DOP853 at rtol 1e-13 with a terminal event (`scipy_solver`);
- seconds per impact of one jitted impact after compilation, and per impact in a jitted
  `jax.vmap` over a batch of impact speeds scattered around v0, with the first-call
  (compile) times apart;
- seconds per impact of scipy `solve_ivp(method="DOP853")` with a terminal event at the
  loosest rtol of `SCIPY_RTOLS` (half decades) whose error in e is <= `TARGET_ERROR`;
- the ratios scipy / jaximpact, single and batch, against the project's targets
  (`TARGETS`: >= 50x single, >= 1000x batch).

scipy and jaximpact are timed in alternation (each round times scipy, then the single
jaximpact call, then the batch; the ratio is the median over rounds of the per-round
ratios), so that both see the same load on a shared machine. Every clock stops after
`jax.block_until_ready` (brax's rule). `euler_row` adds the seed paper's explicit Euler at
its step of 2e-5 s, for its error in e. scipy is an optional dependency: `require_scipy`.
The full sweep over solvers and tolerances is `benchmarks/work_precision.py`, which uses
the scipy problem and the timing helpers of this module.
"""

import math
import os
import statistics
import time
from collections.abc import Callable

import numpy as np

M, V0 = 1.0, 2.5  # the seed paper's mass (kg) and impact speed (m/s)
CASES = {
    # name: (law, parameters in SI units, jaximpact.impact's method)
    "kelvin_voigt": ("kelvin_voigt", dict(c=2e6, b=400.0), "auto"),
    "kelvin_voigt (integrate)": ("kelvin_voigt", dict(c=2e6, b=400.0), "integrate"),
    "maxwell": ("maxwell", dict(c=2e6, b=2000.0), "auto"),
    "hertz_rate": ("hertz_rate", dict(c=2e6, b1=800.0), "auto"),
    "hunt_crossley": ("hunt_crossley", dict(c=2e6, a=0.1), "auto"),
}
LAWS = tuple(dict.fromkeys(law for law, _, _ in CASES.values()))
# F = c x^n + b x^p v, and the name of b (Hunt-Crossley: b = 1.5 a c, p = n = 1.5)
_FAMILY = {
    "kelvin_voigt": (1.0, 0.0, "b"),
    "hertz_viscous": (1.5, 0.0, "b"),
    "hertz_rate": (1.5, 0.5, "b1"),
}
SCIPY_RTOLS = [10.0 ** (-k / 2) for k in range(12, 25)]  # 1e-6 ... 1e-12, half decades
REFERENCE_RTOL = 1e-13
TARGET_ERROR = 1e-9  # error in e that scipy must reach for the comparison
TARGETS = {"single": 50.0, "batch": 1000.0}  # the project's speed-up targets
EULER_DT = 2e-5  # the seed paper's step, s
EULER_LAW = "hertz_rate"  # the paper's own proposal (law 14)


def require_scipy():
    """Import scipy's `solve_ivp`; an `ImportError` that says how to install it."""
    try:
        from scipy.integrate import solve_ivp
    except ImportError:
        raise ImportError(
            "the benchmark compares against scipy, which is not installed: pip install scipy"
        ) from None
    return solve_ivp


# ------------------------------------------------------------------------ timing


def block(tree):
    """`jax.block_until_ready` for JAX outputs, nothing for plain Python values."""
    import jax

    return jax.block_until_ready(tree)


def time_call(fn, *args, rounds=7, min_round_s=0.05, max_total_s=20.0):
    """Median and minimum seconds per call of `fn(*args)` (already compiled/warm).

    Each round repeats the call until it has run `min_round_s` (s); a call slower than that
    is one round by itself, and the number of rounds shrinks (down to 3) so that the whole
    measurement stays near `max_total_s` (s).
    """
    start = time.perf_counter()
    block(fn(*args))
    once = time.perf_counter() - start
    calls = max(1, int(min_round_s / max(once, 1e-7)))
    rounds = max(3, min(rounds, int(max_total_s / max(once * calls, 1e-9))))
    per_call = []
    for _ in range(rounds):
        start = time.perf_counter()
        for _ in range(calls):
            out = fn(*args)
        block(out)
        per_call.append((time.perf_counter() - start) / calls)
    return statistics.median(per_call), min(per_call)


def seconds_per_call(fn, *args, min_round_s=0.05):
    """Seconds per call of `fn(*args)` (warm) over one round of repeated calls lasting at
    least `min_round_s` (s): one sample of an alternated comparison."""
    start = time.perf_counter()
    block(fn(*args))
    once = time.perf_counter() - start
    calls = max(1, int(min_round_s / max(once, 1e-7)))
    start = time.perf_counter()
    for _ in range(calls):
        out = fn(*args)
    block(out)
    return (time.perf_counter() - start) / calls


def first_call(fn, *args):
    """Seconds taken by the first call (tracing and compilation included) and its output."""
    start = time.perf_counter()
    out = block(fn(*args))
    return time.perf_counter() - start, out


def load_average() -> str:
    """The 1, 5 and 15 minute load averages, as `"1.58, 0.80, 0.32"`."""
    one, five, fifteen = os.getloadavg()
    return f"{one:.2f}, {five:.2f}, {fifteen:.2f}"


def machine_info() -> dict:
    """CPU count, JAX backend and versions, and the load average now."""
    import platform

    import jax

    try:
        import scipy

        scipy_version = scipy.__version__
    except ImportError:
        scipy_version = None
    return dict(
        cpu_count=os.cpu_count(),
        processor=platform.processor() or platform.machine(),
        python=platform.python_version(),
        jax=jax.__version__,
        backend=jax.default_backend(),
        scipy=scipy_version,
        compilation_cache=jax.config.jax_compilation_cache_dir,
        load_average=load_average(),
    )


# ------------------------------------------------------------------------ scipy


def scipy_problem(name, params, *, m=M, v0=V0, separation="force"):
    """The dimensional contact problem as a scipy user writes it: right-hand side, initial
    state, absolute-tolerance scales (x*, v0 [, c x*]), the end-of-contact event (positive
    in contact, scaled to O(1)) and the natural contact time t* (s). One phase: the laws
    here are smooth at maximum compression. Laws: kelvin_voigt, hertz_viscous, hertz_rate,
    hunt_crossley (n = 1.5), maxwell; `separation` "force" or "penetration"."""
    c = params["c"]
    if name == "maxwell":
        b = params["b"]
        t_star = math.sqrt(m / c)
        x_star = v0 * t_star
        scales = np.array([x_star, v0, c * x_star])

        def rhs(t, y):
            return [y[1], -y[2] / m, c * (y[1] - y[2] / b)]

        if separation == "force":

            def event(t, y):
                return y[2] / (c * x_star)

        else:

            def event(t, y):
                return y[0] / x_star

        return rhs, [0.0, v0, 0.0], scales, event, t_star
    if name == "hunt_crossley":
        n, p, b = 1.5, 1.5, 1.5 * params["a"] * c
    elif name in _FAMILY:
        n, p, damping = _FAMILY[name]
        b = params[damping]
    else:
        raise ValueError(f"no scipy problem for law {name!r}")
    x_star = (m * v0**2 / c) ** (1 / (n + 1))
    scales = np.array([x_star, v0])
    f_scale = c * x_star**n

    def pos(x, q):
        return x if q == 1 else (1.0 if q == 0 else max(x, 0.0) ** q)

    def rhs(t, y):
        x, v = y
        return [v, -(c * pos(x, n) + b * pos(x, p) * v) / m]

    if name == "hunt_crossley" or separation == "penetration":

        def event(t, y):
            return y[0] / x_star

    elif p == 0:

        def event(t, y):
            return (c * pos(y[0], n) + b * y[1]) / f_scale

    else:

        def event(t, y):
            return min(y[0] / x_star, (c * pos(y[0], n - p) + b * y[1]) / (c * x_star ** (n - p)))

    return rhs, [0.0, v0], scales, event, x_star / v0


def scipy_solver(name, params, method, rtol, *, m=M, v0=V0, separation="force"):
    """A function of no arguments that solves one impact with `solve_ivp(method=method)`,
    `rtol`, `atol = rtol` x the contact's scales and a terminal event, and returns
    `(e, T, nfev)` (T in s; NaN, NaN if the contact did not end)."""
    solve_ivp = require_scipy()
    rhs, y0, scales, event, t_star = scipy_problem(name, params, m=m, v0=v0, separation=separation)
    event.terminal, event.direction = True, -1
    atol = rtol * scales

    def run():
        sol = solve_ivp(
            rhs, (0.0, 1e3 * t_star), y0, method=method, rtol=rtol, atol=atol, events=[event]
        )
        if not sol.t_events[0].size:
            return float("nan"), float("nan"), sol.nfev
        return -sol.y_events[0][0][1] / v0, sol.t_events[0][0], sol.nfev

    return run


def reference(name, params, *, m=M, v0=V0) -> dict:
    """Reference e and T (s) of one impact under the force criterion, and their source:
    closed forms where `jaximpact.closed_forms` has them, else scipy DOP853 at 1e-13."""
    from . import closed_forms

    if name == "kelvin_voigt":
        cf = closed_forms.kelvin_voigt(params["c"], params["b"], m, v0, "force")
        return dict(e=float(cf["e"]), T=float(cf["T"]), source="closed form")
    if name == "maxwell":
        cf = closed_forms.maxwell(params["c"], params["b"], m, v0)
        return dict(e=float(cf["e"]), T=float(cf["T"]), source="closed form")
    e, T, _ = scipy_solver(name, params, "DOP853", REFERENCE_RTOL, m=m, v0=v0)()
    if name == "hunt_crossley":
        e = float(closed_forms.hunt_crossley_restitution(1.5 * params["a"] * v0))
        return dict(e=e, T=float(T), source="e closed form, T scipy DOP853 1e-13")
    return dict(e=float(e), T=float(T), source="scipy DOP853 1e-13")


def relative_error(value, ref) -> float:
    """`|value - ref| / |ref|` (NaN if `value` is not finite)."""
    value = float(value)
    return float(abs(value - ref) / abs(ref)) if math.isfinite(value) else float("nan")


def loosest_scipy(name, params, *, threshold=TARGET_ERROR, e_ref, m=M, v0=V0):
    """The loosest rtol of `SCIPY_RTOLS` at which scipy DOP853 has an error in e <=
    `threshold`: `(rtol, error in e, solver)`, or `(None, None, None)` if none reaches it."""
    for rtol in SCIPY_RTOLS:
        fn = scipy_solver(name, params, "DOP853", rtol, m=m, v0=v0)
        error = relative_error(fn()[0], e_ref)
        if error <= threshold:
            return rtol, error, fn
    return None, None, None


# ------------------------------------------------------------------------ jaximpact


def _solve_function(name, method):
    """`solve(params, v0) -> (e, T)` of jaximpact's `impact` with every default but `method`
    (the parameters are arguments, so XLA cannot fold a closed form into a constant)."""
    from ._laws import law
    from ._solve.impact import impact

    def solve(params, v0):
        r = impact(law(name, **params), m=M, v0=v0, method=method)
        return r.e, r.T

    return solve


def bench_case(case: str, *, batch: int = 1000, rounds: int = 5, min_round_s: float = 0.05):
    """Measure one entry of `CASES` (see the module docstring): a dict with the errors,
    times (s per impact), compile times (s), scipy's rtol and the ratios with the targets.
    `batch` members have impact speeds spread log-uniformly over v0 x [0.8, 1.25] (member
    0 at v0); `rounds` alternated timing rounds of at least `min_round_s` (s) per call."""
    import jax
    import jax.numpy as jnp

    from ._laws import law
    from ._solve.impact import impact

    name, params, method = CASES[case]
    ref = reference(name, params)
    path = impact(law(name, **params), m=M, v0=V0, method=method).path
    solve = _solve_function(name, method)
    args = ({k: jnp.asarray(v) for k, v in params.items()}, jnp.asarray(V0))
    single = jax.jit(solve)
    compile_s, (e, T) = first_call(single, *args)
    speeds = V0 * np.exp(np.random.default_rng(0).uniform(np.log(0.8), np.log(1.25), batch))
    speeds[0] = V0
    batched = jax.jit(jax.vmap(solve, in_axes=(None, 0)))
    bargs = (args[0], jnp.asarray(speeds))
    batch_compile_s, (be, _) = first_call(batched, *bargs)

    rtol, scipy_err_e, scipy_fn = loosest_scipy(name, params, e_ref=ref["e"])
    times = {"scipy": [], "single": [], "batch": []}
    ratios = {"single": [], "batch": []}
    for _ in range(rounds):
        t_scipy = seconds_per_call(scipy_fn, min_round_s=min_round_s) if scipy_fn else None
        t_single = seconds_per_call(single, *args, min_round_s=min_round_s)
        t_batch = seconds_per_call(batched, *bargs, min_round_s=min_round_s) / batch
        times["single"].append(t_single)
        times["batch"].append(t_batch)
        if t_scipy is not None:
            times["scipy"].append(t_scipy)
            ratios["single"].append(t_scipy / t_single)
            ratios["batch"].append(t_scipy / t_batch)

    def median(values):
        return statistics.median(values) if values else None

    row = dict(
        case=case,
        law=name,
        params=params,
        method=method,
        path=path,
        reference=ref["source"],
        e=float(e),
        T=float(T),
        e_ref=ref["e"],
        T_ref=ref["T"],
        err_e=relative_error(e, ref["e"]),
        err_T=relative_error(T, ref["T"]),
        err_e_within_target=bool(relative_error(e, ref["e"]) <= TARGET_ERROR),
        batch_err_e=relative_error(be[0], ref["e"]),
        single_s=median(times["single"]),
        batch_s=median(times["batch"]),
        batch_size=batch,
        compile_s=compile_s,
        batch_compile_s=batch_compile_s,
        scipy_rtol=rtol,
        scipy_err_e=scipy_err_e,
        scipy_s=median(times["scipy"]),
        rounds=rounds,
        load_average=load_average(),
    )
    for kind, goal in TARGETS.items():
        ratio = median(ratios[kind])
        row[f"ratio_{kind}"] = ratio
        row[f"ratio_{kind}_min"] = min(ratios[kind]) if ratios[kind] else None
        row[f"ratio_{kind}_max"] = max(ratios[kind]) if ratios[kind] else None
        row[f"target_{kind}"] = goal
        row[f"target_{kind}_met"] = None if ratio is None else bool(ratio >= goal)
    return row


def euler_row(name: str = EULER_LAW, dt: float = EULER_DT) -> dict:
    """The seed paper's explicit Euler (`jaximpact.euler_bounce`, its printed scheme) at the
    fixed step `dt` (s) for one impact of `CASES[name]` at v0 from first touch, against
    scipy DOP853 at 1e-13 under the same end of contact (x back to 0, as the paper's
    scheme has it), with the seconds per impact of the (compiled) call."""
    from ._laws import law
    from ._solve.euler import euler_bounce

    _, params, _ = next(c for c in CASES.values() if c[0] == name)
    e_ref, T_ref, _ = scipy_solver(
        name, params, "DOP853", REFERENCE_RTOL, separation="penetration"
    )()
    the_law = law(name, **params)

    def run():
        r = euler_bounce(the_law, m=M, h0=0.0, g=0.0, v_drop=V0, t_end=2.5 * T_ref, dt=dt)
        return r.e[0], r.T[0]

    compile_s, (e, T) = first_call(run)
    seconds = time_call(run, rounds=3, min_round_s=0.02, max_total_s=2.0)[0]
    return dict(
        law=name,
        params=params,
        dt=dt,
        scheme="paper",
        separation="penetration",
        e=float(e),
        T=float(T),
        e_ref=float(e_ref),
        T_ref=float(T_ref),
        reference="scipy DOP853 1e-13, contact until x = 0",
        err_e=relative_error(e, e_ref),
        err_T=relative_error(T, T_ref),
        single_s=seconds,
        compile_s=compile_s,
    )


def run_bench(
    laws=LAWS,
    *,
    quick: bool = False,
    on_step: Callable[[str], None] | None = None,
) -> dict:
    """The whole benchmark for the laws named in `laws` (each of `LAWS`; Kelvin-Voigt runs
    as its closed form and as `method="integrate"`): `{"machine", "conditions", "targets",
    "rows", "euler"}`. `quick`: a batch of 100 and 3 short rounds (a smoke test, noisy
    timings). `on_step(label)` is called after each measurement (for a progress bar). The
    Euler row is always law 14 (`EULER_LAW`), whatever `laws` holds."""
    unknown = [name for name in laws if name not in LAWS]
    if unknown:
        raise ValueError(
            f"unknown law {unknown[0]!r} for the benchmark; use some of {', '.join(LAWS)}"
        )
    require_scipy()
    options = dict(batch=100, rounds=3, min_round_s=0.02) if quick else {}
    machine = machine_info()
    rows = []
    for case, (name, _, _) in CASES.items():
        if name in laws:
            rows.append(bench_case(case, **options))
            if on_step is not None:
                on_step(case)
    euler = euler_row()
    if on_step is not None:
        on_step("euler")
    machine["load_average_end"] = load_average()
    return dict(
        machine=machine,
        conditions=dict(m=M, v0=V0, separation="force", g=0.0, quick=quick),
        targets=dict(TARGETS, error_e=TARGET_ERROR),
        rows=rows,
        euler=euler,
    )


def steps(laws=LAWS) -> int:
    """How many times `run_bench(laws)` calls `on_step`."""
    return sum(name in laws for name, _, _ in CASES.values()) + 1


def _us(seconds) -> str:
    """Seconds as microseconds, 3 significant digits (integers from 100 up); `-` for None."""
    if seconds is None:
        return "-"
    value = seconds * 1e6
    return f"{value:.0f}" if value >= 100 else f"{value:.3g}"


def _error(value) -> str:
    if value is None or not math.isfinite(value):
        return "-"
    return "0" if value == 0 else f"{value:.1e}"


def _ratio(row, kind) -> str:
    ratio = row[f"ratio_{kind}"]
    if ratio is None:
        return "-"
    verdict = "met" if row[f"target_{kind}_met"] else "MISSED"
    return f"{ratio:.0f}x {verdict}" if ratio >= 100 else f"{ratio:.3g}x {verdict}"


def bench_text(data: dict, width=None) -> str:
    """The report of `run_bench`'s `data`, fitted to `width` columns (default: the
    terminal's, 88 when stdout is not one): prose wrapped, the table's headers wrapped and,
    where it is still too wide, its columns in two tables that each repeat the law."""
    from ._format import format_number, format_table, terminal_width, wrap_text

    width = terminal_width() if width is None else width
    machine, cond = data["machine"], data["conditions"]
    batch = data["rows"][0]["batch_size"] if data["rows"] else 0
    rounds = data["rows"][0]["rounds"] if data["rows"] else 0
    cache = machine["compilation_cache"]

    def prose(*paragraphs) -> list[str]:  # each wrapped to the width
        return [
            line for p in paragraphs for line in (wrap_text(p, width, then="  ") if p else [""])
        ]

    out = prose(
        f"jaximpact bench{' --quick' if cond['quick'] else ''}: default impact() against scipy "
        f"solve_ivp DOP853 with an event; m = {format_number(cond['m'])} kg, "
        f"v0 = {format_number(cond['v0'])} m/s, separation at zero force, float64",
        f"machine: {machine['cpu_count']} CPUs ({machine['processor']}), jax {machine['jax']} "
        f"({machine['backend']} backend), scipy {machine['scipy']}, python {machine['python']}",
        f"load average (1, 5, 15 min): {machine['load_average']} at start, "
        f"{machine['load_average_end']} at end",
        f"compilation cache: {cache if cache else 'off'}",
        "",
    )
    header = [
        "law",
        "path",
        "err e",
        "err T",
        "jit us",
        "compile s",
        f"batch us ({batch})",
        "batch compile s",
        "scipy rtol",
        "scipy err e",
        "scipy us",
        f"single (>= {TARGETS['single']:.0f}x)",
        f"batch (>= {TARGETS['batch']:.0f}x)",
    ]
    rows = [
        [
            r["case"],
            r["path"],
            _error(r["err_e"]),
            _error(r["err_T"]),
            _us(r["single_s"]),
            f"{r['compile_s']:.2g}",
            _us(r["batch_s"]),
            f"{r['batch_compile_s']:.2g}",
            "-" if r["scipy_rtol"] is None else f"{r['scipy_rtol']:.1e}",
            _error(r["scipy_err_e"]),
            _us(r["scipy_s"]),
            _ratio(r, "single"),
            _ratio(r, "batch"),
        ]
        for r in data["rows"]
    ]
    out += format_table(header, rows, width=width)
    limit = data["targets"]["error_e"]
    loose = [r for r in data["rows"] if not (r["err_e"] is not None and r["err_e"] <= limit)]
    if loose:
        out += prose(
            f"note: the default impact's error in e is above the {limit:.0e} that scipy is "
            "held to for: " + ", ".join(f"{r['case']} ({_error(r['err_e'])})" for r in loose)
        )
    eu = data["euler"]
    out += prose(
        "",
        f"seed paper's explicit Euler (scheme as printed), dt = {format_number(eu['dt'])} s, "
        f"{eu['law']}: e = {eu['e']:.6f} against {eu['e_ref']:.6f} (contact until x = 0, "
        f"scipy DOP853 1e-13): err e {_error(eu['err_e'])}, err T {_error(eu['err_T'])}, "
        f"{_us(eu['single_s'])} us per impact (eager call)",
        "",
        "err: relative error against the reference (closed form where one exists, else scipy "
        "DOP853 at rtol 1e-13); us: microseconds per impact after compilation (batch: per "
        f"member of a jax.vmap over {batch} impact speeds in v0 x [0.8, 1.25]); compile s: "
        "first call (tracing, compilation or the cache's load); ratios: scipy time / "
        f"jaximpact time, median over {rounds} alternated rounds.",
    )
    if "plot" in data:
        out += prose(f"plot written to {data['plot']}")
    return "\n".join(out)
