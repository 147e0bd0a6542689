"""Maxwell's law (eqs. 10-11) with gravity in closed form
(`closed_forms_linear.maxwell_gravity_impact`, taken by `impact`, batches and `bounce`):
against an independent scipy integrator written here (DOP853, rtol 1e-13, atol 1e-15, with
events), against `impact(method="integrate")` and `bounce(method="integrate")`, and its
gradients against central finite differences.

The reference integrates `X' = V`, `V' = gamma - Phi`, `Phi' = V - mu Phi` (`X = x/x*`,
`V = v/v0`, `Phi = F/(c x*)`, `tau = t/t*`, `t* = sqrt(m/c)`, `x* = v0 t*`,
`mu = sqrt(m c)/b`, `gamma = g t*/v0`), phase by phase as `impact` defines them: compression
until `V = 0`, rest (`|V| + |Phi - gamma| <= rest_tol`) or the horizon `tau_max`; then,
unless the body is held, restitution until separation (`Phi = 0` or `X = 0`), `V` back to
0, rest or the horizon.
"""

import functools
import itertools
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import assert_finite
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

import jaximpact as ji
from jaximpact._laws.closed_forms_linear import maxwell_gravity_impact, maxwell_impact

REST_TOL = 1e-7
TAU_MAX = 1e4  # impact's default horizon (units of t*)
SEPARATIONS = ("force", "penetration")
SEPARATED, CAPTURED = int(ji.Status.separated), int(ji.Status.captured)

# ----------------------------------------------------------------- the scipy reference


def _terminal(fun, direction):
    fun.terminal, fun.direction = True, direction
    return fun


def _walk(rhs, t0, y0, events, pieces, kw):
    """`solve_ivp` from `(t0, y0)` over `pieces`, `(end, max_step)` one after the other,
    until a terminal event: `(t, y, fired, peaks)`, `fired` the index of the terminal
    event that ended it (None: the last piece's end), `peaks` the states at the
    non-terminal events."""
    peaks = []
    for end, max_step in pieces:
        if end <= t0:
            continue
        sol = solve_ivp(rhs, (t0, end), y0, events=events, max_step=max_step, **kw)
        peaks += [
            y
            for k, ev in enumerate(events)
            if not getattr(ev, "terminal", False)
            for y in sol.y_events[k]
        ]
        t0, y0 = sol.t[-1], sol.y[:, -1]
        for k, ev in enumerate(events):
            if getattr(ev, "terminal", False) and sol.t_events[k].size:
                return t0, y0, k, peaks
    return t0, y0, None, peaks


def reference(c, b, m, v0, g, separation, *, tau_max=TAU_MAX, atol=1e-15, refine=False):
    """`dict(e, T, x_max, t_max, F_max, x_end, status, ending)` of one impact (SI);
    `ending`: "separated", "held" (at maximum compression), "back" (v back to 0 inside),
    "rest" (the rest_tol instant) or "horizon" (still sinking in at `tau_max`).

    Events are seen where their function changes sign between steps: near the value of
    gravity at which the body just reaches maximum compression, `V` dips below 0 (and
    `|V| + |Phi - gamma|` below `rest_tol`) for a moment shorter than a step, around
    `V`'s first minimum (where `Phi = gamma` again). `refine` finds that instant first and
    steps through it at 1e-4, and 1e-8 within 1e-5 of it (units of t*)."""
    t_s = math.sqrt(m / c)
    x_s, mu, gamma = v0 * t_s, math.sqrt(m * c) / b, g * t_s / v0
    f_s = c * x_s

    def rhs(tau, y):
        return [y[1], gamma - y[2], y[1] - mu * y[2]]

    kw = dict(method="DOP853", rtol=1e-13, atol=atol)
    pieces = [(tau_max, np.inf)]
    y0 = [0.0, 1.0, 0.0]
    if refine:  # V's first minimum: the force falls back through m g
        falls = _terminal(lambda tau, y: y[2] - gamma, -1)
        t2 = _walk(rhs, 0.0, y0, [falls], pieces, kw)[0]
        pieces = [
            (t2 - 1e-2, np.inf),
            (t2 - 1e-5, 1e-4),
            (t2 + 1e-5, 1e-8),
            (t2 + 1e-2, 1e-4),
            (tau_max, np.inf),
        ]
    rest = _terminal(lambda tau, y: abs(y[1]) + abs(y[2] - gamma) - REST_TOL, -1)
    top = _terminal(lambda tau, y: y[1], -1)

    def peak(tau, y):  # dPhi/dtau, zero at a force peak
        return y[1] - mu * y[2]

    peak.direction = -1
    tau_top, y_top, fired, peaks = _walk(rhs, 0.0, y0, [top, rest, peak], pieces, kw)
    forces = [0.0, y_top[2]] + [y[2] for y in peaks[:1]]
    out = dict(
        x_max=y_top[0] * x_s,
        t_max=tau_top * t_s,
        F_max=max(forces) * f_s,
        e=0.0,
        status=CAPTURED,
        T=tau_top * t_s,
        x_end=y_top[0] * x_s,
    )
    if fired == 1:
        return dict(out, ending="rest")
    if fired is None:
        return dict(out, ending="horizon")
    if y_top[2] - gamma <= 0:
        return dict(out, ending="held")
    if separation == "force":
        leave = _terminal(lambda tau, y: y[2], -1)
    else:
        leave = _terminal(lambda tau, y: y[0], -1)
    back = _terminal(lambda tau, y: y[1], 1)
    y1 = np.array(y_top, dtype=float)
    y1[1] = 0.0
    tau, y, fired, _ = _walk(rhs, tau_top, y1, [leave, back, rest], pieces, kw)
    end = dict(out, T=tau * t_s, x_end=y[0] * x_s)
    if fired == 0:
        return dict(end, e=-y[1], status=SEPARATED, ending="separated")
    return dict(end, ending={1: "back", 2: "rest", None: "horizon"}[fired])


# ------------------------------------------------------ the closed form, compiled once


ROWS = 32


@functools.cache
def closed_batch(separation, tau_max=TAU_MAX):
    """`maxwell_gravity_impact` over a batch of `(c, b, m, v0, g)` columns (padded to a
    multiple of ROWS), with `jac`, d(e, T)/d(c, b) by reverse mode (`jax.grad`)."""

    def one(c, b, m, v0, g):
        def e_and_T(q):
            out = maxwell_gravity_impact(
                q[0], q[1], m, v0, g, separation, rest_tol=REST_TOL, tau_max=tau_max
            )
            return jnp.stack([out["e"], out["T"]]), out

        jac, out = jax.jacrev(e_and_T, has_aux=True)(jnp.stack([c, b]))
        return dict(out, jac=jac)

    compiled = jax.jit(jax.vmap(one))

    def call(*columns):
        columns = [np.atleast_1d(np.asarray(col, float)) for col in columns]
        n = len(columns[0])
        size = -(-n // ROWS) * ROWS
        padded = [jnp.asarray(np.concatenate([col, np.full(size - n, col[0])])) for col in columns]
        return {k: np.asarray(v)[:n] for k, v in compiled(*padded).items()}

    return call


def case(c, mu, m, v0, g):
    """One impact, the damping by `mu = sqrt(m c)/b` (critical at 2)."""
    return (c, math.sqrt(m * c) / mu, m, v0, g)


def gamma_of(c, b, m, v0, g):
    return g * math.sqrt(m / c) / v0


# ------------------------------------------------------------------------ the grids

# fast: light and heavy-ish damping, with gravity that hardly matters (a drop at 2.5 m/s
# on a stiff spring), that matters (a soft, light spring at 0.1 m/s: gamma 0.7) and that
# holds the body (g = 200: gamma 14), plus the creeping, over-damped and g = 0 cases
FAST = [
    case(2e6, 0.7, 1.0, 2.5, 9.81),  # the paper's c = 2e6, b = 2020: separates
    case(2e6, 0.1, 1.0, 2.5, 9.81),
    case(1e3, 0.1, 0.05, 0.1, 9.81),  # soft and light: gravity matters
    case(1e3, 0.7, 0.05, 0.1, 9.81),
    case(1e3, 0.1, 0.05, 0.1, 200.0),
    case(2e6, 1.9, 1.0, 2.5, 9.81),  # would rest without gravity: sinks in for ever
    case(1e5, 3.0, 1.0, 1.0, 9.81),  # over-damped
    case(2e6, 0.7, 1.0, 2.5, 0.0),
]


def grid():
    """Light to over-damping (both regimes and critical), g = 0, 9.81 and 200 m/s^2,
    stiff to soft springs, heavy to light bodies, fast to slow impacts."""
    mus = (0.1, 0.5, 1.0, 1.5, 1.9, 1.99, 2.0, 3.0, 10.0)
    product = itertools.product((1e3, 1e5, 2e6), (0.05, 1.0), (0.1, 1.0, 2.5), (0.0, 9.81, 200.0))
    return [case(c, mu, m, v0, g) for (c, m, v0, g), mu in itertools.product(product, mus)]


def near_threshold():
    """Gravity within a hair of the value at which the body just reaches maximum
    compression (`V`'s first minimum is 0): there it comes to rest while compressing, just
    after maximum compression, or creeps in; every rest branch with gravity. (Below
    `mu = 0.5` or so there is no such value: light damping always brings the body back.)"""
    cases = []
    for mu in (0.6, 1.0, 1.6):
        s = mu / 2
        w = math.sqrt(1 - s * s)

        def v_min(gamma, s=s, w=w):  # V at Psi's second zero, Psi from (-gamma, 1)
            t1 = (math.pi - math.atan2(-gamma * w, 1 - s * gamma)) % math.pi / w
            t2 = t1 + math.pi / w
            a, p = -gamma, 1 - s * gamma  # Psi = exp(-s t)(a cos + p sin/w)
            dpsi = math.exp(-s * t2) * (
                (p - s * a) * math.cos(w * t2) - (a * w + s * p / w) * math.sin(w * t2)
            )
            return dpsi + 2 * s * gamma

        gammas = np.geomspace(1e-6, 1e3, 400)
        k = int(np.argmax([v_min(gamma) > 0 for gamma in gammas]))
        gamma_star = brentq(v_min, gammas[k - 1], gammas[k], xtol=1e-16, rtol=1e-15)
        for factor in (1 - 1e-3, 1 - 1e-6, 1 - 1e-8, 1 + 1e-8, 1 + 1e-6, 1 + 1e-3):
            gamma = gamma_star * factor  # v0 = 1, m = 1, c = 1e4: t* = 0.01
            cases.append(case(1e4, mu, 1.0, 1.0, gamma / 0.01))
    return cases


ERRORS = {}


def check(cases, separation, refine=False):
    """Status and fields against the reference: e, T, x_max, t_max, F_max to 1e-9
    relative (e against max(e, 1e-3)), x_end to 1e-9 of x_max; rest instants to 1e-7
    (the reference's own error at atol 1e-15: the state is 1e-7 of its scale there)."""
    got = closed_batch(separation)(*zip(*cases, strict=True))
    assert_finite(got, "maxwell with gravity")
    errors = dict(e=0.0, T=0.0, x_max=0.0, t_max=0.0, F_max=0.0, x_end=0.0, T_rest=0.0)
    endings = set()
    for i, (c, b, m, v0, g) in enumerate(cases):
        want = reference(c, b, m, v0, g, separation, refine=refine)
        endings.add(want["ending"])
        what = f"{separation} c={c:g} b={b:.6g} m={m} v0={v0} g={g:.6g}: {want}"
        assert int(got["status"][i]) == want["status"], f"{what}, status {got['status'][i]}"
        errors["e"] = max(errors["e"], abs(got["e"][i] - want["e"]) / max(want["e"], 1e-3))
        rest = want["ending"] == "rest"
        for key in ("T", "t_max"):
            err = abs(got[key][i] / want[key] - 1.0)
            if rest and (key == "T" or want["T"] == want["t_max"]):
                errors["T_rest"] = max(errors["T_rest"], err)
            else:
                errors[key] = max(errors[key], err)
        for key in ("x_max", "F_max"):
            errors[key] = max(errors[key], abs(got[key][i] / want[key] - 1.0))
        errors["x_end"] = max(errors["x_end"], abs(got["x_end"][i] - want["x_end"]) / want["x_max"])
    ERRORS[(separation, len(cases))] = errors
    print(
        f"{separation}, {len(cases)} cases ({', '.join(sorted(endings))}): "
        + ", ".join(f"{k} {v:.1e}" for k, v in errors.items())
    )
    limits = dict(e=1e-9, T=1e-9, x_max=1e-9, t_max=1e-9, F_max=1e-9, x_end=1e-9, T_rest=1e-7)
    for key, limit in limits.items():
        assert errors[key] <= limit, f"{separation}: {key} off by {errors[key]:.2e}"
    return got, endings


# one criterion in the fast suite, the other in the slow group (each compiles its own batch)


@pytest.mark.slow  # 12 s of compiling; the fast suite keeps the gradients and the path
@pytest.mark.parametrize("separation", SEPARATIONS)
def test_matches_scipy(separation):
    _, endings = check(FAST, separation)
    assert {"separated", "horizon"} <= endings


@pytest.mark.slow
@pytest.mark.very_slow  # 486 scipy integrations per criterion: about 100 s each
@pytest.mark.parametrize("separation", SEPARATIONS)
def test_matches_scipy_wide_grid(separation):
    """486 impacts per criterion: every ending (separated, back, rest, horizon) occurs."""
    _, endings = check(grid(), separation)
    assert {"separated", "back", "rest", "horizon"} <= endings


@pytest.mark.slow
@pytest.mark.parametrize("separation", SEPARATIONS)
def test_matches_scipy_near_the_capture_threshold(separation):
    _, endings = check(near_threshold(), separation, refine=True)
    assert {"rest", "horizon"} <= endings


# ------------------------------------------------------------------------ gradients


def _fd_rows(points, h):
    rows = []
    for c, b, m, v0, g in points:
        rows += [
            (c, b, m, v0, g),
            (c * (1 + h), b, m, v0, g),
            (c * (1 - h), b, m, v0, g),
            (c, b * (1 + h), m, v0, g),
            (c, b * (1 - h), m, v0, g),
        ]
    return rows


def check_gradients(points, separation, h=1e-6):
    """d(e, T)/d(c, b) (`jax.jacrev` through the root solves' implicit steps) against
    central differences in float64."""
    out = closed_batch(separation)(*zip(*_fd_rows(points, h), strict=True))
    assert np.all(np.isfinite(out["jac"]))
    value = np.stack([out["e"], out["T"]], axis=1)
    worst = 0.0
    for i, (c, b, *_) in enumerate(points):
        base = 5 * i
        for k, q in enumerate((c, b)):
            want = (value[base + 1 + 2 * k] - value[base + 2 + 2 * k]) / (2 * h * q)
            got = out["jac"][base][:, k]
            scale = np.abs(want) + 1e-7 * np.abs(value[base]) / q + 1e-300
            err = np.abs(got - want) / scale
            worst = max(worst, float(np.max(err)))
            assert np.all(err <= 1e-5), (points[i], separation, k, got, want)
    return worst


@pytest.mark.slow  # 12 s of compiling each (the fast suite: 3 minutes)
@pytest.mark.parametrize("separation", SEPARATIONS)
def test_gradients_match_finite_differences(separation):
    points = [FAST[0], FAST[2], FAST[3], FAST[4], FAST[5], FAST[6]]
    print(f"{separation}: worst gradient error {check_gradients(points, separation):.1e}")


@pytest.mark.slow
@pytest.mark.parametrize("separation", SEPARATIONS)
def test_gradients_over_the_grid(separation):
    """Every point of the wide grid that separates or returns (finite differences across
    a regime switch, e.g. at critical damping, are not derivatives: skipped), and
    finiteness everywhere."""
    cases = grid()
    got = closed_batch(separation)(*zip(*cases, strict=True))
    assert np.all(np.isfinite(got["jac"]))
    points = [p for i, p in enumerate(cases) if got["status"][i] == SEPARATED]
    assert len(points) >= 40
    print(f"{separation}: worst gradient error {check_gradients(points, separation):.1e}")


# ------------------------------------------------------------------- through `impact`


def test_impact_takes_the_closed_form_with_gravity():
    made = ji.law("maxwell", c=2e6, b=2000.0)
    assert made.closed_form("force", g_is_zero=False) is not None
    for separation in SEPARATIONS:
        r = jax.eval_shape(
            lambda s=separation: ji.impact(made, m=1.0, v0=2.5, g=9.81, separation=s)
        )
        assert r.path == "closed_form"


INTEGRATED = [
    (dict(c=2e6, b=2000.0), dict(m=1.0, v0=2.5, g=9.81)),  # the paper's, dropped
    (dict(c=1e3, b=math.sqrt(50.0) / 0.1), dict(m=0.05, v0=0.1, g=9.81)),  # gravity matters
    # just below the gravity that stops the body before maximum compression (14.165
    # m/s^2): it comes back, and stops inside the surface (v back to 0, captured)
    (dict(c=1e4, b=100.0), dict(m=1.0, v0=1.0, g=14.15)),
]


def _compare_with_integrated(params, kinematics, separation):
    made = ji.law("maxwell", **params)
    a = ji.impact(made, separation=separation, method="closed_form", **kinematics)
    b = ji.impact(made, separation=separation, method="integrate", rtol=1e-12, **kinematics)
    assert a.path == "closed_form" and int(a.num_steps) == 0
    assert int(a.status) == int(b.status)
    worst = 0.0
    for key in ("e", "T", "x_max", "t_max", "F_max", "dissipated", "v_out"):
        x, y = float(getattr(a, key)), float(getattr(b, key))
        err = abs(x - y) / max(abs(y), 1e-3 if key in ("e", "v_out") else 1e-300)
        worst = max(worst, err)
        assert err <= 1e-9, (key, x, y)
    return worst


@pytest.mark.slow
@pytest.mark.parametrize("separation", SEPARATIONS)
def test_against_the_integrated_path(separation):
    params, kinematics = INTEGRATED[0]
    _compare_with_integrated(params, kinematics, separation)


@pytest.mark.slow
@pytest.mark.parametrize("separation", SEPARATIONS)
@pytest.mark.parametrize("params, kinematics", INTEGRATED[1:])
def test_against_the_integrated_path_more(params, kinematics, separation):
    _compare_with_integrated(params, kinematics, separation)


@pytest.mark.slow
def test_horizon_against_the_integrated_path():
    """A body that never reaches maximum compression sinks in at the dashpot's speed
    `m g/b`: captured at the horizon `tau_max`, as the integration that runs there."""
    c, b, m, v0, g = case(2e6, 1.9, 1.0, 2.5, 9.81)
    tau_max = 60.0
    made = ji.law("maxwell", c=c, b=b)
    r = ji.impact(made, m=m, v0=v0, g=g, method="integrate", rtol=1e-12, tau_max=tau_max)
    want = maxwell_gravity_impact(c, b, m, v0, g, "force", tau_max=tau_max)
    assert int(r.status) == int(want["status"]) == CAPTURED
    for key in ("T", "t_max", "x_max", "F_max"):
        np.testing.assert_allclose(float(getattr(r, key)), float(want[key]), rtol=1e-9)
    speed = m * g / b  # the creep at the end: x grows as (m g/b) t
    late = maxwell_gravity_impact(c, b, m, v0, g, "force", tau_max=2 * tau_max)
    slope = (late["x_max"] - want["x_max"]) / (late["T"] - want["T"])
    np.testing.assert_allclose(float(slope), speed, rtol=1e-12)


@pytest.mark.slow
def test_without_gravity_equals_maxwell_impact():
    """At g = 0 the gravity formulas give `maxwell_impact`'s impact (which the closed form
    takes there), every damping and both criteria."""
    cases = [case(2e6, mu, 1.0, 2.5, 0.0) for mu in (0.1, 0.7, 1.5, 1.9, 1.99, 2.0, 3.0)]
    c, b, m, v0, _ = (np.array(col) for col in zip(*cases, strict=True))
    for separation in SEPARATIONS:
        got = closed_batch(separation)(c, b, m, v0, np.zeros_like(c))
        want = jax.vmap(lambda c, b, s=separation: maxwell_impact(c, b, 1.0, 2.5, s))(c, b)
        for key in ("e", "T", "x_max", "t_max", "F_max", "status"):
            scale = np.maximum(np.abs(np.asarray(want[key], float)), 1e-300)
            err = np.max(np.abs(got[key] - np.asarray(want[key])) / scale)
            assert err <= 1e-8, (separation, key, err)


@pytest.mark.slow
def test_vmap_mixes_gravity_and_none():
    """`impact` under `vmap` over g (0 and > 0 members: both formulas run, a select) gives
    each member's own closed form, with finite gradients."""

    def e_T(b, g):
        r = ji.impact(ji.law("maxwell", c=2e6, b=b), m=1.0, v0=2.5, g=g)
        return jnp.stack([r.e, r.T])

    bs = jnp.array([2000.0, 2000.0, 500.0, 500.0])
    gs = jnp.array([0.0, 9.81, 0.0, 9.81])
    got = jax.vmap(e_T)(bs, gs)
    jac = jax.vmap(jax.jacrev(e_T))(bs, gs)
    assert np.all(np.isfinite(np.asarray(jac)))
    for i in range(4):
        want = e_T(float(bs[i]), float(gs[i]))
        np.testing.assert_allclose(np.asarray(got[i]), np.asarray(want), rtol=1e-12)


# ----------------------------------------------------------------------- drops


FIELDS = ("impact_times", "release_times", "e", "T", "release_heights", "x_max", "F_max")


def _drop(name, params, separation, method, **options):
    return ji.bounce(
        ji.law(name, **params),
        m=1.0,
        h0=0.6,
        t_end=3.0,
        separation=separation,
        max_impacts=16,
        method=method,
        **options,
    )


def check_drop(name, params, separation):
    """`bounce`'s contacts from the closed form against integrated ones (rtol 1e-12):
    the same sequence to 1e-9 (release heights to 1e-9 of the largest penetration)."""
    fast = _drop(name, params, separation, "auto")
    slow = _drop(name, params, separation, "integrate", rtol=1e-12)
    n = int(fast.num_impacts)
    assert n == int(slow.num_impacts) >= 1 and int(fast.num_steps) == 0
    assert fast.status_name == slow.status_name
    np.testing.assert_array_equal(fast.contact_status[:n], slow.contact_status[:n])
    scale = float(np.nanmax(np.asarray(slow.x_max)))
    for field in FIELDS:
        a, b = np.asarray(getattr(fast, field))[:n], np.asarray(getattr(slow, field))[:n]
        if field == "release_heights":
            np.testing.assert_allclose(a, b, atol=1e-9 * scale, rtol=0, err_msg=field)
        else:
            np.testing.assert_allclose(a, b, rtol=1e-9, atol=1e-12, err_msg=field)
    np.testing.assert_allclose(float(fast.t_rest), float(slow.t_rest), rtol=1e-9)
    return fast, slow


DROPS = [
    ("maxwell", dict(c=2e6, b=2000.0)),  # mu = 0.7: four bounces (force criterion)
    ("maxwell", dict(c=2e6, b=1e4)),  # mu = 0.14: many
    ("kelvin_voigt", dict(c=2e6, b=480.0)),  # the seed paper's section 7
    ("bingham", dict(c=2e6, b=200.0, P=100.0)),
]


@pytest.mark.slow
def test_bounce_takes_the_closed_form():
    check_drop("maxwell", dict(c=2e6, b=2000.0), "force")


@pytest.mark.slow
@pytest.mark.parametrize("separation", SEPARATIONS)
@pytest.mark.parametrize("name, params", DROPS)
def test_bounce_closed_form_equals_integrated(name, params, separation):
    check_drop(name, params, separation)


@pytest.mark.slow
def test_bounce_closed_form_gradients():
    """A drop's gradients through the closed-form contacts, against central differences."""

    def last_apex(b):
        r = ji.bounce(ji.law("maxwell", c=2e6, b=b), m=1.0, h0=0.6, t_end=1.0, max_impacts=8)
        return r.apex_heights[1]

    b, h = 2000.0, 1e-6
    got = float(jax.grad(last_apex)(b))
    want = (float(last_apex(b * (1 + h))) - float(last_apex(b * (1 - h)))) / (2 * h * b)
    np.testing.assert_allclose(got, want, rtol=1e-5)


@pytest.mark.parametrize("where", ["impact", "calibrate"])
def test_no_gravity_compiles_without_gravitys_formulas(where, monkeypatch):
    """With g a number 0, neither `impact` nor `calibrate` traces the formulas with gravity
    (a traced g compiled both branches: calibrate's compile was 20 s instead of 3 s). The
    solve is traced afresh (its jit wrapper's cache would skip the trace)."""
    import jaximpact._fit.calibrate as calibrate
    import jaximpact._laws.closed_forms as closed_forms
    from jaximpact._fit.forward_jacobian import value_and_jacobian
    from jaximpact._solve.impact import solve_impact

    def refuse(*args, **kwargs):
        raise AssertionError("the formulas with gravity were traced for g = 0")

    monkeypatch.setattr(closed_forms, "maxwell_gravity_impact", refuse)
    monkeypatch.setattr(calibrate, "solve_impact", solve_impact.__wrapped__)
    law = ji.law("maxwell", c=2.7e4, b=200.0)
    options = dict(
        separation="force",
        closed_form=True,
        solver=None,
        rtol=1e-11,
        atol=1e-11,
        max_steps=4096,
        tau_max=1e4,
        rest_tol=1e-7,
        adjoint=None,
        peaks=True,
    )
    solve = solve_impact.__wrapped__
    if where == "impact":
        no_gravity = ji.ImpactOptions(**options, gravity=False)
        jax.eval_shape(lambda v, g: solve(law, 0.0027, v, g, None, no_gravity).e, 1.0, 0.0)
    else:
        raw = calibrate._residual_function(
            law,
            ("b", "c"),
            calibrate.ForwardModel(separation="force", rtol=1e-10, closed_form=True),
            m=0.0027,
            g=0.0,
            has_e=True,
            has_T=False,
        )
        data = (jnp.ones(2), jnp.ones(2), jnp.full(2, jnp.nan), jnp.ones(2), jnp.ones(2))
        jax.eval_shape(lambda t: value_and_jacobian(raw, t, data), jnp.zeros(2))
    # with gravity the formulas are traced (the check above can fail)
    gravity = ji.ImpactOptions(**options, gravity=True)
    with pytest.raises(AssertionError, match="traced for g = 0"):
        jax.eval_shape(lambda v, g: solve(law, 0.0027, v, g, None, gravity).e, 1.0, 0.0)
