"""The general (integrated) path with a user's own law, against issue 23's targets.

A user's law written plainly, `F = c x**1.5 (1 + a v)` (c = 2e6 N/m^1.5, a = 0.3 s/m,
m = 1 kg, v0 = 2.5 m/s), its exact e from the Hunt-Crossley closed form (e depends on
`a v0` alone; `closed_forms.hunt_crossley_restitution`). Each row is a ratio measured in
this one process:

- one jitted impact at the default tolerances against scipy's DOP853 at the loosest rtol
  whose e error is below 1e-9 (same law, numpy, terminal event at x = 0);
- per impact in a `jax.vmap` of 1,000 speeds (1 to 3 m/s) against the same scipy call;
- first calls in fresh processes without the persistent compilation cache, minus a bare
  JAX process (import, x64, one small jitted function): the first impact of a user's law,
  the first `jax.grad` through an integrated impact, the first `calibrate` of a user's law,
  and `compare_laws` over the seed paper's ten laws (e at four speeds).

Run: python benchmarks/general_path.py (writes benchmarks/general_path.md).
"""

import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from _common import load_average, machine, machine_markdown, table, time_call, write_report  # noqa: E402

C, A, M, V0 = 2e6, 0.3, 1.0, 2.5

CHILD = r"""
import json, os, sys, time
os.environ["TF_CPP_MIN_LOG_LEVEL"] = "3"
start = time.perf_counter()
import jax
jax.config.update("jax_enable_x64", True)
jax.config.update("jax_enable_compilation_cache", False)
import jax.numpy as jnp
what = sys.argv[1]
if what == "bare":
    jax.block_until_ready(jax.jit(lambda x: jnp.sin(x) * 2.0)(1.0))
    print(json.dumps({"total": time.perf_counter() - start}))
    sys.exit()
if what.startswith("diffrax"):  # the floor: diffrax alone, the same contact, one event
    import diffrax as dfx, optimistix as optx

    def rhs(t, y, c):
        return jnp.stack([y[1], -c * jnp.maximum(y[0], 0.0) ** 1.5 * (1 + 0.3 * 2.5 * y[1])])

    def solve(c):
        event = dfx.Event(lambda t, y, args, **kw: y[0] + (t < 1e-3),
                          root_finder=optx.Newton(rtol=1e-13, atol=1e-13))
        sol = dfx.diffeqsolve(dfx.ODETerm(rhs), dfx.Tsit5(), 0.0, 10.0, None,
                              jnp.array([0.0, 1.0]), args=c, event=event, max_steps=4096,
                              stepsize_controller=dfx.PIDController(rtol=1e-12, atol=1e-12),
                              throw=False)
        return sol.ys[-1, 1]

    t0 = time.perf_counter()
    jax.block_until_ready((jax.jit(solve) if what == "diffrax_solve" else jax.grad(solve))(1.0))
    print(json.dumps({"total": time.perf_counter() - start, "call": time.perf_counter() - t0}))
    sys.exit()
import jaximpact as ji

def f(x, v, p):
    return p["c"] * x**1.5 * (1 + p["a"] * v)

law = ji.custom_law(f, c=2e6, a=0.3)
calls = {
    "impact": lambda: ji.impact(law, m=1.0, v0=2.5).e,
    "grad": lambda: jax.grad(lambda c: ji.impact(law.replace(c=c), m=1.0, v0=2.5).e)(2e6),
    "calibrate": lambda: ji.calibrate(law, m=1.0, v0=2.5, e=0.65, T=8.4e-3).params["a"],
    "compare_laws": lambda: [r.name for r in ji.compare_laws(
        m=0.0027, v0=[1.0, 1.4, 1.9, 2.4], e=[0.95, 0.94, 0.936, 0.912], progress=False)],
}
t0 = time.perf_counter()
out = calls[what]()
jax.block_until_ready(out) if not isinstance(out, list) else None
print(json.dumps({"total": time.perf_counter() - start, "call": time.perf_counter() - t0}))
"""


def _fresh(what: str) -> dict:
    env = dict(os.environ, JAXIMPACT_CACHE_DIR="", JAXIMPACT_PROGRESS="off")
    env.pop("XLA_FLAGS", None)
    out = subprocess.run(
        [sys.executable, "-c", CHILD, what], capture_output=True, text=True, env=env, check=True
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def _scipy_impact(v0, rtol):
    import numpy as np
    from scipy.integrate import solve_ivp

    def rhs(t, y):
        x = max(y[0], 0.0)
        return [y[1], -C * x**1.5 * (1 + A * y[1]) / M]

    def surface(t, y):
        return y[0]

    surface.terminal, surface.direction = True, -1
    sol = solve_ivp(rhs, (0.0, 1.0), [0.0, v0], "DOP853", events=surface, rtol=rtol, atol=1e-14)
    return -float(np.asarray(sol.y_events[0])[0, 1]) / v0


def _bare_diffrax(law):
    """The least an integrated impact can cost in diffrax: the same nondimensional contact
    (`law.dynamics`), Tsit5 at rtol 1e-12, one terminal event at X = 0 after the start, no
    phases, peaks or checks. Returns e and the number of steps."""
    import diffrax as dfx
    import jax.numpy as jnp
    import optimistix as optx

    dynamics = law.dynamics(m=M, v0=V0, g=0.0)
    term = dfx.ODETerm(lambda t, y, args: dynamics.rhs(y, True))
    event = dfx.Event(
        lambda t, y, args, **kwargs: y[0] - jnp.where(t < 0.1, -1.0, 0.0),
        root_finder=optx.Newton(rtol=1e-13, atol=1e-13),
    )
    sol = dfx.diffeqsolve(
        term,
        dfx.Tsit5(),
        0.0,
        100.0,
        None,
        dynamics.y0(),
        stepsize_controller=dfx.PIDController(rtol=1e-12, atol=1e-12),
        event=event,
        max_steps=4096,
        throw=False,
    )
    return -dynamics.velocity(sol.ys[-1]), sol.stats["num_steps"]


def main():
    import jax

    jax.config.update("jax_enable_x64", True)
    import jax.numpy as jnp

    import jaximpact as ji
    from jaximpact import closed_forms

    loads = [load_average()]
    exact = float(closed_forms.hunt_crossley_restitution(A * V0))

    def f(x, v, p):
        return p["c"] * x**1.5 * (1 + p["a"] * v)

    law = ji.custom_law(f, c=C, a=A)
    one = jax.jit(lambda c: ji.impact(law.replace(c=c), m=M, v0=V0).e)
    e_jax = float(one(C))
    t_jax = time_call(one, C)[0]
    # the loosest scipy rtol whose e is within 1e-9 of the exact value
    for rtol in (1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13):
        e_scipy = _scipy_impact(V0, rtol)
        if abs(e_scipy - exact) <= 1e-9:
            break
    t_scipy = time_call(_scipy_impact, V0, rtol, rounds=5)[0]
    floor = jax.jit(lambda c: _bare_diffrax(law.replace(c=c)))
    e_floor, steps_floor = floor(C)
    t_floor = time_call(floor, C)[0]
    # jax.grad of e: the default (the forward-mode Jacobian, transposed) against diffrax's
    # reverse mode through the same solve, and central differences of the eager impact
    import diffrax as dfx

    def e_of(c, a, adjoint=None):
        return ji.impact(law.replace(c=c, a=a), m=M, v0=V0, adjoint=adjoint).e

    grad_default = jax.jit(jax.grad(e_of, argnums=1))
    grad_reverse = jax.jit(
        jax.grad(lambda c, a: e_of(c, a, dfx.RecursiveCheckpointAdjoint()), argnums=1)
    )
    d_default, d_reverse = float(grad_default(C, A)), float(grad_reverse(C, A))
    d_fd = (e_of(C, A * (1 + 1e-6)) - e_of(C, A * (1 - 1e-6))) / (2e-6 * A)
    t_grad = time_call(grad_default, C, A)[0]
    t_grad_reverse = time_call(grad_reverse, C, A)[0]
    loads.append(load_average())
    speeds = jnp.linspace(1.0, 3.0, 1000)
    many = jax.jit(jax.vmap(lambda v: ji.impact(law, m=M, v0=v).e))
    t_many = time_call(many, speeds, rounds=3)[0] / speeds.size
    e_many = many(speeds)
    exact_many = closed_forms.hunt_crossley_restitution(A * speeds)
    err_many = float(jnp.max(jnp.abs(e_many - exact_many)))
    loads.append(load_average())

    bare = min(_fresh("bare")["total"] for _ in range(2))
    firsts = {what: _fresh(what) for what in ("impact", "grad", "calibrate", "compare_laws")}
    floors = {what: _fresh(what) for what in ("diffrax_solve", "diffrax_grad")}
    loads.append(load_average())

    rows = [
        [
            "one jitted impact (user's law)",
            f"{t_jax * 1e6:.0f} µs, e error {abs(e_jax - exact):.1e}",
            f"DOP853 rtol {rtol:g}: {t_scipy * 1e6:.0f} µs, e error {abs(e_scipy - exact):.1e}",
            f"{t_scipy / t_jax:.0f}x",
            ">= 50x",
        ],
        [
            "floor: a bare diffrax solve of the same contact (Tsit5, rtol 1e-12, one event)",
            f"{t_floor * 1e6:.0f} µs, {int(steps_floor)} steps, e error "
            f"{abs(float(e_floor) - exact):.1e}",
            f"{t_scipy * 1e6:.0f} µs",
            f"{t_scipy / t_floor:.0f}x",
            "-",
        ],
        [
            "one jitted `jax.grad` of e by a (user's law)",
            f"{t_grad * 1e6:.0f} µs (forward Jacobian, transposed), de/da {d_default:.9f}",
            f"diffrax's reverse mode: {t_grad_reverse * 1e6:.0f} µs, de/da {d_reverse:.9f}; "
            f"central difference {float(d_fd):.9f}",
            f"{t_grad_reverse / t_grad:.1f}x",
            "-",
        ],
        [
            "per impact, vmap of 1,000",
            f"{t_many * 1e6:.1f} µs, max e error {err_many:.1e}",
            f"{t_scipy * 1e6:.0f} µs",
            f"{t_scipy / t_many:.0f}x",
            ">= 500x",
        ],
    ]
    targets = {"impact": 1.5, "grad": 4.0, "calibrate": 4.0, "compare_laws": 10.0}
    for what, out in firsts.items():
        extra = out["total"] - bare
        reached = "yes" if extra <= targets[what] else "no"
        rows.append(
            [
                f"first {what} in a fresh process, no cache",
                f"{out['total']:.1f} s (call {out['call']:.1f} s)",
                f"bare JAX process {bare:.1f} s",
                f"+{extra:.1f} s ({reached})",
                f"within {targets[what]:g} s" if what != "compare_laws" else "within 10 s",
            ]
        )
    for what, label in (("diffrax_solve", "solve"), ("diffrax_grad", "grad")):
        out = floors[what]
        rows.append(
            [
                f"floor: first {label} of a bare diffrax contact (Tsit5, one event) in a "
                "fresh process",
                f"{out['total']:.1f} s (call {out['call']:.1f} s)",
                f"bare JAX process {bare:.1f} s",
                f"+{out['total'] - bare:.1f} s",
                "-",
            ]
        )
    text = "\n".join(
        [
            "# The general path: a user's law against issue 23's targets",
            "",
            "Generated by `python benchmarks/general_path.py`. The user's law "
            "`c * x**1.5 * (1 + a * v)` as written (c = 2e6, a = 0.3, m = 1 kg, v0 = 2.5 m/s), "
            "float64, default options (Tsit5, rtol 1e-12 for a user's law); exact e from the "
            "Hunt-Crossley closed form. Ratios are measured in one process; first calls in "
            "fresh processes without the persistent cache (the compare_laws row is the "
            "whole call, not a difference).",
            "",
            machine_markdown(machine(), loads),
            "",
            table(["what", "jaximpact", "reference", "ratio / extra", "target"], rows),
            "",
        ]
    )
    write_report(os.path.join(HERE, "general_path.md"), text)


if __name__ == "__main__":
    main()
