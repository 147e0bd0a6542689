"""Exports of the laws with a contact state (docs/plastic_adhesive.md, "To the engines"),
without the engines: LAMMPS's `jkr` model (its formulas against JKR's, its replica against
its own continuous impact, the export's promise against jaximpact's exact JKR e(v)), and
the one line that says an engine lacks a law (Thornton) and how far its nearest law's e(v)
falls. The real engines run in test_real_plastic_adhesive.py (`-m engines`)."""

import math
import re

import numpy as np
import pytest

import jaximpact as ji
from jaximpact._engines.lammps import jkr as lammps_jkr
from jaximpact._engines.lammps import jkr_viscoelastic as lammps_jkr_viscoelastic
from jaximpact._engines.export import UnrealisedExport
from jaximpact._engines.response import engine_response, stepped_response
from jaximpact._laws.jkr import adhesion_group

R, M = 0.005, 0.004  # a 5 mm sphere of 4 g
E, NU, W = 1e7, 0.3, 1.0  # a soft rubber-like sphere, work of adhesion 1 J/m^2


def wall_law():
    """A JKR law of the sphere on a flat of its own material (R* = R)."""
    return ji.law("jkr", c=ji.hertz_stiffness(E=E, nu=NU, R=R), R=R, w=W)


def pair_law():
    """A JKR law of two such spheres (R* = R/2)."""
    return ji.law("jkr", c=ji.hertz_stiffness(E=E, nu=NU, R=R, R2=R), R=R / 2, w=W)


def test_lammps_jkr_contact_is_jkr_with_w_twice_cohesion_broken_at_the_least_force():
    """LAMMPS's contact radius and force (gran_sub_mod_normal.cpp) are JKR's with
    `w = 2 cohesion`; the neck forms at zero overlap with `-8/9 F_c` and LAMMPS breaks it
    at `-JKRPREFIX (R cohesion^2 / Emix^2)^(1/3)`, where the force is least (`-F_c`), not
    at JKR's least overlap (`-5/9 F_c`)."""
    cohesion, R_eff = 0.5, R / 2
    E_mix = lammps_jkr.emix(E, NU)
    law = ji.law("jkr", c=4 / 3 * E_mix * math.sqrt(R_eff), R=R_eff, w=2 * cohesion)
    pull = lammps_jkr.pulloff_distance(R_eff, cohesion, E_mix)
    deltas = np.concatenate([-pull * np.linspace(1.0, 0.0, 30), np.geomspace(1e-8, 1e-3, 30)])
    a = lammps_jkr.contact_radius(deltas * R_eff, R_eff, cohesion, E_mix)
    jkr_delta = a**2 / R_eff - np.sqrt(4 * math.pi * cohesion * a / E_mix)
    np.testing.assert_allclose(jkr_delta, deltas, rtol=1e-9, atol=1e-12 * pull)
    force = lammps_jkr.normal_force(deltas, R_eff, cohesion, E_mix)
    np.testing.assert_allclose(
        force, np.asarray(law.force(deltas, 0.0)), rtol=1e-8, atol=1e-10 * abs(force).max()
    )
    F_c = 1.5 * math.pi * (2 * cohesion) * R_eff  # = 3 pi cohesion R
    assert lammps_jkr.normal_force(0.0, R_eff, cohesion, E_mix) == pytest.approx(-8 / 9 * F_c)
    assert lammps_jkr.normal_force(-pull, R_eff, cohesion, E_mix) == pytest.approx(-F_c)
    x_f = -0.75 * (math.pi**2 * (2 * cohesion) ** 2 * R_eff / E_mix**2) ** (1 / 3)
    assert float(law.force(x_f, 0.0)) == pytest.approx(-5 / 9 * F_c, rel=1e-6)
    assert -pull > x_f  # LAMMPS breaks the neck first
    # the energies behind the constants: JKR's is jaximpact's sticking speed
    q = float(adhesion_group(law.params["c"], R_eff, 2 * cohesion, M, 1.0))
    V_s = math.sqrt(2 * lammps_jkr.C_JKR * q ** (10 / 3))
    assert float(law.sticking_speed(M)) == pytest.approx(V_s, rel=1e-9)
    assert lammps_jkr.ENERGY_RATIO == pytest.approx(0.49387, abs=1e-5)


def test_lammps_jkr_replica_tends_to_its_continuous_impact():
    """At a fine step the replica of `fix nve/sphere` on LAMMPS's jkr contact gives the
    continuous impact of `lammps_impact` (e and T), and with the law's own `w = 2 cohesion`
    that e is `(1 - 0.4939 (1 - e_JKR^2))^0.5`, not JKR's."""
    law = wall_law()
    E_mix = lammps_jkr.emix(E, NU)
    params = dict(E=E, poisson=NU, cohesion=W / 2, R_eff=R, geometry="wall")
    for v0 in (0.012, 0.03):
        x_star = (M * v0**2 / float(law.params["c"])) ** 0.4
        q = float(adhesion_group(law.params["c"], R, W, M, v0))
        e_cont, tau = lammps_jkr.lammps_impact(q)
        T_cont = tau * x_star / v0
        es, Ts = lammps_jkr.replica(
            {**params, "timestep": T_cont / 4000}, M, v0, phases=(0.25, 0.75)
        )
        assert np.all(np.abs(es - e_cont) < 2e-3 * e_cont), (es, e_cont)
        assert np.all(np.abs(Ts / T_cont - 1) < 1e-3), (Ts, T_cont)
        exact = float(ji.impact(law, m=M, v0=v0).e)
        assert e_cont == pytest.approx(lammps_jkr.literal_restitution(exact), rel=1e-9)
        assert e_cont > exact + 0.02
    assert E_mix == pytest.approx(E / (2 * (1 - NU**2)))


@pytest.mark.parametrize("geometry, law", [("wall", wall_law), ("spheres", pair_law)])
def test_jkr_export_to_lammps_realises_the_laws_e_of_v(geometry, law):
    """`export(jkr law, "lammps")` is LAMMPS's jkr model (no damping), promising the law's e
    and T at v0 (its replica's, within the export's 0.5 % at every start phase, T on their
    mean), and the law's e(v) at every speed (0 below the sticking speed) within the step's
    own error; one warning says how LAMMPS's neck differs from JKR's."""
    law = law()
    V_s = float(law.sticking_speed(M))
    x = ji.export(law, "lammps", m=M, v0=4 * V_s, radius=R, geometry=geometry)
    assert x.engine == "lammps" and x.law.name == "jkr" and x.separation == "force"
    assert all(abs(e / x.target_e - 1) <= 0.005 for e in x.e_range)
    assert abs(x.T / x.target_T - 1) <= 0.005
    assert " jkr " in x.parameters["pair_coeff"] and "damping velocity" in x.snippet
    assert x.parameters["damping"] == 0.0 and x.steps_per_contact >= 5
    assert ("fix wall all wall/gran granular jkr" in x.snippet) == (geometry == "wall")
    assert len(x.warnings) == 1 and "least force" in x.warnings[0], x.warnings
    e_engine, e_law = np.array(x.e_engine), np.array(x.e_target)
    assert e_law[:2].max() == 0.0 and e_engine[:2].max() == 0.0  # 0.4, 0.8 V_s: held
    np.testing.assert_allclose(e_engine[2:], e_law[2:], atol=3e-3)
    if geometry == "wall":  # the law's own material: E kept (for T), cohesion raised
        assert x.parameters["youngs_modulus"] == pytest.approx(E, rel=0.02)
        assert x.parameters["cohesion"] / (W / 2) == pytest.approx(
            lammps_jkr.ENERGY_RATIO ** (-0.6), rel=0.02
        )
    # the inverse: LAMMPS's parameters back to e(v), continuous and stepped
    params = {
        "E": x.parameters["youngs_modulus"],
        "cohesion": x.parameters["cohesion"],
        "poisson": NU,
        "geometry": geometry,
    }
    speeds = [2 * V_s, 4 * V_s]
    _, separation, e_back, _ = engine_response("lammps", params, m=M, speeds=speeds, radius=R)
    assert separation == "force"
    np.testing.assert_allclose(
        e_back, [float(ji.impact(law, m=M, v0=v).e) for v in speeds], rtol=2e-3
    )
    stepped = stepped_response(
        "lammps", {**params, "timestep": x.timestep}, m=M, speeds=[4 * V_s], radius=R
    )
    assert stepped[1][0] == pytest.approx(x.e, rel=1e-12)


def test_jkr_export_refusals_are_one_line():
    """A step that does not resolve the contact is refused with the step that works (the
    recommended one); LAMMPS refuses limit_damping with jkr; below the sticking speed
    there is no impact to export."""
    law = wall_law()
    V_s = float(law.sticking_speed(M))
    good = ji.export(law, "lammps", m=M, v0=5 * V_s, radius=R, geometry="wall", curves=False)
    short = r"in only \d\.\d+ steps .*needs at least 5"  # T over the step: 3.63
    with pytest.raises(UnrealisedExport, match=short) as refused:
        ji.export(
            law, "lammps", m=M, v0=5 * V_s, radius=R, geometry="wall", timestep=1e-3, curves=False
        )
    assert refused.value.working == good.timestep and "\n" not in str(refused.value)
    with pytest.raises(ValueError, match="limit_damping"):
        ji.export(law, "lammps", m=M, v0=5 * V_s, radius=R, limit_damping=True, curves=False)
    with pytest.raises(ValueError, match=f"sticking speed {V_s:.4g} m/s"):
        ji.export(law, "lammps", m=M, v0=0.5 * V_s, radius=R, geometry="wall", curves=False)


def _worst(line: str) -> float:
    return float(re.search(r"by up to ([0-9.e+-]+) ", line).group(1))


def steel():
    """A steel ball of 5 mm on a rigid flat (Thornton 1997; yield speed 0.034 m/s)."""
    m = 4 / 3 * math.pi * R**3 * 7800
    law = ji.law(
        "thornton",
        c=ji.hertz_stiffness(E=2.1e11, nu=0.3, R=R, E2=math.inf),
        x_y=ji.yield_overlap(E=2.1e11, nu=0.3, R=R, Y=1e9, E2=math.inf),
    )
    return law, m


def test_thornton_export_names_the_nearest_law_and_its_worst_gap():
    """No engine has Thornton's law: LAMMPS's export goes to hertz/material with
    coeff_restitution (e the same at every speed), and the first warning says so in one
    line with the worst |de| over the speeds, which is that of the curves it returns. Over
    the speeds a user gives, e is set to the middle of the law's e there: the worst gap is
    then half the law's range (the best a speed-free e can do)."""
    law, m = steel()
    x = ji.export(law, "lammps", m=m, v0=1.0, radius=R, geometry="wall", curves=False)
    line = x.warnings[0]
    assert line.startswith("LAMMPS has no thornton law") and "\n" not in line
    assert "hertz/material with damping coeff_restitution" in line and "mdr" in line
    gaps = np.abs(np.array(x.e_engine) - np.array(x.e_target))
    assert _worst(line) == pytest.approx(gaps.max(), abs=1e-3) and gaps.max() > 0.3
    assert abs(x.e / x.target_e - 1) < 5e-3  # the law's e and T at v0
    speeds = [0.1, 0.3, 1.0, 3.0]
    fit = ji.export(law, "lammps", m=m, v0=speeds, radius=R, geometry="wall")
    e_law = [float(ji.impact(law, m=m, v0=v).e) for v in speeds]
    assert fit.speeds == tuple(speeds) and fit.v0 == pytest.approx(math.sqrt(0.3))
    assert fit.target_e == pytest.approx(0.5 * (max(e_law) + min(e_law)), rel=1e-9)
    np.testing.assert_allclose(fit.e_target, e_law, rtol=1e-9)
    worst = _worst(fit.warnings[0])
    assert worst == pytest.approx(0.5 * (max(e_law) - min(e_law)), abs=2e-3)
    assert worst < _worst(line)
    with pytest.raises(ValueError, match="one speed"):
        ji.export(
            ji.law("hertz_rate", c=2e6, b1=800.0), "lammps", m=0.05, v0=[1.0, 2.0], radius=0.01
        )


def test_jkr_to_an_engine_without_it_names_the_nearest_law():
    """MuJoCo has no JKR: the export goes to its linear spring-dashpot, and says how far its
    e(v) falls (the stuck speeds included)."""
    law = wall_law()
    V_s = float(law.sticking_speed(M))
    x = ji.export(law, "mujoco", m=M, v0=[1.2 * V_s, 5 * V_s, 20 * V_s])
    assert x.warnings[0].startswith("MuJoCo has no jkr law") and "kelvin_voigt" in x.warnings[0]
    gaps = np.abs(np.array(x.e_engine) - np.array(x.e_target))
    assert _worst(x.warnings[0]) == pytest.approx(gaps.max(), abs=1e-3)


def _damped_law(geometry):
    """The rubber-like sphere with JKR adhesion (w = 10 J/m^2) and LAMMPS's viscoelastic
    damping (b = 3 N s/m^1.5): it sticks below about 0.05 m/s."""
    R2, R_eff = (None, R) if geometry == "wall" else (R, R / 2)
    c = ji.hertz_stiffness(E=E, nu=NU, R=R, R2=R2)
    return ji.law("jkr_viscoelastic", c=c, b=3.0, R=R_eff, w=10.0)


@pytest.mark.parametrize("e", [0.3, 0.8, 0.97])
def test_damped_lammps_impact_without_damping_is_the_closed_form(e):
    """`lammps_jkr_viscoelastic.lammps_impact` (scipy's DOP853 through LAMMPS's damped JKR)
    at beta = 0 against `lammps_jkr`'s energy closed form and quadrature: q for e, and the
    duration, to 1e-9."""
    q = lammps_jkr.group_for(e)
    assert lammps_jkr_viscoelastic.group_for(e, 0.0) == pytest.approx(q, rel=1e-9)
    e_damped, tau_damped = lammps_jkr_viscoelastic.lammps_impact(q, 0.0)
    assert e_damped == pytest.approx(e, rel=1e-9)
    assert tau_damped == pytest.approx(lammps_jkr.lammps_impact(q)[1], rel=1e-9)
    assert lammps_jkr_viscoelastic.lammps_impact(q, 0.1)[0] < e  # damping takes energy


@pytest.mark.slow  # jkr_viscoelastic's integrated impact, compiled for it alone (fast: 3 min)
@pytest.mark.parametrize("geometry", ["wall", "spheres"])
def test_damped_jkr_export_to_lammps_realises_the_law_at_v0(geometry):
    """`jkr_viscoelastic` goes to LAMMPS's `jkr` with `damping viscoelastic`: the law's
    damping group kept at v0, the cohesion set so that LAMMPS's continuous impact (scipy) has
    the law's e there, E its T. The replica (velocity Verlet, independent of scipy) at an
    eighth of the export's step is the law's e and T within 2e-4; at the export's step
    within the 0.5 % the export holds it to; below the sticking speed both hold the body."""
    law = _damped_law(geometry)
    v0 = 0.3
    x = ji.export(law, "lammps", m=M, v0=v0, radius=R, geometry=geometry)
    exact = ji.impact(law, m=M, v0=v0)
    assert (
        "jkr" in x.parameters["pair_coeff"] and "damping viscoelastic" in x.parameters["pair_coeff"]
    )
    assert abs(x.e / float(exact.e) - 1) < 5e-3 and abs(x.T / float(exact.T) - 1) < 5e-3
    fine = {**x.parameters, "timestep": x.timestep / 8}
    es, Ts = lammps_jkr_viscoelastic.replica(fine, M, v0)
    assert es.mean() == pytest.approx(float(exact.e), rel=2e-4)
    assert Ts.mean() == pytest.approx(float(exact.T), rel=2e-4)
    stuck, _ = lammps_jkr_viscoelastic.replica({**x.parameters, "timestep": x.timestep}, M, 0.02)
    assert float(ji.impact(law, m=M, v0=0.02).e) == 0.0 and np.all(stuck == 0.0)
    assert x.e_engine[0] == 0.0 and x.e_target[0] == 0.0  # 0.03 m/s: stuck in both
    with pytest.raises(ValueError, match="limit_damping"):
        ji.export(law, "lammps", m=M, v0=v0, radius=R, geometry=geometry, limit_damping=True)


def _dmt_law():
    """The rubber-like sphere on a flat with DMT adhesion (w = 30 J/m^2) and law 14's damping:
    it sticks below about 0.04 m/s."""
    return ji.law("dmt", c=ji.hertz_stiffness(E=E, nu=NU, R=R), b=3.0, R=R, w=30.0)


@pytest.mark.slow  # moved from the fast suite to keep it near 3 minutes
@pytest.mark.parametrize("geometry", ["wall", "spheres"])
def test_dmt_export_to_lammps_is_the_law_itself(geometry):
    """LAMMPS's `dmt` with `damping viscoelastic` is the `dmt` law: the export's engine law
    is the law for the contact's effective mass, as every engine's (its c, b and pull-off
    2 pi w R the given law's times meff/m to 1e-12: halved for two spheres; its R is the
    contact's effective one, R/2 for two spheres), ends contact at x = 0, and its replica
    at the export's step realises the law's e and T within the stepping's error (0.5 %)
    above the sticking speed and sticks below it, as the law does."""
    law = _dmt_law()
    x = ji.export(law, "lammps", m=M, v0=0.3, radius=R, geometry=geometry, curves=False)
    assert x.separation == "penetration" and "dmt" in x.snippet and "viscoelastic" in x.snippet

    def pulloff(law):
        return float(law.parameters["w"] * law.parameters["R"])

    scale = x.law_m / M  # meff/m: 1 on a wall, 1/2 for two spheres
    assert scale == (1.0 if geometry == "wall" else 0.5)
    for key in ("c", "b"):
        assert float(x.law.parameters[key]) == pytest.approx(
            scale * float(law.parameters[key]), rel=1e-12
        )
    assert pulloff(x.law) == pytest.approx(scale * pulloff(law), rel=1e-12)
    assert x.e == pytest.approx(x.target_e, rel=5e-3) and x.T == pytest.approx(x.target_T, rel=5e-3)
    stepping = {**x.parameters, "timestep": x.timestep}
    for v in (0.02, 0.1, 0.3):
        es, _ = stepped_response("lammps", stepping, m=M, speeds=[v], radius=R)[1:3]
        exact = float(ji.impact(law, m=M, v0=v, throw=False).e)
        assert es[0] == pytest.approx(exact, rel=5e-3, abs=1e-12), (v, es, exact)
    # the inverse: the engine's parameters give the law back
    back, separation, _, _ = engine_response("lammps", x.parameters, m=M, speeds=[0.3], radius=R)
    assert back.name == "dmt" and separation == "penetration"
    assert pulloff(back) == pytest.approx(scale * pulloff(law), rel=1e-12)


def test_dmt_export_refusals_are_one_line():
    law = _dmt_law()
    with pytest.raises(ValueError, match="limit_damping") as error:
        ji.export(law, "lammps", m=M, v0=0.3, radius=R, limit_damping=True)
    assert "\n" not in str(error.value)
    # refused before any work: before the law's impact at v0 (which would not separate)
    with pytest.raises(ValueError, match="refuses limit_damping with its dmt model"):
        ji.export(law, "lammps", m=M, v0=0.02, radius=R, limit_damping=True)
    with pytest.raises(ValueError, match="needs the spheres' radius"):
        ji.export(law, "lammps", m=M, v0=0.02)
    with pytest.raises(ValueError, match="does not separate") as error:
        ji.export(law, "lammps", m=M, v0=0.02, radius=R)
    assert "\n" not in str(error.value)
