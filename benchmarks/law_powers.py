"""Constant powers as square roots and multiplies (issue 35, item 1): `x**1.5` against
`x * sqrt(x)` in a user's law and in the table's, force evaluations and whole batches.

XLA's `pow` with a non-integer exponent costs about 10x a square root and a multiply on
CPU. A user's law now goes through `_laws/fast_powers.py` (its jaxpr read, `pow(x, k/2)`
evaluated by `_powers.half_power`), and the table's laws through `contact_pow`, which does
the same for a static exponent. Each row compares, in this one process, the program
compiled as before ("pow": `fast_powers` replaced by the identity for the user's law,
`_powers.half_steps` by `None` for the table's, so both trace `pow` as they used to) with
the library as it is ("sqrt"):

- the force alone: 312 evaluations per member (24 steps x 13 stages of an 8th-order
  Runge-Kutta, shared/notes/performance-4.md) in a jitted `vmap` of 1,000 members;
- a whole batch: `jax.jit(jax.vmap(lambda v0: ji.impact(law, m=1.0, v0=v0).e))` over 1,000
  speeds in [1, 3] m/s (`method="integrate"` for the table's `hertz_rate`), per impact, with
  its largest relative error in e against scipy's DOP853 at rtol 1e-13 (force criterion,
  terminal event) over the same 1,000 speeds;
- scipy's DOP853 at the loosest half-decade rtol whose e error at v0 = 2.5 m/s is <= 1e-9,
  per impact, as the speed reference of the "x scipy" columns.

The laws: a user's `c x**1.5 + b1 x**0.5 v (1 + 0.1 v)` and the table's `hertz_rate`,
`c x^1.5 + b1 x^0.5 v` (c = 2e6 N/m^1.5, b1 = 800 N s/m^1.5, m = 1 kg). Each program is
compiled ahead of time after `jax.clear_caches()` (so that no traced body is shared between
the two variants), and the number of `power` operations in its optimised HLO is given.
Timings alternate between the variants and scipy, round by round; medians. Every clock
stops after `jax.block_until_ready`.

Run: python benchmarks/law_powers.py (writes benchmarks/law_powers.md).
"""

import contextlib
import math
import os
import statistics
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from _common import load_average, machine, machine_markdown, table, write_report  # noqa: E402

C, B1, M, V0 = 2e6, 800.0, 1.0, 2.5
EVALS = 312  # force evaluations per member: 24 steps x 13 stages
BATCH = 1000
ROUNDS = 7
REFERENCE_RTOL = 1e-13


def user_law(x, v, p):
    return p["c"] * x**1.5 + p["b1"] * x**0.5 * v * (1 + 0.1 * v)


def _user_law_np(x, v):
    return C * x**1.5 + B1 * math.sqrt(x) * v * (1 + 0.1 * v)


def _table_law_np(x, v):
    return C * x**1.5 + B1 * math.sqrt(x) * v


def _reduced(law_np):
    """`F / sqrt(x)` as a function of `(x, v)` (the force criterion's event, transversal)."""
    if law_np is _user_law_np:
        return lambda x, v: C * x + B1 * v * (1 + 0.1 * v)
    return lambda x, v: C * x + B1 * v


def scipy_impact(law_np, v0, rtol):
    """e of one impact by scipy DOP853: `rtol`, atol = rtol x the scales, and a terminal
    event where the force (its reduced form `F / sqrt(x)`) or `x` reaches zero."""
    import numpy as np
    from scipy.integrate import solve_ivp

    x_star = (M * v0**2 / C) ** 0.4
    reduced = _reduced(law_np)

    def rhs(t, y):
        x = max(y[0], 0.0)
        return [y[1], -law_np(x, y[1]) / M]

    def end(t, y):
        return min(y[0] / x_star, reduced(max(y[0], 0.0), y[1]) / (C * x_star))

    end.terminal, end.direction = True, -1
    t_star = x_star / v0
    sol = solve_ivp(
        rhs,
        (0.0, 1e3 * t_star),
        [0.0, v0],
        "DOP853",
        rtol=rtol,
        atol=rtol * np.array([x_star, v0]),
        events=end,
    )
    return -float(sol.y_events[0][0][1]) / v0


@contextlib.contextmanager
def as_before(kind):
    """The library as it was before the rewrite: `pow` for the user's law (`kind="user"`)
    or for the table's (`kind="table"`)."""
    import jaximpact._laws.custom as custom
    import jaximpact._powers as powers

    module, name, replacement = {
        "user": (custom, "fast_powers", lambda fn: fn),
        "table": (powers, "half_steps", lambda p: None),
    }[kind]
    saved = getattr(module, name)
    setattr(module, name, replacement)
    try:
        yield
    finally:
        setattr(module, name, saved)


def compiled(fn, *args):
    """`fn` jitted and compiled ahead of time for `args`, after clearing JAX's caches:
    `(compiled, seconds to compile, power ops in its HLO)`."""
    import jax

    jax.clear_caches()
    start = time.perf_counter()
    program = jax.jit(fn).lower(*args).compile()
    seconds = time.perf_counter() - start
    return program, seconds, program.as_text().count(" power(")


def programs(kind, law, method):
    """The force and batch programs of `law`, as before and as now."""
    import jax
    import jax.numpy as jnp

    import jaximpact as ji

    x0 = jnp.geomspace(1e-7, 1e-3, BATCH)
    speeds = jnp.linspace(1.0, 3.0, BATCH)

    def evaluations(x, v):
        def body(i, total):
            s = (i + 1.0) / EVALS
            return total + law.force(x * s, v * (1.0 - 2.0 * s))

        return jax.lax.fori_loop(0, EVALS, body, jnp.zeros_like(x))

    forces = jax.vmap(evaluations)
    batch = jax.vmap(lambda v0: ji.impact(law, m=M, v0=v0, method=method).e)
    out = {}
    for variant in ("pow", "sqrt"):
        context = as_before(kind) if variant == "pow" else contextlib.nullcontext()
        with context:
            out[variant, "force"] = compiled(forces, x0, speeds) + ((x0, speeds),)
            out[variant, "batch"] = compiled(batch, speeds) + ((speeds,),)
    return out


def main():
    import jax

    jax.config.update("jax_enable_x64", True)
    import numpy as np

    import jaximpact as ji
    from jaximpact._bench import seconds_per_call

    loads = [load_average()]
    laws = {
        "a user's law `c x**1.5 + b1 x**0.5 v (1 + 0.1 v)`": (
            "user",
            ji.custom_law(user_law, c=C, b1=B1),
            "auto",
            _user_law_np,
        ),
        'the table\'s `hertz_rate` (`method="integrate"`)': (
            "table",
            ji.law("hertz_rate", c=C, b1=B1),
            "integrate",
            _table_law_np,
        ),
    }
    speeds = np.linspace(1.0, 3.0, BATCH)
    rows = []
    for label, (kind, law, method, law_np) in laws.items():
        built = programs(kind, law, method)
        loads.append(load_average())
        reference = np.array([scipy_impact(law_np, v, REFERENCE_RTOL) for v in speeds])
        e_ref = scipy_impact(law_np, V0, REFERENCE_RTOL)
        for k in range(12, 25):  # the loosest half-decade rtol with e within 1e-9
            rtol = 10.0 ** (-k / 2)
            if abs(scipy_impact(law_np, V0, rtol) - e_ref) <= 1e-9 * e_ref:
                break
        e = {
            variant: np.asarray(built[variant, "batch"][0](*built[variant, "batch"][3]))
            for variant in ("pow", "sqrt")
        }
        errors = {key: float(np.max(np.abs(e[key] - reference) / reference)) for key in e}
        change = float(np.max(np.abs(e["sqrt"] - e["pow"]) / e["pow"]))
        times = {key: [] for key in built}
        times["scipy"] = []
        for _ in range(ROUNDS):
            times["scipy"].append(seconds_per_call(scipy_impact, law_np, V0, rtol, min_round_s=0.2))
            for key, (program, _, _, args) in built.items():
                times[key].append(seconds_per_call(program, *args, min_round_s=0.2) / BATCH)
        median = {key: statistics.median(values) for key, values in times.items()}
        scipy_s = median["scipy"]
        loads.append(load_average())
        for what, title in (
            ("force", f"force, {EVALS} evaluations per member, vmap of {BATCH:,}"),
            ("batch", f"impact batch, vmap of {BATCH:,} speeds, per impact"),
        ):
            before, now = median["pow", what], median["sqrt", what]
            if what == "force":
                cells = [
                    f"{before * 1e6:.2f} µs ({before / EVALS * 1e9:.1f} ns per evaluation)",
                    f"{now * 1e6:.2f} µs ({now / EVALS * 1e9:.1f} ns per evaluation)",
                    "-",
                ]
            else:
                cells = [
                    f"{before * 1e6:.1f} µs ({scipy_s / before:.0f}x scipy)",
                    f"{now * 1e6:.1f} µs ({scipy_s / now:.0f}x scipy)",
                    f"{errors['pow']:.1e} / {errors['sqrt']:.1e} (e changed by {change:.0e})",
                ]
            rows.append(
                [
                    label,
                    title,
                    *cells[:2],
                    f"{before / now:.1f}x",
                    cells[2],
                    f"{built['pow', what][2]} / {built['sqrt', what][2]}",
                    f"{built['pow', what][1]:.1f} / {built['sqrt', what][1]:.1f}",
                ]
            )
        rows.append(
            [
                label,
                f"scipy DOP853, rtol {rtol:.2g} (e error <= 1e-9 at v0 = 2.5 m/s), per impact",
                f"{scipy_s * 1e6:.0f} µs",
                "",
                "",
                "",
                "",
                "",
            ]
        )
    text = "\n".join(
        [
            "# Constant powers as square roots: `x**1.5` against `x * sqrt(x)`",
            "",
            "Generated by `python benchmarks/law_powers.py`. Each law's programs are compiled "
            'twice in this one process: as before ("pow": the law\'s `x**1.5`, `x**0.5` '
            "traced as XLA's `pow`) and as the library is now (\"sqrt\": a user's law "
            "through `fast_powers`, the table's through `contact_pow`: `x * sqrt(x)`, "
            "`sqrt(x)`). c = 2e6 N/m^1.5, b1 = 800 N s/m^1.5, m = 1 kg, speeds 1 to 3 m/s, "
            "float64, default options otherwise. Times are medians over "
            f"{ROUNDS} alternated rounds; the e error is the largest relative error over the "
            f"batch's {BATCH:,} speeds against scipy DOP853 at rtol {REFERENCE_RTOL:g} "
            "(force criterion), and the largest relative change of e between the two "
            "programs. `power` ops are counted in each compiled program's optimised HLO: "
            "those left in the batches are not the law's (the bisection for `x*` of a "
            "user's law, `10**log10_x`; diffrax's step-size controller; the scales).",
            "",
            machine_markdown(machine(), loads),
            "",
            table(
                [
                    "law",
                    "what",
                    "pow (before)",
                    "sqrt (now)",
                    "speed-up",
                    "max e error vs scipy, pow / sqrt",
                    "`power` ops, pow / sqrt",
                    "compile s, pow / sqrt",
                ],
                rows,
            ),
            "",
        ]
    )
    write_report(os.path.join(HERE, "law_powers.md"), text)


if __name__ == "__main__":
    main()
