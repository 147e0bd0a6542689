"""Design studies: sensitivities against finite differences, first-order uncertainty against
Monte Carlo, the bumper optimisation (slow: it compiles a forward-mode Jacobian of a vmapped
three-phase impact inside an optax loop).

The finite differences run through the compiled batch of test_batch.py (hertz_rate, e and T,
blocks of 64 rows); the Jacobians, the sensitivity map and the Monte Carlo through one
compiled `jacobian_batch` (with respect to c and b1, blocks of 64 rows).
"""

import json

import numpy as np
import pytest
from helpers import assert_rel

import jaximpact as ji
from jaximpact import bumper_design, impact_batch, propagate_uncertainty, sensitivity_map
from jaximpact._studies.sensitivity import jacobian_batch

ET = dict(peaks=False, fields=("e", "T", "status"), chunk_size=64, progress=False)
C, B1, M, V0 = 2e6, 800.0, 1.0, 2.5  # the seed paper's Fig. 10


def central_differences(h=1e-5):
    """d(e, T)/d(c, b1) at the paper's point by central differences, in one 64-row batch."""
    rows = [(C, B1), (C * (1 + h), B1), (C * (1 - h), B1), (C, B1 * (1 + h)), (C, B1 * (1 - h))]
    c, b1 = np.array(rows * 13)[:64].T
    out = impact_batch("hertz_rate", {"c": c, "b1": b1}, m=M, v0=V0, **ET)
    values = np.stack([out["e"], out["T"]])
    return np.stack(
        [
            (values[:, 1] - values[:, 2]) / (2 * h * C),
            (values[:, 3] - values[:, 4]) / (2 * h * B1),
        ],
        axis=1,
    )


def test_jacobian_batch_matches_central_differences():
    b1 = B1 * np.linspace(1.0, 2.0, 64)  # 64 rows: the block shape of every Jacobian here
    out = jacobian_batch(
        "hertz_rate", {"c": C, "b1": b1}, wrt=("c", "b1"), m=M, v0=V0, chunk_size=64
    )
    jac = np.array([[out[f"d{y}_d{p}"][0] for p in ("c", "b1")] for y in ("e", "T")])
    assert_rel(jac, central_differences(), 1e-5, "d(e, T)/d(c, b1)")
    assert np.all(np.diff(out["de_db1"]) > 0)  # e falls ever more slowly with b1


def test_first_order_uncertainty_agrees_with_monte_carlo():
    """5 % scatter in c, 10 % in b1: the linear spread of e and T lies within the Monte Carlo
    sampling error (|z| < 3) of the sampled one."""
    law = ji.law("hertz_rate", c=C, b1=B1)
    u = propagate_uncertainty(
        law,
        m=M,
        v0=V0,
        scatter={"c": 0.05 * C, "b1": 0.1 * B1},
        n_samples=4095,  # + the nominal point: 64 blocks of 64 rows
        chunk_size=64,
    )
    assert u.names == ("c", "b1") and u.jacobian.shape == (2, 2)
    assert_rel(u.jacobian, central_differences(), 1e-5, "Jacobian")
    assert u.separated_fraction == 1.0
    assert np.all(np.abs(u.z_std) < 3), (u.std_linear, u.std_mc, u.std_mc_error)
    assert_rel(u.std_linear, u.std_mc, 0.05, "linear vs Monte Carlo spread")
    assert np.all(np.abs(u.mean_mc - u.nominal) < 5 * u.mean_mc_error + 1e-3 * u.std_mc)
    text = repr(u)
    assert "n_samples          = 4095" in text and "f64[" not in text
    json.dumps(u.to_dict(), allow_nan=False)


def test_sensitivity_map_elasticities():
    s = sensitivity_map("hertz_rate", num=8, chunk_size=64)  # one block of 64 rows
    assert s.de_dc.shape == (8, 8) and s.damping_name == "b1"
    # e falls with damping and rises with stiffness; T falls with stiffness
    assert np.all(s.de_ddamping < 0) and np.all(s.de_dc > 0) and np.all(s.dT_dc < 0)
    # law 14's e depends on beta = b1 x*^1.5 / (m v0) with x* ~ c^-0.4: d ln e/d ln c is
    # exactly -0.6 d ln e/d ln b1 (the similarity law)
    assert_rel(s.elasticity("e", "c"), -0.6 * s.elasticity("e", "damping"), 1e-6, "similarity")
    text = repr(s)
    assert text.startswith("SensitivityMap") and "N s/m^1.5" in text and "f64[" not in text
    json.dumps(s.to_dict(), allow_nan=False)


def test_uncertainty_rejects_bad_scatter():
    law = ji.law("hertz_rate", c=C, b1=B1)
    with pytest.raises(ValueError, match="cannot scatter"):
        propagate_uncertainty(law, m=M, v0=V0, scatter={"k": 1.0})
    with pytest.raises(ValueError, match="at least one"):
        propagate_uncertainty(law, m=M, v0=V0, scatter={})


@pytest.mark.slow
def test_bumper_design_meets_the_constraints_and_scales():
    """Two strokes and two restitution targets at once. By law 14's similarity the optimum
    for a stroke k times longer is the same design scaled (c k^-2.5, b1 k^-1.5), so the peak
    force times the stroke is the same for both strokes."""
    d = bumper_design(
        m=1.0,
        speeds=np.linspace(1.0, 3.0, 4),
        x_max_bound=np.array([0.01, 0.02, 0.01]),
        e_target=np.array([0.5, 0.5, 0.15]),
        steps=200,
    )
    assert np.all(d.feasible)
    assert np.all(d.x_max <= d.x_max_bound[:, None] * (1 + 1e-3))
    assert np.all(d.e <= d.e_target[:, None] + 1e-3)
    # the stroke constraint is active: the bumper uses (almost) all of it
    assert np.all(np.max(d.x_max, axis=1) > 0.99 * d.x_max_bound)
    assert_rel(d.F_peak[1] * 0.02, d.F_peak[0] * 0.01, 1e-3, "F_peak x stroke")
    assert_rel(d.c[1], d.c[0] * 2**-2.5, 1e-2, "c scaling")
    # a binding restitution target costs peak force; no design beats the constant force
    assert d.F_peak[2] > d.F_peak[0]
    text = repr(d)  # three designs: each field as a list with its unit
    assert text.startswith("BumperDesign") and "N/m^1.5" in text and "feasible    = [True" in text
    json.dumps(d.to_dict(), allow_nan=False)
    assert np.all(d.F_peak > d.F_ideal)
    # the designed law reproduces the reported response
    check = ji.impact(d.law(0), m=1.0, v0=3.0, rtol=1e-10)
    assert_rel(check.F_max, d.F_max[0, -1], 1e-6, "F_max at 3 m/s")


@pytest.mark.slow
def test_drop_design_recovers_height_and_mass():
    """Apexes of a known drop (from `bounce`) give back its height and mass."""
    from jaximpact import drop_design
    from jaximpact._solve.bounce import bounce

    law = ji.law("hertz_rate", c=1e6, b1=1350.0)
    h0, m = 0.6, 0.8
    b = bounce(law, m=m, h0=h0, t_end=10.0, max_impacts=4, peaks=False)
    target = np.asarray(b.apex_heights[:4])
    d = drop_design(law, apexes=target, h0_guess=1.0, m_guess=0.3)
    assert d.converged and d.loss < 1e-18
    assert_rel([d.h0, d.m], [h0, m], 1e-6, "h0, m")
    assert_rel(d.apexes, target, 1e-8, "apexes")
    assert "h0         = 600 mm" in repr(d) and "converged  = True" in repr(d)
    json.dumps(d.to_dict(), allow_nan=False)
    with pytest.raises(ValueError, match="decrease"):
        drop_design(law, apexes=[0.1, 0.2], h0_guess=1.0, m_guess=0.3)
