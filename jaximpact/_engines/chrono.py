"""Project Chrono (SMC): two equal spheres with `ChContactMaterialSMC` and the Hertz force
model from material properties, by its source (not run here: PyChrono is on conda only).

Chrono main (commit 7689fbc, 2026), `src/chrono/physics/ChContactSMC.cpp`,
`ChDefaultContactForceTorqueSMC::CalculateForceTorque`: `eff_mass = m1 m2/(m1 + m2)`;
`case ChSystemSMC::Hertz` with `UsingMaterialProperties()` (the default):
`Sn = 2 E_eff sqrt(eff_radius delta)`, `beta = ln(cr_eff)/sqrt(ln^2 cr_eff + pi^2)`,
`kn = 2/3 Sn`, `gn = -2 sqrt(5/6) beta sqrt(Sn eff_mass)`; then
`forceN = kn delta - gn relvel_n` "and if negative, set to zero" (line ~175).
`ChContactMaterialSMC.cpp`: `E_eff = 1/((1 - nu1^2)/E1 + (1 - nu2^2)/E2)` (computed in
float), `cr_eff = min(cr1, cr2)` (`ChContactMaterialCompositionStrategy`). That is the Tsuji
form of LAMMPS's `coeff_restitution` (law `tsuji_restitution`) with the force kept
non-attractive (`separation="force"`): the realised e is above the `cr` given, and no `cr`
gives less than about 0.14; the export inverts that law. Chrono's time stepper (implicit
Euler by default) is not replicated: the promise is the continuous law's, at a recommended
step of T/100 or less. Pitfalls: (1) `eff_radius` comes from the collision system: the
Multicore narrowphase computes `R1 R2/(R1 + R2)` for two spheres, but the default Bullet
system leaves `ChCollisionInfo`'s default, 0.1 m (`ChCollisionInfo.cpp`), whatever the
spheres' size: the snippet sets that default to the pair's `R/2`. (2) `eff_mass` uses both
contactables' masses, so a sphere on a fixed ground body sees the ground's own mass (give it
a large one). (3) `cr_eff` is the smaller of the two materials' restitutions.
"""

from . import _stepping
from .base import AbstractEngine, AbstractNormalModel, Design, Key, Stepping
from .lammps import hertz
from .lammps.engine import Lammps

# A fixed body still enters eff_mass = m1 m2/(m1 + m2) with its own mass (ChContactSMC.cpp,
# GetContactableMass): the snippet gives the ground 1e6 m, so eff_mass = m (1 - 1e-6) and gn
# is 5e-7 (relative) below the design's: e moves by less than 1e-6.
GROUND_MASS_RATIO = 1e6


def _ground(parameters) -> list[str]:
    """The fixed ground box of the sphere's material, its top face the plane z = 0, heavy:
    Chrono's eff_mass takes the ground's mass even when it is fixed."""
    return [
        "# the ground: fixed, heavy (eff_mass takes its mass), the sphere's material",
        "ground = chrono.ChBodyEasyBox(1, 1, 0.1, 1000, True, True, mat)",
        "ground.SetPos(chrono.ChVector3d(0, 0, -0.05))",
        f"ground.SetMass({parameters['ground_mass']:.10g})",
        "ground.SetFixed(True)",
        "sys.Add(ground)",
    ]


class SMCHertz(AbstractNormalModel):
    """Chrono's SMC Hertz contact from material properties (`ChContactMaterialSMC`), its force
    always kept non-attractive; its stepper is not replicated (the module's docstring has
    the formulas, sources and pitfalls)."""

    NAME = "ChSystemSMC.Hertz"
    LAW = hertz.HertzMaterial.LAW
    KEYS = (
        *(
            key
            for key in hertz.HertzMaterial.KEYS
            if key.name in ("E", "coeff_restitution", "poisson")
        ),
        Key("limit_damping", "true or false; its force is always kept non-attractive", False),
    )
    STEPPING = (
        "its implicit stepper is not replicated: the continuous law's e and T, at a "
        "recommended step of T/100 or less"
    )
    MASS_DEPENDS = hertz.HertzMaterial.MASS_DEPENDS
    ALLOWS_LIMIT_DAMPING = True
    NEAREST = "its tsuji law"
    SCENES = None

    def design(self, e, T, scene, *, timestep=None, poisson=0.3, limit_damping=False) -> Design:
        """`ChContactMaterialSMC` inputs for target `e` and `T` (s) in `scene` (on a wall,
        `E_eff = E/(2 (1 - nu^2))`, `eff_radius = R`, `eff_mass` = m up to the ground's mass,
        1e6 m); its force always kept non-attractive, whatever `limit_damping`."""
        contact = hertz.tsuji_design(e, T, scene, poisson, clamped=True)
        coefficient, c, R_eff, v0 = contact.coefficient, contact.c, contact.R_eff, scene.v0
        h = _stepping.nice_down(T / 100.0) if timestep is None else float(timestep)
        warnings = [
            f"set the effective curvature radius to {R_eff:.6g} m (the snippet does): "
            "Chrono's default Bullet collision system uses 0.1 m for every contact",
            "Chrono's time stepper is not replicated: e and T are the continuous law's "
            f"(with about {T / h:.0f} steps per contact)",
        ]
        if T / h < 50:
            warnings.append(
                f"timestep {h:.3g} s gives {T / h:.0f} steps per contact: use T/100 or less"
            )
        parameters = {
            "SetYoungModulus": contact.E,
            "SetPoissonRatio": poisson,
            "SetRestitution": coefficient,
            "SetFriction": 0.0,
            "contact_force_model": "ChSystemSMC.Hertz",
            "UseMaterialProperties": True,
            "time_step": h,
            "effective_curvature_radius": R_eff,
            "k": c,
            "b": contact.b,
        }
        if scene.wall:
            parameters["geometry"] = "wall"
            parameters["ground_mass"] = GROUND_MASS_RATIO * scene.m
        return Design(
            parameters=parameters,
            e=contact.e,
            T=contact.tau * (contact.m_eff * v0**2 / c) ** 0.4 / v0,
            timestep=h,
            separation="force",
            warnings=tuple(warnings),
            steps_per_contact=T / h,
        )

    def law_parameters(self, parameters, m):
        """As LAMMPS's: `tsuji`'s `c` = k and `b`."""
        return {"c": parameters["k"], "b": parameters["b"]}

    def response(self, parameters, *, m, radius=None):
        """`(law, separation)`: the Tsuji form with the force always kept non-attractive."""
        return hertz.tsuji_response("chrono", parameters, m=m, radius=radius, clamped=True)

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
        """None: Chrono's implicit stepper is not replicated."""
        return None


class Chrono(AbstractEngine):
    """Chrono's SMC contact; no tangential export yet."""

    NAME = "chrono"
    LABEL = "Chrono"
    SCENES = {
        "spheres": Lammps.SCENES["spheres"],
        "wall": "a sphere of mass m and radius `radius` hitting a fixed ground box (a flat "
        "wall) of its material (mass 1e6 m) head-on at speed v0 (by Chrono's source, not run "
        "here)",
    }
    TWO_SPHERES = True
    CONTINUOUS_PLANT = False
    NORMAL = {"tsuji": SMCHertz()}
    TANGENTIAL = {}

    def snippet(self, parameters) -> str:
        return "\n".join(
            [
                "import pychrono as chrono",
                "sys = chrono.ChSystemSMC()",
                "sys.SetContactForceModel(chrono.ChSystemSMC.Hertz)",
                "sys.UseMaterialProperties(True)",
                "# Bullet (the default collision system) reports no curvature: set the pair's",
                "chrono.ChCollisionInfo.SetDefaultEffectiveCurvatureRadius("
                f"{parameters['effective_curvature_radius']:.10g})",
                "mat = chrono.ChContactMaterialSMC()",
                f"mat.SetYoungModulus({parameters['SetYoungModulus']:.10g})",
                f"mat.SetPoissonRatio({parameters['SetPoissonRatio']:.10g})",
                f"mat.SetRestitution({parameters['SetRestitution']:.10g})",
                "mat.SetFriction(0.0)",
                *(_ground(parameters) if parameters.get("geometry") == "wall" else []),
                f"sys.DoStepDynamics({parameters['time_step']:.6g})  # the step, in the loop",
            ]
        )
