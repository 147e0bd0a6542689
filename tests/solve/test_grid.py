"""The grid path (`_solve/grid.py`): a contact on a fixed grid of its phase-plane angle,
checked against scipy's DOP853 at rtol 1e-13 (two phases, events for x_max and the end,
as tests/reference.py integrates the table's laws, here for any F(x, v)), Hunt-Crossley's
closed form and central differences; and `impact_batch`, which serves on the grid the
rows it can and integrates the others in a second pass.

One program in the fast suite (a user's law under the force criterion, vmapped); what
compiles more is marked slow."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaximpact as ji
from jaximpact import closed_forms
from jaximpact._solve.grid import E_FLOOR, GRID_STEPS, grid_contact

from reference import reference_impact

M = 1.0


def _rate_law(x, v, p):  # the user law: Kuwabara-Kono damping growing with speed
    return p["c"] * x**1.5 + p["b1"] * x**0.5 * v * (1 + 0.1 * v)


def _hc_law(x, v, p):  # Hunt-Crossley as a user writes it: e from the closed form
    return p["c"] * x**1.5 * (1 + p["a"] * v)


def _kv_law(x, v, p):
    return p["c"] * x + p["b"] * v


def _pull_law(x, v, p):  # pulls near the end of restitution under heavy damping
    return p["c"] * x**1.5 + p["b"] * x**0.5 * v


def _np_rate(p):
    return lambda x, v: p["c"] * x**1.5 + p["b1"] * math.sqrt(x) * v * (1 + 0.1 * v)


def _np_hc(p):
    return lambda x, v: p["c"] * x**1.5 * (1 + p["a"] * v)


def scipy_contact(force, m, v0, separation, rtol=1e-13):
    """e, T, x_max of `m x'' = -force(x, v)` from x = 0, v = v0 (SI): DOP853 in two phases
    (to v = 0, then to x = 0 or, under the force criterion, the force's zero inside the
    surface), atol 1e-2 rtol of the energy length and of v0."""
    lo, hi = -30.0, 10.0  # the energy length x F(x, v0) = m v0^2, a scale for atol
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (lo, mid) if 10**mid * force(10**mid, v0) > m * v0**2 else (mid, hi)
    x_star = 10**lo
    kw = dict(method="DOP853", rtol=rtol, atol=[1e-2 * rtol * x_star, 1e-2 * rtol * v0])

    def rhs(t, y):
        return [y[1], -force(max(y[0], 0.0), y[1]) / m]

    def top(t, y):
        return y[1]

    def surface(t, y):
        return y[0]

    def zero(t, y):
        return force(y[0], y[1]) if y[0] > 0 else 1.0

    top.terminal = surface.terminal = zero.terminal = True
    top.direction = surface.direction = zero.direction = -1
    one = solve_ivp(rhs, (0.0, 1.0), [0.0, v0], events=[top], **kw)
    t_max, y_max = float(one.t_events[0][0]), one.y_events[0][0]
    events = [surface] + ([zero] if separation == "force" else [])
    two = solve_ivp(rhs, (t_max, 1.0), [y_max[0], 0.0], events=events, **kw)
    ends = [(float(t[0]), y[0]) for t, y in zip(two.t_events, two.y_events, strict=True) if len(t)]
    t_end, y_end = min(ends, key=lambda end: end[0])
    return dict(e=-float(y_end[1]) / v0, T=t_end, x_max=float(y_max[0]))


def _law(fn, **params):
    return ji.custom_law(fn, **params)


@jax.jit
def _rate_grid(b1, v0):
    law = ji.custom_law(_rate_law, c=2e6, b1=1.0).replace(b1=b1)
    return grid_contact(law, M, v0, separation="force")


# (b1, v0): light to moderate damping, e from 0.99 to 0.7
RATE_CASES = [(20.0, 1.0), (150.0, 2.9), (400.0, 1.7), (800.0, 2.5), (800.0, 1.2), (1500.0, 2.2)]


@pytest.mark.slow  # its own program (the fast batch tests run the grid: path 'grid')
def test_a_users_law_on_the_grid_meets_scipy_to_1e_9():
    b1 = jnp.asarray([b for b, _ in RATE_CASES])
    v0 = jnp.asarray([v for _, v in RATE_CASES])
    out = jax.vmap(_rate_grid)(b1, v0)
    assert bool(jnp.all(out["served"])), out["estimate"]
    for k, (b, v) in enumerate(RATE_CASES):
        want = scipy_contact(_np_rate({"c": 2e6, "b1": b}), M, v, "force")
        for name in ("e", "T", "x_max"):
            assert abs(float(out[name][k]) / want[name] - 1) < 1e-9, (b, v, name)
        assert int(out["num_steps"][k]) == GRID_STEPS


@pytest.mark.slow
@pytest.mark.parametrize("separation", ["force", "penetration"])
def test_both_laws_under_both_criteria_over_speeds(separation):
    """The issue's two user laws over 1 to 3 m/s, every served member within 1e-9 of scipy
    (and of Hunt-Crossley's closed form for e)."""
    v0 = np.linspace(1.0, 3.0, 7)

    @jax.jit
    @jax.vmap
    def hc(a, v):
        law = ji.custom_law(_hc_law, c=2e6, a=1.0).replace(a=a)
        return grid_contact(law, M, v, separation=separation)

    @jax.jit
    @jax.vmap
    def rate(b1, v):
        law = ji.custom_law(_rate_law, c=2e6, b1=1.0).replace(b1=b1)
        return grid_contact(law, M, v, separation=separation)

    for a in (0.01, 0.05, 0.1):
        out = hc(jnp.full(v0.shape, a), jnp.asarray(v0))
        assert bool(jnp.all(out["served"]))
        for k, v in enumerate(v0):
            exact = float(closed_forms.hunt_crossley_restitution(a * v))
            assert abs(float(out["e"][k]) / exact - 1) < 1e-9
            want = scipy_contact(_np_hc({"c": 2e6, "a": a}), M, v, separation)
            for name in ("T", "x_max"):
                assert abs(float(out[name][k]) / want[name] - 1) < 1e-9, (a, v, name)
    for b1 in (100.0, 800.0):
        out = rate(jnp.full(v0.shape, b1), jnp.asarray(v0))
        assert bool(jnp.all(out["served"]))
        for k, v in enumerate(v0):
            want = scipy_contact(_np_rate({"c": 2e6, "b1": b1}), M, v, separation)
            for name in ("e", "T", "x_max"):
                assert abs(float(out[name][k]) / want[name] - 1) < 1e-9, (b1, v, name)


@pytest.mark.slow
def test_a_flagged_member_is_never_served():
    """Heavy damping (Hunt-Crossley a v0 = 5, Kelvin-Voigt zeta 0.88) and a force that
    pulls (penetration, b = 2e4) are not served; the grid's numbers there are wrong."""
    hc = grid_contact(_law(_hc_law, c=2e6, a=2.0), M, 2.5, separation="force")
    kv = grid_contact(_law(_kv_law, c=2e6, b=0.88 * 2 * math.sqrt(2e6)), M, 2.5, separation="force")
    pull = grid_contact(_law(_pull_law, c=2e6, b=2e4), M, 2.5, separation="penetration")
    assert not bool(hc["served"]) and not bool(kv["served"]) and not bool(pull["served"])
    assert float(closed_forms.hunt_crossley_restitution(5.0)) < E_FLOOR


@pytest.mark.slow
def test_impact_batch_serves_the_grid_and_integrates_the_rest():
    """A batch mixing light damping, heavy damping (a v0 = 5) and a pulling force: the rows
    the grid served say "grid" and meet the reference; the others say "integrated" and
    equal `ji.impact` of their row to 1e-9."""
    law = _law(_pull_law, c=2e6, b=800.0)
    b = np.array([800.0, 2e4, 300.0, 2e4, 1200.0])
    v0 = np.array([2.5, 2.5, 1.5, 1.2, 2.9])
    fields = ("e", "T", "x_max", "F_max", "status", "path")
    # at impact's rtol for a user's law (a batch's default is 1e-11)
    out = ji.impact_batch(
        law,
        {"b": b},
        m=M,
        v0=v0,
        separation="penetration",
        fields=fields,
        rtol=1e-12,
        progress=False,
    )
    assert list(out["path"]) == ["grid", "integrated", "grid", "integrated", "grid"]
    for k in range(b.size):
        r = ji.impact(law.replace(b=b[k]), m=M, v0=v0[k], separation="penetration")
        assert int(out["status"][k]) == int(r.status)
        for name in ("e", "T", "x_max"):
            want = float(getattr(r, name))
            assert abs(out[name][k] - want) <= 1e-9 * abs(want), (k, name)
        if out["path"][k] == "grid":
            ref = reference_impact(
                "hertz_rate",
                {"c": 2e6, "b1": b[k]},
                m=M,
                v0=v0[k],
                separation="penetration",
                rtol=1e-13,
            )
            for name in ("e", "T", "x_max"):
                assert abs(out[name][k] / ref[name] - 1) < 1e-9, (k, name)
    heavy = _law(_hc_law, c=2e6, a=2.0)  # a v0 = 5: e = 0.197
    kv = _law(_kv_law, c=2e6, b=0.88 * 2 * math.sqrt(2e6))
    for law, fields in ((heavy, ("e", "T", "x_max", "path")), (kv, ("e", "T", "path"))):
        out = ji.impact_batch(law, m=M, v0=[2.5, 2.5], fields=fields, rtol=1e-12, progress=False)
        r = ji.impact(law, m=M, v0=2.5)
        assert list(out["path"]) == ["integrated", "integrated"]
        for name in fields[:-1]:
            assert abs(out[name][0] / float(getattr(r, name)) - 1) < 1e-9


@pytest.mark.slow
def test_the_gradient_of_e_through_the_grid_matches_central_differences():
    """jax.jacfwd of e by a and c through the fixed grid, against central differences of
    the grid itself and against the exact de/da of Hunt-Crossley's closed form."""
    v0, a = 2.5, 0.1

    def e_of(c, a):
        law = ji.custom_law(_hc_law, c=1.0, a=1.0).replace(c=c, a=a)
        return grid_contact(law, M, v0, separation="force")["e"]

    jac = jax.jit(jax.jacfwd(e_of, argnums=(0, 1)))(2e6, a)
    e = jax.jit(e_of)
    for k, (x, step) in enumerate(((2e6, 2e6 * 1e-5), (a, a * 1e-5))):
        args = [2e6, a]
        args[k] = x + step
        up = float(e(*args))
        args[k] = x - step
        down = float(e(*args))
        central = (up - down) / (2 * step)
        assert abs(float(jac[k]) - central) <= 1e-6 * abs(float(jac[k])) + 1e-12
    # Hunt-Crossley: e depends on a v0 alone, -u - ln(1 - u) = alpha - ln(1 + alpha)
    alpha = a * v0
    ee = float(closed_forms.hunt_crossley_restitution(alpha))
    u = alpha * ee
    du = alpha * (1 - u) / ((1 + alpha) * u)
    exact = v0 * (du / alpha - u / alpha**2)
    assert abs(float(jac[1]) / exact - 1) < 1e-8
    assert abs(float(jac[0])) < 1e-12  # e does not depend on c
