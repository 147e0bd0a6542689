"""The `dmt` law (issue 26): Hertz with the rate damping of law 14 and DMT's adhesion
`2 pi w R` while in contact, `F = c x^1.5 + b x^0.5 v - 2 pi w R`, contact ending at x = 0.

The adhesion pulls in as gravity does, so the impact is read off law 14's gravity table
under the penetration criterion with `gamma = (m g + 2 pi w R) x*/(m v0^2)`; checked against
an independent scipy DOP853 integration of the contact, the integrated path, law 14 under
an equal gravity, the sticking (captured) speeds, gradients and a fit of e(v) with sticking
as data.
"""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaximpact as ji

TOL = 1e-9
FIELDS = ("e", "T", "x_max", "F_max")


def scipy_dmt(c, b, R, w, m, v0, g=0.0, rtol=1e-13):
    """(e, T, x_max, F_max) of m x'' = -(c x^1.5 + b x^0.5 v - 2 pi w R) + m g from
    (0, v0), DOP853 at `rtol`; e = 0 where the body turns back inside the surface
    (captured by the adhesion)."""
    pull = 2 * math.pi * w * R
    kw = dict(method="DOP853", rtol=rtol, atol=1e-18)

    def rhs(t, y):
        x = max(y[0], 0.0)
        return [y[1], -(c * x**1.5 + b * math.sqrt(x) * y[1] - pull) / m + g]

    def event(fun, direction, terminal=True):
        fun.terminal, fun.direction = terminal, direction
        return fun

    def peak(t, y):  # dF/dt times x^0.5 (finite at first touch)
        x, v = max(y[0], 0.0), y[1]
        a = rhs(t, y)[1]
        return 1.5 * c * x * v + b * (0.5 * v * v + x * a)

    top = event(lambda t, y: y[1], -1)
    one = solve_ivp(rhs, (0, 1e3), [0.0, v0], events=[top, event(peak, -1, False)], **kw)
    t_max, x_max = one.t_events[0][0], one.y_events[0][0][0]
    force = [c * y[0] ** 1.5 + b * math.sqrt(max(y[0], 0)) * y[1] - pull for y in one.y_events[1]]
    f_max = max([-pull, c * x_max**1.5 - pull, *force])
    back = event(lambda t, y: y[1] + 1e-14 * v0, 1)
    two = solve_ivp(rhs, (0, 1e3), [x_max, 0.0], events=[event(lambda t, y: y[0], -1), back], **kw)
    if len(two.t_events[0]) == 0:
        return 0.0, t_max + two.t_events[1][0], x_max, f_max
    return -two.y_events[0][0][1] / v0, t_max + two.t_events[0][0], x_max, f_max


# c = m = v0 = 1 (x* = t* = 1): beta is b, the adhesion's group is 2 pi w R
CASES = [
    dict(c=1.0, b=0.1, R=1.0, w=0.05 / (2 * math.pi)),
    dict(c=1.0, b=0.01, R=1.0, w=0.2 / (2 * math.pi)),
    dict(c=1.0, b=1.0, R=0.5, w=0.01 / math.pi),
]


@pytest.mark.parametrize("params", CASES)
def test_matches_scipy_on_the_table(params):
    r = ji.impact(ji.law("dmt", **params), m=1.0, v0=1.0)
    assert r.path == "similarity" and int(r.num_steps) == 0 and r.status_name == "separated"
    want = scipy_dmt(**params, m=1.0, v0=1.0)
    for field, value in zip(FIELDS, want, strict=True):
        error = abs(float(getattr(r, field)) / value - 1)
        assert error < TOL, f"{field}: {error:.2e}"
    # the adhesion does no net work over a contact that ends at x = 0
    assert float(r.dissipated) == pytest.approx(0.5 * (1 - float(r.e) ** 2), rel=1e-12)


@pytest.mark.slow
def test_a_microsphere_in_SI_units_and_the_integrated_path():
    """A 10 um silica-like sphere (m = 1e-11 kg) at 0.5 m/s, with gravity: the table and the
    integrated path at rtol 1e-12 agree to 1e-9, and both to scipy."""
    R, m = 5e-6, 1.1e-12
    c = ji.hertz_stiffness(E=7e10, nu=0.17, R=R)
    params = dict(c=c, b=2e-2, R=R, w=0.05)
    law = ji.law("dmt", **params)
    r = ji.impact(law, m=m, v0=0.5, g=9.81)
    ref = ji.impact(law, m=m, v0=0.5, g=9.81, method="integrate", rtol=1e-12)
    assert r.path == "similarity" and ref.path == "integrated"
    want = scipy_dmt(**params, m=m, v0=0.5, g=9.81)
    for field, value in zip(FIELDS, want, strict=True):
        assert float(getattr(r, field)) == pytest.approx(value, rel=TOL), field
        assert float(getattr(ref, field)) == pytest.approx(value, rel=TOL), field


def test_without_adhesion_it_is_law_14_and_with_it_law_14_under_gravity():
    base = dict(c=2e6, b=800.0)
    plain = ji.impact(ji.law("dmt", **base, R=0.01, w=0.0), m=1.0, v0=2.5)
    law14 = ji.impact(
        ji.law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5, separation="penetration"
    )
    for field in (*FIELDS, "t_max"):
        assert float(getattr(plain, field)) == pytest.approx(float(getattr(law14, field)), rel=TOL)
    # an adhesion of 2 pi w R = 2000 N on 1 kg is a gravity of 2000 m/s^2 inside the contact
    w = 2000.0 / (2 * math.pi * 0.01)
    dmt = ji.impact(ji.law("dmt", **base, R=0.01, w=w), m=1.0, v0=2.5)
    pulled = ji.impact(
        ji.law("hertz_rate", c=2e6, b1=800.0), m=1.0, v0=2.5, g=2000.0, separation="penetration"
    )
    for field in ("e", "T", "x_max", "t_max"):
        assert float(getattr(dmt, field)) == pytest.approx(float(getattr(pulled, field)), rel=TOL)
    assert float(dmt.F_max) == pytest.approx(float(pulled.F_max) - 2000.0, rel=TOL)


@pytest.mark.slow
def test_sticks_below_a_speed_with_the_integrated_paths_status():
    """Slow impacts are captured by the adhesion (e = 0, status captured), fast ones leave;
    inside one vmap the table serves some members and the integrator the others."""
    law = ji.law("dmt", c=1.0, b=0.3, R=1.0, w=0.1 / (2 * math.pi))
    speeds = jnp.asarray([0.05, 0.2, 0.5, 1.0, 3.0])

    def one(v0, method):
        r = ji.impact(law, m=1.0, v0=v0, method=method, throw=False)
        return jnp.stack([r.e, r.T, r.x_max]), r.status

    got, status = jax.jit(jax.vmap(lambda v: one(v, "auto")))(speeds)
    want, status_want = jax.jit(jax.vmap(lambda v: one(v, "integrate")))(speeds)
    np.testing.assert_array_equal(np.asarray(status), np.asarray(status_want))
    names = [ji.Status(int(s)).name for s in np.asarray(status)]
    assert names[0] == "captured" and names[-1] == "separated"
    np.testing.assert_allclose(np.asarray(got), np.asarray(want), rtol=1e-8)
    assert float(got[0, 0]) == 0.0


@pytest.mark.slow
def test_gradients_match_central_differences():
    def outputs(x, method, rtol):
        c, b, w, v0 = x
        r = ji.impact(ji.law("dmt", c=c, b=b, R=1.0, w=w), m=1.0, v0=v0, method=method, rtol=rtol)
        return jnp.stack([r.e, r.T])

    x = jnp.asarray([1.0, 0.1, 0.05 / (2 * math.pi), 1.0])
    jac = jax.jacrev(lambda x: outputs(x, "auto", 1e-11))(x)
    fd = []
    for i in range(4):
        h = float(x[i]) * 1e-4
        fd.append(
            (
                outputs(x.at[i].add(h), "integrate", 1e-12)
                - outputs(x.at[i].add(-h), "integrate", 1e-12)
            )
            / (2 * h)
        )
    fd = np.stack(fd, axis=1)
    scale = np.abs(fd).max(axis=1, keepdims=True)
    assert np.max(np.abs(np.asarray(jac) - fd) / scale) < 1e-6


@pytest.mark.slow
def test_calibrate_recovers_damping_and_adhesion_with_sticking_as_data():
    """e(v) of a DMT contact, the slowest speed captured (e = 0): b and w come back; the
    captured row is matched by a captured impact, not refused."""
    truth = ji.law("dmt", c=1.0, b=0.3, R=1.0, w=0.1 / (2 * math.pi))
    v0 = np.array([0.05, 0.4, 0.7, 1.0, 1.6, 2.5])
    e = np.array([float(ji.impact(truth, m=1.0, v0=v, throw=False).e) for v in v0])
    assert e[0] == 0.0 and np.all(e[1:] > 0)
    start = ji.law("dmt", c=1.0, b=0.2, R=1.0, w=0.06 / (2 * math.pi))
    fit = ji.calibrate(start, m=1.0, v0=v0, e=e, free=("b", "w"))
    assert bool(fit.reproduces), fit
    assert float(fit.params["b"]) == pytest.approx(0.3, rel=1e-5)
    assert float(fit.params["w"]) == pytest.approx(0.1 / (2 * math.pi), rel=1e-5)


def test_bad_input_is_refused_in_one_line():
    with pytest.raises(ValueError, match="R"):
        ji.law("dmt", c=1.0, b=0.1, R=0.0, w=0.1)
    with pytest.raises(ValueError, match="w"):
        ji.law("dmt", c=1.0, b=0.1, R=1.0, w=-0.1)
