"""Project Chrono (SMC): two equal spheres with `ChContactMaterialSMC` and the Hertz force
model from material properties, by its source (not run here: PyChrono is on conda only).

`src/chrono/physics/ChContactSMC.h`, `ChSystemSMC::Hertz` with `UseMaterialProperties(true)`
(the defaults): `kn = 2/3 S_n`, `gn = -2 sqrt(5/6) beta sqrt(S_n m_eff)`,
`S_n = 2 E_eff sqrt(R_eff delta)`, `beta = ln(cr)/sqrt(ln^2 cr + pi^2)`,
`forceN = kn delta - gn v_n`, and a negative `forceN` is set to zero. With
`E_eff = 1/((1 - nu1^2)/E1 + (1 - nu2^2)/E2)` (`ChContactMaterialCompositeSMC`) that is the
Tsuji form of LAMMPS's `coeff_restitution` (law `tsuji_restitution`) with the force kept
non-attractive (`separation="force"`): the realised e is above the `cr` given, and no `cr`
gives less than about 0.14; the export inverts that law. Chrono's time stepper (implicit
Euler by default) is not replicated: the promise is the continuous law's, at a recommended
step of T/100 or less. Pitfalls: `m_eff` uses both contactables' masses, so a sphere on a
fixed ground body has `m_eff = m M/(m + M)` with the ground's own mass `M` (give it a large
one); `cr_eff` is the smaller of the two materials' restitutions.
"""

import math

from . import lammps

NAME = "chrono"
SCENE = lammps.SCENE
law = lammps.law


def design(e, T, *, m, v0, radius, poisson=0.3, timestep=None, limit_damping=True):
    coefficient = lammps.coefficient_for(e, limit_damping=True)
    realised_e, tau = lammps.impact_at_unit_scales(coefficient, "force")
    m_eff, R_eff = m / 2.0, radius / 2.0
    c = m_eff * v0**2 * (tau / (T * v0)) ** 2.5
    E = c * 3.0 / (4.0 * math.sqrt(R_eff)) * 2.0 * (1.0 - poisson**2)
    b = lammps.damp_coefficient(coefficient) * math.sqrt(m_eff * c) if coefficient < 1 else 0.0
    h = lammps.nice_down(T / 100.0) if timestep is None else float(timestep)
    warnings = [
        "Chrono's time stepper is not replicated: e and T are the continuous law's "
        f"(with about {T / h:.0f} steps per contact)"
    ]
    if T / h < 50:
        warnings.append(
            f"timestep {h:.3g} s gives {T / h:.0f} steps per contact: use T/100 or less"
        )
    parameters = {
        "SetYoungModulus": E,
        "SetPoissonRatio": poisson,
        "SetRestitution": coefficient,
        "SetFriction": 0.0,
        "contact_force_model": "ChSystemSMC.Hertz",
        "UseMaterialProperties": True,
        "time_step": h,
        "k": c,
        "b": b,
    }
    return dict(
        parameters=parameters,
        e=realised_e,
        T=tau * (m_eff * v0**2 / c) ** 0.4 / v0,
        e_range=None,
        T_range=None,
        steps_per_contact=T / h,
        warnings=warnings,
        separation="force",
    )


def snippet(parameters) -> str:
    return "\n".join(
        [
            "import pychrono as chrono",
            "sys = chrono.ChSystemSMC()",
            "sys.SetContactForceModel(chrono.ChSystemSMC.Hertz)",
            "sys.UseMaterialProperties(True)",
            "mat = chrono.ChContactMaterialSMC()",
            f"mat.SetYoungModulus({parameters['SetYoungModulus']:.10g})",
            f"mat.SetPoissonRatio({parameters['SetPoissonRatio']:.10g})",
            f"mat.SetRestitution({parameters['SetRestitution']:.10g})",
            "mat.SetFriction(0.0)",
            f"sys.DoStepDynamics({parameters['time_step']:.6g})  # the step, in the loop",
        ]
    )
