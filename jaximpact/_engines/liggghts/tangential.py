"""LIGGGHTS's tangential model for jaximpact's `mindlin` law: `tangential history` of
`pair_style gran model hertz` (and of its primitive wall), with its spring and damper tied to
the material's E, nu and restitution.

LIGGGHTS-PUBLIC 3.8 (commit 3d5c00f), `src/normal_model_hertz.h` (lines 231-240):
`St = 8 G* sqrt(R* delta)`, `kt = St`, `gammat = -2 sqrt(5/6) betaeff sqrt(St meff)` when
`tangential_damping` is on (the default), with `betaeff = ln e / sqrt(ln^2 e + pi^2)` of the
`coefficientRestitution`; `src/global_properties.cpp`: `1/G* = 2 (2 - nu1)(1 + nu1)/Y1 +
2 (2 - nu2)(1 + nu2)/Y2`. `src/tangential_model_history.h` (lines 150-215): the shear
displacement grows by the slip velocity times the step, the spring's force `-kt shear` is
tested against `coefficientFriction |Fn|` (the normal force with its damping); beyond it the
spring is rescaled to the limit and the force is the limit, else the damper `-gammat v_t` is
added. That is jaximpact's `mindlin` (displacement history) with its EDEM/LIGGGHTS damper
`beta` (the spring alone tested, the damper only while sticking), term for term.

So LIGGGHTS realises a `mindlin` law with `G*` and `beta` that come from its normal contact:
for two like spheres (and a sphere on a primitive wall of its own type) `G* / Y* =
(1 - nu) / (2 (2 - nu))`, `Y* = Y / (2 (1 - nu^2))`, from 1/4 at `nu = 0` to 1/6 at
`nu = 0.5`. Since the normal contact fixes `Y*` alone, the export designs it again at the
Poisson's ratio that gives the law's `G*` (`TangentialHistory.poisson`; the modulus
follows), within LIGGGHTS's `0 <= nu <= 0.5` (0.4999 at most here); the damper is on with the normal
contact's `beta` or off (`tangential_damping off`) for `beta = 0`. Outside those, LIGGGHTS
realises the nearest `mindlin` law, which the export names. LIGGGHTS applies the
tangential force halfway through the overlap (`surface_model_default.h`: `cri = radi -
0.5 deltan`): its promise is `oblique_impact(contact_point="midpoint")`.
"""

import math

from ..base import AbstractTangentialModel, Design
from ..lammps.hertz import damp_coefficient
from .normal import _DESIGN_KEYS, render

# global_properties.cpp: 0 <= poissonsRatio <= 0.5; jaximpact's moduli take nu < 0.5
_NU_RANGE = (0.0, 0.4999)


def shear_ratio(nu: float) -> float:
    """`G* / Y*` of two like materials of Poisson's ratio `nu`, LIGGGHTS's `Geff / Yeff`."""
    return (1.0 - nu) / (2.0 * (2.0 - nu))


def poisson_for(ratio: float) -> float:
    """The Poisson's ratio whose `G* / Y*` is `ratio`, clamped to [0, 0.4999] (LIGGGHTS
    takes [0, 0.5])."""
    nu = (1.0 - 4.0 * ratio) / (1.0 - 2.0 * ratio) if ratio != 0.5 else math.inf
    return min(max(nu, _NU_RANGE[0]), _NU_RANGE[1])


def y_star(p: dict) -> float:
    """LIGGGHTS's `Yeff` (Pa) of two like materials of the design values `p`."""
    nu = float(p["poisson"])
    return p["youngs_modulus"] / (2.0 * (1.0 - nu * nu))


def tangential_values(p: dict, tangential) -> dict:
    """The design values `p` (`youngs_modulus`, `poisson`, `coeff_restitution`) with what
    LIGGGHTS's tangential history then realises for `tangential` (a `mindlin` law):
    `friction`, `G_star` (Pa), `tangential_beta` and `tangential_damping` (on where the law
    has a damper)."""
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
    """Where LIGGGHTS's `mindlin` law differs from `tangential`'s (relative 1e-9), in
    words, or an empty list."""
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
    """LIGGGHTS's `tangential history`: Mindlin's spring with displacement history, its G*
    and damper tied to the normal contact (the module's docstring)."""

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
        """The Poisson's ratio (within [0, 0.5]) at which LIGGGHTS's G* is the law's with the
        normal contact's Y* of the `design`."""
        return poisson_for(float(tangential.params["G_star"]) / y_star(design.parameters))

    def parameters(self, design: Design, tangential) -> dict:
        """The design's parameters (designed at `poisson`'s ratio) with `tangential` (a
        `mindlin` law) as LIGGGHTS's tangential history: its friction, the damper on or
        off."""
        parameters = design.parameters
        p = tangential_values(
            {k: parameters[k] for k in _DESIGN_KEYS if k in parameters}, tangential
        )
        return render(
            p, parameters["limitForce"], parameters["particle_range"], "fix_wall" in parameters
        )

    def realised(self, parameters, tangential):
        """The `mindlin` law LIGGGHTS realises (its G* and damper tied to E, nu, e)."""
        from ..._oblique import tangential_law

        beta = parameters["tangential_beta"]
        return tangential_law(
            "mindlin", G_star=parameters["G_star"], mu=parameters["friction"], beta=beta
        )

    def notes(self, parameters, tangential) -> list[str]:
        """Poisson's ratio set for G*, and where LIGGGHTS's `mindlin` law is the nearest."""
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
