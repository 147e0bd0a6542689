"""Drake's friction on its continuous plant: Coulomb's `mu` regularised by Stribeck's curve.
At the contact point, `f_n = k x (1 + d v)_+` and the friction `-mu(s) f_n u/|u|`, `u` the
slip, `s = |u| / v_s`, `v_s` the stiction tolerance (default 1e-4 m/s;
`multibody_plant.cc`, `StribeckModel`):

    mu(s) = mu_s step5(s)                              for s < 1
    mu(s) = mu_s - (mu_s - mu_d) step5((s - 1) / 2)     for 1 <= s < 3
    mu(s) = mu_d                                       for s >= 3

with `step5(x) = x^3 (10 + x (6 x - 15))`; two geometries' mu combine as `2 mu1 mu2 / (mu1 +
mu2)`. The lever arm is `R - x/2` (the point halfway through the penetration); no tangential
spring. `oblique_replica` equals Drake 1.51.1's plant to 1e-9 (tests/engines)."""

import math

import numpy as np

from ..base import AbstractTangentialModel, Design

STICTION_TOLERANCE = 1e-4  # m/s, Drake's default
INERTIA = 0.4  # a solid sphere, I = 0.4 m R^2 (UnitInertia.SolidSphere)


def _step5(x):
    return x**3 * (10.0 + x * (6.0 * x - 15.0))


def stribeck(s, mu_s: float, mu_d: float):
    """Drake's friction coefficient at slip `s` in units of the stiction tolerance."""
    s = np.asarray(s, float)
    ramp = mu_s * _step5(np.minimum(s, 1.0))
    fall = mu_s - (mu_s - mu_d) * _step5(np.clip((s - 1.0) / 2.0, 0.0, 1.0))
    return np.where(s < 1.0, ramp, fall)


def oblique_replica(parameters, *, m, radius, v_n, v_t):
    """`(e, e_t, omega)` (each with a last axis of one, no phases) of a free solid sphere (`m`
    kg, `radius` m) meeting Drake's half space at `v_n`, `v_t` (m/s, arrays of one shape, no
    spin before) in a continuous plant with the exported `parameters`: point contact, Coulomb
    friction (static = dynamic) and stiction tolerance; Radau at rtol 1e-10."""
    from scipy.integrate import solve_ivp

    k, d = parameters["point_contact_stiffness"], parameters["hunt_crossley_dissipation"]
    mu, stiction = parameters["friction"][0], parameters["stiction_tolerance"]
    moment = INERTIA * m * radius**2
    t_scale = math.sqrt(m / k)

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

    def one(v_n, v_t):
        sol = solve_ivp(
            rhs,
            (0.0, 1e3 * t_scale),
            [0.0, v_n, v_t, 0.0],
            method="Radau",
            rtol=1e-10,
            atol=1e-14 * max(v_n, abs(v_t)),
            events=out,
            first_step=1e-6 * t_scale,
        )
        if not sol.t_events[0].size:
            raise RuntimeError("Drake's replica did not end the contact (no separation)")
        _, rate, v, omega = sol.y_events[0][0]
        return -rate / v_n, v / v_t, omega

    v_n, v_t = np.broadcast_arrays(np.asarray(v_n, float), np.asarray(v_t, float))
    rows = [one(a, b) for a, b in zip(v_n.ravel(), v_t.ravel(), strict=True)]
    return tuple(np.array(column).reshape(v_n.shape + (1,)) for column in zip(*rows, strict=True))


class StribeckFriction(AbstractTangentialModel):
    """Drake's friction for any tangential law: its `mu`, static and dynamic."""

    MODEL = "Drake's Stribeck-regularised Coulomb friction"
    FRICTION = (
        "Drake has no tangential spring: a tangential law goes as its Coulomb mu alone "
        "(static = dynamic), regularised by Drake's Stribeck curve below the stiction "
        "tolerance, in the continuous plant"
    )
    CONTACT_POINT = {"wall": 0.5}  # halfway through the penetration (integrated)

    def check(self, tangential, *, timestep) -> None:
        if timestep:
            raise ValueError(
                "drake's friction is exported for its continuous plant only (a discrete "
                "plant's friction is not replicated here): leave timestep unset"
            )

    def poisson(self, design: Design, tangential) -> None:
        return None

    def parameters(self, design: Design, tangential) -> dict:
        mu = float(tangential.params["mu"])
        return dict(design.parameters, friction=[mu, mu], stiction_tolerance=STICTION_TOLERANCE)

    def realised(self, parameters, tangential):
        return tangential

    def notes(self, parameters, tangential) -> list[str]:
        return []

    def oblique(self, parameters, *, m, radius, v_n, v_t):
        return oblique_replica(parameters, m=m, radius=radius, v_n=v_n, v_t=v_t)
