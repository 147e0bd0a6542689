"""Drake's friction (jaximpact/_engines/drake/friction.py): its continuous plant's oblique
impact (point contact, Stribeck-regularised Coulomb friction) integrated here against Drake
itself (`pytest.mark.engines`), and the export of a tangential law to Drake as its Coulomb
mu, with what Drake then realises (fast tests)."""

import math

import pytest
from harness import require, run_drake_oblique

import jaximpact as ji
from jaximpact._engines.drake.friction import stribeck

M, R, V0 = 0.05, 0.01, 1.0
LAW = ji.law("point_contact", c=2e5, d=0.5)  # Drake's own law: e = 0.75 at 1 m/s
SPRING = ji.tangential_law("linear_history", kt=1e5, mu=0.3)


@pytest.fixture(scope="module")
def exported():
    return ji.export(LAW, "drake", m=M, v0=V0, radius=R, tangential=SPRING, curves=False)


@pytest.mark.engines
@pytest.mark.parametrize("angle", [5.0, 20.0, 45.0, 75.0])
def test_drake_realises_the_exports_promise(exported, angle):
    """Drake's error-controlled continuous plant (accuracy 1e-10) against the promise, in
    sticking (5-45 degrees) and gross sliding (75): measured within 1e-10."""
    require("pydrake")
    k = exported.angles.index(angle)
    v_n, v_t = V0 * math.cos(math.radians(angle)), V0 * math.sin(math.radians(angle))
    e, e_t, omega = run_drake_oblique(exported.parameters, m=M, radius=R, v_n=v_n, v_t=v_t)
    print(
        f"{angle:4.0f} deg: Drake e {e:.9f} e_t {e_t:.9f} omega {omega:.6f} | promise "
        f"{exported.e_n_engine[k]:.9f} {exported.e_t_engine[k]:.9f} "
        f"{exported.omega_engine[k]:.6f}"
    )
    assert e == pytest.approx(exported.e_n_engine[k], abs=1e-8)
    assert e_t == pytest.approx(exported.e_t_engine[k], abs=1e-8)
    assert omega * R / v_t == pytest.approx(exported.omega_engine[k] * R / v_t, abs=1e-8)


@pytest.mark.slow  # 6 s: the export's e_t(theta) (the fast suite: 3 minutes)
def test_the_export_to_drake_takes_mu_and_says_how_far_it_falls(exported):
    """Drake's friction has no spring: it brings the slip to rest (rolling, e_t near 5/7 for
    a solid sphere) where the Cundall-Strack spring gives the slip back (e_t 0.48-0.54);
    in gross sliding (75 degrees) both are Coulomb's impulse result, equal to 1e-9."""
    x = exported
    assert x.parameters["friction"] == [0.3, 0.3] and x.parameters["stiction_tolerance"] == 1e-4
    assert "CoulombFriction(0.3, 0.3)" in x.snippet and "set_stiction_tolerance" in x.snippet
    for k, angle in enumerate(x.angles):
        if angle <= 45.0:
            assert x.e_t_engine[k] == pytest.approx(5.0 / 7.0, abs=0.003)
            assert x.e_t_target[k] < 0.6
    k = x.angles.index(75.0)
    assert x.e_t_engine[k] == pytest.approx(x.e_t_target[k], abs=1e-9)
    note = next(w for w in x.warnings if w.startswith("Drake has no tangential spring"))
    assert "by up to 0.229" in note and "normal e runs 0.7492 to 0.9205" in note


def test_drake_refuses_a_discrete_plant_and_a_missing_radius_in_one_line():
    with pytest.raises(ValueError, match="continuous plant only .*: leave timestep unset"):
        ji.export(LAW, "drake", m=M, v0=V0, radius=R, tangential=SPRING, timestep=1e-4)
    with pytest.raises(ValueError, match=r"needs the sphere's radius .*: pass radius="):
        ji.export(LAW, "drake", m=M, v0=V0, tangential=SPRING)


def test_stribeck_is_drakes_curve():
    """0 at rest, mu_s at the stiction tolerance, mu_d from three tolerances on, smooth
    (step5) between."""
    assert stribeck(0.0, 0.5, 0.3) == 0.0
    assert stribeck(1.0, 0.5, 0.3) == pytest.approx(0.5)
    assert stribeck(3.0, 0.5, 0.3) == pytest.approx(0.3)
    assert stribeck(10.0, 0.5, 0.3) == pytest.approx(0.3)
    assert stribeck(0.5, 0.5, 0.3) == pytest.approx(0.5 * 0.5)  # step5(1/2) = 1/2
    assert stribeck(2.0, 0.5, 0.3) == pytest.approx(0.4)
