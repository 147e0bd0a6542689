"""Material inputs (`hertz_stiffness`, `effective_mass`, `effective_radius`) against hand
values, and their one-line refusals."""

import math

import pytest

import jaximpact as ji


def test_hertz_stiffness_steel_ball_on_steel_plate():
    # E* = E / (2 (1 - nu^2)) = 2e11 / 1.82 = 1.0989e11 Pa; c = 4/3 E* sqrt(0.01)
    assert ji.hertz_stiffness(E=2e11, nu=0.3, R=0.01) == pytest.approx(
        4.0 / 3.0 * 2e11 / 1.82 * 0.1, rel=1e-14
    )


def test_hertz_stiffness_two_spheres_two_materials():
    # steel R = 10 mm on glass R = 5 mm: 1/E* = 0.91/2e11 + (1 - 0.22^2)/7e10, R* = 10/3 mm
    e_star = 1.0 / (0.91 / 2e11 + (1 - 0.22**2) / 7e10)
    expected = 4.0 / 3.0 * e_star * math.sqrt(0.01 * 0.005 / 0.015)
    got = ji.hertz_stiffness(E=2e11, nu=0.3, R=0.01, E2=7e10, nu2=0.22, R2=0.005)
    assert got == pytest.approx(expected, rel=1e-14)
    # a rigid flat: E* = E / (1 - nu^2)
    rigid = ji.hertz_stiffness(E=1e7, nu=0.45, R=0.02, E2=math.inf)
    assert rigid == pytest.approx(4.0 / 3.0 * 1e7 / (1 - 0.45**2) * math.sqrt(0.02), rel=1e-14)


def test_effective_mass_and_radius():
    assert ji.effective_mass(0.1, 0.3) == pytest.approx(0.075, rel=1e-15)
    assert ji.effective_mass(0.2) == 0.2  # against a fixed body
    assert ji.effective_radius(0.01, 0.01) == pytest.approx(0.005, rel=1e-15)
    assert ji.effective_radius(0.01) == 0.01  # on a flat


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda: ji.hertz_stiffness(E=0.0, nu=0.3, R=0.01), "E must be"),
        (lambda: ji.hertz_stiffness(E=2e11, nu=0.5, R=0.01), r"nu .*\(-1, 0.5\)"),
        (lambda: ji.hertz_stiffness(E=2e11, nu=-1.0, R=0.01), r"nu .*\(-1, 0.5\)"),
        (lambda: ji.hertz_stiffness(E=2e11, nu=0.3, R=-0.01), "R must be"),
        (lambda: ji.hertz_stiffness(E=2e11, nu=0.3, R=0.01, nu2=0.7), "nu2"),
        (lambda: ji.effective_mass(0.0, 1.0), "m1 must be"),
        (lambda: ji.effective_mass(1.0, -2.0), "m2 must be"),
        (lambda: ji.effective_radius(float("nan")), "R1 must be"),
    ],
)
def test_material_inputs_reject_bad_values_in_one_line(call, match):
    with pytest.raises(ValueError, match=match) as info:
        call()
    assert "\n" not in str(info.value)


def test_fixed_stiffness_law_for_calibrate():
    """The documented way to fix c from materials: the law takes the number as it is."""
    c = ji.hertz_stiffness(E=2e11, nu=0.3, R=0.01)
    law = ji.law("hertz_rate", c=c, b1=100.0)
    assert float(law.c) == c
