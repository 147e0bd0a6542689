"""MuJoCo's friction (jaximpact/_engines/mujoco/friction.py): the replica of its pyramidal
cone on an oblique sphere against MuJoCo itself (`pytest.mark.engines`), and the export of a
tangential law to MuJoCo as its Coulomb mu, with what MuJoCo then realises (fast tests)."""

import math

import numpy as np
import pytest
from harness import require, run_mujoco_oblique

import jaximpact as ji
from jaximpact._engines.mujoco import solref as mj
from jaximpact._engines.mujoco.friction import frictional_solref, head_on_factor, oblique_replica

# Kharaz's alumina sphere (R = 2.5 mm) at 3.9 m/s, e = 0.98 (Tsuji's damping), mu = 0.092
R = 2.5e-3
M = 4000.0 * 4.0 / 3.0 * math.pi * R**3
LAW = ji.law("tsuji", c=4.2e9, b=15.0)
MINDLIN = ji.tangential_law("mindlin", G_star=1.35e10, mu=0.092)

# a soft, damped contact (MuJoCo's defaults' scale) where its friction acts: solref in
# both forms, friction 0.3, a 1 cm sphere at 1 m/s
SOFT = {"standard": (0.002, 0.5), "direct": (-4e6, -300.0)}


def _soft_parameters(solref, mu=0.3):
    return dict(
        solref=list(solref),
        solimp=list(mj.SOLIMP),
        timestep=1e-4,
        friction=[mu, 0.0, 0.0],
        condim=3,
        cone="pyramidal",
        impratio=1.0,
    )


@pytest.mark.engines
@pytest.mark.parametrize("form", list(SOFT))
@pytest.mark.parametrize("angle", [5.0, 20.0, 45.0, 75.0])
def test_the_replica_is_mujoco(form, angle):
    """The normal and tangential restitution and the spin after, per first-touch phase, to
    round-off (measured: 1e-14 in e and e_t, 1e-12 rad/s), in stick, slip and sliding."""
    require("mujoco")
    parameters = _soft_parameters(SOFT[form])
    v_n, v_t = math.cos(math.radians(angle)), math.sin(math.radians(angle))
    phases = (0.1, 0.6, 0.95)
    engine = run_mujoco_oblique(parameters, radius=0.01, v_n=v_n, v_t=v_t, phases=phases)
    replica = oblique_replica(
        parameters["solref"],
        parameters["timestep"],
        mu=0.3,
        radius=0.01,
        v_n=v_n,
        v_t=v_t,
        phases=phases,
    )
    for got, want in zip(replica, engine, strict=True):
        np.testing.assert_allclose(got, want, rtol=1e-10, atol=1e-10)


@pytest.mark.engines
def test_mujoco_realises_the_exports_promise():
    """The export's e_t, spin and normal e at each angle are the mean of MuJoCo's over the
    16 first-touch phases (its own runs of the exported parameters), and head-on MuJoCo
    with friction realises the law's e (solref corrected for the cone)."""
    require("mujoco")
    x = ji.export(LAW, "mujoco", m=M, v0=3.9, radius=R, tangential=MINDLIN, curves=False)
    from jaximpact._engines._stepping import PHASES

    for angle in (5.0, 45.0, 75.0):
        k = x.angles.index(angle)
        v_n, v_t = 3.9 * math.cos(math.radians(angle)), 3.9 * math.sin(math.radians(angle))
        e, e_t, omega = run_mujoco_oblique(
            x.parameters, radius=R, v_n=v_n, v_t=v_t, phases=PHASES, m=M
        )
        print(
            f"{angle:4.0f} deg: MuJoCo e {e.mean():.6f} e_t {e_t.mean():.6f} omega "
            f"{omega.mean():.3f} | promise {x.e_n_engine[k]:.6f} {x.e_t_engine[k]:.6f} "
            f"{x.omega_engine[k]:.3f} | law e_t {x.e_t_target[k]:.5f}"
        )
        assert e.mean() == pytest.approx(x.e_n_engine[k], rel=1e-9)
        assert e_t.mean() == pytest.approx(x.e_t_engine[k], rel=1e-9)
        assert omega.mean() == pytest.approx(x.omega_engine[k], rel=1e-8)
    tiny = 1e-9 * 3.9  # head-on: a slip too small to matter
    e, _, _ = run_mujoco_oblique(x.parameters, radius=R, v_n=3.9, v_t=tiny, phases=PHASES)
    assert e.mean() == pytest.approx(x.target_e, rel=2e-3)


@pytest.mark.parametrize("mu", [0.05, 0.3, 1.0, 2.0])
def test_head_on_the_corrected_cone_is_the_frictionless_contact(mu):
    """With solref divided by `head_on_factor(mu)` the cone's normal motion head-on is the
    frictionless row's (MuJoCo's normal replica) to round-off, at every start phase."""
    solref, h = SOFT["standard"], 1e-4
    e_frictionless, _ = mj.replica(solref, h, 1.0)
    e, _, _ = oblique_replica(
        frictional_solref(solref, h, mu), h, mu=mu, radius=0.01, v_n=1.0, v_t=1e-12
    )
    np.testing.assert_allclose(e, e_frictionless, rtol=1e-9)
    assert head_on_factor(1.0) == pytest.approx(1.0, abs=1e-15)  # mu^2 (1 + mu^2) = 2


@pytest.mark.slow  # 5.5 s: the export's e_t(theta) (the fast suite: 3 minutes)
def test_the_export_to_mujoco_takes_mu_and_says_how_far_it_falls():
    """Kharaz's sphere: MuJoCo's stiff, nearly elastic contact (e = 0.98) lasts about 12 us,
    while its friction acts at the rate of its damping (about 3e3 /s): e_t stays near 0.99
    at every angle where the Mindlin law gives 0.62 to 0.95; the warning says so."""
    x = ji.export(LAW, "mujoco", m=M, v0=3.9, radius=R, tangential=MINDLIN, curves=False)
    p = x.parameters
    assert p["friction"][0] == pytest.approx(0.092) and p["condim"] == 3
    assert 'friction="0.092' in x.snippet and 'cone="pyramidal"' in x.snippet
    assert p["solref"][0] < 0 and p["cone_factor"] == pytest.approx(head_on_factor(0.092))
    assert len(x.e_t_engine) == len(x.e_n_engine) == len(x.e_t_target) == len(x.angles)
    assert min(x.e_t_engine) > 0.985 and min(x.e_t_target) < 0.7  # weak against Coulomb
    gap = max(abs(a - b) for a, b in zip(x.e_t_engine, x.e_t_target, strict=True))
    note = next(w for w in x.warnings if w.startswith("MuJoCo has no tangential spring"))
    assert f"by up to {gap:.3g}" in note and "normal e runs" in note
    assert any("B T = 0.04" in w for w in x.warnings)  # why: 3.1e3 /s over 12.8 us
    assert tuple(x.to_dict()["e_n_engine"]) == x.e_n_engine


@pytest.mark.slow  # moved from the fast suite to keep it near 3 minutes
def test_mujoco_without_friction_is_the_frictionless_contact():
    frictionless = ji.tangential_law("linear_history", kt=1e6, mu=0.0)
    x = ji.export(LAW, "mujoco", m=M, v0=3.9, radius=R, tangential=frictionless, curves=False)
    assert x.parameters["condim"] == 1 and "cone_factor" not in x.parameters
    assert x.e_t_engine == pytest.approx([1.0] * len(x.angles))
    assert x.omega_engine == pytest.approx([0.0] * len(x.angles))
    assert x.e_n_engine[0] == pytest.approx(x.e, rel=1e-3)
