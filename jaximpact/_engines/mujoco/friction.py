"""MuJoCo's friction: Coulomb's `mu` in its soft pyramidal cone (`condim="3"`), no tangential
spring. src/engine/engine_core_constraint.c: `mj_instantiateContact` makes four rows, the
edges `J_n +- mu J_t1`, `J_n +- mu J_t2`, each pushing only; `mj_diagApprox` `diagA = (1 +
mu^2)/m`; `mj_makeImpedance` `R_py = 2 mu^2 (1 - d)/d diagA` on every edge (`impratio = 1`),
`D = 1/R_py`, `aref = -B (J v) - K d r` (K, B from solref); the solver minimises `1/2 (a -
a0)' M (a - a0) + sum 1/2 D (J a - aref)^2` over the edges where `J a < aref`; the lever arm
is `R + r/2`. Head-on the edges share the normal acceleration `d_eff aref`, `d_eff = 1 / (1 +
mu^2 (1 + mu^2) (1 - d) / (2 d))`: the export divides out `head_on_factor` = `d_eff / d`.
Obliquely the damping carries the slip, so e changes with the incidence. In the plane of
incidence the two edges across it act as one normal row: the replica solves a 3 x 3 system
(x, z, spin) per active set (equal to MuJoCo 4.0 to round-off, tests/engines)."""

import itertools
import math

import numpy as np

from .. import _stepping
from ..base import AbstractTangentialModel, Design
from .solref import SOLIMP, continuous, effective, replica

INERTIA = 0.4  # MuJoCo's solid sphere, I = 0.4 m R^2
_ACTIVE = np.array(list(itertools.product([0.0, 1.0], repeat=3)))  # edge +, edge -, the pair


def head_on_factor(mu: float) -> float:
    """`d_eff / d`: how much the cone of friction `mu` stiffens and damps the contact head-on."""
    d = SOLIMP[0]  # the impedance
    d_eff = 1.0 / (1.0 + mu**2 * (1.0 + mu**2) * (1.0 - d) / (2.0 * d))
    return d_eff / d


def frictional_solref(solref, timestep: float, mu: float) -> list[float]:
    """The direct solref with which the cone of friction `mu` realises head-on what `solref`
    (at `timestep`, s) gives a frictionless row: both over `head_on_factor(mu)`."""
    stiffness, damping = effective(solref, timestep)
    s = head_on_factor(mu)
    return [-stiffness / s, -damping / s]


def _edge_solve(J, aref, D, inv_mass):
    """`(a_x, a_z, a_spin)` of the active set whose solution is consistent (`J a <= aref` on
    active rows, `>=` on the others)."""
    M = np.diag(1.0 / inv_mass)
    best, violation = None, None
    for active in _ACTIVE:
        weights = D * active  # (..., 3)
        H = M + np.einsum("...i,...ij,...ik->...jk", weights, J, J)
        rhs = np.einsum("...i,...ij->...j", weights * aref, J)
        a = np.linalg.solve(H, rhs[..., None])[..., 0]
        jar = np.einsum("...ij,...j->...i", J, a) - aref
        bad = np.where(active > 0, np.maximum(jar, 0.0), np.maximum(-jar, 0.0)).sum(-1)
        if best is None:
            best, violation = a, bad
        else:
            take = bad < violation
            best = np.where(take[..., None], a, best)
            violation = np.where(take, bad, violation)
    return best


def oblique_replica(solref, timestep, *, mu, radius, v_n, v_t, phases=_stepping.PHASES):
    """`(e, e_t, omega)` per start phase (the last axis) of a free sphere (`radius` m, inertia
    `INERTIA m R^2`) meeting a plane at `v_n`, `v_t` (m/s, no spin before) under MuJoCo's
    Euler step `timestep` (s) with `solref`, friction `mu` (the module's docstring)."""
    h = float(timestep)
    stiffness, damping = effective(solref, h)
    d = SOLIMP[0]  # the impedance
    K_d, B = stiffness / d, damping / d  # aref = -B (J v) - (K d) r
    diag = 1.0 + mu**2  # mj_diagApprox, per unit mass
    D = 1.0 / (2.0 * mu**2 * (1.0 - d) / d * diag)
    D_rows = np.array([D, D, 2.0 * D])
    inv_mass = np.array([1.0, 1.0, 1.0 / (INERTIA * radius**2)])
    v_n = np.asarray(v_n, float)[..., None]  # (..., phase)
    v_t = np.asarray(v_t, float)[..., None]
    gap = v_n * h * np.asarray(phases, float)  # the distance at the first step (> 0: apart)
    vel = np.stack(np.broadcast_arrays(v_t, -v_n, 0.0 * gap), -1)
    started = np.zeros(gap.shape, bool)
    done = np.zeros(gap.shape, bool)
    for _ in range(10_000_000):
        touching = gap < 0.0
        lever = radius + 0.5 * np.minimum(gap, 0.0)
        t = np.stack([np.ones_like(gap), np.zeros_like(gap), -lever], -1)
        n = np.broadcast_to(np.array([0.0, 1.0, 0.0]), t.shape)
        J = np.stack([n + mu * t, n - mu * t, n], -2)
        aref = -B * np.einsum("...ij,...j->...i", J, vel) - K_d * gap[..., None]
        a = np.where(touching[..., None], _edge_solve(J, aref, D_rows, inv_mass), 0.0)
        live = ~done
        vel = np.where(live[..., None], vel + h * a, vel)
        gap = np.where(live, gap + h * vel[..., 1], gap)
        started |= touching
        done |= started & ~touching
        if done.all():
            return vel[..., 1] / v_n, vel[..., 0] / v_t, vel[..., 2]
    raise RuntimeError("the replica did not finish the contact; the time step is far too small")


class PyramidalFriction(AbstractTangentialModel):
    """MuJoCo's friction for any tangential law: its `mu` on the pyramidal cone."""

    MODEL = "MuJoCo's pyramidal friction cone"
    FRICTION = (
        "MuJoCo has no tangential spring: a tangential law goes as its Coulomb mu alone, in "
        "MuJoCo's soft pyramidal friction cone (condim 3), solref corrected for the cone's "
        "stiffening head-on; the cone acts on the slip at the rate of the contact's damping, "
        "so a nearly elastic contact (low dampratio) barely slows it"
    )
    CONTACT_POINT = {"wall": 0.5}  # halfway through the penetration (replicated)

    def check(self, tangential, *, timestep) -> None:
        """MuJoCo takes any tangential law's `mu`."""

    def poisson(self, design: Design, tangential) -> None:
        return None

    def parameters(self, design: Design, tangential) -> dict:
        """Friction `mu` on the cone, solref direct over `head_on_factor(mu)` (`mu = 0`: condim
        1, unchanged)."""
        parameters = design.parameters
        mu = float(tangential.params["mu"])
        out = dict(
            parameters,
            friction=[mu, 0.0, 0.0],
            condim=3 if mu > 0 else 1,
            cone="pyramidal",
            impratio=1.0,
        )
        if mu > 0:
            out["solref"] = frictional_solref(parameters["solref"], parameters["timestep"], mu)
            out["cone_factor"] = head_on_factor(mu)
        return out

    def realised(self, parameters, tangential):
        return tangential

    def notes(self, parameters, tangential) -> list[str]:
        """The cone slows the slip at the damping's rate `B` (1/s) over `T`: `B T` well below
        1 leaves it almost as it came."""
        if "cone_factor" not in parameters:
            return []
        stiffness, damping = effective(parameters["solref"], parameters["timestep"])
        zeta = damping / (2.0 * math.sqrt(stiffness))
        duration = continuous(zeta)[1] / math.sqrt(stiffness)
        return [
            f"MuJoCo's friction slows the slip at the rate of its contact damping, "
            f"{damping:.3g} /s, over a contact of {duration:.3g} s: B T = "
            f"{damping * duration:.2g} (it acts fully only where B T is several, a damping "
            "ratio near 1)"
        ]

    def oblique(self, parameters, *, m, radius, v_n, v_t):
        mu = float(parameters.get("friction", [0.0])[0])
        if mu > 0:
            return oblique_replica(
                parameters["solref"], parameters["timestep"], mu=mu, radius=radius, v_n=v_n, v_t=v_t
            )
        v_n = np.atleast_1d(np.asarray(v_n, float))
        e = np.stack([replica(parameters["solref"], parameters["timestep"], v)[0] for v in v_n])
        return e, np.ones_like(e), np.zeros_like(e)
