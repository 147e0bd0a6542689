"""Chrono's SMC Hertz contact from material properties, by its source (not run here: PyChrono
is on conda only). Chrono 7689fbc, `src/chrono/physics/ChContactSMC.cpp`, `CalculateForceTorque`:
`Sn = 2 E_eff sqrt(eff_radius delta)`, `beta = ln(cr_eff)/sqrt(ln^2 cr_eff + pi^2)`, `kn = 2/3
Sn`, `gn = -2 sqrt(5/6) beta sqrt(Sn eff_mass)`, `forceN = kn delta - gn relvel_n`, zero where
negative; `ChContactMaterialSMC.cpp`: `E_eff = 1/((1 - nu1^2)/E1 + (1 - nu2^2)/E2)`, `cr_eff =
min(cr1, cr2)`: LAMMPS's Tsuji form with the force clamped (`"force"`), inverted. Its implicit
stepper is not replicated (a step of T/100 or less). Pitfalls: Bullet's `eff_radius` is
`ChCollisionInfo`'s default 0.1 m (the snippet sets R/2); `eff_mass` takes a fixed ground's
mass (give it a large one); `cr_eff` is the smaller restitution."""

from . import _stepping
from .base import AbstractEngine, AbstractNormalModel, Design, Key, Stepping
from .lammps import hertz
from .lammps.engine import Lammps

# the ground's mass over m: eff_mass = m (1 - 1e-6), e moved by less than 1e-6
GROUND_MASS_RATIO = 1e6


def _ground(parameters) -> list[str]:
    """The fixed, heavy ground box of the sphere's material, its top face z = 0."""
    return [
        "# the ground: fixed, heavy (eff_mass takes its mass), the sphere's material",
        "ground = chrono.ChBodyEasyBox(1, 1, 0.1, 1000, True, True, mat)",
        "ground.SetPos(chrono.ChVector3d(0, 0, -0.05))",
        f"ground.SetMass({parameters['ground_mass']:.10g})",
        "ground.SetFixed(True)",
        "sys.Add(ground)",
    ]


class SMCHertz(AbstractNormalModel):
    """Chrono's SMC Hertz contact (the module's docstring)."""

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
        return {"c": parameters["k"], "b": parameters["b"]}

    def response(self, parameters, *, m, radius=None):
        return hertz.tsuji_response("chrono", parameters, m=m, radius=radius, clamped=True)

    def stepper(self, parameters, *, m, radius=None) -> Stepping | None:
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
