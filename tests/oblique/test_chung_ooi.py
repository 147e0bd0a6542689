"""Chung & Ooi (2011)'s particle-impact benchmarks and Kharaz, Gorham & Salman (2001)'s
oblique impacts, with the inputs and the expected numbers of
shared/notes/contact-physics.md, sections 1 and 4 (the digitised curves as Kratos
DEMApplication stores them, `tests/DEM3D_chung_ooi_tests`).

- Tests 1-3 (normal impacts): exact Hertz answers (T) and the restitution a damping set
  for `e_in` delivers, through `oblique_impact`.
- Test 4 (Kharaz's alumina sphere, 3.9 m/s, 5-85 degrees): Hertz-Mindlin against the
  reference curves (e_t, spin, the contact point's rebound angle), and beyond the rigid
  transition (32.5 degrees) against the rigid-body theory and Kharaz's measurements.
- Test 5 (gross-sliding plateau) and Test 6 (gross-sliding branch, x < 1): the exact parts.
  Their stick and micro-slip branches are compared in docs/oblique.md, not asserted: the
  digitised curves there need a tangential damping this library's Mindlin law lacks (Test
  6) or disagree with Test 4's own reference at the same psi (Test 5).
- Test 7 (two identical spheres with equal and opposite spins): no slip, the spins come
  out unchanged (the reference's identity line); the same spheres spinning the same way
  against the scipy oracle and, beyond the rigid transition, the impulse theory.
- Test 8 (spheres of two sizes) with the public PySPH reproduction's inputs (the partner
  five times the radius, 1000 times as dense): the gross-sliding branch, as Test 6's.
"""

import functools

import numpy as np
import pytest

import jaximpact as ji
from jaximpact._oblique import incidence, oblique_impact, rigid_oblique, tangential_law, two_spheres

pytestmark = pytest.mark.slow

HERTZ_T = 3.2180654597  # T = 3.218 (m*^2 / (c^2 v))^(1/5) for an undamped Hertz contact


def sphere(E, nu, rho, R):
    """Mass, Hertz stiffness on a rigid plane and shear modulus of a sphere."""
    m = rho * 4.0 / 3.0 * np.pi * R**3
    return m, 4.0 / 3.0 * E / (1 - nu**2) * np.sqrt(R), E / (2 * (1 + nu))


@functools.cache
def tsuji_damping(e, c, m, v0):
    """The damping `b` of `c x^1.5 + b x^0.25 v` whose restitution is `e` (independent of
    the speed for this law; bisection on `impact`)."""
    lo, hi = 0.0, 10.0 * np.sqrt(m * c)
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        found = float(ji.impact(ji.law("tsuji", c=c, b=mid), m=m, v0=v0).e)
        lo, hi = (mid, hi) if found > e else (lo, mid)
    return 0.5 * (lo + hi)


@pytest.mark.parametrize(
    "test, E, nu, rho, R, v, T_table",
    [
        ("1 glass", 48e9, 0.20, 2800.0, 0.010, 20.0, 40.339e-6),
        ("1 limestone", 20e9, 0.25, 2500.0, 0.010, 20.0, 54.20e-6),
        ("2 Al alloy", 70e9, 0.30, 2699.0, 0.10, 0.2, 731.66e-6),
        ("2 Mg alloy", 40e9, 0.35, 1800.0, 0.10, 0.2, 767.07e-6),
    ],
)
def test_normal_hertz(test, E, nu, rho, R, v, T_table):
    """Tests 1 (two identical spheres: m* = m/2, R* = R/2) and 2 (a sphere on a rigid
    plane): e = 1 and the Hertz contact time, with friction on and no tangential motion."""
    m = rho * 4.0 / 3.0 * np.pi * R**3
    if test.startswith("1"):
        eff = two_spheres(m, R, m, R)
        E_star = E / (2 * (1 - nu**2))
    else:
        eff = dict(m=m, R=R, inertia=0.4)
        E_star = E / (1 - nu**2)
    c = 4.0 / 3.0 * E_star * np.sqrt(eff["R"])
    tl = tangential_law("mindlin", G=E / (2 * (1 + nu)), nu=nu, mu=0.35)
    r = oblique_impact(ji.law("hunt_crossley", c=c, a=0.0), tl, **eff, v_n=v, v_t=0.0)
    T_hertz = HERTZ_T * (eff["m"] ** 2 / (c**2 * v)) ** 0.2
    assert float(r.e) == pytest.approx(1.0, abs=1e-9)
    assert float(r.T) == pytest.approx(T_hertz, rel=1e-9)
    assert float(r.T) == pytest.approx(T_table, rel=2e-4)  # the notes' 5 digits


@pytest.mark.parametrize("material", [(380e9, 0.23, 4000.0), (100e9, 0.25, 7000.0)])
def test_restitution_delivered(material):
    """Test 3: a damping set for e_in gives e_out = e_in (the identity line), obliquely too
    (a rigid plane: the tangential contact does not touch the normal one)."""
    m, c, G = sphere(*material, 2.5e-3)
    tl = tangential_law("mindlin", G=G, nu=material[1], mu=0.0)
    for e_in in (0.2, 0.6, 1.0):
        b = tsuji_damping(e_in, c, m, 3.9) if e_in < 1 else 0.0
        law = ji.law("tsuji", c=c, b=b)
        for v_t in (0.0, 2.0):
            r = oblique_impact(law, tl, m=m, R=2.5e-3, v_n=3.9, v_t=v_t)
            assert float(r.e) == pytest.approx(e_in, abs=1e-9)
            if v_t:  # mu = 0: no tangential force at all
                assert float(r.v_t_out) == v_t and float(r.omega_out) == 0.0


# Test 4, Al oxide on a rigid plane (Kratos Materials4: wall E = 7e20): the reference curves
# (Kratos `benchmark4_graph1_ref.dat`, graph2 and graph3 as digitised in the notes)
THETA_4 = [5.17, 10.16, 14.99, 20.06, 25.05, 30.12, 35.03, 40.02, 50.0, 59.98, 69.96, 80.02, 85.01]
E_T_4 = [0.948, 0.687, 0.624, 0.616, 0.634, 0.684, 0.737, 0.781, 0.845, 0.893, 0.932, 0.966, 0.983]
OMEGA_4 = [-19, -213, -378, -511, -599, -617, -582, -545, -457, -357, -246, -126, -63]
ANGLE_4 = [3.8, -1.6, -5.5, -7.5, -7.5, -3.5, 3.4, 11.6, 29.4, 47.8, 64.6, 78.7, 84.5]
ALUMINA = (380e9, 0.23, 4000.0)


@functools.cache
def sweep_4(name="mindlin", anvil=None, thetas=None):
    """e, e_t, spin (rad/s, the reference's sign), contact-point rebound angle (degrees)
    and the centre's, the number of switches, at `thetas` (degrees, a tuple; default
    THETA_4, or KHARAZ_THETA with an anvil); `anvil`: (E, nu) of an elastic plane
    (Kharaz's glass), None: rigid."""
    R = 2.5e-3
    m, c, G = sphere(*ALUMINA, R)
    extra = {}
    if anvil is not None:
        E2, nu2 = anvil
        E_star = 1 / ((1 - ALUMINA[1] ** 2) / ALUMINA[0] + (1 - nu2**2) / E2)
        c = 4.0 / 3.0 * E_star * np.sqrt(R)
        extra = dict(G2=E2 / (2 * (1 + nu2)), nu2=nu2)
    law = ji.law("tsuji", c=c, b=tsuji_damping(0.98, c, m, 3.9))
    tl = tangential_law(name, G=G, nu=ALUMINA[1], mu=0.092, **extra)
    rows = []
    if thetas is None:
        thetas = THETA_4 if anvil is None else KHARAZ_THETA
    for theta in thetas:
        v_n, v_t = (float(v) for v in incidence(3.9, np.deg2rad(theta)))
        r = oblique_impact(law, tl, m=m, R=R, v_n=v_n, v_t=v_t)
        assert r.status_name == "separated"
        rows.append(
            (
                float(r.e),
                float(r.e_t),
                -float(r.omega_out),
                np.rad2deg(float(r.angle_out_contact)),
                np.rad2deg(float(r.angle_out)),
                int(r.num_switches),
            )
        )
    return np.array(rows)


def test4_against_the_reference_curves():
    """Hertz-Mindlin (displacement history) reproduces the Test 4 reference: e_t within
    0.01, the spin within 6 rad/s, the contact point's rebound angle within 1 degree
    (measured: 0.009, 5 rad/s, 0.9 degrees)."""
    rows = sweep_4("mindlin")
    assert np.allclose(rows[:, 0], 0.98, atol=1e-9)
    assert np.max(np.abs(rows[:, 1] - E_T_4)) < 0.01
    assert np.max(np.abs(rows[:, 2] - OMEGA_4)) < 6.0
    assert np.max(np.abs(rows[:, 3] - ANGLE_4)) < 1.0
    # the micro-slip dip: e_t least near 20 degrees, the contact point reversed (< 0)
    assert np.argmin(rows[:, 1]) == 3 and np.all(rows[2:5, 3] < -4.0)
    # force history: the same beyond the rigid transition, 0.06 off at 5 degrees
    force = sweep_4("mindlin_force")
    assert np.allclose(force[6:, 1], rows[6:, 1], atol=1e-6)
    assert np.max(np.abs(force[:, 1] - E_T_4)) < 0.07


def test4_gross_sliding_is_rigid():
    """Beyond tan(theta) = 3.5 mu (1 + e) (32.5 degrees) the contact slides throughout
    (after a first-touch stick that the damping's x^0.25 gives, 1e-4 of the impulse):
    e_t and the angles are the rigid-body ones."""
    rows = sweep_4("mindlin")
    for k, theta in enumerate(THETA_4):
        if theta < 33.0:
            continue
        v_n, v_t = (float(v) for v in incidence(3.9, np.deg2rad(theta)))
        rigid = rigid_oblique(mu=0.092, e=rows[k, 0], v_n=v_n, v_t=v_t, R=2.5e-3)
        assert bool(rigid["sliding"])
        assert rows[k, 1] == pytest.approx(float(rigid["e_t"]), abs=2e-4)
        assert rows[k, 3] == pytest.approx(np.rad2deg(float(rigid["angle_out_contact"])), abs=0.02)


# Kharaz et al. (2001), alumina on soda-lime glass (E = 70 GPa, nu = 0.25), as Lethe
# digitised them (notes 4.2): incidence, e_t; incidence, rebound angle of the centre
KHARAZ_THETA = [39.38, 49.69, 60.02]
KHARAZ_E_T = [0.771, 0.848, 0.901]
KHARAZ_ANGLE = [(39.54, 32.61), (49.75, 45.13), (60.21, 57.47)]


def test_kharaz_measurements_beyond_the_transition():
    """Where the rigid theory holds (theta >= 40 degrees, Kharaz's own conclusion), the
    computed e_t is within 0.01 of the measured one (measured: 0.0071), and the centre's
    rebound angle that `oblique_impact` computes, at the incidence of each angle
    measurement, within 1 degree of the measured one (measured: 0.67, 0.42, 0.47 degrees,
    the computed angle the larger each time). The contact slides there after a first-touch
    stick (the damping's x^0.25): the rigid theory's angle at the computed e, to 1e-3
    degrees (measured 3e-5)."""
    rows = sweep_4("mindlin", anvil=(70e9, 0.25))
    assert np.max(np.abs(rows[:, 1] - KHARAZ_E_T)) < 0.01
    thetas, measured = (tuple(column) for column in zip(*KHARAZ_ANGLE, strict=True))
    at_angles = sweep_4("mindlin", anvil=(70e9, 0.25), thetas=thetas)
    angles = at_angles[:, 4]
    assert np.max(np.abs(angles - measured)) < 1.0
    for theta, row in zip(thetas, at_angles, strict=True):
        v_n, v_t = (float(v) for v in incidence(3.9, np.deg2rad(theta)))
        rigid = rigid_oblique(mu=0.092, e=row[0], v_n=v_n, v_t=v_t, R=2.5e-3)
        assert row[4] == pytest.approx(np.rad2deg(float(rigid["angle_out"])), abs=1e-3)
    # and the elastic anvil changes nothing there (gross sliding): the rigid plane's e_t
    rigid_plane = sweep_4("mindlin")
    assert rows[0, 1] == pytest.approx(np.interp(39.38, THETA_4, rigid_plane[:, 1]), abs=0.01)


def test5_gross_sliding_plateau():
    """Test 5 (steel and polyethylene, R = 10 um, V_n = 5 m/s, mu = 0.3, e = 1): beyond
    psi = V_st / (mu V_cn) = 7 the contact slides throughout and R omega' / (mu V_cn) is
    the rigid -2.5 (1 + e) = -5 (the reference's sign) to 1e-9; the digitised curves
    (-5.004, -4.991 steel; -4.963, -4.942 polyethylene at psi = 10, 20) within 0.06."""
    R, v_n, mu = 1e-5, 5.0, 0.3
    for material, digitised in (
        ((208e9, 0.30, 7850.0), (-5.004, -4.991)),
        ((1e9, 0.40, 1400.0), (-4.963, -4.942)),
    ):
        m, c, G = sphere(*material, R)
        tl = tangential_law("mindlin", G=G, nu=material[1], mu=mu)
        law = ji.law("hunt_crossley", c=c, a=0.0)
        for psi, expected in zip((10.0, 20.0), digitised, strict=True):
            r = oblique_impact(law, tl, m=m, R=R, v_n=v_n, v_t=psi * mu * v_n)
            assert int(r.num_switches) == 0
            spin = -R * float(r.omega_out) / (mu * v_n)
            assert spin == pytest.approx(-5.0, rel=1e-9)
            assert spin == pytest.approx(expected, abs=0.06)


# Test 6 (Al alloy, R = 0.1 m, V_n = 0.2 m/s, mu = 0.4, e = 0.5, spin only): beta against
# x = 3.5 mu (1 + e) V_n / V_st, the first points of Kratos' benchmark8_graph1 "Test 6"
X_6 = [
    0.18716577540106982,
    0.35828877005347604,
    0.550802139037434,
    0.764705882352942,
    0.97860962566845,
]
BETA_6 = [
    -0.8152230971128611,
    -0.6262467191601051,
    -0.43937007874015754,
    -0.23779527559055114,
    -0.017322834645669194,
]


def test6_gross_sliding_branch():
    """For x < 1 the rigid contact slides throughout: beta = x - 1. The Tsuji damping
    (x^0.25) makes the compliant contact stick for its first instants, which costs up to
    0.015 in beta (at x = 0.98); the digitised curve within 0.025."""
    R, v_n, mu, e = 0.1, 0.2, 0.4, 0.5
    m, c, G = sphere(70e9, 0.33, 2700.0, R)
    law = ji.law("tsuji", c=c, b=tsuji_damping(e, c, m, v_n))
    tl = tangential_law("mindlin", G=G, nu=0.33, mu=mu)
    for x, digitised in zip(X_6, BETA_6, strict=True):
        u = 3.5 * mu * (1 + e) * v_n / x
        r = oblique_impact(law, tl, m=m, R=R, v_n=v_n, v_t=0.0, omega=-u / R)
        beta = -float(r.e_t_contact)
        assert float(r.e) == pytest.approx(e, abs=1e-9)
        assert beta == pytest.approx(x - 1.0, abs=0.02)
        assert beta == pytest.approx(digitised, abs=0.025)


# Test 8 with the inputs of the public PySPH reproduction (dineshadepu/pysph, examples,
# test 8; notes 1.4): sphere 1 (R = 0.1 m) meets sphere 2 (R = 0.5 m, 1000 times as dense,
# at rest) at V_n = 0.2 m/s, its contact point moved by its spin alone; Al alloy (70 GPa,
# 0.33, 2700 kg/m^3) and nylon (2.5 GPa, 0.4, 1000 kg/m^3); case A with the shear modulus
# 1000 times the material's, case B with the material's; mu = 0.4, e = 0.5 (Tsuji).
# Kratos' benchmark8_graph1 digitises cases A and B: the same as Test 6's for x < 5.8
MATERIALS_8 = {"Al alloy": (70e9, 0.33, 2700.0), "nylon": (2.5e9, 0.4, 1000.0)}


@pytest.mark.parametrize("material", MATERIALS_8)
@pytest.mark.parametrize("case, factor", [("A", 1000.0), ("B", 1.0)])
def test8_two_spheres_of_two_sizes_gross_sliding_branch(material, case, factor):
    """For x < 1 the contact slides throughout, as in Test 6: beta = x - 1 within 0.02
    (the Tsuji damping's first instants of sticking, measured 0.016 at worst), the
    digitised curve within 0.025 (measured 0.020). Beyond, case A's stiff spring brings
    the slip to rest (beta within 0.006 of 0 from x = 1.2 to 24, 35-71 stick-slip
    switches), where the digitised curve rises to +0.11 and falls to -0.32, and case B
    is Test 6's (docs/oblique.md): not asserted."""
    E, nu, rho = MATERIALS_8[material]
    R1, R2, v_n, mu, e = 0.1, 0.5, 0.2, 0.4, 0.5
    m1, m2 = rho * 4.0 / 3.0 * np.pi * R1**3, 1000.0 * rho * 4.0 / 3.0 * np.pi * R2**3
    eff = two_spheres(m1, R1, m2, R2)
    c = 4.0 / 3.0 * E / (2 * (1 - nu**2)) * np.sqrt(eff["R"])
    law = ji.law("tsuji", c=c, b=tsuji_damping(e, c, eff["m"], v_n))
    G = factor * E / (2 * (1 + nu))
    tl = tangential_law("mindlin", G=G, nu=nu, G2=G, nu2=nu, mu=mu)
    for x, digitised in zip(X_6, BETA_6, strict=True):
        u = 3.5 * mu * (1 + e) * v_n / x  # the slip, by sphere 1's spin alone
        r = oblique_impact(law, tl, **eff, v_n=v_n, v_t=0.0, omega=u / eff["R"])
        beta = -float(r.e_t_contact)
        assert float(r.e) == pytest.approx(e, abs=1e-9)
        assert beta == pytest.approx(x - 1.0, abs=0.02)
        assert beta == pytest.approx(digitised, abs=0.025)


# Test 7 (notes 1.1; Kratos `Benchmark7`): two identical spheres, R = 0.1 m, sphere 1 at
# -R x moving at +0.2 m/s along x, sphere 2 at +R x at -0.2 m/s; spins about y,
# +omega0 for sphere 1 and -omega0 for sphere 2, omega0 = 2 tan(5k degrees) (k = 1..17,
# 0.175 to 22.9 rad/s); mu = 0.4, e = 0.5. The reference (Kratos `benchmark7_graph2.dat`)
# is the identity, omega' = omega0, and the tangential velocity 0.
OMEGA_7 = [2.0 * np.tan(np.deg2rad(5.0 * k)) for k in range(1, 18)]
MATERIALS_7 = {"Al alloy": (70e9, 0.33, 2700.0), "copper": (120e9, 0.35, 8900.0)}
R_7, V_7, MU_7, E_7 = 0.1, 0.2, 0.4, 0.5
X_HAT, Y_HAT, Z_HAT = np.eye(3)


def contact_velocities(v1, w1, v2, w2, R):
    """Velocities (m/s, 3-vectors) of the two spheres' material points at the contact
    (the origin), sphere 1 centred at -R x, sphere 2 at +R x: `v + w x r`."""
    return v1 + np.cross(w1, R * X_HAT), v2 + np.cross(w2, -R * X_HAT)


def hunt_crossley_a(e, v):
    """The `a` (s/m) of `c x^1.5 (1 + 1.5 a v)` whose restitution at `v` is `e`:
    `-alpha e - ln(1 - alpha e) = alpha - ln(1 + alpha)`, `alpha = 1.5 a v`."""
    from scipy.optimize import brentq

    alpha = brentq(
        lambda a: -a * e - np.log1p(-a * e) - a + np.log1p(a), 1e-6, 1.0 / e - 1e-9, xtol=1e-15
    )
    return alpha / (1.5 * v)


def two_spinning_spheres(material, w1, w2):
    """Sphere 1's and sphere 2's outgoing tangential (z) velocities and y spins, the
    slip after (from those, by `contact_velocities`), the result and the effective inputs,
    for Test 7's spheres with spins `w1`, `w2` (rad/s, about y)."""
    E, nu, rho = material
    m = rho * 4.0 / 3.0 * np.pi * R_7**3
    eff = two_spheres(m, R_7, m, R_7)
    c = 4.0 / 3.0 * E / (2 * (1 - nu**2)) * np.sqrt(eff["R"])
    G = E / (2 * (1 + nu))
    law = ji.law("hunt_crossley", c=c, a=hunt_crossley_a(E_7, 2 * V_7))
    tl = tangential_law("mindlin", G=G, nu=nu, G2=G, nu2=nu, mu=MU_7)
    v1, v2 = V_7 * X_HAT, -V_7 * X_HAT
    p1, p2 = contact_velocities(v1, w1 * Y_HAT, v2, w2 * Y_HAT, R_7)
    # the effective sphere on a plane: normal x (1 towards 2), tangent z; slip u = v_t - R* w
    v_t = float((v1 - v2) @ Z_HAT)
    u = float((p1 - p2) @ Z_HAT)
    inputs = dict(**eff, v_n=float((v1 - v2) @ X_HAT), v_t=v_t, omega=(v_t - u) / eff["R"])
    r = oblique_impact(law, tl, **inputs)
    J = float(r.impulse_t) * Z_HAT  # on sphere 1; -J on sphere 2
    moment = 0.4 * m * R_7**2  # kg m^2
    out1 = (v1 + J / m, w1 * Y_HAT + np.cross(R_7 * X_HAT, J) / moment)
    out2 = (v2 - J / m, w2 * Y_HAT + np.cross(-R_7 * X_HAT, -J) / moment)
    q1, q2 = contact_velocities(*out1, *out2, R_7)
    spheres = np.array([out1[0] @ Z_HAT, out1[1] @ Y_HAT, out2[0] @ Z_HAT, out2[1] @ Y_HAT])
    return spheres, float((q1 - q2) @ Z_HAT), r, dict(inputs, c=c, G_star=G / (2 * (2 - nu)))


@pytest.mark.parametrize("material", MATERIALS_7)
def test7_two_identical_spheres_spinning(material):
    """Test 7 as Chung & Ooi (and Kratos) set it: the spins +-omega0 about y move both
    contact points at `-omega0 R z` (derived with cross products), so there is no slip:
    each sphere leaves with its spin (the reference's identity line) and no tangential
    velocity, e = 0.5 (1e-9). The same spheres spinning the same way (+omega0 each) slip at
    `-2 omega0 R`; then the outcome is the scipy oracle's (`oblique_oracle`, the same
    switches, within 1e-8 of the slip in; measured 1.3e-9: stick, micro-slip and gross
    sliding over the sweep), and beyond the rigid transition (`2 omega0 R >= 3.5 mu (1 + e)
    2 V`: omega0 >= 4.2 rad/s) the impulse theory's (1e-9, measured 4.4e-10): each sphere
    leaves at `mu (1 + e) V = 0.12 m/s` with its spin 3 rad/s smaller, whatever omega0."""
    from oblique_oracle import oblique_oracle

    slid = 0
    for omega0 in OMEGA_7:
        p1, p2 = contact_velocities(V_7 * X_HAT, omega0 * Y_HAT, -V_7 * X_HAT, -omega0 * Y_HAT, R_7)
        assert np.allclose(p1[1:], [0.0, -omega0 * R_7]) and np.allclose(p2[1:], p1[1:])
        spheres, slip_out, r, inputs = two_spinning_spheres(MATERIALS_7[material], omega0, -omega0)
        assert inputs["v_t"] == 0.0 and inputs["omega"] == 0.0
        assert r.status_name == "separated" and float(r.e) == pytest.approx(E_7, abs=1e-9)
        assert float(r.impulse_t) == 0.0 and slip_out == 0.0
        assert np.array_equal(spheres, [0.0, omega0, 0.0, -omega0])

        # the other sense: the contact points move against each other
        spheres, slip_out, r, inputs = two_spinning_spheres(MATERIALS_7[material], omega0, omega0)
        assert inputs["v_t"] == 0.0 and inputs["omega"] * inputs["R"] == pytest.approx(
            2 * omega0 * R_7, rel=1e-15
        )
        assert r.status_name == "separated" and float(r.e) == pytest.approx(E_7, abs=1e-8)
        # momentum: equal and opposite; the slip after, rebuilt from the spheres, is u_out
        assert spheres[2] == pytest.approx(-spheres[0], rel=1e-15)
        assert spheres[3] == pytest.approx(spheres[1], rel=1e-15)
        assert slip_out == pytest.approx(float(r.u_out), rel=1e-12, abs=1e-15)
        assert abs(float(r.impulse_t)) <= MU_7 * float(r.impulse_n) * (1 + 1e-9)
        o = oblique_oracle(
            c=inputs["c"],
            a=float(hunt_crossley_a(E_7, 2 * V_7)),
            m=inputs["m"],
            R=inputs["R"],
            inertia=inputs["inertia"],
            v_n=inputs["v_n"],
            v_t=0.0,
            omega=inputs["omega"],
            mu=MU_7,
            G_star=inputs["G_star"],
        )
        assert int(r.num_switches) == o["switches"], omega0
        # in units of the slip in, 2 omega0 R (omega_out nearly vanishes at small omega0)
        errors = (
            abs(float(r.v_t_out) - o["v_t_out"]),
            inputs["R"] * abs(float(r.omega_out) - o["omega_out"]),
        )
        assert max(errors) <= 1e-8 * 2 * omega0 * R_7, omega0
        rigid = rigid_oblique(
            mu=MU_7,
            e=float(r.e),
            v_n=inputs["v_n"],
            v_t=0.0,
            R=inputs["R"],
            omega=inputs["omega"],
            inertia=inputs["inertia"],
        )
        if omega0 > 4.2:
            assert bool(rigid["sliding"]) and int(r.num_switches) == 0
            slid += 1
            kick = MU_7 * (1 + float(r.e)) * V_7  # J / m, m/s
            assert spheres[0] == pytest.approx(kick, rel=1e-9)
            assert spheres[1] == pytest.approx(omega0 - kick / (0.4 * R_7), rel=1e-9)
            assert float(r.v_t_out) == pytest.approx(float(rigid["v_t_out"]), rel=1e-9)
            assert float(r.omega_out) == pytest.approx(float(rigid["omega_out"]), rel=1e-9)
        else:
            assert not bool(rigid["sliding"])
    assert slid == 5


def test_coulomb_bound_everywhere():
    """The tangential impulse never exceeds mu times the normal one (the normal force of
    these laws never pulls): incidence 1-89 degrees, three tangential laws, the damping
    (x^0.25) that makes the contact stick at first touch. Before the first `FIRST_TOUCH`
    of every contact was integrated apart, a change of mode inside the solver's first
    step went unseen at 85 degrees and e_t came out 0.37 instead of 0.98."""
    R = 2.5e-3
    m, c, G = sphere(*ALUMINA, R)
    law = ji.law("tsuji", c=c, b=tsuji_damping(0.98, c, m, 3.9))
    for tl in (
        tangential_law("mindlin", G=G, nu=ALUMINA[1], mu=0.092),
        tangential_law("mindlin_force", G=G, nu=ALUMINA[1], mu=0.092),
        tangential_law("linear_history", kt=1e9, mu=0.092),
    ):
        for theta in np.linspace(1.0, 89.0, 23):
            v_n, v_t = (float(v) for v in incidence(3.9, np.deg2rad(theta)))
            r = oblique_impact(law, tl, m=m, R=R, v_n=v_n, v_t=v_t)
            assert r.status_name == "separated", (tl.name, theta)
            bound = 0.092 * float(r.impulse_n) * (1 + 1e-9)
            assert abs(float(r.impulse_t)) <= bound, (tl.name, theta)
            if theta > 35.0:  # gross sliding: the rigid theory
                rigid = rigid_oblique(mu=0.092, e=float(r.e), v_n=v_n, v_t=v_t, R=R)
                assert float(r.e_t) == pytest.approx(float(rigid["e_t"]), abs=2e-6)
