"""`bounce`: closed-form flights, one impact solve per contact, against an independent chain
(analytic parabolas and scipy DOP853 contacts with gravity); statuses, histories, the seed
paper's Euler baseline, gradients.

Compilation dominates: the default tests share one compiled drop (hertz_rate, force
criterion, `MAX_IMPACTS` contacts) and its history; other laws and transformations are slow.
"""

import functools
import json
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from reference import _solve
from scipy.integrate import solve_ivp

import jaximpact as ji
from jaximpact._solve.bounce import BounceStatus, bounce
from jaximpact._solve.euler import euler_bounce
from jaximpact._solve.flight import Flight, free_flight

G, H0, M = 9.81, 0.6, 1.0  # the seed paper's section 7
MAX_IMPACTS = 16
SECTION7 = {
    "hertz_rate": dict(c=1e6, b1=1350.0),
    "kelvin_voigt": dict(c=2e6, b=480.0),
    "kelvin_voigt_modified": dict(c=2e6, b1=8e5),
}
SEPARATIONS = ("force", "penetration")


def reference_bounces(name, params, *, m, h0, g, separation, n, drag=None, rtol=1e-12):
    """The first `n` contacts of a drop from rest, built independently of jaximpact: flights
    as parabolas (or, with drag, integrated by scipy), contacts by `tests/reference.py`
    (scipy DOP853 with gravity). Rows: impact time, impact speed, e, T, penetration at
    separation."""
    if drag is None:
        t_imp, v_in = math.sqrt(2 * h0 / g), math.sqrt(2 * g * h0)
    else:
        t_imp, v_in = _scipy_landing(0.0, h0, 0.0, g, drag)
    rows = []
    for _ in range(n):
        res, _, s2 = _solve(name, params, m, v_in, separation, g, rtol)
        T, e = res["T"], res["e"]
        x_end = float(s2.sol(T)[0]) if separation == "force" else 0.0
        rows.append((t_imp, v_in, e, T, x_end))
        u = e * v_in
        if drag is None:
            # y(s) = -x_end + u s - g s^2 / 2 = 0, the later root
            flight = (u + math.sqrt(u * u - 2 * g * x_end)) / g
            t_imp, v_in = t_imp + T + flight, math.sqrt(u * u - 2 * g * x_end)
        else:
            t_imp, v_in = _scipy_landing(t_imp + T, -x_end, u, g, drag)
    return np.array(rows)


def _scipy_landing(t0, y0, u0, g, k):
    """Time and speed at which `y'' = -g - k u|u|` from `(y0, u0)` comes down to y = 0."""

    def rhs(t, s):
        return [s[1], -g - k * s[1] * abs(s[1])]

    def floor(t, s):
        return s[0]

    floor.terminal, floor.direction = True, -1  # falling crossings only
    sol = solve_ivp(
        rhs, (t0, t0 + 100.0), [y0, u0], method="DOP853", rtol=1e-13, atol=1e-15, events=floor
    )
    return float(sol.t_events[0][-1]), float(-sol.y_events[0][-1][1])


@functools.cache
def drop(name="hertz_rate", separation="force", t_end=3.0, min_flight=1e-6, **params):
    params = params or SECTION7[name]
    return bounce(
        ji.law(name, **params),
        m=M,
        h0=H0,
        t_end=t_end,
        g=G,
        separation=separation,
        max_impacts=MAX_IMPACTS,
        min_flight=min_flight,
    )


def check_against_reference(name, separation, rows=4, tol=1e-7):
    ref = reference_bounces(name, SECTION7[name], m=M, h0=H0, g=G, separation=separation, n=rows)
    b = drop(name, separation)
    times = np.asarray(b.impact_times[:rows])
    e = np.asarray(b.e[:rows])
    t_err = np.max(np.abs(times - ref[:, 0]) / ref[:, 0])
    e_err = np.max(np.abs(e - ref[:, 2]))
    assert t_err < tol, f"{name} {separation}: impact times off by {t_err:.2e} (relative)"
    assert e_err < tol, f"{name} {separation}: e off by {e_err:.2e}"
    T_err = np.max(np.abs(np.asarray(b.T[:rows]) - ref[:, 3]) / ref[:, 3])
    assert T_err < tol
    depth = np.abs(-np.asarray(b.release_heights[:rows]) - ref[:, 4])
    assert np.max(depth) < 1e-9
    return t_err, e_err


# ----------------------------------------------------------------------------- flights


@pytest.mark.parametrize("drag", [None, 0.14])
@pytest.mark.parametrize("u0", [2.5, -1.5, 0.0])
def test_flight_against_scipy(drag, u0):
    k = 0.0 if drag is None else drag
    ts = np.linspace(0.0, 0.4, 9)
    sol = solve_ivp(
        lambda t, s: [s[1], -G - k * s[1] * abs(s[1])],
        (0.0, 0.4),
        [0.3, u0],
        method="DOP853",
        rtol=1e-13,
        atol=1e-14,
        t_eval=ts,
    )
    y, u = free_flight(ts, y0=0.3, u0=u0, g=G, drag=drag)
    np.testing.assert_allclose(np.asarray(y), sol.y[0], rtol=0, atol=1e-11)
    np.testing.assert_allclose(np.asarray(u), sol.y[1], rtol=0, atol=1e-10)


@pytest.mark.parametrize("drag", [None, 0.14])
def test_landing_against_scipy(drag):
    t_land, v_land = Flight.from_state(0.1, -1e-4, 2.0, g=G, drag=drag).landing()
    if drag is None:
        t_ref = 0.1 + (2.0 + math.sqrt(4.0 - 2 * G * 1e-4)) / G
        v_ref = math.sqrt(4.0 - 2 * G * 1e-4)
    else:
        t_ref, v_ref = _scipy_landing(0.1, -1e-4, 2.0, G, drag)
    assert abs(float(t_land) - t_ref) < 1e-12
    assert abs(float(v_land) - v_ref) < 1e-11


def test_flight_gradients_finite_at_rest_and_match_fd():
    def landing(params):
        h, k = params
        return jnp.stack(Flight.from_state(0.0, h, 0.0, g=G, drag=k).landing())

    p = jnp.array([0.6, 0.14])
    landing = jax.jit(landing)
    J = jax.jacfwd(landing)(p)
    assert np.all(np.isfinite(np.asarray(J)))
    step = 1e-6
    for i in range(2):
        dp = jnp.zeros(2).at[i].set(step)
        fd = (landing(p + dp) - landing(p - dp)) / (2 * step)
        np.testing.assert_allclose(np.asarray(J[:, i]), np.asarray(fd), rtol=1e-6)
    assert np.all(np.isfinite(np.asarray(jax.grad(lambda p: landing(p)[0])(p))))


# --------------------------------------------------------------------- against scipy


def test_matches_independent_chain_hertz_rate_force():
    t_err, e_err = check_against_reference("hertz_rate", "force")
    print(f"hertz_rate force: impact times {t_err:.1e}, e {e_err:.1e}")


@pytest.mark.slow
@pytest.mark.parametrize("separation", SEPARATIONS)
@pytest.mark.parametrize("name", list(SECTION7))
def test_matches_independent_chain(name, separation):
    t_err, e_err = check_against_reference(name, separation)
    print(f"{name} {separation}: impact times {t_err:.1e}, e {e_err:.1e}")


def test_section7_first_impact_at_paper_speed():
    b = drop()
    assert abs(float(b.impact_times[0]) - math.sqrt(2 * H0 / G)) < 1e-12
    assert abs(float(b.impact_speeds[0]) - 3.431) < 1e-3  # "3.43 m/s" in the paper
    assert int(b.num_impacts) >= 4
    assert np.all(np.diff(np.asarray(b.impact_times[: int(b.num_impacts)])) > 0)
    n = int(b.num_impacts)
    # the flight between contacts is closed-form: rebound speed in, same speed back
    assert np.all(np.asarray(b.rebound_speeds[: n - 1]) > 0)
    np.testing.assert_allclose(
        np.asarray(b.rebound_speeds[:4]), np.asarray(b.e[:4] * b.impact_speeds[:4]), rtol=1e-12
    )
    assert np.all(np.asarray(b.F_max[:4]) > 0) and np.all(np.asarray(b.x_max[:4]) > 0)


# ---------------------------------------------------------------------------- statuses


def test_comes_to_rest_under_gravity():
    b = drop()
    assert b.status_name == "at_rest"
    n = int(b.num_impacts)
    last = int(b.contact_status[n - 1])
    assert last == ji.Status.captured  # gravity held the ball in the surface
    assert float(b.t_rest) > float(b.impact_times[n - 1])
    assert np.all(np.isnan(np.asarray(b.e[n:])))


def test_stops_at_t_end():
    b = drop(t_end=1.0)
    assert b.status_name == "t_end"
    n = int(b.num_impacts)
    assert float(b.impact_times[n - 1]) <= 1.0
    assert np.isnan(float(b.t_rest))


def test_reports_running_out_of_impacts():
    b = drop(t_end=10.0, c=1e6, b1=100.0)  # e about 0.96: many more than MAX_IMPACTS bounces
    assert b.status_name == "max_impacts"
    assert int(b.num_impacts) == MAX_IMPACTS
    with pytest.raises(Exception, match="max_impacts"):
        bounce(
            ji.law("hertz_rate", c=1e6, b1=100.0),
            m=M,
            h0=H0,
            t_end=10.0,
            max_impacts=MAX_IMPACTS,
            throw=True,
        )


def test_a_drop_prints_its_contacts_with_units():
    b = drop()  # comes to rest
    n = int(b.num_impacts)
    text = repr(b)
    assert text == b.summary() and "f64[" not in text and "Array(" not in text
    assert "status      = at_rest" in text and f"num_impacts = {n}" in text
    assert f"e = {float(b.e[0]):.4g}, T = " in text and "ms," in text and "m/s in" in text
    assert text.rstrip().endswith("captured")  # the last contact: gravity held the ball
    d = b.to_dict()
    assert len(d["e"]) == n and d["contact_status"][-1] == "captured"
    assert d["status"] == "at_rest" and d["t_rest"] == pytest.approx(float(b.t_rest))
    json.dumps(d, allow_nan=False)
    many = drop(t_end=10.0, c=1e6, b1=100.0)  # 16 contacts: the first 4 and the last 2
    text = repr(many)
    assert "contact 4 " in text and "contact 5 " not in text and "contact 16" in text
    assert "10 more contacts" in text and "- (not at rest)" in text


def test_a_batch_of_drops_prints_the_real_contacts():
    both = jax.tree.map(lambda *xs: jnp.stack(xs), drop(), drop(t_end=1.0))
    text = repr(both)
    assert "a batch of drops" in text and "t_end 1, at_rest 1" in text
    assert "not finite" not in text  # the padding after the last contact is not shown
    d = both.to_dict()
    assert d["status"] == ["at_rest", "t_end"] and len(d["e"]) == 2
    json.dumps(d, allow_nan=False)


def test_zeno_cut_at_min_flight():
    b = drop(t_end=10.0, min_flight=0.45, c=1e6, b1=100.0)
    assert b.status_name == "at_rest"
    n = int(b.num_impacts)
    flights = np.asarray(b.impact_times[1:n] - b.release_times[: n - 1])
    assert np.all(flights >= 0.45)
    last_flight = float(b.t_rest) - float(b.release_times[n - 1])
    assert 0 < last_flight < 0.45


# ---------------------------------------------------------------------------- histories


@functools.cache
def histories():
    b = drop()
    n = int(b.num_impacts)
    inside = np.asarray(b.impact_times[:2])[:, None] + np.asarray(b.T[:2])[:, None] * np.linspace(
        0.05, 0.95, 7
    )  # seven instants inside each of the first two contacts
    ts = np.sort(np.concatenate([np.linspace(0.0, 2.2, 400), inside.ravel()]))
    y, u, F = (np.asarray(a) for a in b.trajectory(jnp.asarray(ts)))
    return b, n, ts, y, u, F


@pytest.mark.slow  # moved from the fast suite to keep it near 3 minutes
def test_height_in_flight_is_the_parabola():
    b, n, ts, y, u, F = histories()
    first = ts < float(b.impact_times[0])
    np.testing.assert_allclose(y[first], H0 - 0.5 * G * ts[first] ** 2, atol=1e-12)
    np.testing.assert_allclose(u[first], -G * ts[first], atol=1e-12)
    assert np.all(F[first] == 0)
    # between the first two contacts: apex of the flight
    between = (ts > float(b.release_times[0])) & (ts < float(b.impact_times[1]))
    assert np.max(y[between]) <= float(b.apex_heights[0]) + 1e-12
    top = float(b.apex_heights[0])
    assert (
        abs(top - float(b.rebound_speeds[0]) ** 2 / (2 * G) - float(b.release_heights[0])) < 1e-12
    )


@pytest.mark.slow  # 5 s: the drop's trajectory and scipy (the fast suite: 3 minutes)
def test_height_inside_contact_from_the_contact_solution():
    b, n, ts, y, u, F = histories()
    name, params = "hertz_rate", SECTION7["hertz_rate"]
    for k in range(2):
        inside = (ts > float(b.impact_times[k])) & (ts < float(b.release_times[k]))
        assert inside.sum() >= 7
        res, s1, s2 = _solve(name, params, M, float(b.impact_speeds[k]), "force", G, 1e-12)
        local = ts[inside] - float(b.impact_times[k])
        x_ref = np.where(
            local <= res["t_max"],
            s1.sol(np.minimum(local, res["t_max"]))[0],
            s2.sol(np.maximum(local, res["t_max"]))[0],
        )
        # the drop's contacts are read off the gravity table; its histories integrate
        # them (rtol 1e-10): the two chains' impact instants differ by ~5e-10 s, which is
        # ~1.5e-9 m of penetration at ~3 m/s
        np.testing.assert_allclose(-y[inside], x_ref, rtol=1e-7, atol=5e-9)
        assert np.all(F[inside] >= -1e-9)
    assert np.all(np.isfinite(y[ts <= float(b.t_rest)]))


@pytest.mark.slow  # the trajectory of the test above (tests/test_fuzz.py keeps one fast)
def test_height_at_rest_after_t_rest():
    b, n, ts, y, u, F = histories()
    rest = ts > float(b.t_rest)
    assert rest.any()
    # held at the depth where the captured contact's solve stopped (the ball's first halt
    # inside the surface: within a static deflection, (m g / c)^(2/3) = 4.6e-4 m, of 0)
    assert np.all((y[rest] < 0) & (y[rest] > -4.6e-4)) and np.all(u[rest] == 0)
    assert np.ptp(y[rest]) == 0
    np.testing.assert_allclose(F[rest], M * G)


# ---------------------------------------------------------------------------- Euler


@pytest.mark.parametrize("name", list(SECTION7))
def test_paper_euler_reproduces_printed_restitution(name):
    printed = {"hertz_rate": 0.64, "kelvin_voigt": 0.64, "kelvin_voigt_modified": 0.54}[name]
    r = euler_bounce(ji.law(name, **SECTION7[name]), m=M, h0=H0, t_end=1.0)
    assert abs(r.impact_times[0] - math.sqrt(2 * H0 / G)) < 2e-5
    # the printed values are rounded and, for law 14, not the first bounce's
    assert abs(r.e[0] - printed) < (0.02 if name == "hertz_rate" else 0.005)


def test_euler_converges_to_the_penetration_criterion():
    law = ji.law("kelvin_voigt", **SECTION7["kelvin_voigt"])
    e_exact = math.exp(-math.pi * 480.0 / math.sqrt(4 * 2e6 - 480.0**2))  # g = 0
    coarse = euler_bounce(law, m=M, h0=H0, t_end=0.4, scheme="euler").e[0]
    fine = euler_bounce(law, m=M, h0=H0, t_end=0.4, scheme="euler", dt=2e-7).e[0]
    assert abs(fine - e_exact) < 0.1 * abs(coarse - e_exact)
    assert abs(fine - e_exact) < 2e-3  # gravity shifts e by about 1e-4


# -------------------------------------------------------------------------- transforms


@pytest.mark.slow
def test_gradients_forward_reverse_and_finite_differences(monkeypatch):
    """Reverse mode (jacrev) goes through the forward-mode Jacobian, transposed
    (`adjoint.by_forward_jacobian`: a jitted grad of a user's law's third impact time took
    1.2 ms against 10.6 ms through diffrax's reverse mode, its first call 16 s against
    28 s, measured), and equals jacfwd and central differences."""
    from jaximpact._solve import bounce as bounce_module

    calls = []
    wrapped = bounce_module.through_forward_jacobian
    monkeypatch.setattr(
        bounce_module,
        "through_forward_jacobian",
        lambda *a, **k: calls.append(1) or wrapped(*a, **k),
    )

    def f(p):
        b = bounce(ji.law("hertz_rate", c=p[0], b1=p[1]), m=M, h0=H0, t_end=1.5, max_impacts=8)
        return jnp.concatenate([b.impact_times[:4], b.e[:4]])

    p = jnp.array([1e6, 1350.0])
    J_fwd = np.asarray(jax.jacfwd(f)(p))
    J_rev = np.asarray(jax.jacrev(f)(p))
    assert calls, "jax.jacrev did not go through the forward Jacobian"
    scale = np.abs(J_fwd).max(axis=0)
    assert np.max(np.abs(J_fwd - J_rev) / scale) < 1e-10
    h = 1e-6
    fd = np.stack(
        [(f(p.at[i].mul(1 + h)) - f(p.at[i].mul(1 - h))) / (2 * h * p[i]) for i in range(2)], axis=1
    )
    assert np.max(np.abs(J_fwd - fd) / scale) < 1e-6


@pytest.mark.slow
def test_height_gradient_matches_finite_differences():
    ts = jnp.linspace(0.3, 1.2, 40)

    def heights(b1):
        b = bounce(ji.law("hertz_rate", c=1e6, b1=b1), m=M, h0=H0, t_end=1.5, max_impacts=8)
        return b.height(ts)

    J = np.asarray(jax.jacfwd(heights)(1350.0))
    fd = np.asarray((heights(1350.0 * (1 + 1e-6)) - heights(1350.0 * (1 - 1e-6))) / (2.7e-3))
    assert np.all(np.isfinite(J))
    assert np.max(np.abs(J - fd)) < 1e-6 * np.max(np.abs(J))


@pytest.mark.slow
def test_vmap_over_drop_heights():
    law = ji.law("hertz_rate", **SECTION7["hertz_rate"])
    heights = jnp.array([0.2, 0.6, 1.0])
    first = jax.vmap(lambda h: bounce(law, m=M, h0=h, t_end=2.0, max_impacts=8).impact_times[0])
    np.testing.assert_allclose(
        np.asarray(first(heights)), np.sqrt(2 * np.asarray(heights) / G), rtol=1e-12
    )


@pytest.mark.slow
def test_drag_matches_independent_chain():
    law = ji.law("hertz_rate", c=1e6, b1=1350.0)
    b = bounce(law, m=M, h0=H0, t_end=1.5, max_impacts=8, drag=0.14)
    ref = reference_bounces(
        "hertz_rate", dict(c=1e6, b1=1350.0), m=M, h0=H0, g=G, separation="force", n=3, drag=0.14
    )
    np.testing.assert_allclose(np.asarray(b.impact_times[:3]), ref[:, 0], rtol=1e-7)
    np.testing.assert_allclose(np.asarray(b.e[:3]), ref[:, 2], atol=1e-7)
    no_drag = drop()
    assert float(b.impact_times[1]) < float(no_drag.impact_times[1])  # drag shortens flights


# ------------------------------------------------------------------------------ errors


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(m=-1.0), "mass"),
        (dict(h0=-0.1), "h0"),
        (dict(t_end=0.0), "t_end"),
        (dict(g=0.0), "gravity"),
        (dict(max_impacts=0), "max_impacts"),
        (dict(separation="glue"), "separation"),
        (dict(drag=-0.1), "drag"),
        (dict(drag=1.0, v_drop=5.0), "terminal speed"),
        (dict(h0=0.0), "h0 = 0 with v_drop = 0"),
        (dict(h0=math.nan), "h0"),
        (dict(h0=math.inf), "h0"),
        (dict(t_end=-1.0), "t_end"),
        (dict(t_end=math.nan), "t_end"),
        (dict(m=0.0), "mass"),
        (dict(v_drop=math.nan), "v_drop"),
        (dict(min_flight=-1.0), "min_flight"),
        (dict(h0=[0.1, 0.2]), "scalar h0"),
        (dict(rtol=0.0), "rtol"),
        (dict(rtol=-1e-8), "rtol"),
        (dict(rtol=math.nan), "rtol"),
        (dict(rtol=1.0), "rtol"),
        (dict(atol=0.0), "atol"),
        (dict(rest_tol=0.0), "rest_tol"),
        (dict(tau_max=-1.0), "tau_max"),
        (dict(max_steps=0), "max_steps"),
        (dict(max_steps=2.5), "max_steps"),
        (dict(max_impacts=True), "max_impacts"),
    ],
)
def test_bad_input_is_a_one_line_value_error(kwargs, message):
    args = dict(m=M, h0=H0, t_end=1.0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=message) as error:
        bounce(ji.law("hertz_rate", c=1e6, b1=1350.0), **args)
    assert len(str(error.value).splitlines()) == 1


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(h0="0.5"), "h0 must be a real number"),
        (dict(m=None), "m must be a real number"),
        (dict(peaks="no"), "peaks"),
        (dict(solver="tsit5"), "diffrax solver"),
        (dict(adjoint="forward"), "diffrax adjoint"),
        (dict(rtol="1e-8"), "rtol must be a number"),
    ],
)
def test_wrong_type_is_a_type_error(kwargs, message):
    args = dict(m=M, h0=H0, t_end=1.0)
    args.update(kwargs)
    with pytest.raises(TypeError, match=message):
        bounce(ji.law("hertz_rate", c=1e6, b1=1350.0), **args)


def test_h0_zero_with_a_downward_speed_is_a_drop():
    """Only a ball at rest on the floor is refused: thrown down from the floor it bounces."""
    b = bounce(
        ji.law("hertz_rate", c=1e6, b1=1350.0),
        m=M,
        h0=0.0,
        v_drop=1.0,
        t_end=0.3,
        max_impacts=MAX_IMPACTS,
    )
    assert int(b.num_impacts) >= 2
    assert float(b.impact_times[0]) == 0.0 and np.isfinite(float(b.e[0]))


def test_bad_law_is_a_type_error():
    with pytest.raises(TypeError, match="law"):
        bounce("hertz_rate", m=M, h0=H0, t_end=1.0)


def test_status_enum_names():
    names = ["t_end", "at_rest", "max_impacts", "failed", "invalid"]
    assert [s.name for s in BounceStatus] == names


@pytest.mark.slow  # compiles a user's law's drop and two references
def test_a_drop_at_its_defaults_meets_1e_9():
    """Each contact's e at `bounce`'s defaults within 1e-9 of the same drop integrated at
    rtol 1e-13, for a user's Hunt-Crossley law and the table's (read off the gravity
    table), and Thornton's first contact against `impact` with gravity (issue 34, item 11:
    at the old default rtol 1e-10 the table's third contact was 1.1e-8 off, the user's
    law's 7.6e-9)."""
    plain = ji.custom_law(lambda x, v, p: p["c"] * x**1.5 * (1 + 1.5 * p["a"] * v), c=2e6, a=0.2)
    table = ji.law("hunt_crossley", c=2e6, a=0.2, n=1.5)
    reference = ji.bounce(table, m=1.0, h0=0.6, t_end=1.5, rtol=1e-13)
    n = 5
    assert int(reference.num_impacts) >= n
    for law in (plain, table):
        drop = ji.bounce(law, m=1.0, h0=0.6, t_end=1.5)
        np.testing.assert_allclose(drop.e[:n], reference.e[:n], rtol=0, atol=1e-9)
    thornton = ji.law("thornton", c=2e6, x_y=1e-4)
    first = ji.bounce(thornton, m=1.0, h0=0.6, t_end=0.4).e[0]
    v_in = (2 * 9.81 * 0.6) ** 0.5
    exact = ji.impact(thornton, m=1.0, v0=v_in, g=9.81, rtol=1e-13).e
    assert abs(float(first) - float(exact)) <= 1e-9
