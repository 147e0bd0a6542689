"""`fit_oblique` recovers a tangential law from synthetic rebounds made by
`oblique_impact`, with standard errors that cover the truth under noise."""

import numpy as np
import pytest

import jaximpact as ji
from jaximpact._oblique import fit_oblique, incidence, oblique_impact, tangential_law

E, NU, RHO, R = 380e9, 0.23, 4000.0, 2.5e-3
M = RHO * 4.0 / 3.0 * np.pi * R**3
C = 4.0 / 3.0 * E / (1 - NU**2) * np.sqrt(R)
LAW = ji.law("hunt_crossley", c=C, a=0.01)
ANGLES = np.deg2rad([5.0, 12.0, 20.0, 30.0, 45.0, 60.0])
V_N, V_T = (np.asarray(v) for v in incidence(3.9, ANGLES))


def rebounds(tangential):
    pairs = zip(V_N, V_T, strict=True)
    out = [oblique_impact(LAW, tangential, m=M, R=R, v_n=a, v_t=b) for a, b in pairs]
    return np.array([float(r.e_t) for r in out]), np.array([float(r.omega_out) for r in out])


def test_fit_input_checks():
    tl = tangential_law("linear_history", kt=1e7, mu=0.1)
    base = dict(m=M, R=R, v_n=V_N, v_t=V_T)
    with pytest.raises(ValueError, match="needs measured e_t or omega_out"):
        fit_oblique(LAW, tl, **base)
    with pytest.raises(ValueError, match="free must name parameters"):
        fit_oblique(LAW, tl, **base, e_t=np.ones(6), free=("G_star",))
    with pytest.raises(ValueError, match="e_t has 3 values where v_n has 6"):
        fit_oblique(LAW, tl, **base, e_t=np.ones(3))
    with pytest.raises(ValueError, match="start value of mu must be a finite number > 0"):
        fit_oblique(LAW, tangential_law("linear_history", kt=1e7, mu=0.0), **base,
                    e_t=np.ones(6))  # fmt: skip
    with pytest.raises(ValueError, match="takes the normal law first"):
        fit_oblique(tl, tl, **base, e_t=np.ones(6))


@pytest.mark.slow
def test_recovers_linear_history():
    """kt = 5e7 N/m, mu = 0.15 from e_t and the spin at six angles (stick, micro-slip and
    gross sliding), starting 2.5x and 1.5x off: to 1e-7."""
    e_t, omega = rebounds(tangential_law("linear_history", kt=5e7, mu=0.15))
    start = tangential_law("linear_history", kt=2e7, mu=0.1)
    fit = fit_oblique(LAW, start, m=M, R=R, v_n=V_N, v_t=V_T, e_t=e_t, omega_out=omega)
    assert bool(fit.converged)
    assert float(fit.params["kt"]) == pytest.approx(5e7, rel=1e-7)
    assert float(fit.params["mu"]) == pytest.approx(0.15, rel=1e-7)
    assert float(fit.loss) < 1e-16
    assert np.allclose(np.asarray(fit.e_t), e_t, atol=1e-9)
    assert "kt" in fit.summary()


@pytest.mark.slow
def test_recovers_mindlin_with_noise():
    """G* and mu of a Mindlin law from e_t alone with noise 0.003 (given as sigma_e_t):
    the truth within three standard errors (measured: 0.9 and 1.3), which the noise sets."""
    g_star = E / (2 * (1 + NU)) / (2 - NU)
    e_t, _ = rebounds(tangential_law("mindlin", G_star=g_star, mu=0.092))
    noisy = e_t + 0.003 * np.random.default_rng(7).standard_normal(e_t.shape)
    start = tangential_law("mindlin", G_star=0.5 * g_star, mu=0.12)
    fit = fit_oblique(LAW, start, m=M, R=R, v_n=V_N, v_t=V_T, e_t=noisy, sigma_e_t=0.003,
                      free=("G_star", "mu"))  # fmt: skip
    assert bool(fit.converged)
    for name, truth in (("G_star", g_star), ("mu", 0.092)):
        value, se = float(fit.params[name]), float(fit.stderr[name])
        assert 0 < se < 0.5 * truth
        assert abs(value - truth) < 3 * se, (name, value, se, truth)
