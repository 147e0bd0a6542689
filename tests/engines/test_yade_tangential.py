"""Yade's ViscElMat shear (jaximpact/_engines/yade.py): a `linear_history` law exported with
the normal one through ViscElMat's explicit kn, cn, ks, cs, against real Yade on a fixed wall
and between two spheres (`pytest.mark.engines`; Debian's `yade`), and the export's choices
(fast tests)."""

import functools
import math

import pytest
from harness import require_executable, run_yade_oblique

import jaximpact as ji

R, M, V0 = 0.01, 0.05, 1.0
LAW = ji.law("kelvin_voigt", c=2e5, b=3.0)  # e = 0.954, a soft contact: x_max / R = 0.05
SPRINGS = {
    "stiff": ji.tangential_law("linear_history", kt=1e5, mu=0.3),
    "soft": ji.tangential_law("linear_history", kt=1e4, mu=0.1),
}


@functools.cache
def _export(name):
    return ji.export(
        LAW, "yade", m=M, v0=V0, radius=R, geometry="wall", tangential=SPRINGS[name], curves=False
    )


@pytest.mark.engines
@pytest.mark.parametrize("name", list(SPRINGS))
def test_yade_realises_the_tangential_promise_on_a_wall(name):
    """e_t within 0.002 and the spin within 1 % of v_t/R of the promise (the law's spring
    with the force at Yade's contact point, the wall's plane: lever arm R - x) from 5 to 75
    degrees. Measured: within 0.0011 and 0.3 %, the rest Yade's leapfrog at 400 steps per
    contact; with the lever arm R the promise was 0.025 off at 5 degrees."""
    require_executable("yade")
    x = _export(name)
    for angle in (5.0, 20.0, 45.0, 75.0):
        k = x.angles.index(angle)
        v_n, v_t = V0 * math.cos(math.radians(angle)), V0 * math.sin(math.radians(angle))
        e, e_t, omega = run_yade_oblique(x.parameters, m=M, radius=R, v_n=v_n, v_t=v_t)
        print(
            f"{name} {angle:4.0f} deg: Yade e {e:.5f} e_t {e_t:.5f} omega {omega:8.3f} | "
            f"promise {x.e_n_engine[k]:.5f} {x.e_t_engine[k]:.5f} {x.omega_engine[k]:8.3f}"
            f" | law e_t {x.e_t_target[k]:.5f}"
        )
        assert e_t == pytest.approx(x.e_t_engine[k], abs=0.002)
        assert abs(omega - x.omega_engine[k]) * R / v_t < 0.01
        assert e == pytest.approx(x.e_n_engine[k], rel=1e-3)


@pytest.mark.slow  # moved from the fast suite to keep it near 3 minutes
def test_the_material_is_explicit_and_the_normal_contact_unchanged():
    x = _export("stiff")
    p = x.parameters
    assert p["material"].startswith("ViscElMat(kn=") and "ks=200000.0, cs=0.0" in p["material"]
    assert f"frictionAngle={math.atan(0.3)!r}" in p["material"]
    assert f"kn={2.0 * p['kn']!r}, cn={2.0 * p['cn']!r}" in p["material"]
    assert x.e == pytest.approx(x.target_e, rel=5e-3)
    note = next(w for w in x.warnings if w.startswith("its e_t departs from the law's"))
    assert "lever arm R - 1 x" in note and "contact_point=1" in note


def test_other_tangential_laws_and_a_damper_are_refused_in_one_line():
    mindlin = ji.tangential_law("mindlin", G_star=1e9, mu=0.1)
    with pytest.raises(ValueError, match="export a linear_history law"):
        ji.export(LAW, "yade", m=M, v0=V0, radius=R, geometry="wall", tangential=mindlin)
    damped = ji.tangential_law("linear_history", kt=1e5, mu=0.3, ct=0.5)
    with pytest.raises(ValueError, match="export with ct=0"):
        ji.export(LAW, "yade", m=M, v0=V0, radius=R, geometry="wall", tangential=damped)


# two spheres: a contact short enough (T = 49 us) that their line of centres turns little
PAIR_LAW = ji.law("kelvin_voigt", c=2e8, b=100.0)
PAIR_SPRINGS = {
    "stiff": ji.tangential_law("linear_history", kt=1e8, mu=0.3),
    "soft": ji.tangential_law("linear_history", kt=1e7, mu=0.1),
}


@functools.cache
def _pair_export(name):
    return ji.export(
        PAIR_LAW, "yade", m=M, v0=V0, radius=R, tangential=PAIR_SPRINGS[name], curves=False
    )


@pytest.mark.engines
@pytest.mark.parametrize("name", list(PAIR_SPRINGS))
def test_yade_realises_the_tangential_promise_between_two_spheres(name):
    """Two equal spheres (the pair's effective sphere, contact point halfway through the
    overlap: lever arm R - x/2 each): e_t within 0.005, each sphere's spin within 1 % of
    v_t/R, e within 0.01 from 5 to 75 degrees. Measured: 0.0026 (at 5 degrees, sticking),
    0.4 % and 0.0083 at 75 degrees, the line of centres turning by 0.0024 rad there (the
    export's estimate of its effect, 0.0088, stays below its warning)."""
    require_executable("yade")
    x = _pair_export(name)
    assert not any("line of centres" in w for w in x.warnings)
    for angle in (5.0, 20.0, 45.0, 75.0):
        k = x.angles.index(angle)
        v_n, v_t = V0 * math.cos(math.radians(angle)), V0 * math.sin(math.radians(angle))
        e, e_t, omega = run_yade_oblique(x.parameters, m=M, radius=R, v_n=v_n, v_t=v_t)
        promise = (x.e_n_engine[k], x.e_t_engine[k], x.omega_engine[k])
        print(
            f"{name} {angle:4.0f} deg: Yade {e:.5f} {e_t:.5f} {omega:8.3f} | promise "
            "{:.5f} {:.5f} {:8.3f}".format(*promise)
        )
        assert e_t == pytest.approx(promise[1], abs=0.005)
        assert abs(omega - promise[2]) * R / v_t < 0.01
        assert e == pytest.approx(promise[0], abs=0.01)


@pytest.mark.slow  # moved from the fast suite to keep it near 3 minutes
def test_two_soft_spheres_are_warned_of_their_turning_line_of_centres():
    """The wall test's soft contact between two spheres (T = 1.6 ms, R = 1 cm): the line of
    centres turns by 0.075 rad at 75 degrees, and real Yade's e there is 0.72 against the
    promise's 0.954 (measured): the export says so. Its promise is finite at every angle
    (it once ran out of segments at 60 degrees)."""
    x = ji.export(LAW, "yade", m=M, v0=V0, radius=R, tangential=SPRINGS["stiff"], curves=False)
    note = next(w for w in x.warnings if "line of centres" in w)
    assert "0.075 rad" in note and "geometry='wall'" in note
    assert all(math.isfinite(v) for v in x.e_t_engine + x.omega_engine)
