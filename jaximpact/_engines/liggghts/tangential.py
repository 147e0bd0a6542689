"""LIGGGHTS's `tangential history` for a `mindlin` law, its spring and damper tied to E, nu
and e. LIGGGHTS-PUBLIC 3.8 (3d5c00f), `src/normal_model_hertz.h` lines 231-240: `kt = 8 G*
sqrt(R* delta)`, `gammat = -2 sqrt(5/6) betaeff sqrt(kt meff)` (`tangential_damping`, on by
default); `src/global_properties.cpp`: `1/G* = 2 (2 - nu1)(1 + nu1)/Y1 + 2 (2 - nu2)(1 +
nu2)/Y2`; `src/tangential_model_history.h` lines 150-215: the spring alone is tested against
`coefficientFriction |Fn|` and rescaled to it, the damper added only while sticking:
`mindlin` with EDEM's `beta`, term for term. Like materials have `G*/Y* = (1 - nu) / (2 (2 -
nu))`, so the export designs the normal contact again at the nu that gives the law's G*
(within [0, 0.4999]), the damper on with the normal `beta` or off; else LIGGGHTS realises the
nearest `mindlin` law, named. The force acts halfway through the overlap
(`surface_model_default.h`: `cri = radi - 0.5 deltan`)."""

import math

from ..base import AbstractTangentialModel, Design
from ..lammps.hertz import damp_coefficient
from .normal import _DESIGN_KEYS, render

_NU_RANGE = (0.0, 0.4999)  # LIGGGHTS's [0, 0.5]; jaximpact's moduli take nu < 0.5


def shear_ratio(nu: float) -> float:
    """LIGGGHTS's `Geff / Yeff` of like materials of Poisson's ratio `nu`."""
    return (1.0 - nu) / (2.0 * (2.0 - nu))


def poisson_for(ratio: float) -> float:
    """The Poisson's ratio whose `G* / Y*` is `ratio`, within `_NU_RANGE`."""
    nu = (1.0 - 4.0 * ratio) / (1.0 - 2.0 * ratio) if ratio != 0.5 else math.inf
    return min(max(nu, _NU_RANGE[0]), _NU_RANGE[1])


def y_star(p: dict) -> float:
    """LIGGGHTS's `Yeff` (Pa) of like materials of the design values `p`."""
    nu = float(p["poisson"])
    return p["youngs_modulus"] / (2.0 * (1.0 - nu * nu))


def tangential_values(p: dict, tangential) -> dict:
    """The design values `p` with what the history realises for `tangential`: `friction`,
    `G_star` (Pa), `tangential_beta`, `tangential_damping`."""
    params = {k: float(v) for k, v in tangential.params.items()}
    damped = params.get("beta", 0.0) > 0.0
    # LIGGGHTS's -betaeff: LAMMPS's damp coefficient over sqrt(5)
    beta = damp_coefficient(p["coeff_restitution"]) / math.sqrt(5.0) if damped else 0.0
    return dict(
        p,
        friction=params["mu"],
        G_star=y_star(p) * shear_ratio(float(p["poisson"])),
        tangential_beta=beta,
        tangential_damping=damped,
    )


def differences(parameters: dict, tangential) -> list[str]:
    """Where LIGGGHTS's `mindlin` law differs from `tangential` (relative 1e-9), in words."""
    given = {k: float(v) for k, v in tangential.params.items()}
    out = []
    if abs(parameters["G_star"] / given["G_star"] - 1.0) > 1e-9:
        out.append(
            f"G* = {parameters['G_star']:.4g} Pa for the law's {given['G_star']:.4g} Pa "
            f"(Poisson's ratio at its bound {parameters['poisson']:g})"
        )
    beta = given.get("beta", 0.0)
    if abs(parameters["tangential_beta"] - beta) > 1e-9 * max(beta, 1e-300):
        out.append(
            f"beta = {parameters['tangential_beta']:.4g} (its normal contact's) for the "
            f"law's {beta:.4g}"
        )
    return out


class TangentialHistory(AbstractTangentialModel):
    """LIGGGHTS's `tangential history` (the module's docstring)."""

    MODEL = (
        "LIGGGHTS's tangential history is Mindlin's spring with displacement history "
        "(k_t = 8 G* (R x)^0.5)"
    )
    FRICTION = None
    # surface_model_default.h: cri = radi - 0.5 deltan, on a wall and between spheres
    CONTACT_POINT = {"wall": 0.5, "spheres": 0.5}

    def check(self, tangential, *, timestep) -> None:
        """LIGGGHTS takes any `mindlin` law (the nearest where its G* or damper cannot be)."""

    def poisson(self, design: Design, tangential) -> float:
        """The nu at which G* is the law's with the `design`'s Y*."""
        return poisson_for(float(tangential.params["G_star"]) / y_star(design.parameters))

    def parameters(self, design: Design, tangential) -> dict:
        parameters = design.parameters
        p = tangential_values(
            {k: parameters[k] for k in _DESIGN_KEYS if k in parameters}, tangential
        )
        return render(
            p, parameters["limitForce"], parameters["particle_range"], "fix_wall" in parameters
        )

    def realised(self, parameters, tangential):
        from ..._oblique import tangential_law

        beta = parameters["tangential_beta"]
        return tangential_law(
            "mindlin", G_star=parameters["G_star"], mu=parameters["friction"], beta=beta
        )

    def notes(self, parameters, tangential) -> list[str]:
        out = [
            f"LIGGGHTS's G* comes from E and nu: poissonsRatio {parameters['poisson']:.6g} "
            f"(youngsModulus {parameters['youngs_modulus']:.6g} Pa) gives the tangential "
            "law's G* with the normal contact's Y*"
        ]
        changed = differences(parameters, tangential)
        if changed:
            out.append("LIGGGHTS realises the nearest mindlin law: " + "; ".join(changed))
        return out

    def oblique(self, parameters, *, m, radius, v_n, v_t):
        return None
