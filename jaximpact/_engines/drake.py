"""Drake: point contact in a continuous MultibodyPlant (`time_step = 0`), `f = k x (1 + d v)`.

Drake's docs (multibody "Contact Modeling", `drake::multibody::CoulombFriction` and
`geometry::AddContactMaterial`: `point_contact_stiffness` k (N/m), `hunt_crossley_dissipation`
d (s/m)) give the normal force of point contact as `f = k x (1 + d v)`, clamped to be
non-negative: Hunt & Crossley with n = 1 (law `point_contact`). Its restitution depends on
`d v0` alone (`closed_forms.hunt_crossley_restitution`), so it changes with the impact speed:
an export is exact at the `v0` it was made for. Drake documents no d-from-e formula. Two
geometries combine as springs in series, `k = k1 k2 / (k1 + k2)`,
`d = (k2 d1 + k1 d2) / (k1 + k2)`: giving both the body and the ground `2k` and `d` yields
`k` and `d`. A discrete plant (`time_step > 0`) adds numerical dissipation (TAMSI, Lagged,
Similar) or ignores d (SAP); the promise is for the continuous plant.
"""

import math

import numpy as np
from scipy.optimize import brentq

NAME = "drake"
SCENE = (
    "a body of mass m on a fixed half space (both geometries with the exported properties), "
    "no gravity, approaching along the normal at v0, continuous plant (time_step = 0)"
)


def _tau(alpha: float) -> float:
    """The duration of `m x'' = -k x (1 + D v)` at `k = m = v0 = 1`, `D = alpha` (units of
    `sqrt(m/k)`), from jaximpact's solver."""
    from .._laws import law
    from .._solve.impact import impact

    return float(impact(law("point_contact", c=1.0, d=alpha), m=1.0, v0=1.0).T)


def alpha_for(e: float) -> float:
    from ..closed_forms import hunt_crossley_restitution

    if e >= 1.0:
        return 0.0
    f = lambda a: float(hunt_crossley_restitution(a)) - e  # noqa: E731
    hi = 1.0
    while f(hi) > 0:
        hi *= 4.0
        if hi > 1e12:
            raise ValueError(f"Drake's point contact cannot realise e = {e:g}")
    return brentq(f, 0.0, hi, xtol=1e-15, rtol=1e-13)


def design(e, T, *, m, v0, timestep=None):
    from ..closed_forms import hunt_crossley_restitution

    warnings = []
    alpha = alpha_for(e)
    d = alpha / v0
    k = m * (_tau(alpha) / T) ** 2
    if timestep:
        steps = T / timestep
        warnings.append(
            f"a discrete plant (time_step {timestep:.3g} s, {steps:.0f} steps per contact) adds "
            "its own dissipation: measured with TAMSI, Lagged and Similar, e came out 36 % low "
            "at 10 steps per contact, 11 % at 40, 4.6 % at 100, 0.5 % at 1000 "
            "(benchmarks/drake_discrete.md); SAP ignores hunt_crossley_dissipation (e near 0 "
            "there). The promised e and T are for time_step = 0"
        )
    parameters = {
        "point_contact_stiffness": k,
        "hunt_crossley_dissipation": d,
        "time_step": 0.0,
        "per_geometry": {"point_contact_stiffness": 2.0 * k, "hunt_crossley_dissipation": d},
        "contact_model": "point",
    }
    return dict(
        parameters=parameters,
        e=float(hunt_crossley_restitution(alpha)),
        T=float(_tau(alpha) * math.sqrt(m / k)),
        e_range=None,
        T_range=None,
        steps_per_contact=None,
        warnings=warnings,
    )


def snippet(parameters) -> str:
    per = parameters["per_geometry"]
    return (
        "from pydrake.geometry import AddContactMaterial, ProximityProperties\n"
        "props = ProximityProperties()\n"
        f"AddContactMaterial(dissipation={per['hunt_crossley_dissipation']!r}, "
        f"point_stiffness={per['point_contact_stiffness']!r}, properties=props)\n"
        "# give these props to BOTH geometries in contact (they combine in series)\n"
        "plant = MultibodyPlant(time_step=0.0)  # continuous: the promise holds\n"
        "plant.set_contact_model(ContactModel.kPoint)"
    )


def law(parameters, m: float):
    from .._laws import law as make_law

    return make_law(
        "point_contact",
        c=parameters["point_contact_stiffness"],
        d=parameters["hunt_crossley_dissipation"],
    )


def simulate(parameters, *, m, v0, radius=0.01, time_step=0.0, accuracy=1e-10, approximation=None):
    """Run Drake: a sphere (mass `m`, radius `radius`) onto a half space, gravity off.
    Returns `(e, T)`, T from the contact force's first and last non-zero sample (continuous
    plant: dense sampling through the integrator's steps). `time_step > 0`: a discrete plant,
    with `approximation` (`"tamsi"`, `"sap"`, `"lagged"`, `"similar"`; None: Drake's
    default)."""
    from pydrake.geometry import AddContactMaterial, HalfSpace, ProximityProperties, Sphere
    from pydrake.math import RigidTransform
    from pydrake.multibody.plant import (
        AddMultibodyPlantSceneGraph,
        ContactModel,
        CoulombFriction,
    )
    from pydrake.multibody.tree import SpatialInertia, UnitInertia
    from pydrake.systems.analysis import Simulator
    from pydrake.systems.framework import DiagramBuilder

    per = parameters["per_geometry"]
    builder = DiagramBuilder()
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=time_step)
    plant.set_contact_model(ContactModel.kPoint)
    if approximation is not None:
        from pydrake.multibody.plant import DiscreteContactApproximation

        plant.set_discrete_contact_approximation(
            getattr(DiscreteContactApproximation, "k" + approximation.capitalize())
        )
    props = ProximityProperties()
    AddContactMaterial(
        dissipation=per["hunt_crossley_dissipation"],
        point_stiffness=per["point_contact_stiffness"],
        friction=CoulombFriction(0.0, 0.0),
        properties=props,
    )
    body = plant.AddRigidBody(
        "ball", SpatialInertia(m, np.zeros(3), UnitInertia.SolidSphere(radius))
    )
    plant.RegisterCollisionGeometry(body, RigidTransform(), Sphere(radius), "ball", props)
    plant.RegisterCollisionGeometry(
        plant.world_body(),
        HalfSpace.MakePose([0, 0, 1], [0, 0, 0]),
        HalfSpace(),
        "ground",
        props,
    )
    plant.mutable_gravity_field().set_gravity_vector([0, 0, 0])
    plant.Finalize()
    diagram = builder.Build()
    simulator = Simulator(diagram)
    context = simulator.get_mutable_context()
    plant_context = plant.GetMyMutableContextFromRoot(context)
    plant.SetFreeBodyPose(plant_context, body, RigidTransform([0, 0, radius]))
    from pydrake.multibody.math import SpatialVelocity

    plant.SetFreeBodySpatialVelocity(plant_context, body, SpatialVelocity(np.zeros(3), [0, 0, -v0]))
    integrator = simulator.get_mutable_integrator()
    integrator.set_target_accuracy(accuracy)
    k = parameters["point_contact_stiffness"]
    t_scale = math.sqrt(m / k)
    integrator.set_maximum_step_size(t_scale / 200)
    integrator.request_initial_step_size_target(t_scale / 1000)
    simulator.Initialize()
    t_end = None
    t = 0.0
    dt = t_scale / 200
    for _ in range(1_000_000):
        t += dt
        simulator.AdvanceTo(t)
        z = plant.GetFreeBodyPose(plant_context, body).translation()[2]
        vz = body.EvalSpatialVelocityInWorld(plant_context).translational()[2]
        if z > radius and vz > 0:
            t_end = t
            break
    # refine the exit: the ball leaves x = 0 at constant speed after the force vanished
    # (f = k x (1 + d v) vanishes only at x = 0 for d v > -1)
    T = t_end - (z - radius) / vz
    return float(vz / v0), float(T)
