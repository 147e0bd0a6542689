"""Drake's friction on a sphere meeting a half space obliquely: Coulomb's `mu` regularised by
Stribeck's curve in its continuous plant, and the oblique impact that plant realises.

Drake's continuous `MultibodyPlant` (point contact, `time_step = 0`) applies at the contact
point the normal force `f_n = k x (1 + d v)_+` and the friction `-mu(s) f_n u/|u|`, `u` the
slip velocity of the contact point, `s = |u| / v_s` with the stiction tolerance `v_s`
(`set_stiction_tolerance`, default 1e-4 m/s), and Stribeck's curve (Drake's
`multibody_plant.cc`, `StribeckModel`):

    mu(s) = mu_s step5(s)                              for s < 1
    mu(s) = mu_s - (mu_s - mu_d) step5((s - 1) / 2)     for 1 <= s < 3
    mu(s) = mu_d                                       for s >= 3

with `step5(x) = x^3 (10 + x (6 x - 15))`; the static and dynamic `mu` of the two geometries
combine as `2 mu1 mu2 / (mu1 + mu2)` (equal values give the value). The point lies halfway
through the penetration, so the friction's lever arm about the sphere's centre is
`R - x/2`. There is no tangential spring: below the stiction tolerance the friction is a
steep viscous force, which brings the slip to (nearly) zero, Coulomb's sticking.

`oblique_replica` integrates these equations with scipy's Radau (implicit: the friction is
stiff near `u = 0`) to rtol 1e-10; it equals Drake 1.51.1's error-controlled plant to 1e-9
(tests/engines).
"""

import math

import numpy as np

from ..base import AbstractTangentialModel, Design

STICTION_TOLERANCE = 1e-4  # m/s, Drake's default
INERTIA = 0.4  # a solid sphere, I = 0.4 m R^2 (UnitInertia.SolidSphere)


def _step5(x):
    return x**3 * (10.0 + x * (6.0 * x - 15.0))


def stribeck(s, mu_s: float, mu_d: float):
    """Drake's friction coefficient at the slip speed `s` in units of the stiction
    tolerance."""
    s = np.asarray(s, float)
    ramp = mu_s * _step5(np.minimum(s, 1.0))
    fall = mu_s - (mu_s - mu_d) * _step5(np.clip((s - 1.0) / 2.0, 0.0, 1.0))
    return np.where(s < 1.0, ramp, fall)


def _one(k, d, m, radius, mu, v_n, v_t, stiction, inertia, rtol):
    from scipy.integrate import solve_ivp

    moment = inertia * m * radius**2

    def rhs(t, y):
        x, rate, v, omega = y
        f_n = max(0.0, k * x * (1.0 + d * rate)) if x > 0 else 0.0
        lever = radius - 0.5 * x
        u = v - lever * omega
        f_t = -float(stribeck(abs(u) / stiction, mu, mu)) * f_n * math.copysign(1.0, u)
        return [rate, -f_n / m, f_t / m, -f_t * lever / moment]

    def out(t, y):
        return y[0]

    out.terminal, out.direction = True, -1
    t_scale = math.sqrt(m / k)
    sol = solve_ivp(
        rhs,
        (0.0, 1e3 * t_scale),
        [0.0, v_n, v_t, 0.0],
        method="Radau",
        rtol=rtol,
        atol=1e-14 * max(v_n, abs(v_t)),
        events=out,
        first_step=1e-6 * t_scale,
    )
    if not sol.t_events[0].size:
        raise RuntimeError("Drake's replica did not end the contact (no separation)")
    _, rate, v, omega = sol.y_events[0][0]
    return -rate / v_n, v / v_t, omega


def oblique_replica(
    *, k, d, m, radius, mu, v_n, v_t, stiction=STICTION_TOLERANCE, inertia=INERTIA, rtol=1e-10
):
    """`(e, e_t, omega)` of a free sphere of mass `m` (kg), radius `radius` (m) and moment of
    inertia `inertia m R^2` meeting Drake's half space at normal and tangential speeds `v_n`,
    `v_t` (m/s; arrays of one shape, no spin before) in a continuous plant with point
    contact `k` (N/m), `d` (s/m), friction `mu` (static = dynamic) and stiction tolerance
    `stiction` (m/s): the normal and tangential restitution and the spin after (rad/s,
    positive rolling forward), each with a last axis of one (no first-touch phases)."""
    v_n, v_t = np.broadcast_arrays(np.asarray(v_n, float), np.asarray(v_t, float))
    rows = [
        _one(k, d, m, radius, mu, a, b, stiction, inertia, rtol)
        for a, b in zip(v_n.ravel(), v_t.ravel(), strict=True)
    ]
    return tuple(np.array(column).reshape(v_n.shape + (1,)) for column in zip(*rows, strict=True))


class StribeckFriction(AbstractTangentialModel):
    """Drake's friction for any tangential law: its Coulomb `mu`, static and dynamic, on the
    continuous plant."""

    MODEL = "Drake's Stribeck-regularised Coulomb friction"
    FRICTION = (
        "Drake has no tangential spring: a tangential law goes as its Coulomb mu alone "
        "(static = dynamic), regularised by Drake's Stribeck curve below the stiction "
        "tolerance, in the continuous plant"
    )
    CONTACT_POINT = {"wall": 0.5}  # halfway through the penetration (integrated)

    def check(self, tangential, *, timestep) -> None:
        """Drake takes any tangential law's `mu` on its continuous plant."""
        if timestep:
            raise ValueError(
                "drake's friction is exported for its continuous plant only (a discrete "
                "plant's friction is not replicated here): leave timestep unset"
            )

    def poisson(self, design: Design, tangential) -> None:
        return None

    def parameters(self, design: Design, tangential) -> dict:
        """The design's parameters with Coulomb's `mu` of `tangential` as static and dynamic
        friction
        of both geometries, and Drake's default stiction tolerance ."""
        mu = float(tangential.params["mu"])
        return dict(design.parameters, friction=[mu, mu], stiction_tolerance=STICTION_TOLERANCE)

    def realised(self, parameters, tangential):
        return tangential

    def notes(self, parameters, tangential) -> list[str]:
        return []

    def oblique(self, parameters, *, m, radius, v_n, v_t):
        """The continuous plant's oblique impact with the exported friction, integrated
        (`oblique_replica`)."""
        return oblique_replica(
            k=parameters["point_contact_stiffness"],
            d=parameters["hunt_crossley_dissipation"],
            m=m,
            radius=radius,
            mu=parameters["friction"][0],
            v_n=v_n,
            v_t=v_t,
            stiction=parameters["stiction_tolerance"],
        )
