"""Tangential laws: the table, `tangential_law`'s checks, stiffness and units."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
import pytest

import jaximpact as ji
from jaximpact._oblique import (
    TANGENTIAL_LAW_NAMES,
    TANGENTIAL_LAWS,
    AbstractTangentialLaw,
    LinearHistoryLaw,
    MindlinLaw,
    shear_modulus_star,
    tangential_law,
)


def test_table_names_and_histories():
    assert TANGENTIAL_LAW_NAMES == (
        "linear_history",
        "mindlin",
        "mindlin_force",
        "mindlin_rescale",
        "mindlin_rescale_force",
    )
    assert TANGENTIAL_LAWS["linear_history"].history == "displacement"
    assert TANGENTIAL_LAWS["mindlin"].history == "displacement"
    assert TANGENTIAL_LAWS["mindlin_force"].history == "force"
    assert TANGENTIAL_LAWS["mindlin_rescale"].history == "displacement"
    assert TANGENTIAL_LAWS["mindlin_rescale_force"].history == "force"
    assert [n for n, spec in TANGENTIAL_LAWS.items() if spec.rescaled] == [
        "mindlin_rescale",
        "mindlin_rescale_force",
    ]
    for spec in TANGENTIAL_LAWS.values():
        assert "mu" in spec.parameters and spec.engines and spec.reference


def test_a_rescaled_history_shrinks_with_the_contact_radius_on_unloading():
    """`stick_rate` adds `Q v / (2x)` where the overlap closes (`v < 0`), nothing while it
    opens, and each rescaled Mindlin law exports to LAMMPS's own model."""
    from jaximpact._engines.lammps.tangential import tangential_clause

    for name, history in (("mindlin_rescale", "displacement"), ("mindlin_rescale_force", "force")):
        tl = tangential_law(name, G_star=1e10, mu=0.2)
        plain = tangential_law(name.replace("_rescale", ""), G_star=1e10, mu=0.2)
        dyn = tl.dynamics(m=1e-3, R=1e-3, inertia=0.4, x_star=1e-6, v_n=1.0)
        base = plain.dynamics(m=1e-3, R=1e-3, inertia=0.4, x_star=1e-6, v_n=1.0)
        assert dyn.history == base.history == history
        q, x, u = 0.3, 0.25, 0.1
        assert float(dyn.stick_rate(q, x, u, 0.5)) == float(base.stick_rate(q, x, u, 0.5))
        shrink = float(dyn.stick_rate(q, x, u, -0.5) - base.stick_rate(q, x, u, -0.5))
        assert shrink == pytest.approx(q * -0.5 / (2 * x), rel=1e-15)
        # below RESCALE_FLOOR x* the state stops shrinking and the force takes what it owes
        from jaximpact._oblique.tangential import RESCALE_FLOOR

        tiny = 0.25 * RESCALE_FLOOR
        assert float(dyn.stick_rate(q, tiny, u, -0.5)) == float(base.stick_rate(q, tiny, u, -0.5))
        ratio = float(dyn.elastic(q, tiny)) / float(base.elastic(q, tiny))
        assert ratio == pytest.approx(0.5, rel=1e-14)  # (x / floor)^0.5
        assert float(dyn.elastic(q, x)) == float(base.elastic(q, x))  # above it, all of it
        held = dyn.held(1.0, 1e-6, tiny, 0.0)
        assert float(dyn.elastic(held, tiny)) == pytest.approx(-1e-6, rel=1e-12)
        lammps = "mindlin_rescale" if history == "displacement" else "mindlin_rescale/force"
        assert tangential_clause(tl) == f"tangential {lammps} 8e+10 0 0.2"


def test_linear_history_fields_are_fit_parameters():
    tl = tangential_law("linear_history", kt=1e7, mu=0.3)
    assert isinstance(tl, LinearHistoryLaw) and isinstance(tl, AbstractTangentialLaw)
    assert set(tl.params) == {"kt", "mu", "ct"}
    assert float(tl.ct) == 0.0 and float(tl.kt) == 1e7
    leaves = jax.tree_util.tree_leaves(eqx.filter(tl, eqx.is_inexact_array))
    assert len(leaves) == 3  # every parameter is an array an optimiser can update
    assert float(tl.stiffness(1e-6)) == 1e7
    assert float(tl.replace(mu=0.1).mu) == pytest.approx(0.1)


def test_mindlin_stiffness_and_shear_modulus():
    E, nu, R, x = 380e9, 0.23, 2.5e-3, 4e-6
    G = E / (2 * (1 + nu))
    tl = tangential_law("mindlin", G=G, nu=nu, mu=0.092)
    assert isinstance(tl, MindlinLaw) and tl.name == "mindlin"
    G_star = G / (2 - nu)  # a rigid plane
    assert float(tl.G_star) == pytest.approx(G_star, rel=1e-15)
    assert float(tl.stiffness(x, R=R)) == pytest.approx(8 * G_star * np.sqrt(R * x), rel=1e-14)
    # outside the surface: no stiffness, and no NaN gradient
    assert float(tl.stiffness(-1e-9, R=R)) == 0.0
    assert float(jax.grad(lambda x: tl.stiffness(x, R=R))(0.0)) == 0.0
    # a second body: 1/G* = (2 - nu)/G + (2 - nu2)/G2
    G2, nu2 = 70e9 / 2.5, 0.25
    two = tangential_law("mindlin_force", G=G, nu=nu, G2=G2, nu2=nu2, mu=0.092)
    expected = 1 / ((2 - nu) / G + (2 - nu2) / G2)
    assert float(two.G_star) == pytest.approx(expected, rel=1e-14)
    assert float(shear_modulus_star(G, nu, G2, nu2)) == pytest.approx(expected, rel=1e-14)
    assert two.history == "force"
    direct = tangential_law("mindlin", G_star=G_star, mu=0.092)
    assert set(direct.params) == {"G_star", "mu", "beta"} and float(direct.beta) == 0.0


def test_dynamics_scales():
    """K = k0 x*^(power + 2) / (m v_n^2), D = ct x* / (m v_n), 1/inertia."""
    m, R, v_n, x_star = 2.6e-4, 2.5e-3, 3.0, 1e-5
    tl = tangential_law("linear_history", kt=1e7, mu=0.2, ct=3.0)
    d = tl.dynamics(m=m, R=R, inertia=0.4, x_star=x_star, v_n=v_n)
    assert float(d.k0) == pytest.approx(1e7 * x_star**2 / (m * v_n**2))
    assert float(d.damping) == pytest.approx(3.0 * x_star / (m * v_n))
    assert float(d.inv_inertia) == pytest.approx(2.5)
    mind = tangential_law("mindlin", G_star=5e10, mu=0.2)
    d = mind.dynamics(m=m, R=R, inertia=0.4, x_star=x_star, v_n=v_n)
    X = 0.7
    k_si = float(mind.stiffness(X * x_star, R=R))
    assert float(d.stiffness(jnp.asarray(X))) == pytest.approx(k_si * x_star**2 / (m * v_n**2))


@pytest.mark.parametrize(
    "name, params, match",
    [
        ("coulomb", dict(mu=0.3), "unknown tangential law 'coulomb'"),
        ("linear_history", dict(kt=1e7, mu=-0.1), "mu must be a finite number >= 0"),
        ("linear_history", dict(kt=0.0, mu=0.1), "kt must be a finite number > 0"),
        ("linear_history", dict(kt=-1e7, mu=0.1), "kt must be a finite number > 0"),
        ("linear_history", dict(kt=1e7, mu=0.1, ct=-1.0), "ct must be a finite number >= 0"),
        ("linear_history", dict(kt=1e7, mu=0.1, G=1e9), "has no parameter G"),
        ("linear_history", dict(mu=0.1), "needs kt"),
        ("linear_history", dict(kt=1e7), "needs mu"),
        ("mindlin", dict(mu=0.1), "needs G .* and nu, or G_star"),
        ("mindlin", dict(G_star=1e9, G=1e9, nu=0.3, mu=0.1), "give G_star or G and nu"),
        ("mindlin", dict(G=1e9, nu=0.7, mu=0.1), r"Poisson's ratio nu must lie in \(-1, 0.5\)"),
        ("mindlin", dict(G=-1e9, nu=0.3, mu=0.1), "shear modulus G must be a finite number > 0"),
        ("mindlin", dict(G=1e9, nu=0.3, nu2=0.2, mu=0.1), "nu2 without G2"),
        ("mindlin", dict(G_star=1e9, mu=float("nan")), "mu must be a finite number"),
    ],
)
def test_bad_input_is_one_line(name, params, match):
    with pytest.raises(ValueError, match=match) as info:
        tangential_law(name, **params)
    assert "\n" not in str(info.value)


def test_a_modulus_without_its_poisson_ratio_takes_0_3_and_says_so():
    """DESIGN.md's call `tangential_law("mindlin", G=3e10, mu=0.3)`: G* = G / (2 - 0.3), a
    warning naming nu; with a second body each ratio not given alike."""
    with pytest.warns(UserWarning, match="nu not given, taken as 0.3"):
        tl = tangential_law("mindlin", G=3e10, mu=0.3)
    assert float(tl.params["G_star"]) == pytest.approx(3e10 / 1.7, rel=1e-15)
    with pytest.warns(UserWarning, match="nu2 not given"):
        two = tangential_law("mindlin", G=3e10, nu=0.25, G2=7e10, mu=0.3)
    assert float(two.params["G_star"]) == pytest.approx(1 / (1.75 / 3e10 + 1.7 / 7e10), rel=1e-14)


def test_bad_types_and_replace():
    with pytest.raises(TypeError, match="must be a number"):
        tangential_law("linear_history", kt="stiff", mu=0.1)
    tl = tangential_law("linear_history", kt=1e7, mu=0.1)
    with pytest.raises(ValueError, match="has no parameter G_star"):
        tl.replace(G_star=1.0)
    with pytest.raises(ValueError, match="mu must be a finite number >= 0"):
        tl.replace(mu=-1.0)


def test_checks_survive_jit():
    """A negative mu only known at run time is refused by `eqx.error_if`."""

    @jax.jit
    def build(mu):
        return tangential_law("linear_history", kt=1e7, mu=mu).mu

    assert float(build(0.2)) == pytest.approx(0.2)
    with pytest.raises(Exception, match="mu must be a finite number >= 0"):
        build(-0.2).block_until_ready()


def test_normal_law_is_not_tangential():
    assert not isinstance(ji.law("hertz_rate", c=1e9, b1=0.0), AbstractTangentialLaw)
