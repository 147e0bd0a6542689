"""The two-group table of a dry force (`_curves.gravity`, group "dry"): Bingham-modified
(eq. 8, `F = c x + b1 x v + P sgn(v)`) without gravity read off `(beta, pi)`, against an
independent scipy DOP853 integration of its two phases, the integrated path, gradients
against central differences, `vmap`, the fall-back to the integrator outside the table
(same status), `calibrate` and the shipped file.

In the units c = m = v0 = 1 (x* = t* = 1): beta = b1 v0/c is `b1`, pi = P/(c x*) is `P`.
"""

import functools
import zlib

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from scipy.integrate import solve_ivp

import jaximpact as ji
from jaximpact._curves import gravity
from jaximpact._curves.shapes import CurveKey

OUTPUTS = ("e", "T", "x_max", "F_max")
TOL = 1e-9
SEPARATIONS = ("force", "penetration")


def scipy_bingham_modified(beta, pi, separation):
    """(e, T, x_max, F_max) of X'' = -X - beta X X' - pi sgn(X') from (0, 1), each phase
    its own DOP853 solve at rtol 1e-13 ended by its events; e = 0 where the body is held
    (X_max <= pi at maximum compression, or V back to 0 before separation)."""
    kw = dict(method="DOP853", rtol=1e-13, atol=1e-16)

    def event(fun, direction, terminal=True):
        fun.terminal, fun.direction = terminal, direction
        return fun

    def compress(t, y):
        return [y[1], -y[0] - beta * y[0] * y[1] - pi]

    def force_rate(t, y):  # dF/dt in compression, F = X + beta X V + pi
        a = compress(t, y)[1]
        return y[1] + beta * y[1] ** 2 + beta * y[0] * a

    one = solve_ivp(
        compress,
        (0, 1e3),
        [0.0, 1.0],
        events=[event(lambda t, y: y[1], -1), event(force_rate, -1, terminal=False)],
        **kw,
    )
    t_max, x_max = one.t_events[0][0], one.y_events[0][0][0]
    peaks = [pi, x_max + pi] + [y[0] + beta * y[0] * y[1] + pi for y in one.y_events[1]]
    f_max = max(peaks)
    if x_max <= pi:
        return 0.0, t_max, x_max, f_max

    def restore(t, y):
        return [y[1], -y[0] - beta * y[0] * y[1] + pi]

    if separation == "force":
        leave = event(lambda t, y: y[0] + beta * y[0] * y[1] - pi, -1)
    else:
        leave = event(lambda t, y: y[0], -1)
    back = event(lambda t, y: y[1] + 1e-14, 1)
    two = solve_ivp(restore, (0, 1e3), [x_max, 0.0], events=[leave, back], **kw)
    if len(two.t_events[0]) == 0:
        return 0.0, t_max + two.t_events[1][0], x_max, f_max
    return -two.y_events[0][0][1], t_max + two.t_events[0][0], x_max, f_max


def _law(beta, pi):
    return ji.law("bingham_modified", c=1.0, b1=beta, P=pi)


@functools.cache
def _batched(separation, method="auto", rtol=1e-11):
    def one(beta, pi):
        r = ji.impact(
            _law(beta, pi),
            m=1.0,
            v0=1.0,
            separation=separation,
            method=method,
            rtol=rtol,
            throw=False,
        )
        return {k: getattr(r, k) for k in (*OUTPUTS, "status", "num_steps")}

    return jax.jit(jax.vmap(one))


def _table(separation):
    return gravity.table_for(CurveKey(1.0, 1.0, separation), "dry")


def _points(separation, count):
    """Log-uniform beta in [1e-6, beta_max] and pi in each piece's [0, G_k]."""
    table = _table(separation)
    rng = np.random.default_rng(zlib.crc32(f"dry {separation}".encode()))
    s = rng.uniform(np.log(1e-6), table.breaks[-1] - 1e-9, count)
    k = np.searchsorted(table.breaks, s, side="right") - 1
    return np.exp(s), table.gamma_max[k] * rng.uniform(0.0, 1.0, count) ** 2


def _check_against_scipy(separation, count):
    """`count` points of the table: e, T, x_max, F_max within 1e-9 of scipy, without a
    solver step, status separated."""
    betas, pis = _points(separation, count)
    got = _batched(separation)(jnp.asarray(betas), jnp.asarray(pis))
    assert np.all(np.asarray(got["num_steps"]) == 0)
    assert np.all(np.asarray(got["status"]) == ji.Status.separated)
    for i, (beta, pi) in enumerate(zip(betas, pis, strict=True)):
        want = scipy_bingham_modified(beta, pi, separation)
        for field, value in zip(OUTPUTS, want, strict=True):
            error = abs(float(got[field][i]) / value - 1)
            assert error < TOL, f"{field} at beta={beta:.3g}, pi={pi:.3g}: {error:.2e}"


@pytest.mark.slow  # 4.5 s each (the fast suite: 3 minutes)
@pytest.mark.parametrize("separation", SEPARATIONS)
def test_table_matches_scipy(separation):
    _check_against_scipy(separation, 6 if separation == "force" else 4)


@pytest.mark.slow
@pytest.mark.parametrize("separation", SEPARATIONS)
def test_table_matches_scipy_widely(separation):
    _check_against_scipy(separation, 40)


@pytest.mark.slow
def test_the_seed_papers_case_takes_the_table():
    """The paper's case 5 (c = 2e6, b1 = 200, P = 400, m = 1 kg, v0 = 2.5 m/s): read off
    the table (`path` similarity, no solver step), the integrated path at rtol 1e-12 to
    1e-9, and the energy taken is 1/2 m v0^2 (1 - e^2)."""
    law = ji.law("bingham_modified", c=2e6, b1=200.0, P=400.0)
    r = ji.impact(law, m=1.0, v0=2.5)
    ref = ji.impact(law, m=1.0, v0=2.5, method="integrate", rtol=1e-12)
    assert r.path == "similarity" and int(r.num_steps) == 0 and r.status_name == "separated"
    for field in (*OUTPUTS, "t_max", "v_out", "dissipated"):
        assert float(getattr(r, field)) == pytest.approx(float(getattr(ref, field)), rel=TOL)
    assert ji.impact(law, m=1.0, v0=2.5, method="integrate").path == "integrated"


@pytest.mark.slow
def test_outside_the_table_integrates_with_the_same_status():
    """A dry force that holds the body (stuck at maximum compression, or, under the
    penetration criterion, after its speed comes back to 0) is integrated inside the same
    call: the same answer and status as `method="integrate"`."""
    separation = "penetration"
    betas = np.array([0.3, 0.5, 1e-3, 5.0])
    pis = np.array([0.05, 0.7, 0.4, 0.2])  # in, stuck at the top, stuck later, stuck later
    got = _batched(separation)(jnp.asarray(betas), jnp.asarray(pis))
    want = _batched(separation, "integrate")(jnp.asarray(betas), jnp.asarray(pis))
    np.testing.assert_array_equal(np.asarray(got["status"]), np.asarray(want["status"]))
    assert list(np.asarray(got["status"]) == ji.Status.separated) == [True, False, False, False]
    assert list(np.asarray(got["num_steps"]) > 0) == [False, True, True, True]
    for field in OUTPUTS:
        np.testing.assert_allclose(np.asarray(got[field]), np.asarray(want[field]), rtol=TOL)


@pytest.mark.slow
def test_gradients_match_central_differences():
    """d/d(c, b1, P, v0) of e and T on the table against central differences of the
    integrated path at rtol 1e-12; forward mode agrees with reverse mode."""

    def outputs(x, method, rtol):
        c, b1, P, v0 = x
        law = ji.law("bingham_modified", c=c, b1=b1, P=P)
        r = ji.impact(law, m=1.0, v0=v0, method=method, rtol=rtol)
        return jnp.stack([r.e, r.T])

    x = jnp.asarray([2e6, 200.0, 400.0, 2.5])
    jac = jax.jacrev(lambda x: outputs(x, "auto", 1e-11))(x)
    columns = []
    for i in range(4):
        h = float(x[i]) * 1e-4
        up = outputs(x.at[i].add(h), "integrate", 1e-12)
        down = outputs(x.at[i].add(-h), "integrate", 1e-12)
        columns.append((up - down) / (2 * h))
    fd = np.stack(columns, axis=1)
    scale = np.abs(fd).max(axis=1, keepdims=True)
    assert np.max(np.abs(np.asarray(jac) - fd) / scale) < 1e-6
    jf = jax.jacfwd(lambda x: outputs(x, "auto", 1e-11))(x)
    np.testing.assert_allclose(np.asarray(jf), np.asarray(jac), rtol=1e-10)


@pytest.mark.slow
def test_calibrate_reads_the_table():
    """e at four speeds from the table's own impacts: calibrate recovers b1 and P (c held)
    on the table, without a solver step in its final impacts."""
    truth = ji.law("bingham_modified", c=2e6, b1=200.0, P=400.0)
    v0 = np.array([1.0, 1.8, 2.5, 3.5])
    e = [float(ji.impact(truth, m=1.0, v0=v).e) for v in v0]
    start = ji.law("bingham_modified", c=2e6, b1=120.0, P=250.0)
    fit = ji.calibrate(start, m=1.0, v0=v0, e=e, free=("b1", "P"))
    assert bool(fit.reproduces)
    assert float(fit.params["b1"]) == pytest.approx(200.0, rel=1e-6)
    assert float(fit.params["P"]) == pytest.approx(400.0, rel=1e-6)


def test_shipped_file():
    """The tail (each piece's last coefficients times G_k) estimates the error from above:
    its largest, 1.3e-9 (force criterion, beta in [3.9e-7, 2.0e-6]), is mostly the reference
    impacts' scatter divided by gamma; 40 random points of that piece are within 1.3e-10
    of scipy in e, T, x_max, F_max."""
    tables = gravity.load(gravity.SHIPPED_DRY_FILE, "dry")
    assert set(tables) == set(gravity.SHIPPED_DRY)
    for table in tables.values():
        assert table.group == "dry"
        assert table.tail.max() < 2e-9
        assert np.all(table.gamma_max <= gravity.GAMMA_FRACTION * table.capture + 1e-15)
    assert gravity.SHIPPED_DRY_FILE.stat().st_size < 2e6


def _fit_programs(monkeypatch):
    """The `integrate_outside` of each call of a host fit's program on a table path."""
    from jaximpact._fit import calibrate as fitting

    calls = []
    for kind, program in list(fitting._evaluated_compiled.items()):

        def counted(law, theta, data, m, g, options, program=program):
            calls.append(options.impact.integrate_outside)
            return program(law, theta, data, m, g, options)

        monkeypatch.setitem(fitting._evaluated_compiled, kind, counted)
    return calls


def test_a_fit_inside_the_table_compiles_no_integration(monkeypatch):
    """Every impact of a fit in the table: its one program reads the table alone (the
    integration of the impacts outside it, 8 of a first fit's 10 s, is not compiled)."""
    truth = ji.law("bingham_modified", c=2e6, b1=200.0, P=400.0)
    v0 = np.array([1.0, 1.8, 2.5, 3.5])
    e = [float(ji.impact(truth, m=1.0, v0=v).e) for v in v0]
    calls = _fit_programs(monkeypatch)
    start = ji.law("bingham_modified", c=2e6, b1=150.0, P=300.0)
    fit = ji.calibrate(start, m=1.0, v0=v0, e=e, free=("b1", "P"), optimizer="lm")
    assert calls and not any(calls)
    assert float(fit.params["P"]) == pytest.approx(400.0, rel=1e-6)


@pytest.mark.slow  # compiles the integration: 10 s
def test_a_fit_from_outside_the_table_integrates_there(monkeypatch):
    """A start that holds the slowest body (stuck: outside the table): that evaluation is
    made again with the integration, and the fit still recovers the law."""
    truth = ji.law("bingham_modified", c=2e6, b1=200.0, P=400.0)
    v0 = np.array([1.0, 1.8, 2.5, 3.5])
    e = [float(ji.impact(truth, m=1.0, v0=v).e) for v in v0]
    start = ji.law("bingham_modified", c=2e6, b1=200.0, P=1500.0)
    assert ji.impact(start, m=1.0, v0=1.0, throw=False).path == "integrated"
    calls = _fit_programs(monkeypatch)
    fit = ji.calibrate(start, m=1.0, v0=v0, e=e, free=("b1", "P"), optimizer="lm")
    assert calls[:2] == [False, True]
    assert float(fit.params["b1"]) == pytest.approx(200.0, rel=1e-6)
    assert float(fit.params["P"]) == pytest.approx(400.0, rel=1e-6)
