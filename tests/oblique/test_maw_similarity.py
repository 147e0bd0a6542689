"""Maw, Barber & Fawcett's similarity (notes/contact-physics.md, 4.1), as `oblique_impact`
solves it: with a Hertz normal law (Hunt-Crossley damping `a`) and a Mindlin tangential
spring `k_t = k0 x^0.5` (`k0 = 8 G* R^0.5`), in the normal contact's units (`x*`,
`t* = x*/v_n`) the oblique impact depends on four groups alone,

    psi = u / (mu v_n),   k0 / c,   kappa = 1 + m R^2 / I,   a v_n,

(`u = v_t - R omega` the incident slip), so `e`, `e_t_contact`, the stick-slip switches and
`T / t*` are those of any scene with the same groups. A constant spring (`linear_history`)
has no such group: `kt x*^(1/2) / c` changes with `v_n`, and so does its `e_t` at one `psi`.
"""

import numpy as np
import pytest

import jaximpact as ji


def _scene(scale_m, scale_v, scale_mu, scale_c, scale_R, psi, name="mindlin_force"):
    """A base scene (a 5 mm, 0.26 g sphere at 3.9 m/s on a plane, c = 4.2e9 N/m^1.5,
    a = 0.05 s/m, G* = 1.35e10 Pa, mu = 0.1) scaled so that the four groups stay."""
    m, R, v_n, mu = 2.6e-4 * scale_m, 2.5e-3 * scale_R, 3.9 * scale_v, 0.1 * scale_mu
    c = 4.2e9 * scale_c
    G_star = 1.35e10 * scale_c / np.sqrt(scale_R)  # k0 / c fixed
    law = ji.law("hunt_crossley", c=c, a=0.05 / scale_v)  # a v_n fixed
    if name == "linear_history":
        tangential = ji.tangential_law(name, kt=2e6, mu=mu)
    else:
        tangential = ji.tangential_law(name, G_star=G_star, mu=mu)
    v_t = psi * mu * v_n
    r = ji.oblique_impact(law, tangential, m=m, R=R, v_n=v_n, v_t=v_t, omega=0.0, inertia=0.4)
    x_star = (m * v_n**2 / c) ** 0.4
    return r, x_star / v_n


SCALES = [(1, 1, 1, 1, 1), (3.0, 0.25, 2.0, 0.2, 4.0), (0.1, 5.0, 0.5, 7.0, 0.3)]


# mindlin_force in the slow group: 5 s of compiling (the fast suite: 3 minutes)
@pytest.mark.parametrize("name", ["mindlin", pytest.param("mindlin_force", marks=pytest.mark.slow)])
@pytest.mark.parametrize("psi", [0.4, 1.5, 4.0])
def test_the_impact_depends_on_the_groups_alone(name, psi):
    """Three scenes of one `psi`, `k0/c`, `kappa`, `a v_n` (masses 0.1-3x, speeds 0.25-5x,
    friction 0.5-2x, stiffness 0.2-7x, radii 0.3-4x): the same `e`, `e_t_contact` and
    switches, `T` in units of `t*` alike, to the solve's accuracy (measured: 1.5e-8 at
    worst, in `e_t_contact`, mindlin_force at psi = 0.4)."""
    runs = [_scene(*s, psi, name) for s in SCALES]
    base, t_base = runs[0]
    for r, t_star in runs[1:]:
        assert int(r.num_switches) == int(base.num_switches)
        assert float(r.e) == pytest.approx(float(base.e), abs=5e-8)
        assert float(r.e_t_contact) == pytest.approx(float(base.e_t_contact), abs=5e-8)
        assert float(r.T) / t_star == pytest.approx(float(base.T) / t_base, rel=1e-8)


@pytest.mark.slow  # 5 s of compiling linear_history (the fast suite: 3 minutes)
def test_a_constant_spring_has_no_such_group():
    """`linear_history` at one `psi`: its e_t moves with the normal speed (the groups of the
    Mindlin spring do not hold)."""
    slow, _ = _scene(1, 1, 1, 1, 1, 1.5, "linear_history")
    fast, _ = _scene(1, 4.0, 1, 1, 1, 1.5, "linear_history")
    assert abs(float(slow.e_t_contact) - float(fast.e_t_contact)) > 0.01
