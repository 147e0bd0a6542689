"""Closed forms against the integrator (`method="integrate"`, rtol 1e-12) and independent
formulas (scipy's Lambert W and Beta functions)."""

import math

import hypothesis
import hypothesis.strategies as st
import jax
import mpmath
import numpy as np
import pytest
import scipy.special
from helpers import V0, M, assert_finite, assert_rel, rel_err, solver
from scipy.optimize import brentq

import jaximpact as ji
from jaximpact import closed_forms

ORACLE_RTOL = 1e-12  # the integrator's tolerance when it serves as an oracle

# Compiled once: called eagerly, the closed forms that solve for a root (Hunt-Crossley's e,
# Kelvin-Voigt's rest time) recompile optimistix's root_find on every call (0.3-0.9 s each)
kelvin_voigt = jax.jit(closed_forms.kelvin_voigt, static_argnames="separation")
hunt_crossley_restitution = jax.jit(closed_forms.hunt_crossley_restitution)
KEYS = ("e", "T", "x_max", "t_max", "F_max")


def closed(fields):
    return {k: np.asarray(v) for k, v in fields.items()}


def compare(got, want, what, rtol=1e-9, e_atol=1e-11, keys=KEYS):
    """Relative comparison; `e` also gets an absolute tolerance (in units of v0): the
    integrator's error in the exit speed is absolute, so a small e keeps ~1e-12 of it."""
    worst = 0.0
    for key in keys:
        atol = e_atol if key == "e" else 0.0
        assert_rel(got[key], want[key], rtol, f"{what} {key}", atol=atol)
        worst = max(worst, rel_err(got[key], want[key]))
    return worst


# ---------------------------------------------------------------------- Kelvin-Voigt

KV_C, KV_M, KV_V0 = 1e4, 1.0, 1.0  # critical damping at b = 2 sqrt(m c) = 200
UNDER = [0.0, 20.0, 100.0, 150.0, 190.0]
OVER = [250.0, 400.0, 1000.0, 5000.0]


@pytest.mark.parametrize("b", UNDER + [199.0, 200.0, 201.0] + OVER)
def test_kelvin_voigt_force_criterion(b):
    """Eq. (5) holds for every damping, over-damped included (and exactly critical)."""
    want = closed(kelvin_voigt(KV_C, b, KV_M, KV_V0, separation="force"))
    got = solver("kelvin_voigt", "force", rtol=ORACLE_RTOL)(dict(c=KV_C, b=b), m=KV_M, v0=KV_V0)
    assert int(got["status"]) == int(want["status"]) == ji.Status.separated
    keys, rtol = KEYS, 1e-9
    if b > 200.0:
        # ill-conditioned T: F crosses zero with slope c v_out, v_out = -e v0 small (e = 0.0093
        # at b = 1000), so dT ~ dF/(c e v0): measured 2e-9 (b = 1000) and 3.3e-6 (b = 5000)
        assert_rel(got["T"], want["T"], 1e-7 if b < 5000 else 1e-5, f"b={b} T")
        keys = ("e", "x_max", "t_max", "F_max")
    if b >= 5000:
        # x_max = 2e-4 x* (x* = v0 sqrt(m/c) ignores the damping): the solver's absolute
        # error is 1e-12 x*, so 2.5e-9 relative in t_max, 5e-9 in x_max
        rtol = 1e-8
    compare(got, want, f"force b={b}", keys=keys, rtol=rtol)
    if b == 0.0:
        assert_rel(want["T"], math.pi * math.sqrt(KV_M / KV_C), 1e-15, "undamped T")
        assert_rel(want["e"], 1.0, 1e-15, "undamped e")


@pytest.mark.slow
@pytest.mark.parametrize("b", UNDER)
def test_kelvin_voigt_penetration_criterion_under_damped(b):
    want = closed(kelvin_voigt(KV_C, b, KV_M, KV_V0, separation="penetration"))
    got = solver("kelvin_voigt", "penetration", rtol=ORACLE_RTOL)(
        dict(c=KV_C, b=b), m=KV_M, v0=KV_V0
    )
    assert int(got["status"]) == int(want["status"]) == ji.Status.separated
    compare(got, want, f"penetration b={b}")
    # the paper's formula: e = exp(-pi b / sqrt(4 m c - b^2)), T = 2 pi m / sqrt(4 m c - b^2)
    root = math.sqrt(4 * KV_M * KV_C - b**2)
    assert_rel(want["e"], math.exp(-math.pi * b / root), 1e-13, "paper e")
    assert_rel(want["T"], 2 * math.pi * KV_M / root, 1e-13, "paper T")


@pytest.mark.slow
@pytest.mark.parametrize("b", OVER)
def test_kelvin_voigt_penetration_criterion_over_damped(b):
    want = closed(kelvin_voigt(KV_C, b, KV_M, KV_V0, separation="penetration"))
    assert_finite(want, "closed form")
    assert int(want["status"]) == ji.Status.captured
    assert want["e"] == 0.0 and math.isfinite(want["T"]) and want["T"] > want["t_max"]
    integrate = solver("kelvin_voigt", "penetration", rtol=ORACLE_RTOL)
    if b >= 5000:
        # the integrated creep to rest runs out of steps at rtol 1e-12 (the closed form is
        # the default path); a failed solve is refused, not returned as numbers
        with pytest.raises(RuntimeError, match="ran out of steps"):
            integrate(dict(c=KV_C, b=b), m=KV_M, v0=KV_V0)
        return
    got = integrate(dict(c=KV_C, b=b), m=KV_M, v0=KV_V0)
    assert int(got["status"]) == ji.Status.captured
    rtol = 1e-9
    compare(got, want, f"over-damped b={b}", keys=("e", "x_max", "t_max", "F_max"), rtol=rtol)


def exact_rest_time(c, b, m, v0, rest_tol=1e-7):
    """When over-damped Kelvin-Voigt has |V| + |X + beta V| = rest_tol (X = x / x*,
    x* = v0 sqrt(m/c), V = v/v0), as `impact` defines a captured contact's T; computed in
    logarithms, free of overflow."""
    t_star = math.sqrt(m / c)
    beta = b * t_star / m
    s = beta / 2
    q = math.sqrt(s * s - 1)
    slow, fast = -s + q, -s - q

    def excess(tau):
        d = math.exp((fast - slow) * tau)
        x = (1 - d) / (slow - fast)
        v = (slow - fast * d) / (slow - fast)
        return slow * tau + math.log(abs(v) + abs(x + beta * v)) - math.log(rest_tol)

    return brentq(excess, 1.0, 1e6, xtol=1e-14, rtol=1e-15) * t_star


@pytest.mark.parametrize(
    "b",
    [
        250.0,
        300.0,
        1000.0,
        3000.0,
    ],
)
def test_overdamped_rest_time(b):
    """The documented T of a captured over-damped Kelvin-Voigt contact (penetration)."""
    exact = exact_rest_time(KV_C, b, KV_M, KV_V0)
    want = closed(kelvin_voigt(KV_C, b, KV_M, KV_V0, separation="penetration"))
    assert_rel(want["T"], exact, 1e-9, f"closed-form rest time b={b}")


@pytest.mark.slow
@pytest.mark.parametrize("b", [250.0, 300.0, 1000.0])
def test_overdamped_rest_time_integrated(b):
    """The integrated rest time sits at the solver's noise floor (|V| + |F| ~ 1e-9 is near
    rtol times the stiffness): measured 1.8e-6, 1.7e-6, 2.1e-3 relative at rtol 1e-12."""
    exact = exact_rest_time(KV_C, b, KV_M, KV_V0)
    got = solver("kelvin_voigt", "penetration", rtol=ORACLE_RTOL)(
        dict(c=KV_C, b=b), m=KV_M, v0=KV_V0
    )
    assert int(got["status"]) == ji.Status.captured
    assert_rel(got["T"], exact, 1e-2, f"integrated rest time b={b}")


@pytest.mark.parametrize("separation", ["force", "penetration"])
def test_kelvin_voigt_impact_uses_the_closed_form(separation):
    for b in (0.0, 400.0, 3000.0):
        want = closed(kelvin_voigt(2e6, b, M, V0, separation=separation))
        got = solver("kelvin_voigt", separation, method="auto")(dict(c=2e6, b=b))
        assert int(got["num_steps"]) == 0
        compare(got, want, f"auto b={b}", rtol=1e-15, e_atol=0.0)


# --------------------------------------------------------------------------- Maxwell


@pytest.mark.parametrize("b", [800.0, 1000.0, 2000.0, 1e4, 1e5])
def test_maxwell_under_damped(b):
    """c = 2e6, m = 1: under-damped while 4 b^2 > m c, i.e. b > 707."""
    c = 2e6
    want = closed(closed_forms.maxwell(c, b, M, V0))
    assert int(want["status"]) == ji.Status.separated
    got = solver("maxwell", "force", rtol=ORACLE_RTOL)(dict(c=c, b=b))
    assert int(got["status"]) == ji.Status.separated
    # F_max for light damping (b = 1e5): test_force_peak_near_maximum_compression
    compare(got, want, f"maxwell b={b}", keys=KEYS if b < 1e5 else KEYS[:-1])
    # the paper's formulas (eqs. 10-11)
    q = math.sqrt(4 * b * b - c * M)
    assert_rel(want["e"], math.exp(-math.pi * math.sqrt(c * M) / q), 1e-13, "paper e")
    assert_rel(want["T"], 2 * math.pi * b * math.sqrt(c * M) / (c * q), 1e-13, "paper T")


@pytest.mark.parametrize(
    "name, params, exact",
    [
        ("maxwell", dict(c=2e6, b=1e5), lambda: closed_forms.maxwell(2e6, 1e5, M, V0)),
        ("kelvin_voigt", dict(c=2e6, b=2.0), lambda: closed_forms.kelvin_voigt(2e6, 2.0, M, V0)),
    ],
    ids=["maxwell-b1e5", "kelvin_voigt-b2"],
)
def test_force_peak_near_maximum_compression(name, params, exact):
    got = solver(name, "force", rtol=ORACLE_RTOL)(params)
    # the peak's event comes first in the _TO_PEAK phase (it was missed by 1.0e-4 for
    # Maxwell and 9.9e-7 for Kelvin-Voigt while V = 0 came first, diffrax issue #639)
    assert_rel(got["F_max"], np.asarray(exact()["F_max"]), 1e-9, f"{name} F_max")


# ---------------------------------------------------------------------- Hunt-Crossley


@pytest.mark.slow
@pytest.mark.parametrize("n", [1.0, 1.5, 2.5])
@pytest.mark.parametrize("a", [1e-3, 0.1, 1.0, 10.0])
def test_hunt_crossley_restitution_vs_integrator(a, n):
    alpha = 1.5 * a * V0
    want = float(hunt_crossley_restitution(alpha))
    got = solver("hunt_crossley", rtol=ORACLE_RTOL)(dict(c=2e6, a=a, n=n))
    assert int(got["status"]) == ji.Status.separated
    # measured worst 1.0e-9 relative (n = 1, a = 10: e = 0.027, 2.7e-11 absolute)
    assert_rel(got["e"], want, 1e-9, f"hunt_crossley a={a} n={n} e", atol=1e-10)


@pytest.mark.parametrize("alpha", np.logspace(-2, 2, 9))
def test_hunt_crossley_restitution_vs_lambert_w(alpha):
    """e = (1 + W0(-(1 + alpha) exp(-(1 + alpha)))) / alpha, accurate for alpha >= 1e-2
    (below, the argument nears the branch point -1/e and W0 loses digits)."""
    z = -(1 + alpha) * math.exp(-(1 + alpha))
    expected = (1 + scipy.special.lambertw(z, 0).real) / alpha
    got = hunt_crossley_restitution(alpha)
    assert_rel(got, expected, 1e-11, f"e at alpha={alpha}")  # measured worst 7e-13


def test_hunt_crossley_restitution_small_alpha():
    """e = 1 - 2 alpha/3 + O(alpha^2), with full precision down to tiny alpha."""
    for alpha in (1e-12, 1e-8, 1e-5):
        e = float(hunt_crossley_restitution(alpha))
        assert abs(e - (1 - 2 * alpha / 3)) <= alpha**2 + 2.3e-16, (alpha, e)
    assert float(hunt_crossley_restitution(0.0)) == 1.0
    # and the implicit equation -alpha e - ln(1 - alpha e) = alpha - ln(1 + alpha)
    for alpha in (1e-3, 0.3, 3.0):
        e = float(hunt_crossley_restitution(alpha))
        lhs = -alpha * e - math.log1p(-alpha * e)
        assert_rel(lhs, alpha - math.log1p(alpha), 1e-12, f"implicit equation at {alpha}")


def lambert_w_restitution(alpha):
    """The oracle: e = (1 + W0(-(1 + alpha) exp(-(1 + alpha))))/alpha and de/dalpha, in
    mpmath with enough digits for the branch point (1 + W0 ~ alpha for small alpha)."""
    digits = 40 + 2 * max(0, int(-math.log10(alpha)))
    with mpmath.workdps(digits):
        a = mpmath.mpf(float(alpha))
        e = (1 + mpmath.lambertw(-(1 + a) * mpmath.exp(-(1 + a)), 0).real) / a
        # from -u - ln(1 - u) = a - ln(1 + a), u = a e: du/da = a (1 - u)/((1 + a) u)
        u = a * e
        de = (1 - u) / ((1 + a) * u) - e / a
        return float(e), float(de)


# the values the bisection lost its bracket at (float32 and float64), and the series joins
HARD_ALPHAS = [44.7, 51.6, 112.0, 508.0, 708.0, 2512.0, 3548.0, 0.1, 0.09999999, 1.0]


def test_hunt_crossley_restitution_every_alpha_against_mpmath():
    """To 1e-12 relative over alpha in [1e-8, 1e6], as one batch (measured worst 9e-16)."""
    alphas = np.concatenate([np.logspace(-8, 6, 141), HARD_ALPHAS])
    got = np.asarray(hunt_crossley_restitution(alphas))
    want = np.array([lambert_w_restitution(a)[0] for a in alphas])
    assert got.shape == alphas.shape
    assert_rel(got, want, 1e-12, "e(alpha) batch")
    # one by one (the same compiled scalar function as the property test)
    for alpha in HARD_ALPHAS:
        assert_rel(hunt_crossley_restitution(alpha), lambert_w_restitution(alpha)[0], 1e-12, "e")
    # a 2-d array keeps its shape
    grid = np.array([[1e-3, 44.7], [51.6, 3548.0]])
    want = [[lambert_w_restitution(a)[0] for a in row] for row in grid]
    assert_rel(hunt_crossley_restitution(grid), np.array(want), 1e-12, "2-d")


def test_hunt_crossley_restitution_limits_and_float32():
    assert float(hunt_crossley_restitution(0.0)) == 1.0
    assert float(hunt_crossley_restitution(np.inf)) == 0.0
    assert_rel(hunt_crossley_restitution(1e300), 1e-300, 1e-14, "e ~ 1/alpha")
    assert_rel(hunt_crossley_restitution(1e-300), 1.0, 1e-15, "e ~ 1")
    assert_rel(hc_grad(0.0), -2 / 3, 1e-14, "de/dalpha at 0")
    # float32: no error, single-precision answers
    alphas = np.array(HARD_ALPHAS + [1e-4, 0.375, 1e5], dtype=np.float32)
    with jax.enable_x64(False):
        got = np.asarray(jax.jit(closed_forms.hunt_crossley_restitution)(alphas))
    assert got.dtype == np.float32
    want = np.array([lambert_w_restitution(float(a))[0] for a in alphas])
    assert_rel(got, want, 2e-6, "float32 e")


@pytest.mark.parametrize("bad", [-1.0, np.nan, [0.3, -2.0], [[0.1, np.nan]]])
def test_hunt_crossley_restitution_refuses_negative_and_nan(bad):
    with pytest.raises(ValueError, match="alpha = D v0 must be >= 0"):
        closed_forms.hunt_crossley_restitution(bad)
    with pytest.raises(TypeError, match="real number"):
        closed_forms.hunt_crossley_restitution("0.5")
    # traced (a batch must not abort): NaN for the bad member only
    out = np.asarray(hunt_crossley_restitution(np.array([-1.0, np.nan, 0.375])))
    assert np.isnan(out[:2]).all() and np.isfinite(out[2])


def test_hunt_crossley_restitution_gradient():
    """grad (implicit, through the last Newton step) against the analytic de/dalpha and
    central differences of the function itself, one by one and under vmap."""
    alphas = np.array([1e-8, 1e-3, 0.0999, 0.1, 0.5, 3.0, 44.7, 51.6, 708.0, 1e4])
    grads = np.asarray(hc_grad_batch(alphas))
    want = np.array([lambert_w_restitution(a)[1] for a in alphas])
    assert_rel(grads, want, 1e-9, "de/dalpha (vmap)")
    for alpha in (0.5, 44.7, 3548.0):
        h = 1e-5 * alpha
        fd = (hunt_crossley_restitution(alpha + h) - hunt_crossley_restitution(alpha - h)) / (2 * h)
        assert_rel(hc_grad(alpha), fd, 1e-7, f"grad vs finite differences at {alpha}")


hc_grad = jax.jit(jax.grad(closed_forms.hunt_crossley_restitution))
hc_grad_batch = jax.jit(jax.vmap(jax.grad(closed_forms.hunt_crossley_restitution)))


@hypothesis.settings(max_examples=60, deadline=None, derandomize=True)
@hypothesis.given(log_alpha=st.floats(min_value=-8.0, max_value=6.0))
def test_hunt_crossley_restitution_property(log_alpha):
    """Log-uniform alpha in [1e-8, 1e6]: e to 1e-12 and its gradient to 1e-9 (mpmath)."""
    alpha = 10.0**log_alpha
    e, de = lambert_w_restitution(alpha)
    assert_rel(hunt_crossley_restitution(alpha), e, 1e-12, f"e at alpha={alpha!r}")
    assert_rel(hc_grad(alpha), de, 1e-9, f"de/dalpha at alpha={alpha!r}")


# ----------------------------------------------------------- undamped Hertz (power law)

HERTZ_K = 2 * 1.25**0.4 * scipy.special.beta(0.4, 0.5) / 2.5  # 3.2180654597...


@pytest.mark.slow
@pytest.mark.parametrize("separation", ["force", "penetration"])
def test_undamped_hertz_contact_time_has_one_constant(separation):
    """T = K (m^2 / (c^2 v0))^(1/5) with one K over 27 decades-apart (m, c, v0)."""
    run = solver("hertz_viscous", separation, rtol=ORACLE_RTOL)
    constants = []
    for m in (1e-6, 1.0, 1e3):
        for c in (1e3, 1e8, 1e13):
            for v0 in (1e-3, 1.0, 100.0):
                got = run(dict(c=c, b=0.0), m=m, v0=v0)
                want = closed(closed_forms.power_spring(c, 1.5, m, v0))
                assert int(got["status"]) == ji.Status.separated
                compare(got, want, f"power spring m={m} c={c} v0={v0}", rtol=1e-10, e_atol=0)
                constants.append(got["T"] / (m**2 / (c**2 * v0)) ** 0.2)
    constants = np.array(constants)
    # measured spread 9e-16: the nondimensional solve is the same for every (m, c, v0)
    assert constants.max() / constants.min() - 1 < 1e-12
    assert_rel(constants, np.full_like(constants, HERTZ_K), 1e-10, "K")


def test_power_spring_formula():
    for n in (1.0, 1.5, 2.5):
        p = closed(closed_forms.power_spring(3e5, n, 0.2, 1.7))
        x_max = ((n + 1) * 0.2 * 1.7**2 / (2 * 3e5)) ** (1 / (n + 1))
        assert_rel(p["x_max"], x_max, 1e-14, "x_max")
        # energy: m v0^2 / 2 = c x_max^(n+1) / (n+1)
        assert_rel(3e5 * x_max ** (n + 1) / (n + 1), 0.5 * 0.2 * 1.7**2, 1e-13, "energy")
        beta = scipy.special.beta(1 / (n + 1), 0.5)
        assert_rel(p["T"], 2 * x_max / 1.7 * beta / (n + 1), 1e-13, "T")
    # n = 1 is the undamped linear spring: T = pi sqrt(m / c)
    assert_rel(
        closed_forms.power_spring(3e5, 1.0, 0.2, 1.7)["T"],
        math.pi * math.sqrt(0.2 / 3e5),
        1e-14,
        "linear T",
    )
