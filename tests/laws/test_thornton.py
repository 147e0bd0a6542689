"""Thornton's (1997) elastic-perfectly-plastic law: the closed form against the published
formula, against an independent scipy integration of the model, and the integrated path
against both; gradients against central differences; fits of x_y from e(v)."""

import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st
from scipy.integrate import solve_ivp

import jaximpact as ji
from jaximpact._laws.thornton import thornton_restitution

# steel (E = 210 GPa, nu = 0.3, Y = 1 GPa, 7800 kg/m^3), R = 5 mm, on a rigid flat
R, RHO = 5e-3, 7800.0
M = 4.0 / 3.0 * math.pi * R**3 * RHO
C = 4.0 / 3.0 * 2.1e11 / (1 - 0.3**2) * math.sqrt(R)
P_Y = 1.6e9
X_Y = R * (math.pi * P_Y / (2 * 2.1e11 / (1 - 0.3**2))) ** 2
LAW = ji.law("thornton", c=C, x_y=X_Y)
V_Y = float(LAW.yield_speed(M))


def scipy_thornton(c, x_y, m, v0, g=0.0, separation="force", rtol=1e-13):
    """The model integrated by scipy's DOP853 at `rtol` (1e-13), in units x_s = (m v0^2/c)^0.4,
    t_s = x_s / v0: loading to v = 0, then Hertzian unloading about x_p to x = x_p (force
    criterion) or x = 0 (penetration). Returns e, T, x_max, F_max, t_max (SI)."""
    xs = (m * v0**2 / c) ** 0.4
    ts, fs = xs / v0, m * v0**2 / xs
    X_y, gam = x_y / xs, g * xs / v0**2

    def loading(X):
        return X**1.5 if X <= X_y else math.sqrt(X_y) * (1.5 * X - 0.5 * X_y)

    def stop(t, y):
        return y[1]

    stop.terminal, stop.direction = True, -1
    first = solve_ivp(
        lambda t, y: [y[1], -loading(max(y[0], 0.0)) + gam],
        (0, 100),
        [0, 1],
        method="DOP853",
        rtol=rtol,
        atol=1e-15,
        events=stop,
    )
    t_m, (X_m, _) = first.t_events[0][0], first.y_events[0][0]
    F_m = loading(X_m)
    c_p = math.sqrt(X_m**1.5 / F_m)
    X_p = X_m - (F_m / c_p) ** (2 / 3)

    def unloading(t, y):
        return [y[1], -c_p * max(y[0] - X_p, 0.0) ** 1.5 + gam]

    def leave(t, y):
        return y[0] - (X_p if separation == "force" else 0.0)

    leave.terminal, leave.direction = True, -1
    second = solve_ivp(
        unloading,
        (t_m, t_m + 100),
        [X_m, 0.0],
        method="DOP853",
        rtol=rtol,
        atol=1e-15,
        events=leave,
    )
    t_end, (_, V_end) = second.t_events[0][0], second.y_events[0][0]
    return dict(e=-V_end, T=t_end * ts, x_max=X_m * xs, F_max=F_m * fs, t_max=t_m * ts)


@pytest.mark.parametrize(
    "ratio, e",
    [
        (1.5, 0.971239),
        (2, 0.930626),
        (3, 0.862740),
        (5, 0.773337),
        (10, 0.658558),
        (30, 0.504389),
        (100, 0.374299),
        (1000, 0.210701),
    ],
)
def test_restitution_is_thorntons_formula_and_the_published_table(ratio, e):
    """The table of shared/notes/contact-physics.md, 2.1 (formula = model, 6 digits), from
    the impact itself (its closed form) and from the formula."""
    assert float(thornton_restitution(ratio)) == pytest.approx(e, abs=5e-7)
    r = ji.impact(LAW, m=M, v0=ratio * V_Y)
    assert r.path == "closed_form" and r.status_name == "separated"
    assert float(r.e) == pytest.approx(e, abs=5e-7)
    assert float(thornton_restitution(0.7)) == 1.0  # elastic below the yield speed


@pytest.mark.parametrize("ratio", [0.5, 1.2, 3.0, 40.0, 1e4])
@pytest.mark.parametrize("separation", ["force", "penetration"])
def test_closed_form_matches_an_independent_scipy_integration(ratio, separation):
    v0 = ratio * V_Y
    ref = scipy_thornton(C, X_Y, M, v0, separation=separation)
    r = ji.impact(LAW, m=M, v0=v0, separation=separation)
    for key, value in ref.items():
        assert float(getattr(r, key)) == pytest.approx(value, rel=1e-9), key


@pytest.mark.parametrize("ratio", [0.5, 3.0, 200.0])
def test_the_integrated_path_matches_the_closed_form(ratio):
    v0 = ratio * V_Y
    exact = ji.impact(LAW, m=M, v0=v0)
    r = ji.impact(LAW, m=M, v0=v0, method="integrate")
    assert r.path == "integrated" and r.status_name == "separated"
    for key in ("e", "T", "x_max", "F_max", "t_max"):
        assert float(getattr(r, key)) == pytest.approx(float(getattr(exact, key)), rel=2e-9)


def test_with_gravity_it_matches_scipy():
    """A slow drop (gravity matters: a soft contact, v0 near the yield speed)."""
    law = ji.law("thornton", c=2e5, x_y=2e-4)
    m, v0, g = 0.5, 0.3, 9.81  # g x* / v0^2 = 0.24
    r = ji.impact(law, m=m, v0=v0, g=g)
    assert r.path == "integrated"
    ref = scipy_thornton(2e5, 2e-4, m, v0, g=g)
    for key, value in ref.items():
        assert float(getattr(r, key)) == pytest.approx(value, rel=1e-8), key


def test_the_impact_depends_on_v0_over_the_yield_speed_alone():
    other = ji.law("thornton", c=3.0 * C, x_y=0.2 * X_Y)
    m = 7.0 * M
    v = 4.0 * float(other.yield_speed(m))
    assert float(ji.impact(other, m=m, v0=v).e) == pytest.approx(
        float(ji.impact(LAW, m=M, v0=4.0 * V_Y).e), rel=1e-13
    )


@pytest.mark.parametrize("method", ["auto", pytest.param("integrate", marks=pytest.mark.slow)])
@pytest.mark.parametrize("ratio", [1.05, 20.0])  # just above the yield speed, and well above
def test_gradients_match_central_differences(method, ratio):
    v0 = ratio * V_Y

    def outputs(params):
        r = ji.impact(
            ji.law("thornton", c=params[0], x_y=params[1]), m=M, v0=v0, method=method, peaks=False
        )
        return jnp.stack([r.e, r.T])

    p = jnp.array([C, X_Y])
    jac = jax.jacfwd(outputs)(p)
    for k in range(2):
        h = p[k] * 1e-6
        step = jnp.zeros(2).at[k].set(h)
        fd = (outputs(p + step) - outputs(p - step)) / (2 * h)
        np.testing.assert_allclose(jac[:, k], fd, rtol=2e-5 if method == "auto" else 1e-3)


def test_calibrate_recovers_the_yield_overlap_from_e_at_several_speeds():
    v0 = jnp.array([0.02, 0.05, 0.1, 0.3, 1.0, 3.0])
    e = jax.vmap(lambda v: ji.impact(LAW, m=M, v0=v).e)(v0)
    fit = ji.calibrate(ji.law("thornton", c=C, x_y=5 * X_Y), m=M, v0=v0, e=e, free=("x_y",))
    assert fit.converged and fit.reproduces
    assert float(fit.params["x_y"]) == pytest.approx(X_Y, rel=1e-8)


def test_a_fitted_yield_overlap_gives_the_yield_stress_back():
    """The overlap fitted from e(v) gives back the limiting pressure it was made from
    (`yield_pressure`, the inverse of `yield_overlap`), hence Y = p_y / 1.6."""
    v0 = jnp.array([0.05, 0.3, 1.0])
    e = jax.vmap(lambda v: ji.impact(LAW, m=M, v0=v).e)(v0)
    fit = ji.calibrate(ji.law("thornton", c=C, x_y=3 * X_Y), m=M, v0=v0, e=e, free=("x_y",))
    p_y = ji.yield_pressure(float(fit.params["x_y"]), E=2.1e11, nu=0.3, R=R, E2=math.inf)
    assert p_y == pytest.approx(P_Y, rel=1e-8)


# Bridges, Hatzes & Lin (1984, Nature 309:333), frost-covered ice at about 185 K: the
# published fit to their measured e(v), e = 0.34 v^-0.234 (v in cm/s), as coded in
# MarkCLewis/HardSphereCollSims (CoefficientsOfRestitution.h) and cited in
# shared/notes/contact-physics.md 2.4; sampled over their measured speeds, 0.015-5 cm/s
BRIDGES_V = np.geomspace(0.015, 5.0, 10) * 1e-2  # m/s
BRIDGES_E = 0.34 * (BRIDGES_V * 1e2) ** -0.234


@pytest.mark.slow  # compare_laws fits every law of the table: 20 s
def test_bridges_ice_e_of_v_picks_the_plastic_law():
    """A published plastic e(v): Thornton's law fits Bridges et al.'s ice within RMS 0.0073
    (measured 0.00724) over 2.5 decades of speed, with a yield speed of 0.063 mm/s (their
    fit reaches e = 1 at 0.1 mm/s); `compare_laws` ranks it first, 95 times below the best
    viscoelastic law in the sum of squares (the v^(-1/4) tail is plastic). The sphere: ice,
    R = 2.75 cm, E = 9 GPa (e depends on v0/v_y alone, so only v_y is determined)."""
    R_ice = 0.0275
    m = 917.0 * 4.0 / 3.0 * math.pi * R_ice**3
    c = ji.hertz_stiffness(E=9e9, nu=0.33, R=R_ice, E2=math.inf)
    fit = ji.calibrate(
        ji.law("thornton", c=c, x_y=1e-7), m=m, v0=BRIDGES_V, e=BRIDGES_E, free=("x_y",)
    )
    rms = float(np.sqrt(np.mean((np.asarray(fit.e) - BRIDGES_E) ** 2)))
    v_y = float(fit.law.yield_speed(m))
    print(f"thornton RMS {rms:.5f}, v_y = {v_y * 1e3:.4f} mm/s")
    assert fit.converged and rms < 0.0073
    assert v_y == pytest.approx(6.26e-5, rel=0.01)
    ranking = ji.compare_laws(m=m, v0=BRIDGES_V, e=BRIDGES_E, progress=False)
    assert ranking[0].name == "thornton"
    viscoelastic = [r for r in ranking if ji.LAWS[r.name].kind == "viscoelastic"]
    assert viscoelastic[0].sum_sq > 90 * ranking[0].sum_sq


@settings(max_examples=50, deadline=None)
@given(
    x_y=st.floats(1e-12, 1e-3),
    E=st.floats(1e6, 1e12),
    nu=st.floats(0.0, 0.49),
    R=st.floats(1e-6, 1.0),
    flat=st.booleans(),
)
def test_yield_pressure_inverts_yield_overlap(x_y, E, nu, R, flat):
    bodies = dict(E2=math.inf) if flat else dict(E2=2 * E, nu2=nu, R2=3 * R)
    p_y = ji.yield_pressure(x_y, E=E, nu=nu, R=R, **bodies)
    assert ji.yield_overlap(E, nu, R, p_y=p_y, **bodies) == pytest.approx(x_y, rel=1e-12)
    with pytest.raises(ValueError, match="x_y"):
        ji.yield_pressure(-x_y, E=E, nu=nu, R=R)


def test_the_force_remembers_the_largest_overlap():
    x_m = 4 * X_Y
    F_m = float(LAW.force(x_m, 0.0))
    assert F_m == pytest.approx(C * math.sqrt(X_Y) * (1.5 * x_m - 0.5 * X_Y), rel=1e-14)
    assert float(LAW.force(X_Y / 2, 0.0)) == pytest.approx(C * (X_Y / 2) ** 1.5, rel=1e-14)
    # unloading: Hertzian about x_p with R_p / R = c x_m^1.5 / F_m; zero below x_p
    c_p = C * math.sqrt(C * x_m**1.5 / F_m)
    x_p = x_m - (F_m / c_p) ** (2 / 3)
    x = 0.5 * (x_p + x_m)
    assert float(LAW.force(x, -1.0, x_max=x_m)) == pytest.approx(c_p * (x - x_p) ** 1.5, rel=1e-12)
    assert float(LAW.force(0.9 * x_p, -1.0, x_max=x_m)) == 0.0
    assert float(LAW.force(x_m, 0.0, x_max=x_m)) == pytest.approx(F_m, rel=1e-12)


def test_yield_overlap_gives_the_notes_yield_speeds():
    """contact-physics.md, 2.1: steel on a rigid flat, p_y = 1.6 Y, R = 5 mm: v_y = 0.034 m/s;
    on a same-material flat 0.136 m/s."""
    rigid = ji.yield_overlap(E=2.1e11, nu=0.3, R=R, Y=1e9, E2=math.inf)
    c = ji.hertz_stiffness(E=2.1e11, nu=0.3, R=R, E2=math.inf)
    assert float(ji.law("thornton", c=c, x_y=rigid).yield_speed(M)) == pytest.approx(
        0.034, abs=6e-4
    )
    same = ji.yield_overlap(E=2.1e11, nu=0.3, R=R, Y=1e9)
    c = ji.hertz_stiffness(E=2.1e11, nu=0.3, R=R)
    assert float(ji.law("thornton", c=c, x_y=same).yield_speed(M)) == pytest.approx(0.136, abs=6e-4)
    assert ji.yield_overlap(E=2.1e11, nu=0.3, R=R, p_y=1.6e9, E2=math.inf) == pytest.approx(rigid)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: ji.law("thornton", c=C, x_y=0.0), "x_y"),
        (lambda: ji.law("thornton", c=C, x_y=-1e-7), "x_y"),
        (lambda: ji.law("thornton", c=C), "needs x_y"),
        (lambda: LAW.replace(b=1.0), "no parameter b"),
        (lambda: ji.yield_overlap(E=2e11, nu=0.3, R=R), "p_y"),
        (lambda: ji.yield_overlap(E=2e11, nu=0.3, R=R, Y=-1.0), "Y"),
    ],
)
def test_bad_input_gets_one_clear_line(call, message):
    with pytest.raises(ValueError, match=message) as info:
        call()
    assert "\n" not in str(info.value)
