"""`jaximpact.impact` against the scipy reference, statuses, gravity, histories, vmap, errors."""

import functools
import json
import math
import os
import subprocess
import sys
import textwrap
import warnings

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import (
    PAPER_IDS,
    PAPER_SETS,
    V0,
    M,
    assert_finite,
    assert_rel,
    rel_err,
    result_fields,
    solver,
)
from reference import reference_impact, reference_trajectory

import jaximpact as ji

SEPARATIONS = ("force", "penetration")
# x^1.5 laws: the default rtol 1e-10 leaves up to 1.3e-8 in e (hertz_modified, penetration
# criterion; 3.5e-9 for the others), so the 1e-8 comparison runs them at rtol 1e-11
HERTZ = ("hertz_viscous", "hertz_modified", "hertz_rate", "hunt_crossley")
STATUS = {
    "separated": ji.Status.separated,
    "stuck": ji.Status.stuck,
    "captured": ji.Status.captured,
}


def rtol_for(name):
    return 1e-11 if name in HERTZ else 1e-10


@functools.cache
def reference(name, params_items, separation, g=0.0, m=M, v0=V0):
    return reference_impact(name, dict(params_items), m=m, v0=v0, separation=separation, g=g)


# ------------------------------------------------------------- (a) against scipy


def check_against_reference(result, ref, rtol, what):
    assert int(result["status"]) == STATUS[ref["status"]], what
    errors = {}
    for key in ("e", "T", "x_max", "t_max"):
        errors[key] = assert_rel(result[key], ref[key], rtol, f"{what} {key}")
    # the reference's F_max is the largest of 2000 samples per phase: a lower bound,
    # measured up to 7e-8 below the true peak
    assert result["F_max"] >= ref["F_max"] * (1 - rtol), what
    errors["F_max"] = assert_rel(result["F_max"], ref["F_max"], 1e-6, f"{what} F_max")
    return errors


# fast: one Hertz-family law under the force criterion and one dry-force law under the
# penetration criterion; every other (law, criterion) is a compilation each (slow group)
FAST_PAPER_SETS = {("hertz_rate", "force"), ("bingham", "penetration")}


@pytest.mark.parametrize(
    "row, separation",
    [
        pytest.param(
            row,
            separation,
            marks=[] if (row[0], separation) in FAST_PAPER_SETS else [pytest.mark.slow],
            id=f"{row_id}-{separation}",
        )
        for row, row_id in zip(PAPER_SETS, PAPER_IDS, strict=True)
        for separation in SEPARATIONS
    ],
)
def test_paper_sets_match_scipy(row, separation):
    name, params, _, _ = row
    ref = reference(name, tuple(params.items()), separation)
    result = solver(name, separation, rtol=rtol_for(name))(params)
    check_against_reference(result, ref, 1e-8, f"{name} {separation}")
    assert_finite(result, name)
    assert int(result["status"]) == ji.Status.separated or name == "maxwell"


@pytest.mark.parametrize(
    "row, separation",
    [
        pytest.param(
            row,
            separation,
            marks=[] if (row[0], separation) == ("bingham", "penetration") else [pytest.mark.slow],
            id=f"{row_id}-{separation}",
        )
        for row, row_id in zip(PAPER_SETS, PAPER_IDS, strict=True)
        for separation in SEPARATIONS
    ],
)
def test_paper_sets_at_default_rtol(row, separation):
    """What the default `rtol=1e-10` gives (a compilation per law and criterion; fast for
    bingham's penetration solve, which test_paper_sets_match_scipy compiles anyway)."""
    name, params, _, _ = row
    ref = reference(name, tuple(params.items()), separation)
    result = solver(name, separation)(params)
    # measured worst: 1.3e-8 (hertz_modified, penetration, e); 1e-10 elsewhere off Hertz
    check_against_reference(result, ref, 3e-8 if name in HERTZ else 1e-9, name)


@pytest.mark.parametrize(
    "separation", ["force", pytest.param("penetration", marks=pytest.mark.slow)]
)
def test_kelvin_voigt_default_is_the_closed_form(separation):
    params = dict(c=2e6, b=400.0)
    law = ji.law("kelvin_voigt", **params)
    result = ji.impact(law, m=M, v0=V0, separation=separation)
    assert result.path == "closed_form" and int(result.num_steps) == 0
    ref = reference("kelvin_voigt", tuple(params.items()), separation)
    check_against_reference(
        {k: getattr(result, k) for k in ("e", "T", "x_max", "t_max", "F_max", "status")},
        ref,
        1e-10,
        f"closed form {separation}",
    )
    integrated = ji.impact(law, m=M, v0=V0, separation=separation, method="integrate")
    assert integrated.path == "integrated"


@pytest.mark.parametrize(
    "row",
    [
        pytest.param(row, marks=[] if row[0] == "hertz_rate" else [pytest.mark.slow])
        for row in PAPER_SETS
    ],
    ids=PAPER_IDS,
)
def test_dissipated_energy_and_exit_speed(row):
    for name, params, _, _ in [row]:
        r = solver(name, rtol=rtol_for(name))(params)
        assert_rel(r["v_out"], -r["e"] * V0, 1e-14, f"{name} v_out")
        kinetic = 0.5 * M * V0**2
        assert_rel(r["dissipated"], kinetic * (1 - r["e"] ** 2), 1e-13, name, atol=1e-15 * kinetic)
        assert 0 < r["t_max"] < r["T"] and r["x_max"] > 0 and r["num_steps"] > 0


# ---------------------------------------------------------------------- (b) statuses


@pytest.mark.slow  # test_statuses_are_reported_in_words has a stuck bingham too
def test_bingham_with_a_large_dry_force_sticks():
    params = dict(c=2e6, b=200.0, P=5000.0)
    ref = reference("bingham", tuple(params.items()), "force")
    assert ref["status"] == "stuck"
    for separation in SEPARATIONS:
        r = solver("bingham", separation)(params)
        assert_finite(r, "stuck bingham")
        assert int(r["status"]) == ji.Status.stuck
        assert r["e"] == 0.0 and r["v_out"] == 0.0
        # stuck at maximum compression: T is the instant the body came to rest
        assert_rel(r["T"], r["t_max"], 1e-14, "stuck T")
        assert_rel(r["T"], ref["T"], 1e-9, "stuck T vs scipy")
        assert_rel(r["x_max"], ref["x_max"], 1e-9, "stuck x_max vs scipy")
        assert_rel(r["dissipated"], 0.5 * M * V0**2, 1e-14, "all energy dissipated")


OVERDAMPED_KV = dict(c=1e4, b=1000.0)  # damping ratio 5


@pytest.mark.parametrize(
    "method", [pytest.param("integrate", marks=pytest.mark.slow), "closed_form"]
)
def test_overdamped_kelvin_voigt_is_captured_under_penetration(method):
    r = solver("kelvin_voigt", "penetration", method=method)(OVERDAMPED_KV, m=1.0, v0=1.0)
    assert (int(r["num_steps"]) == 0) == (method == "closed_form")
    assert_finite(r, "captured KV")
    assert int(r["status"]) == ji.Status.captured
    assert r["e"] == 0.0 and r["v_out"] == 0.0
    assert r["T"] > r["t_max"] > 0
    ref = reference("kelvin_voigt", tuple(OVERDAMPED_KV.items()), "penetration", m=1.0, v0=1.0)
    assert ref["status"] == "captured"
    assert_rel(r["x_max"], ref["x_max"], 1e-9, "x_max")
    # T (the rest time): test_closed_forms.py::test_overdamped_rest_time*


@pytest.mark.parametrize("method", [pytest.param("integrate", marks=pytest.mark.slow), "auto"])
def test_overdamped_kelvin_voigt_separates_under_force(method):
    """The force criterion ends every Kelvin-Voigt contact, over-damped ones included."""
    r = solver("kelvin_voigt", "force", method=method)(OVERDAMPED_KV, m=1.0, v0=1.0)
    ref = reference("kelvin_voigt", tuple(OVERDAMPED_KV.items()), "force", m=1.0, v0=1.0)
    assert int(r["status"]) == ji.Status.separated
    assert_rel(r["e"], ref["e"], 1e-7, "e")  # e = 0.0093: absolute error ~2e-10
    # ill-conditioned: the force crosses zero with slope dF/dt = c v_out, v_out = -e v0
    # small, so dT = dF / (c e v0): measured 2.0e-7 at rtol 1e-10 (the closed form: 2e-14)
    assert_rel(r["T"], ref["T"], 1e-8 if method == "auto" else 1e-6, "T")


@pytest.mark.parametrize(
    "separation", ["force", pytest.param("penetration", marks=pytest.mark.slow)]
)
def test_overdamped_maxwell_is_captured(separation):
    """b = 100 << sqrt(m c)/2: the dashpot stops the body, the spring relaxes, no rebound;
    the body stops at x = m v0 / b (momentum m v0 = integral of F = b x_final)."""
    params = dict(c=2e6, b=100.0)
    r = solver("maxwell", separation)(params)
    assert_finite(r, "captured maxwell")
    assert int(r["status"]) == ji.Status.captured
    assert r["e"] == 0.0
    assert 0 < r["T"] < 1.0
    # the creep is cut where |V| + |F| falls below rest_tol = 1e-7 (units of v0 and
    # m v0^2/x*), so x_max is short of its limit by about that much
    assert_rel(r["x_max"], M * V0 / 100.0, 1e-6, "x_max = m v0 / b")


def test_statuses_are_reported_in_words():
    r = ji.impact(ji.law("bingham", c=2e6, b=200.0, P=5000.0), m=M, v0=V0)
    assert r.status_name == "stuck" and not bool(r.separated)
    r = ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=M, v0=V0, rtol=1e-11)
    assert r.status_name == "separated" and bool(r.separated)


def test_throw_raises_when_not_separated():
    law = ji.law("bingham", c=2e6, b=200.0, P=5000.0)
    with pytest.raises(Exception, match="did not end in separation"):
        jax.block_until_ready(ji.impact(law, m=M, v0=V0, throw=True).e)


# ----------------------------------------------------------------------- (c) gravity


@pytest.mark.parametrize(
    "name",
    # Bingham's closed form with gravity: tests/laws/test_closed_forms_linear.py
    ["hertz_rate", pytest.param("bingham", marks=pytest.mark.slow), "maxwell"],
)
def test_gravity_matches_scipy(name):
    params = next(p for n, p, _, _ in PAPER_SETS if n == name)
    r = solver(name, rtol=rtol_for(name))(params, g=9.81)
    ref = reference(name, tuple(params.items()), "force", g=9.81)
    assert_finite(r, name)
    check_against_reference(r, ref, 1e-8, f"{name} with gravity")
    without = solver(name, rtol=rtol_for(name))(params)
    assert r["x_max"] > without["x_max"] and r["e"] < without["e"]


def test_gravity_keeps_the_closed_form():
    """Kelvin-Voigt under gravity is exact too (tests/laws/test_closed_forms_linear.py)."""
    law = ji.law("kelvin_voigt", c=2e6, b=400.0)
    r = ji.impact(law, m=M, v0=V0, g=9.81)
    assert r.path == "closed_form" and int(r.num_steps) == 0
    ref = reference("kelvin_voigt", (("c", 2e6), ("b", 400.0)), "force", g=9.81)
    assert_rel(r.e, ref["e"], 1e-9, "KV e with gravity")
    assert_rel(r.T, ref["T"], 1e-9, "KV T with gravity")


@pytest.mark.parametrize(
    "separation", ["force", pytest.param("penetration", marks=pytest.mark.slow)]
)  # penetration's program is its own (the fast suite: 3 minutes)
def test_slow_impact_under_gravity_is_captured(separation):
    """v0 = 0.1 m/s on a soft, damped spring: the body sinks to x = m g / c and the spring
    never lifts it back; the contact ends when the body stops moving out (v back to 0)."""
    params = dict(c=1e4, b=50.0)
    r = solver("kelvin_voigt", separation)(params, m=1.0, v0=0.1, g=9.81)
    ref = reference("kelvin_voigt", tuple(params.items()), separation, g=9.81, m=1.0, v0=0.1)
    assert_finite(r, "slow impact")
    assert ref["status"] == "captured"
    assert int(r["status"]) == ji.Status.captured
    assert r["e"] == 0.0
    assert_rel(r["T"], ref["T"], 1e-8, "T (v back to 0)")
    assert_rel(r["x_max"], ref["x_max"], 1e-8, "x_max")


@pytest.mark.xfail(
    strict=True,
    reason="library bug: over-damped contact resting under gravity never meets rest_tol "
    "(state noise ~beta*rtol > 1e-9) and a rest event in an early phase does not stop "
    "the later phases: status out_of_steps after 4096 steps, T = 11.2 s",
)
@pytest.mark.parametrize("v0", [0.01, 0.1])
def test_slow_overdamped_impact_under_gravity_is_captured(v0):
    r = solver("kelvin_voigt", "force")(OVERDAMPED_KV, m=1.0, v0=v0, g=9.81)
    assert_finite(r, "slow over-damped impact")
    assert r["e"] == 0.0
    assert int(r["status"]) == ji.Status.captured, int(r["status"])
    # settles on the slow mode, rate 0.101/t*, t* = 0.01 s: well under 1 s
    assert r["T"] < 1.0


# ---------------------------------------------------------------------- (d) histories


@pytest.mark.parametrize("name", ["hertz_rate", pytest.param("bingham", marks=pytest.mark.slow)])
def test_histories(name):
    params = next(p for n, p, _, _ in PAPER_SETS if n == name)
    plain = solver(name, rtol=rtol_for(name))(params)
    T, t_max = float(plain["T"]), float(plain["t_max"])
    inside = np.linspace(0.0, T, 23)[1:-1]
    after = T * np.array([1.0 + 1e-9, 1.3, 2.0])
    # diffrax wants increasing times: sort, and find the special instants again
    ts = np.sort(np.concatenate([[-0.1 * T, 0.0, t_max, T], inside, after]))
    i_max, i_T = int(np.searchsorted(ts, t_max)), int(np.searchsorted(ts, T))
    i_in = np.flatnonzero((ts > 0) & (ts < T) & (ts != t_max))
    r = ji.impact(ji.law(name, **params), m=M, v0=V0, ts=ts, rtol=rtol_for(name))
    h = {
        k: np.asarray(getattr(r, k))
        for k in ("ts", "x", "v", "F", "T", "t_max", "x_max", "v_out", "status")
    }
    assert h["x"].shape == h["v"].shape == h["F"].shape == ts.shape
    assert_rel(h["ts"], ts, 1e-14, "ts round trip")
    assert_rel(h["T"], T, 1e-13, "same T with ts=")
    assert_rel(h["t_max"], t_max, 1e-13, "same t_max with ts=")
    # approach: free flight towards the surface, no force
    assert_rel(h["x"][0], -0.1 * T * V0, 1e-12, "x before touch")
    assert h["F"][0] == 0.0 and h["v"][0] == V0
    # first touch
    assert h["x"][1] == 0.0 and h["v"][1] == V0
    # maximum compression
    assert_rel(h["x"][i_max], h["x_max"], 1e-10, "x(t_max) = x_max")
    assert abs(h["v"][i_max]) <= 1e-9 * V0, h["v"][i_max]
    assert h["x"].max() <= h["x_max"] * (1 + 1e-12)
    # separation under the force criterion: the force is back to zero
    F_max = np.max(h["F"])
    assert abs(h["F"][i_T]) <= 1e-8 * F_max, h["F"][i_T] / F_max
    # inside the contact: the scipy trajectory
    x_ref, v_ref = reference_trajectory(name, params, m=M, v0=V0, ts=ts[i_in])
    assert_rel(h["x"][i_in], x_ref, 0, "x(t) inside", atol=1e-8 * h["x_max"])
    assert_rel(h["v"][i_in], v_ref, 0, "v(t) inside", atol=1e-8 * V0)
    assert np.all(h["F"][i_in] > 0)
    # after separation: free flight at v_out, no force
    x_T, v_out = h["x"][i_T], h["v_out"]
    assert_rel(h["v"][-3:], np.full(3, v_out), 1e-12, "v after T")
    assert_rel(h["x"][-3:], x_T + v_out * (after - T), 0, "x after T", atol=1e-12 * V0 * T)
    assert np.all(h["F"][-3:] == 0.0)
    assert h["x"][-1] < 0  # left the surface


# --------------------------------------------------------------------------- (e) vmap


@pytest.mark.slow
def test_vmap_over_stiffness_equals_the_loop():
    cs = jnp.array([1e5, 2e6, 3e7, 1e9])
    batched = jax.vmap(
        lambda c: result_fields(
            ji.impact(
                ji.law("hertz_rate", c=c, b1=800.0), m=M, v0=V0, rtol=1e-11, method="integrate"
            )
        )
    )(cs)
    for i, c in enumerate(np.asarray(cs)):
        one = solver("hertz_rate", rtol=1e-11)(dict(c=c, b1=800.0))
        for key in ("e", "T", "x_max", "status"):
            assert_rel(batched[key][i], one[key], 1e-12, f"vmap {key} at c={c}")


@pytest.mark.slow  # 7 s: bingham's integrated path under vmap (the fast suite: 3 minutes)
def test_vmap_over_speed_equals_the_loop_with_stuck_members():
    """One stuck member (small v0: the dry force holds it) must not spoil the batch."""
    v0s = jnp.array([0.1, 0.3, 1.0, 2.5, 10.0])
    params = dict(c=2e6, b=200.0, P=400.0)
    law = ji.law("bingham", **params)
    # the integrated path (bingham's default is now its closed form, whose vmap with stuck
    # members is tests/laws/test_closed_forms_linear.py::test_impact_fields_dissipated_...)
    batched = jax.vmap(
        lambda v0: result_fields(ji.impact(law, m=M, v0=v0, rtol=1e-10, method="integrate"))
    )(v0s)
    statuses = np.asarray(batched["status"])
    assert list(statuses[:2]) == [ji.Status.stuck] * 2
    assert list(statuses[2:]) == [ji.Status.separated] * 3
    assert_finite(batched, "vmapped bingham")
    for i, v0 in enumerate(np.asarray(v0s)):
        one = solver("bingham")(params, v0=v0)
        for key in ("e", "T", "x_max", "status"):
            assert_rel(batched[key][i], one[key], 1e-12, f"vmap {key} at v0={v0}")
    ref = reference("bingham", tuple(params.items()), "force", v0=0.1)
    assert_rel(batched["T"][0], ref["T"], 1e-9, "stuck T at v0=0.1")


# -------------------------------------------------------------------- (f) input errors


KV = ji.law("kelvin_voigt", c=2e6, b=400.0)


@pytest.mark.parametrize(
    "kwargs, needle",
    [
        (dict(m=0.0, v0=V0), "mass m must be a finite number > 0 kg, got 0.0"),
        (dict(m=-1.0, v0=V0), "mass m must be a finite number > 0 kg, got -1.0"),
        (dict(m=float("nan"), v0=V0), "mass m must be a finite number > 0"),
        (dict(m=M, v0=0.0), "impact speed v0 must be a finite number > 0 m/s, got 0.0"),
        (dict(m=M, v0=-2.5), "impact speed v0 must be a finite number > 0 m/s, got -2.5"),
        (dict(m=M, v0=V0, g=-9.81), "gravity g must be a finite number >= 0"),
        (dict(m=M, v0=V0, separation="contact"), "separation must be one of"),
        (dict(m=M, v0=V0, method="exact"), "method must be one of"),
        (dict(m=np.ones(2), v0=V0), "use jax.vmap for a batch"),
        (dict(m=M, v0=V0, ts=np.ones((2, 2))), "ts must be a 1-D array"),
    ],
)
def test_bad_input_is_a_one_line_value_error(kwargs, needle):
    with pytest.raises(ValueError) as excinfo:
        ji.impact(KV, **kwargs)
    message = str(excinfo.value)
    assert needle in message, message
    assert "\n" not in message
    if "separation" in kwargs:
        assert "'force'" in message and "'penetration'" in message and "'contact'" in message


def test_no_closed_form_is_a_value_error():
    with pytest.raises(ValueError, match="no closed form for law 'hertz_rate'"):
        ji.impact(ji.law("hertz_rate", c=2e6, b1=800.0), m=M, v0=V0, method="closed_form")


def test_not_a_law_is_a_type_error():
    with pytest.raises(TypeError, match="needs a law from jaximpact.law"):
        ji.impact({"c": 2e6}, m=M, v0=V0)


def test_bad_mass_under_jit_is_nan_and_invalid():
    """Not an error under `jit`: one bad member must not abort a batch (DESIGN.md, "Off the
    curves"; tests/solve/test_invalid_members.py has the batches)."""
    solve = jax.jit(lambda m: ji.impact(KV, m=m, v0=V0))
    assert_rel(solve(M).e, ji.impact(KV, m=M, v0=V0).e, 1e-15, "jit e")
    bad = solve(-1.0)
    assert np.isnan(float(bad.e)) and np.isnan(float(bad.T)) and bad.status_name == "invalid"


# ------------------------------------------------------------------ (g) custom laws


def kelvin_voigt_force(x, v, p):
    return p["c"] * x + p["b"] * v


def hertz_rate_force(x, v, p):
    return p["c"] * ji.safe_pow(x, 1.5) + p["b1"] * ji.safe_pow(x, 0.5) * v


@pytest.mark.parametrize(
    "fn, name, params, separation",
    [
        pytest.param(
            kelvin_voigt_force,
            "kelvin_voigt",
            dict(c=2e6, b=400.0),
            "force",
            marks=pytest.mark.slow,
        ),
        pytest.param(
            kelvin_voigt_force,
            "kelvin_voigt",
            dict(c=2e6, b=400.0),
            "penetration",
            marks=pytest.mark.slow,
        ),
        pytest.param(  # 7 s of compiling; tests/laws/test_custom_laws.py keeps the check
            hertz_rate_force,
            "hertz_rate",
            dict(c=2e6, b1=800.0),
            "force",
            marks=pytest.mark.slow,
        ),
        pytest.param(
            hertz_rate_force,
            "hertz_rate",
            dict(c=2e6, b1=800.0),
            "penetration",
            marks=pytest.mark.slow,
        ),
    ],
    ids=[
        "kelvin_voigt-force",
        "kelvin_voigt-penetration",
        "hertz_rate-force",
        "hertz_rate-penetration",
    ],
)
def test_custom_law_reproduces_the_builtin(fn, name, params, separation):
    rtol = rtol_for(name)
    custom = ji.custom_law(fn, **params)
    custom = ji.impact(custom, m=M, v0=V0, separation=separation, rtol=rtol)
    custom = {k: np.asarray(getattr(custom, k)) for k in ("e", "T", "x_max", "t_max", "status")}
    builtin = solver(name, separation, rtol=rtol)(params)
    for key in ("e", "T", "x_max", "t_max"):
        # measured worst: 2.3e-8 (hertz_rate, penetration, e)
        assert_rel(custom[key], builtin[key], 1e-7, f"custom {name} {separation} {key}")
    assert int(custom["status"]) == ji.Status.separated


# ---------------------------------------------------------------------- (h) float32


FLOAT32_SCRIPT = textwrap.dedent(
    """
    import json
    import warnings
    import jax
    import jaximpact as ji
    assert not jax.config.jax_enable_x64
    out = {}
    for label, name, params, kw in [
        ("hertz_rate", "hertz_rate", dict(c=2e6, b1=800.0), {}),
        ("kelvin_voigt", "kelvin_voigt", dict(c=2e6, b=400.0), {}),
    ]:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r = ji.impact(ji.law(name, **params), m=1.0, v0=2.5, method="integrate", **kw)
        out[label] = dict(dtype=str(r.e.dtype), e=float(r.e), T=float(r.T),
                          x_max=float(r.x_max), status=int(r.status),
                          steps=int(r.num_steps), warnings=[str(w.message) for w in caught])
    print(json.dumps(out))
    """
)


@pytest.mark.slow
def test_float32_without_x64():
    env = dict(os.environ, JAX_ENABLE_X64="0", JAX_PLATFORMS="cpu")
    proc = subprocess.run(
        [sys.executable, "-c", FLOAT32_SCRIPT],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    for label, r in out.items():
        assert r["dtype"] == "float32", label
        assert r["status"] == ji.Status.separated, label
        # the default rtol 1e-11 is raised to 1e-7, which float32 can meet, and says so:
        # about 30 steps instead of about 700 spent chasing rounding noise
        assert any("rtol 1e-11 -> 1e-07" in w for w in r["warnings"]), r["warnings"]
        assert r["steps"] < 100, (label, r["steps"])
        params = next(p for n, p, _, _ in PAPER_SETS if n == label)
        ref = reference(label, tuple(params.items()), "force")
        for key in ("e", "T", "x_max"):
            assert math.isfinite(r[key]), (label, key)
            # measured: 1.2e-6 (hertz_rate e); float32 eps is 1.2e-7
            assert rel_err(r[key], ref[key]) < 1e-4, (label, key, rel_err(r[key], ref[key]))


def test_a_custom_law_that_pulls_is_said_to_be_unphysical():
    """A user's law with F(0, v0) < 0 (it pulls the body in at first touch) gets a warning
    with the force it gave; it once returned e = 4.12 as if it were a result. The same
    function pushing (d < 0) gets none (one compiled law for both)."""
    pull = ji.custom_law(lambda x, v, p: p["k"] * x - p["d"] * v, k=2e6, d=4e4)
    with pytest.warns(UserWarning, match=r"pulls the body in .* -1e\+05 N"):
        ji.impact(pull, m=1.0, v0=2.5, max_steps=64, throw=False)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ji.impact(pull.replace(d=-400.0), m=1.0, v0=2.5, max_steps=64, throw=False)


def test_restitution_does_not_end_on_the_noise_of_its_first_speed():
    """Restitution starts at maximum compression, where a damped law's `V = W - beta X`
    is a cancellation (its noise up to beta rtol X, 1e-12): its "moving in again"
    condition (positive before the event) must not fire on a speed of that size, which
    under another XLA rounding ended an over-damped Kelvin-Voigt (b 25x critical) at
    t_max as captured. It fires at `V = _TURN_NOISE` (1e-10 v0)."""
    from jaximpact._solve import phases

    dyn = ji.law("kelvin_voigt", c=1e4, b=5000.0).dynamics(m=1.0, v0=1.0, g=0.0)
    plan = (phases._TO_PEAK, phases._TO_MAX_COMPRESSION, phases._TO_SEPARATION)
    _, moving_in, _ = phases._event_conditions(dyn, "force", plan, 1e-7)
    x = 0.0199
    for noise in (-1e-12, 0.0, 1e-12, 5e-11):  # W = beta X + noise: V = noise
        y = jnp.stack([jnp.asarray(x), dyn.beta * x + noise])
        assert float(moving_in(0.0, y, phases._TO_SEPARATION)) > 0, noise
    y = jnp.stack([jnp.asarray(x), dyn.beta * x + 1e-9])  # moving in, beyond the noise
    assert float(moving_in(0.0, y, phases._TO_SEPARATION)) < 0


@pytest.mark.slow
@pytest.mark.parametrize("b", [5000.0, 20000.0])
def test_restitution_that_starts_on_rounding_noise_still_separates(monkeypatch, b):
    """At maximum compression an over-damped Kelvin-Voigt's speed `V = W - beta X` (beta
    = 50 at b = 5000) is a cancellation. Compiled another way (XLA's CPU fusion emitters
    off, `_compiling.quick_jit`, at the suite's optimisation level 0) its noise tripped
    restitution's "moving in again" event on the first step: captured at t_max, e = 0.
    It now fires at `V = _TURN_NOISE`, and the impact separates with the closed form's e."""
    from jaximpact._compiling import quick_jit
    from jaximpact._solve import impact as impact_module

    monkeypatch.setattr(
        impact_module, "solve_impact", quick_jit(impact_module.solve_impact.__wrapped__)
    )
    law = ji.law("kelvin_voigt", c=1e4, b=b)  # 25x and 100x critical damping (200 N s/m)
    got = ji.impact(law, m=1.0, v0=1.0, rtol=1e-12, method="integrate", throw=False)
    want = ji.impact(law, m=1.0, v0=1.0)  # Kelvin-Voigt's closed form
    assert got.status_name == "separated"
    # e = 4e-4 and 2.5e-5: the force's zero is crossed with slope c v_out, ill-conditioned
    # (test_closed_forms.py: T to 1e-5 at b = 5000); e here within 1e-6 of itself
    assert abs(float(got.e) - float(want.e)) <= 1e-6 * float(want.e)
