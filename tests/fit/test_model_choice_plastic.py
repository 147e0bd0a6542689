"""`compare_laws` tells a plastic contact from a viscoelastic one by e(v) (and T): e(v) of a
steel ball (Thornton's law, 0.3 % noise) ranks `thornton` first; e(v) of a rubber-like
ball (Kuwabara-Kono, `hertz_rate`) ranks it behind a viscoelastic law."""

import math

import jax
import numpy as np
import pytest

import jaximpact as ji

R, M = 5e-3, 4.0 / 3.0 * math.pi * 5e-3**3 * 7800.0
SPEEDS = np.array([0.1, 0.3, 0.6, 1.0, 2.0, 3.0])
NOISE = np.array([1.0, -1.0, 0.5, -0.5, 1.0, -1.0])
LAWS = ("thornton", "hertz_rate", "hunt_crossley", "kelvin_voigt")


def _measured(law, m):
    r = jax.vmap(lambda v: ji.impact(law, m=m, v0=v))(SPEEDS)
    return np.asarray(r.e) * (1 + 0.003 * NOISE), np.asarray(r.T) * (1 + 0.003 * NOISE[::-1])


@pytest.mark.slow
def test_e_of_v_of_a_steel_ball_picks_the_plastic_law():
    steel = ji.law(
        "thornton",
        c=ji.hertz_stiffness(E=2.1e11, nu=0.3, R=R, E2=math.inf),
        x_y=ji.yield_overlap(E=2.1e11, nu=0.3, R=R, Y=1e9, E2=math.inf),
    )
    e, T = _measured(steel, M)
    ranks = ji.compare_laws(m=M, v0=SPEEDS, e=e, T=T, laws=LAWS, progress=False)
    assert ranks[0].name == "thornton"
    assert ranks[0].sum_sq < 0.05 * ranks[1].sum_sq
    assert float(ranks[0].fit.params["x_y"]) == pytest.approx(float(steel.x_y), rel=0.05)


@pytest.mark.slow
def test_e_of_v_of_a_rubber_ball_picks_a_viscoelastic_law():
    rubber = ji.law("hertz_rate", c=2e6, b1=800.0)
    e, T = _measured(rubber, 1.0)
    ranks = ji.compare_laws(m=1.0, v0=SPEEDS, e=e, T=T, laws=LAWS, progress=False)
    assert ranks[0].name != "thornton"
    names = [r.name for r in ranks]
    assert names.index("hertz_rate") < names.index("thornton")
