"""Exports without the engines: each engine's design hits its targets through its replica
of the engine's stepping, what it cannot realise is refused in one line, the continuous laws
it names meet the engines' documented forces (an independent scipy integration), and the
engines are declared through one interface and one registry."""

import math

import numpy as np
import pytest

import jaximpact as ji
from jaximpact._engines.drake import normal as drake_engine
from jaximpact._engines.liggghts import normal as liggghts_engine
from jaximpact._engines.mujoco import solref as mujoco_engine
from jaximpact._engines.base import Scene
from jaximpact._engines.export import ENGINES
from jaximpact._engines.response import engine_response, stepped_response

SOLREF = ENGINES["mujoco"].NORMAL["kelvin_voigt"]  # MuJoCo's normal model
UNIT = Scene(m=1.0, v0=1.0, radius=None, geometry="wall")
WALL_M, WALL_R = 0.004, 0.005


def test_mujoco_replica_tends_to_the_exact_force_criterion_impact():
    """At 20000 steps per contact the replica of MuJoCo's Euler step is the exact linear
    spring-dashpot under the force criterion (closed form) to first order in the step."""
    zeta, w0 = 0.3, 1000.0
    exact = ji.closed_forms.kelvin_voigt(w0**2, 2 * zeta * w0, 1.0, 1.0, "force")
    h = float(exact["T"]) / 20000
    e, T = mujoco_engine.replica((1.0 / (w0 * zeta), zeta), h, 1.0)
    assert np.all(np.abs(e / float(exact["e"]) - 1) < 1e-4)
    assert np.all(np.abs(T / float(exact["T"]) - 1) < 2e-4)


def test_mujoco_refsafe_raises_timeconst():
    """timeconst below two steps acts as 2 steps (standard form), never in direct form."""
    k, b = mujoco_engine.effective((1e-4, 1.0), 1e-3)
    assert k == pytest.approx(1.0 / (2e-3) ** 2) and b == pytest.approx(2.0 / 2e-3)
    assert mujoco_engine.effective((-5.0, -2.0), 1e-3) == (5.0, 2.0)


@pytest.mark.parametrize("e, T", [(0.75, 0.01), (0.3, 2e-3)])
def test_mujoco_design_hits_targets_through_the_replica(e, T):
    out = SOLREF.design(e, T, UNIT)
    assert abs(out.e / e - 1) < 1e-3 and abs(out.T / T - 1) < 2e-3
    lo, hi = out.e_range
    assert lo <= out.e <= hi and (hi - lo) / 2 < 0.005 * e
    tc, dr = out.parameters["solref"]
    assert tc >= 2 * out.parameters["timestep"] and dr == pytest.approx(out.parameters["dampratio"])


def test_mujoco_coarse_step_is_warned():
    out = SOLREF.design(0.5, 2e-3, UNIT, timestep=2e-4)
    assert any("steps per contact" in w or "refsafe" in w for w in out.warnings)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        (dict(engine="bullet", e=0.5, T=1e-3), "unknown engine 'bullet'"),
        (dict(engine="lammps", e=0.5, T=1e-3), "radius"),
        (dict(engine="mujoco", e=1.5, T=1e-3), r"\(0, 1\]"),
        (dict(engine="mujoco", e=0.0, T=1e-3), r"\(0, 1\]"),
        (dict(engine="mujoco", e=0.5, T=-1.0), "T must be"),
        (dict(engine="mujoco", e=0.5, T=1e-3, m=0.0), "m must be"),
        (dict(engine="lammps", e=0.5, T=1e-3, radius=0.01, poisson=0.6), r"\(-1, 0.5\)"),
        (dict(engine="lammps", e=0.1, T=1e-3, radius=0.01, limit_damping=True), "limit_damping"),
        (dict(engine="drake", e=0.5), "duration"),
    ],
)
def test_export_rejects_bad_input_in_one_line(kwargs, match):
    kwargs = {"m": 0.05, "v0": 1.0, **kwargs}
    engine = kwargs.pop("engine")
    with pytest.raises(ValueError, match=match) as info:
        ji.export(None, engine, **kwargs)
    assert "\n" not in str(info.value)


def test_export_from_targets_mujoco():
    x = ji.export(None, "mujoco", m=0.05, v0=1.0, e=0.6, T=5e-3, curves=False)
    assert abs(x.e / 0.6 - 1) < 1e-3 and abs(x.T / 5e-3 - 1) < 2e-3
    assert len(x.parameters["solref"]) == 2 and len(x.parameters["solimp"]) == 5
    assert x.timestep == x.parameters["timestep"] > 0
    assert 'solref="' in x.snippet and "timestep" in x.snippet


def test_engine_e_stepped_response_converges_to_the_continuous_law():
    """LAMMPS's velocity-Verlet replica at a fine step gives the continuous law's e and T
    (jaximpact's solver, another code path) to 1e-4; a coarse step departs further; Drake's
    discrete solver is not modelled (None), nor a LAMMPS input without a timestep."""
    params = {"E": 1e7, "coeff_restitution": 0.5, "poisson": 0.3}
    _, _, e, T = engine_response("lammps", params, m=0.05, speeds=[1.0, 2.0], radius=0.01)
    errors = []
    for h in (1e-6, 5e-5):
        stepped = stepped_response(
            "lammps", {**params, "timestep": h}, m=0.05, speeds=[1.0, 2.0], radius=0.01
        )
        assert stepped[0] == h
        errors.append(max(abs(a / b - 1) for a, b in zip(stepped[1], e, strict=True)))
        assert all(
            lo <= mid <= hi for lo, mid, hi in zip(stepped[3], stepped[1], stepped[4], strict=True)
        )
    assert errors[0] < 1e-4 < errors[1]
    assert stepped_response("lammps", params, m=0.05, speeds=[1.0], radius=0.01) is None
    drake_params = {"point_contact_stiffness": 1e5, "hunt_crossley_dissipation": 0.2}
    assert stepped_response("drake", drake_params, m=1.0, speeds=[1.0]) is None


def _documented_hertz_impact(E, nu, restitution, *, m, radius, v0, clamp, ground_mass=None):
    """Two equal spheres under the Hertz law with restitution-based damping as LIGGGHTS
    (gran_model_hertz doc) and Chrono (ChContactSMC.h) write it, integrated by scipy:
    `F = 4/3 Y* sqrt(R* d) d + 2 sqrt(5/6) (-beta) sqrt(S_n m*) v`, `S_n = 2 Y* sqrt(R* d)`,
    clamped at 0 when `clamp`. Returns `(e, T)`, T while the force is positive (clamped) or
    while the spheres overlap. With `ground_mass` (kg): one sphere on a fixed flat ground of
    its material of that mass (`R* = R`, the damping's `m* = m M/(m + M)` as Chrono forms
    it, the sphere moving with its own mass m)."""
    from scipy.integrate import solve_ivp

    Y = E / (2 * (1 - nu**2))
    R, mass = radius / 2, m / 2
    damping_mass = mass
    if ground_mass is not None:
        R, mass = radius, m
        damping_mass = m if math.isinf(ground_mass) else m * ground_mass / (m + ground_mass)
    beta = math.log(restitution) / math.sqrt(math.log(restitution) ** 2 + math.pi**2)

    def raw_force(d, v):
        Sn = 2 * Y * math.sqrt(R * max(d, 0.0))
        return 2.0 / 3.0 * Sn * d - 2 * math.sqrt(5 / 6) * beta * math.sqrt(Sn * damping_mass) * v

    def force(d, v):
        f = raw_force(d, v)
        return max(f, 0.0) if clamp else f

    def rhs(t, y):
        return [y[1], -force(y[0], y[1]) / mass]

    t_scale = (mass * v0**2 / (4 / 3 * Y * math.sqrt(R))) ** 0.4 / v0

    def end(t, y):
        return raw_force(y[0], y[1]) if clamp and t > 1e-3 * t_scale else y[0]

    end.terminal, end.direction = True, -1
    sol = solve_ivp(
        rhs,
        (0, 100 * t_scale),
        [0.0, v0],
        method="DOP853",
        rtol=1e-12,
        atol=[1e-14 * v0 * t_scale, 1e-14 * v0],
        events=end,
    )
    return -sol.y_events[0][0][1] / v0, sol.t_events[0][0]


@pytest.mark.parametrize("e", [0.3, 0.8])
def test_liggghts_and_chrono_exports_meet_their_documented_laws(e):
    """The exported Young's modulus and restitution, fed to the engines' documented force
    (an independent scipy integration), give the asked e and T: LIGGGHTS (overlap ends the
    contact: the coefficient is the e) to 1e-7; Chrono (force clamped at 0: the export
    inverts it) to 1e-6; each export's promise within 0.5 % of the target."""
    m, radius, v0, T = 0.004, 0.005, 1.0, 1e-3
    x = ji.export(None, "liggghts", m=m, v0=v0, e=e, T=T, radius=radius, curves=False)
    got_e, got_T = _documented_hertz_impact(
        x.parameters["youngs_modulus"],
        0.3,
        x.parameters["coeff_restitution"],
        m=m,
        radius=radius,
        v0=v0,
        clamp=False,
    )
    assert abs(got_e - e) < 1e-7 and abs(got_T / T - 1) < 1e-7
    assert abs(x.e / e - 1) < 0.005 and "coefficientRestitution" in x.snippet
    y = ji.export(None, "chrono", m=m, v0=v0, e=e, T=T, radius=radius, curves=False)
    got_e, got_T = _documented_hertz_impact(
        y.parameters["SetYoungModulus"],
        0.3,
        y.parameters["SetRestitution"],
        m=m,
        radius=radius,
        v0=v0,
        clamp=True,
    )
    assert abs(got_e - e) < 1e-6 and abs(got_T / T - 1) < 1e-6
    assert y.parameters["SetRestitution"] < e  # the clamp raises e: a lower cr is asked
    assert any("not replicated" in w for w in y.warnings)


def test_chrono_cannot_go_below_its_clamped_floor():
    with pytest.raises(ValueError, match="cannot realise e = 0.05"):
        ji.export(None, "chrono", m=0.004, v0=1.0, e=0.05, T=1e-3, radius=0.005)


def test_yade_export_inverts_its_clamped_law():
    """Yade's ViscElMat keeps the force non-attractive: `en` is not the e realised, so the
    export asks for a lower `en`; the continuous law it names (kelvin_voigt with kn, cn,
    separation by force) gives the target, and e <= exp(-2) is refused in one line."""
    x = ji.export(None, "yade", m=0.01, v0=1.0, e=0.5, T=1e-3, radius=0.01, curves=False)
    assert x.parameters["en"] < 0.5 and x.parameters["NewtonIntegrator_damping"] == 0.0
    law = ENGINES["yade"].NORMAL["kelvin_voigt"].law(x.parameters, 0.01)
    r = ji.impact(law, m=0.005, v0=1.0, separation="force")
    assert abs(float(r.e) / 0.5 - 1) < 1e-6 and abs(float(r.T) / 1e-3 - 1) < 1e-6
    assert "NewtonIntegrator(damping=0.0)" in x.snippet
    with pytest.raises(ValueError, match=r"cannot realise e = 0.1.*exp\(-2\)"):
        ji.export(None, "yade", m=0.01, v0=1.0, e=0.1, T=1e-3, radius=0.01)


def test_liggghts_refuses_what_its_sanity_checks_refuse():
    with pytest.raises(ValueError, match="coefficientRestitution <= 0.05"):
        ji.export(None, "liggghts", m=0.004, v0=1.0, e=0.02, T=1e-3, radius=0.005)
    assert liggghts_engine.particle_range_line(2e11) == "hard_particles yes"
    assert liggghts_engine.particle_range_line(1e6) == "soft_particles yes"
    assert liggghts_engine.particle_range_line(1e8) is None


def test_drake_discrete_replica_converges_and_is_stepped_by_engine_e():
    """The discrete replica tends to the continuous plant's closed-form e as the step
    shrinks (another code path: `hunt_crossley_restitution`), and `stepped_response` gives
    it for parameters with a `time_step`."""
    x = ji.export(None, "drake", m=1.0, v0=1.0, e=0.6, T=0.01, curves=False)
    gaps = []
    for h in (1e-4, 1e-5, 1e-6):
        es, Ts = drake_engine.replica(x.parameters, 1.0, 1.0, h)
        gaps.append(abs(es.mean() / x.e - 1))
    # first order in the step: 3.6 %, 0.36 %, 0.037 %
    assert 8 < gaps[0] / gaps[1] < 12 and 8 < gaps[1] / gaps[2] < 12 and gaps[2] < 1e-3
    stepped = stepped_response("drake", {**x.parameters, "time_step": 1e-4}, m=1.0, speeds=[1.0])
    assert stepped[0] == 1e-4 and stepped[1][0] == pytest.approx(
        drake_engine.replica(x.parameters, 1.0, 1.0, 1e-4)[0].mean(), rel=1e-12
    )


@pytest.mark.parametrize(
    "engine, kwargs",
    [
        ("mujoco", {}),
        ("drake", {"timestep": 2e-4}),
        ("drake", {}),
        ("lammps", {"radius": 0.01}),
        ("liggghts", {"radius": 0.01, "limit_damping": True}),
        ("yade", {"radius": 0.01}),
        ("chrono", {"radius": 0.01}),
    ],
)
def test_export_curve_at_v0_is_the_promise(engine, kwargs):
    """The engine's e(v) that export gives is what it promises at v0: its stepping where
    replicated (MuJoCo, Drake discrete, LAMMPS, LIGGGHTS, Yade), else the continuous law
    (Drake's continuous plant; Chrono), to 1e-6."""
    x = ji.export(None, engine, m=1.0, v0=1.0, e=0.7, T=0.02, **kwargs)
    assert x.speeds[3] == 1.0
    assert x.e_engine[3] == pytest.approx(x.e, rel=1e-6)
    assert x.T_engine[3] == pytest.approx(x.T, rel=1e-6)


@pytest.mark.parametrize("engine", ["lammps", "liggghts", "yade", "chrono"])
def test_wall_geometry_leaves_the_default_export_unchanged(engine):
    """geometry="spheres" is the default, bit for bit; "wall" is another scene with other
    parameters; an unknown geometry, or "spheres" for a body-on-plane engine, is refused in
    one line, and MuJoCo's and Drake's scene is already the wall."""
    kwargs = dict(m=WALL_M, v0=1.0, radius=WALL_R, e=0.6, T=1e-3)
    default = ji.export(None, engine, **kwargs)
    spheres = ji.export(None, engine, geometry="spheres", **kwargs)
    assert default.to_dict() == spheres.to_dict()
    assert "geometry" not in default.parameters
    wall = ji.export(None, engine, geometry="wall", **kwargs)
    assert wall.parameters["geometry"] == "wall" and "wall" in wall.scene
    assert wall.snippet != default.snippet
    with pytest.raises(ValueError, match="not 'plate'") as info:
        ji.export(None, engine, geometry="plate", **kwargs)
    assert "\n" not in str(info.value)
    mujoco = ji.export(None, "mujoco", m=0.05, v0=1.0, e=0.6, T=1e-2, curves=False)
    assert (
        ji.export(
            None, "mujoco", m=0.05, v0=1.0, e=0.6, T=1e-2, curves=False, geometry="wall"
        ).to_dict()
        == mujoco.to_dict()
    )
    with pytest.raises(ValueError, match="not 'spheres'"):
        ji.export(None, "drake", m=0.05, v0=1.0, e=0.6, T=1e-2, geometry="spheres")


@pytest.mark.parametrize("limit_damping", [False, True])
def test_lammps_wall_export_is_the_sphere_on_a_flat(limit_damping):
    """fix wall/gran takes the sphere's own mass and radius and E* = E/(2 (1 - nu^2)) (the
    wall of the sphere's material): the exported E gives c = hertz_stiffness(E, nu, R), the
    Tsuji law on mass m realises the target (continuous), the snippet carries the same
    model on the wall, and e(v) at v0 is the promise. The same dimensionless contact as
    the pair: the promise equals the two-sphere export's."""
    kwargs = dict(m=WALL_M, v0=1.0, radius=WALL_R, e=0.5, T=5e-4, limit_damping=limit_damping)
    x = ji.export(None, "lammps", geometry="wall", **kwargs)
    p = x.parameters
    assert p["k"] == pytest.approx(
        ji.hertz_stiffness(E=p["youngs_modulus"], nu=0.3, R=WALL_R), rel=1e-12
    )
    model = p["pair_coeff"].removeprefix("pair_coeff * * ")
    assert p["fix_wall"] == f"fix wall all wall/gran granular {model} zplane 0.0 NULL"
    assert p["fix_wall"] in x.snippet.splitlines()
    r = ji.impact(x.law, m=WALL_M, v0=1.0, separation=x.separation)
    assert float(r.e) == pytest.approx(0.5, rel=1e-6)
    assert float(r.T) == pytest.approx(5e-4, rel=1e-6)
    assert x.e_engine[3] == pytest.approx(x.e, rel=1e-6)
    pair = ji.export(None, "lammps", **kwargs)
    assert x.e == pytest.approx(pair.e, rel=1e-9) and x.T == pytest.approx(pair.T, rel=1e-9)
    assert x.timestep == pair.timestep
    # engine-e on the wall parameters: the same law and stepping
    params = {
        "E": p["youngs_modulus"],
        "coeff_restitution": p["coeff_restitution"],
        "limit_damping": limit_damping,
        "geometry": "wall",
    }
    _, _, e_back, T_back = engine_response("lammps", params, m=WALL_M, speeds=[1.0], radius=WALL_R)
    assert e_back[0] == pytest.approx(0.5, rel=1e-6) and T_back[0] == pytest.approx(5e-4, rel=1e-6)
    stepped = stepped_response(
        "lammps", {**params, "timestep": x.timestep}, m=WALL_M, speeds=[1.0], radius=WALL_R
    )
    assert stepped[1][0] == pytest.approx(x.e, rel=1e-12)


def test_yade_wall_export_uses_yades_mass_convention():
    """A wall of mass 0 gets massR = m/2 in Yade, acting on the sphere's mass m: the export
    inverts that (kelvin_voigt with Yade's kn, cn on mass m gives the target), and what
    the clamped law cannot reach on a wall (e <= 0.2079) is refused in one line."""
    x = ji.export(None, "yade", m=0.01, v0=1.0, e=0.5, T=1e-3, radius=0.01, geometry="wall")
    law = ENGINES["yade"].NORMAL["kelvin_voigt"].law(x.parameters, 0.01)
    r = ji.impact(law, m=0.01, v0=1.0, separation="force")
    assert float(r.e) == pytest.approx(0.5, rel=1e-6)
    assert float(r.T) == pytest.approx(1e-3, rel=1e-6)
    pair = ji.export(None, "yade", m=0.01, v0=1.0, e=0.5, T=1e-3, radius=0.01)
    assert x.parameters["en"] < pair.parameters["en"]  # more damping asked of massR = m/2
    assert "utils.wall(" in x.snippet and "Ig2_Wall_Sphere_ScGeom()" in x.snippet
    assert x.e_engine[3] == pytest.approx(x.e, rel=1e-6) and abs(x.e / 0.5 - 1) < 0.005
    with pytest.raises(ValueError, match="e = 0.2 on a wall of mass 0.*0.2079") as info:
        ji.export(None, "yade", m=0.01, v0=1.0, e=0.2, T=1e-3, radius=0.01, geometry="wall")
    assert "\n" not in str(info.value)


@pytest.mark.parametrize("e", [0.3, 0.8])
def test_liggghts_and_chrono_wall_exports_meet_their_documented_laws(e):
    """The wall exports fed to the documented force on a sphere against a flat of its
    material (R* = R; Chrono's damping mass m M/(m + M) with its heavy ground): the target
    e and T, LIGGGHTS to 1e-7 and Chrono to 1e-6."""
    m, radius, v0, T = WALL_M, WALL_R, 1.0, 1e-3
    x = ji.export(
        None, "liggghts", m=m, v0=v0, e=e, T=T, radius=radius, geometry="wall", curves=False
    )
    got_e, got_T = _documented_hertz_impact(
        x.parameters["youngs_modulus"],
        0.3,
        x.parameters["coeff_restitution"],
        m=m,
        radius=radius,
        v0=v0,
        clamp=False,
        ground_mass=math.inf,
    )
    assert abs(got_e - e) < 1e-7 and abs(got_T / T - 1) < 1e-7
    assert "primitive type 1 zplane 0.0" in x.parameters["fix_wall"]
    y = ji.export(
        None, "chrono", m=m, v0=v0, e=e, T=T, radius=radius, geometry="wall", curves=False
    )
    got_e, got_T = _documented_hertz_impact(
        y.parameters["SetYoungModulus"],
        0.3,
        y.parameters["SetRestitution"],
        m=m,
        radius=radius,
        v0=v0,
        clamp=True,
        ground_mass=y.parameters["ground_mass"],
    )
    assert abs(got_e - e) < 1e-6 and abs(got_T / T - 1) < 1e-6
    assert y.parameters["effective_curvature_radius"] == radius
    assert f"ground.SetMass({y.parameters['ground_mass']:.10g})" in y.snippet


# ------------------------------------------------- one interface, one registry (issue 25)


def test_every_engine_is_a_final_class_declaring_its_facts():
    """The registry holds one instance of each engine's final class, under its NAME; each
    declares its facts (the scene is two spheres exactly where TWO_SPHERES says) and its
    tables of final normal and tangential models, each declaring its own facts; a law of
    the normal table exports to its row."""
    from jaximpact._engines.base import (
        FACTS,
        NORMAL_FACTS,
        TANGENTIAL_FACTS,
        AbstractEngine,
        AbstractNormalModel,
        AbstractTangentialModel,
        Key,
        scene_geometry,
    )

    assert list(ENGINES) == ["mujoco", "lammps", "drake", "liggghts", "chrono", "yade"]
    for name, engine in ENGINES.items():
        assert isinstance(engine, AbstractEngine) and type(engine).__bases__ == (AbstractEngine,)
        assert engine.NAME == name and all(hasattr(engine, fact) for fact in FACTS)
        assert set(engine.SCENES) <= {"spheres", "wall"}
        assert engine.TWO_SPHERES == ("spheres" in engine.SCENES)
        assert scene_geometry(engine, None) == next(iter(engine.SCENES))
        for law, model in engine.NORMAL.items():
            assert isinstance(model, AbstractNormalModel) and model.LAW == law
            assert type(model).__bases__ == (AbstractNormalModel,)
            assert all(hasattr(model, fact) for fact in NORMAL_FACTS)
            names = [key.name for key in model.KEYS]
            assert len(set(names)) == len(names) and all(isinstance(k, Key) for k in model.KEYS)
            assert names[: sum(k.needed for k in model.KEYS)] == [
                k.name for k in model.KEYS if k.needed
            ]
        assert set(engine.TANGENTIAL) <= set(ji.TANGENTIAL_LAW_NAMES)
        for model in engine.TANGENTIAL.values():
            assert isinstance(model, AbstractTangentialModel)
            assert type(model).__bases__ == (AbstractTangentialModel,)
            assert all(hasattr(model, fact) for fact in TANGENTIAL_FACTS)
            assert set(engine.SCENES) <= set(model.CONTACT_POINT)
        assert engine.KEYS == next(iter(engine.NORMAL.values())).KEYS
    x = ji.export(None, "lammps", m=0.01, v0=1.0, e=0.5, T=1e-3, radius=0.01, curves=False)
    assert x.law.name == next(iter(ENGINES["lammps"].NORMAL))


def test_engines_are_abstract_or_final():
    from jaximpact._engines.base import AbstractEngine, AbstractNormalModel
    from jaximpact._engines.mujoco.engine import Mujoco
    from jaximpact._engines.mujoco.normal import Solref

    for abstract in (AbstractEngine, AbstractNormalModel):
        with pytest.raises(TypeError):
            abstract()
    for final in (Mujoco, Solref):
        with pytest.raises(TypeError, match="final"):
            type("Derived", (final,), {})
    with pytest.raises(TypeError, match="does not declare"):

        class Undeclared(AbstractEngine):
            NAME = "undeclared"


def test_design_and_stepping_are_named_records():
    """`design` gives a `Design`, `stepper` a `Stepping` (or None where the step does not
    apply): named fields, not a dict and a tuple."""
    from jaximpact._engines.base import Design, Stepping

    out = SOLREF.design(0.6, 5e-3, UNIT)
    assert isinstance(out, Design) and out.separation == "force" and out.stepping is not None
    stepping = SOLREF.stepper(out.stepping, m=1.0)
    assert isinstance(stepping, Stepping) and stepping.timestep == out.timestep
    es, _ = stepping.run(1.0)
    assert es.mean() == pytest.approx(out.e, rel=1e-12)
    chrono = ENGINES["chrono"].NORMAL["tsuji"]
    assert chrono.stepper({"E": 1e7, "coeff_restitution": 0.5}, m=1.0) is None
    drake_params = {"point_contact_stiffness": 1e5, "hunt_crossley_dissipation": 0.2}
    assert ENGINES["drake"].NORMAL["point_contact"].stepper(drake_params, m=1.0) is None


def _toy_engine():
    """An engine written as docs/layout.md's recipe says: a linear spring-dashpot on a plane
    whose force never pulls (`kelvin_voigt`, separation by force), its continuous law only:
    one normal model in its `NORMAL` table, no tangential model."""
    from jaximpact._engines.base import AbstractEngine, AbstractNormalModel, Design, Key

    class SpringDashpot(AbstractNormalModel):
        NAME = "spring-dashpot"
        LAW = "kelvin_voigt"
        KEYS = (Key("k", "N/m"), Key("c", "N s/m"))
        STEPPING = "not replicated: the continuous law's e and T"
        MASS_DEPENDS = "its k and c scale with the mass"
        ALLOWS_LIMIT_DAMPING = True
        NEAREST = "its kelvin_voigt law"
        SCENES = None

        def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False):
            zeta = mujoco_engine.dampratio_for(e)
            realised_e, tau = mujoco_engine.continuous(zeta)
            w0 = tau / T
            parameters = {"k": scene.m * w0**2, "c": 2 * zeta * w0 * scene.m}
            return Design(parameters, e=realised_e, T=T, timestep=0.0, separation="force")

        def law_parameters(self, parameters, m):
            return {"c": parameters["k"], "b": parameters["c"]}

        def response(self, parameters, *, m, radius=None):
            return self.law(parameters, m), "force"

        def stepper(self, parameters, *, m, radius=None):
            return None

    class Toy(AbstractEngine):
        NAME = "toy"
        LABEL = "Toy"
        SCENES = {"wall": "a body of mass m on a plane at v0"}
        TWO_SPHERES = False
        CONTINUOUS_PLANT = True
        NORMAL = {"kelvin_voigt": SpringDashpot()}
        TANGENTIAL = {}

        def snippet(self, parameters):
            return f"k = {parameters['k']!r}\nc = {parameters['c']!r}"

    return Toy()


def test_a_new_engine_is_one_class_and_one_registry_entry(monkeypatch, capsys):
    """Registered in `ENGINES` alone, an engine is exported by `ji.export`, named by the
    command line's help and taken by `jaximpact export` and `engine-e`."""
    import json

    from jaximpact._cli import main

    monkeypatch.setitem(ENGINES, "toy", _toy_engine())
    x = ji.export(None, "toy", m=0.1, v0=1.0, e=0.6, T=1e-3)
    r = ji.impact(x.law, m=0.1, v0=1.0, separation=x.separation)
    assert float(r.e) == pytest.approx(0.6, rel=1e-6) and x.e_engine[3] == pytest.approx(x.e)
    assert x.scene == "a body of mass m on a plane at v0" and x.snippet.startswith("k = ")
    with pytest.raises(SystemExit):
        main(["export", "--help"])
    assert "Toy" in capsys.readouterr().out
    main(["export", "toy", "--e", "0.6", "--T", "1e-3", "--mass", "0.1", "--v0", "1", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert out["parameters"] == x.parameters
    params = json.dumps({"k": out["parameters"]["k"], "c": out["parameters"]["c"]})
    main(
        [
            "engine-e",
            "--engine",
            "toy",
            "--params",
            params,
            "--mass",
            "0.1",
            "--speed",
            "1",
            "--json",
        ]
    )
    assert json.loads(capsys.readouterr().out)["e"][0] == pytest.approx(0.6, rel=1e-6)
    with pytest.raises(SystemExit):
        main(["export", "toy", "--e", "0.6", "--T", "1e-3", "--v0", "1"])
    assert "toy needs the mass: give --mass (kg); its k and c scale" in capsys.readouterr().err
