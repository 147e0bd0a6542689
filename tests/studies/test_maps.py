"""`restitution_map` and `plot_map`: the seed paper's Figs. 1 and 7, and the other laws.

The integrated map shares its compiled batch with test_batch.py (hertz_rate, e and T, blocks
of 64 rows: an 8 x 8 grid); maps of other integrated laws are slow.
"""

import json

import matplotlib
import numpy as np
import pytest
from helpers import assert_rel
from reference import reference_impact

import jaximpact as ji
from jaximpact._studies.maps import plot_map, restitution_map

matplotlib.use("Agg")

GRID = dict(num=8, chunk_size=64)  # 64 points: one block of test_batch.py's shape


def test_figure_1_kelvin_voigt_matches_the_closed_form():
    rmap = restitution_map("kelvin_voigt", num=21)  # m = 1 kg, c 2e6-2e7, b 200-1000
    assert rmap.path == "closed_form" and rmap.e.shape == (21, 21)
    assert rmap.c[0] == 2e6 and rmap.c[-1] == 2e7 and rmap.damping[[0, -1]].tolist() == [200, 1000]
    b, c = np.meshgrid(rmap.damping, rmap.c, indexing="ij")
    exact = ji.closed_forms.kelvin_voigt(c, b, 1.0, 2.5)
    assert_rel(rmap.e, exact["e"], 1e-14, "e")
    assert_rel(rmap.T, exact["T"], 1e-14, "T")
    # the paper's reading of Fig. 1: T is set by c, e falls with b and rises with c
    assert np.all(np.diff(rmap.e, axis=0) < 0) and np.all(np.diff(rmap.e, axis=1) > 0)
    assert np.ptp(np.log(rmap.T), axis=1).min() > 5 * np.ptp(np.log(rmap.T), axis=0).max()


def test_figure_7_maxwell_takes_the_paper_formulas_when_under_damped():
    rmap = restitution_map("maxwell", num=9)
    assert rmap.path == "closed_form"
    b, c = np.meshgrid(rmap.damping, rmap.c, indexing="ij")
    q = np.sqrt(4 * b**2 - c * 1.0)
    assert_rel(rmap.e, np.exp(-np.pi * np.sqrt(c * 1.0) / q), 1e-13, "e, paper")
    assert_rel(rmap.T, 2 * np.pi * b * np.sqrt(c * 1.0) / (c * q), 1e-13, "T, paper")
    assert np.all(rmap.status == ji.Status.separated)


def test_curves_map_matches_scipy():
    rmap = restitution_map("hertz_rate", **GRID)
    assert rmap.path == "similarity" and rmap.damping_name == "b1" and rmap.e.shape == (8, 8)
    assert np.all(np.diff(rmap.e, axis=0) < 0)  # more b1, less restitution
    text = repr(rmap)  # numbers with units, the axes in the law's own
    assert "N/m^1.5" in text and "N s/m^1.5" in text and "64 values" in text
    assert "f64[" not in text and "Array(" not in text
    json.dumps(rmap.to_dict(), allow_nan=False)
    for i, j in ((0, 0), (3, 5), (7, 7)):
        ref = reference_impact(
            "hertz_rate", dict(c=rmap.c[j], b1=rmap.damping[i]), m=1.0, v0=2.5, rtol=1e-12
        )
        assert_rel(rmap.e[i, j], ref["e"], 1e-7, f"e[{i},{j}]")
        assert_rel(rmap.T[i, j], ref["T"], 1e-7, f"T[{i},{j}]")


def test_plot_map_draws_two_contour_panels(tmp_path):
    rmap = restitution_map("kelvin_voigt", num=11)
    fig = plot_map(rmap)
    assert len(fig.axes) == 4  # two panels and their colour bars
    assert fig.axes[0].get_yscale() == "log"
    path = tmp_path / "fig1.png"
    fig.savefig(path)
    assert path.stat().st_size > 10_000


def test_every_law_has_a_default_map():
    for name, spec in ji.LAWS.items():
        lo, hi = spec.map_range
        assert spec.damping in spec.parameters and 0 <= lo < hi, name
        assert set(spec.map_fixed) <= set(spec.parameters), name


def test_restitution_map_rejects_bad_inputs():
    with pytest.raises(ValueError, match="unknown law"):
        restitution_map("nope")
    with pytest.raises(ValueError, match="no damping parameter"):
        restitution_map("kelvin_voigt", damping_name="a")
    with pytest.raises(ValueError, match="at least 2"):
        restitution_map("kelvin_voigt", c=[2e6])
    with pytest.raises(ValueError, match="fixed must not"):
        restitution_map("bingham", fixed={"P": 400.0, "b": 3.0})


@pytest.mark.slow
@pytest.mark.parametrize("name", ["lankarani_nikravesh", "flores", "hunt_crossley_nominal"])
def test_hunt_crossley_variants_match_the_exact_restitution(name):
    """Solved through hunt_crossley's compiled solve; e is exact (Lambert W)."""
    from jaximpact._laws.hunt_crossley_variants import FORMULAS

    rmap = restitution_map(name, num=6)
    e_nominal, c = np.meshgrid(rmap.damping, rmap.c, indexing="ij")
    exact = ji.closed_forms.hunt_crossley_restitution(FORMULAS[name](e_nominal, 2.5) * 2.5)
    assert_rel(rmap.e, exact, 1e-7, "e")


@pytest.mark.slow
def test_maxwell_map_integrated_equals_the_closed_form():
    closed = restitution_map("maxwell", num=6)
    integrated = restitution_map("maxwell", num=6, method="integrate")
    assert integrated.path == "integrated"
    assert_rel(integrated.e, closed.e, 1e-8, "e")
    assert_rel(integrated.T, closed.T, 1e-9, "T")


@pytest.mark.slow
@pytest.mark.parametrize(
    "name",
    [n for n in ji.LAW_NAMES if n not in ("kelvin_voigt", "maxwell", "hertz_rate")],
)
def test_every_law_maps_without_failures(name):
    geometry = {k: 0.01 for k in ji.LAWS[name].geometry}  # a radius of 1 cm (JKR)
    fixed = {**ji.LAWS[name].map_fixed, **geometry} if geometry else None
    rmap = restitution_map(name, num=5, fixed=fixed)
    assert np.all(np.isfinite(rmap.e)) and np.all(np.isfinite(rmap.T))
    assert np.all((rmap.e >= 0) & (rmap.e <= 1)) and np.all(rmap.T > 0)


def test_a_law_with_geometry_needs_it_given():
    with pytest.raises(ValueError, match=r"needs its geometry held fixed: pass fixed=\{'R'"):
        restitution_map("jkr", num=3)
