"""Thornton's plastic law and the JKR adhesive law: e(v) on their exact paths against scipy.

For each law, an e(v) sweep over decades of speed (Thornton: v/v_y from 0.5 to 1e4; JKR:
v/V_s from 0.5 to 20) is computed three ways, in this one process:

- jaximpact's exact path (`ji.impact`, path `closed_form`: Thornton's incomplete beta
  function, JKR's energy and a quadrature of T), one jitted impact and a `jax.vmap` of the
  whole sweep;
- jaximpact's integrated path (`method="integrate"`, diffrax with events), the same sweep
  in a `jax.vmap`, as the general path would give it;
- scipy's DOP853 with terminal events (the tests' independent references,
  `tests/laws/test_thornton.py::scipy_thornton`, `tests/laws/test_jkr.py::scipy_jkr`), at
  the loosest rtol whose e is within 1e-9 of the exact one over the sweep, one impact at a
  time.

Each row gives the time per impact and the largest e error against the exact closed form
(the published formulas, checked in the tests against scipy at rtol 1e-13), and the ratio of
scipy's time to jaximpact's. Steel sphere (R = 5 mm) on a rigid flat for Thornton, a
20 µm glass-like sphere for JKR (w = 0.2 J/m^2), as in the tests.

Run: python benchmarks/plastic_adhesive.py (writes benchmarks/plastic_adhesive.md).
"""

import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "tests", "laws"))
from _common import load_average, machine, machine_markdown, table, time_call, write_report  # noqa: E402

SCIPY_RTOLS = (1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13)


def _sweep(law_name):
    """(law, m, speeds, scipy(v0, rtol) -> e, exact(speeds) -> e) of one law."""
    import numpy as np

    from jaximpact import law as ji_law

    if law_name == "thornton":
        import test_thornton as t

        from jaximpact._laws.thornton import thornton_restitution

        speeds = t.V_Y * np.geomspace(0.5, 1e4, 24)

        def reference(v0, rtol):
            return t.scipy_thornton(t.C, t.X_Y, t.M, float(v0), rtol=rtol)["e"]

        def exact(v):
            return np.asarray(thornton_restitution(np.asarray(v) / t.V_Y))

        return t.LAW, t.M, speeds, reference, exact
    if law_name == "dmt":  # no closed form: scipy at rtol 1e-13 is the reference
        import test_dmt as d

        params = d.CASES[0]  # c = m = v0 = 1 units: beta 0.1, the adhesion's group 0.05
        law = ji_law("dmt", **params)
        speeds = np.geomspace(0.6, 3.0, 24)

        def reference(v0, rtol):
            return d.scipy_dmt(**params, m=1.0, v0=float(v0), rtol=rtol)[0]

        def exact(v):
            return np.array([reference(s, 1e-13) for s in np.atleast_1d(v)])

        return law, 1.0, speeds, reference, exact
    import test_jkr as j

    speeds = j.V_S * np.geomspace(0.5, 20.0, 24)

    def reference(v0, rtol):
        return j.scipy_jkr(j.C, j.R, j.W, j.M, float(v0), rtol=rtol)["e"]

    def exact(v):
        ratio = np.asarray(v) / j.V_S
        return np.where(ratio > 1.0, np.sqrt(np.clip(1.0 - ratio**-2.0, 0.0, None)), 0.0)

    return j.LAW, j.M, speeds, reference, exact


def _rows(law_name):
    import jax
    import jax.numpy as jnp
    import numpy as np

    import jaximpact as ji

    law, m, speeds, reference, exact = _sweep(law_name)
    want = exact(speeds)
    v = jnp.asarray(speeds)
    one = jax.jit(lambda v0: ji.impact(law, m=m, v0=v0).e)
    many = jax.jit(jax.vmap(lambda v0: ji.impact(law, m=m, v0=v0).e))
    many_integrated = jax.jit(jax.vmap(lambda v0: ji.impact(law, m=m, v0=v0, method="integrate").e))
    fast_path = ji.impact(law, m=m, v0=float(speeds[-1])).path
    assert fast_path in ("closed_form", "similarity"), fast_path
    label = "exact path" if fast_path == "closed_form" else "gravity table"
    err_one = abs(float(one(v[-1])) - float(want[-1]))
    t_one = time_call(one, v[-1])[0]
    err_many = float(np.max(np.abs(np.asarray(many(v)) - want)))
    t_many = time_call(many, v)[0] / speeds.size
    err_int = float(np.max(np.abs(np.asarray(many_integrated(v)) - want)))
    t_int = time_call(many_integrated, v, rounds=3)[0] / speeds.size
    for rtol in SCIPY_RTOLS:
        got = np.array([reference(s, rtol) for s in speeds])
        err_scipy = float(np.max(np.abs(got - want)))
        if err_scipy <= 1e-9:
            break
    t_scipy = time_call(lambda: [reference(s, rtol) for s in speeds], rounds=3)[0] / speeds.size
    scipy_cell = f"DOP853 rtol {rtol:g}: {t_scipy * 1e6:.0f} µs, e error {err_scipy:.1e}"
    return [
        [
            f"{law_name}: one jitted impact ({label})",
            f"{t_one * 1e6:.1f} µs, e error {err_one:.1e}",
            scipy_cell,
            f"{t_scipy / t_one:.0f}x",
        ],
        [
            f"{law_name}: per impact, vmap of {speeds.size} speeds ({label})",
            f"{t_many * 1e6:.2f} µs, max e error {err_many:.1e}",
            scipy_cell,
            f"{t_scipy / t_many:.0f}x",
        ],
        [
            f"{law_name}: per impact, vmap of {speeds.size} speeds (integrated, diffrax)",
            f"{t_int * 1e6:.1f} µs, max e error {err_int:.1e}",
            scipy_cell,
            f"{t_scipy / t_int:.0f}x",
        ],
    ]


def main():
    import jax

    jax.config.update("jax_enable_x64", True)

    info = machine()
    loads = [load_average()]
    rows = []
    for law_name in ("thornton", "jkr", "dmt"):
        rows += _rows(law_name)
        loads.append(load_average())
    text = "\n".join(
        [
            "# Thornton, JKR and DMT: e(v) on the fast paths against scipy",
            "",
            "Generated by `python benchmarks/plastic_adhesive.py`. e(v) over 24 speeds "
            "(Thornton v/v_y = 0.5 to 1e4, JKR v/V_s = 0.5 to 20, DMT 0.6 to 3 m/s in the "
            "units c = m = 1, beta 0.1, adhesion group 0.05, on law 14's gravity table); errors "
            "against the exact closed form (DMT: scipy at rtol 1e-13); scipy at the loosest "
            "rtol whose e is within 1e-9 over the sweep, "
            "one impact at a time; ratios measured in this one process, float64.",
            "",
            machine_markdown(info, loads),
            "",
            table(["what", "jaximpact", "scipy", "scipy / jaximpact"], rows),
            "",
        ]
    )
    write_report(os.path.join(HERE, "plastic_adhesive.md"), text)


if __name__ == "__main__":
    main()
