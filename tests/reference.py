"""Independent scipy reference integrator for jaximpact tests (no JAX).

Physics (SI): x is the penetration (x > 0 inside the surface), v = dx/dt; contact
starts at x = 0 with v = v0 > 0.  During contact m x'' = -F(x, v) + m g, with F > 0
pushing the body out.  Dry forces (P) take the sign of v, so the impact is integrated
in two phases with scipy's DOP853: phase 1 (compression, dry sign +1) from (0, v0)
until v = 0, then phase 2 (restitution, dry sign -1) until separation.

Separation criteria:
* ``"force"``: first time F <= 0 in restitution.  The event function is positive in
  contact and crosses zero transversally: F itself for laws with a dry force, with
  p = 0 (no x^p factor on the damping), or for maxwell (F is a state); for
  F = c x^n + d x^p v with p > 0 it is min(x, c x^(n-p) + d v) (both scaled).
* ``"penetration"``: x returns to 0.
In restitution, v returning to 0 from below means rest inside the surface: status
"stuck" for laws with a dry force P, else "captured".  At maximum compression, if the
restitution force at (x_max, 0-) minus m g is <= 0 the body is "stuck" at once.
Under "penetration" an asymptotic approach to rest (max(x/x_max, -v/v0) < 1e-9, e.g.
over-damped Kelvin-Voigt) or reaching the horizon is reported as "captured".
For stuck/captured e = 0 and T is the time the body came to rest (inf if it only
approaches rest asymptotically).
"""

from __future__ import annotations

import math

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

_DRY = ("bingham", "bingham_modified", "bingham_compression")
_CAPTURE_TOL = 1e-9


def _law(name, prm):
    """(c, n, d, p, P_comp, P_rest): F = c x^n + d x^p v + (P_comp if v>0 else -P_rest)."""
    c = float(prm["c"])
    table = {
        "kelvin_voigt": lambda: (1.0, prm["b"], 0.0, 0.0, 0.0),
        "kelvin_voigt_modified": lambda: (1.0, prm["b1"], 1.0, 0.0, 0.0),
        "bingham": lambda: (1.0, prm["b"], 0.0, prm["P"], prm["P"]),
        "bingham_modified": lambda: (1.0, prm["b1"], 1.0, prm["P"], prm["P"]),
        "bingham_compression": lambda: (1.0, 0.0, 0.0, prm["P"], 0.0),
        "hertz_viscous": lambda: (1.5, prm["b"], 0.0, 0.0, 0.0),
        "hertz_modified": lambda: (1.5, prm["b"], 1.0, 0.0, 0.0),
        "hertz_rate": lambda: (1.5, prm["b1"], 0.5, 0.0, 0.0),
        "hunt_crossley": lambda: (
            prm.get("n", 1.5),
            1.5 * prm["a"] * c,
            prm.get("n", 1.5),
            0.0,
            0.0,
        ),
    }
    if name not in table:
        raise ValueError(f"unknown law {name!r}")
    n, d, p, pc, pr = table[name]()
    return c, float(n), float(d), float(p), float(pc), float(pr)


def _pow(x, q):
    """x**q with max(x, 0) for non-integer q (works on scalars and arrays)."""
    if q == 0.0:
        return np.ones_like(np.asarray(x, dtype=float))
    if q == 1.0:
        return x
    return np.maximum(x, 0.0) ** q


def _force(law, x, v, s):
    c, n, d, p, pc, pr = law
    return c * _pow(x, n) + d * _pow(x, p) * v + (pc if s > 0 else -pr)


def reference_force(name, params, x, v, phase_sign) -> float:
    """Contact force F(x, v); phase_sign +1 compression, -1 restitution (not maxwell)."""
    if name == "maxwell":
        raise ValueError("maxwell force is a state; not supported by reference_force")
    return float(_force(_law(name, params), x, v, phase_sign))


def _solve(name, params, m, v0, separation, g, rtol):
    if separation not in ("force", "penetration"):
        raise ValueError(f"unknown separation criterion {separation!r}")
    maxwell = name == "maxwell"
    c = float(params["c"])
    law = None if maxwell else _law(name, params)
    n = 1.0 if maxwell else law[1]
    xs = v0 * math.sqrt(m / c) if maxwell else (m * v0**2 / c) ** (1.0 / (n + 1.0))
    ts, Fs = xs / v0, c * xs**n  # time and force scales
    atol = 1e-2 * rtol * np.array([xs, v0] + ([Fs] if maxwell else []))
    kw = dict(method="DOP853", rtol=rtol, atol=atol, dense_output=True)

    def F_of(y, s):
        return y[2] if maxwell else _force(law, y[0], y[1], s)

    def rhs(t, y, s):
        dy = [y[1], g - F_of(y, s) / m]
        if maxwell:
            dy.append(c * (y[1] - y[2] / float(params["b"])))
        return dy

    def event(fun, direction):
        fun.terminal, fun.direction = True, direction
        return fun

    if maxwell and g == 0.0 and math.sqrt(m * c) / float(params["b"]) >= 2.0:
        # over-damped Maxwell: V'' + mu V' + V = 0 (tau = t/t*), V(0) = 1, V'(0) = 0 stays
        # positive for ever (proven, not integrated: a long integration finds a noise-level
        # zero of V and reports a rest or a rebound with e ~ 1e-20). The body sinks in
        # towards x = mu x* while the force relaxes: captured.
        mu = math.sqrt(m * c) / float(params["b"])
        s_, q_ = 0.5 * mu, math.sqrt(max(0.25 * mu * mu - 1.0, 1e-300))
        tau_p = math.atanh(q_ / s_) / q_ if q_ > 1e-8 else 1.0 / s_
        phi_p = math.exp(-s_ * tau_p) * (math.sinh(q_ * tau_p) / q_ if q_ > 1e-8 else tau_p)
        return (
            dict(
                x_max=mu * xs,
                t_max=math.inf,
                e=0.0,
                T=math.inf,
                status="captured",
                F_max=phi_p * c * xs,
            ),
            None,
            None,
        )

    # ---- phase 1: compression, until v = 0 ------------------------------------
    y0 = [0.0, v0] + ([0.0] if maxwell else [])
    top = event(lambda t, y, s: y[1] / v0, -1)
    s1 = solve_ivp(rhs, (0.0, 1e6 * ts), y0, events=[top], args=(1,), **kw)
    if not s1.t_events[0].size:
        raise RuntimeError(f"{name}: no maximum compression found ({s1.message})")
    t_max = float(s1.t_events[0][0])
    ytop = np.array(s1.y_events[0][0], dtype=float)
    ytop[1] = 0.0
    x_max = float(ytop[0])
    dry = name in _DRY and float(params.get("P", 0.0)) > 0.0
    out = dict(x_max=x_max, t_max=t_max)

    def fmax(sols):
        vals = []
        for sol in sols:
            tt = np.linspace(sol.t[0], sol.t[-1], 2000)
            yy = sol.sol(tt)
            vals.append(np.max(F_of(yy, 1 if sol is s1 else -1)))
        return float(max(vals))

    if F_of(ytop, -1) - m * g <= 0.0:  # cannot rebound: stuck at x_max
        # (without a dry force: over-damped Maxwell, whose speed and force only decay
        # towards 0 together; held without a dry force is a capture)
        out.update(e=0.0, T=t_max, status="stuck" if dry else "captured", F_max=fmax([s1]))
        return out, s1, None

    # ---- phase 2: restitution, until separation / rest ------------------------
    if separation == "penetration":
        sep = lambda t, y, s: y[0] / xs
    elif maxwell:
        sep = lambda t, y, s: y[2] / Fs
    else:
        _, _, d, p, _, pr = law
        if pr > 0.0 or p == 0.0 or d == 0.0:
            sep = lambda t, y, s: _force(law, y[0], y[1], s) / Fs
        elif n == p:  # F = x^p (c + d v), Hunt-Crossley type:
            # m (c + d v)' = d (m g - x^p (c + d v)), so c + d v only decays towards 0 while
            # x > 0 (its sign there is rounding noise): the force vanishes at x = 0 only
            sep = lambda t, y, s: y[0] / xs
        else:  # F = x^p (c x^(n-p) + d v)
            sep = lambda t, y, s: min(
                y[0] / xs, (c * _pow(y[0], n - p) + d * y[1]) / (c * xs ** (n - p))
            )
    events = [event(sep, -1), event(lambda t, y, s: y[1] / v0, 1)]
    if separation == "penetration":
        events.append(event(lambda t, y, s: max(y[0] / x_max, -y[1] / v0) - _CAPTURE_TOL, -1))
    horizon = t_max + 1e4 * (t_max + ts)
    s2 = solve_ivp(rhs, (t_max, horizon), ytop, events=events, args=(-1,), **kw)
    if s2.status < 0:
        raise RuntimeError(f"{name}: restitution integration failed ({s2.message})")
    if s2.t_events[0].size:
        v_out = float(s2.y_events[0][0][1])
        out.update(e=-v_out / v0, T=float(s2.t_events[0][0]), status="separated")
    elif s2.t_events[1].size:
        out.update(e=0.0, T=float(s2.t_events[1][0]), status="stuck" if dry else "captured")
    else:  # asymptotic rest or horizon
        out.update(e=0.0, T=math.inf, status="captured")
    out["F_max"] = fmax([s1, s2])
    return out, s1, s2


def reference_impact(
    name: str,
    params: dict,
    *,
    m: float,
    v0: float,
    separation: str = "force",
    g: float = 0.0,
    rtol: float = 1e-12,
) -> dict:
    """returns dict(e=..., T=..., x_max=..., t_max=..., F_max=...,
    status="separated"|"stuck"|"captured")"""
    return _solve(name, params, m, v0, separation, g, rtol)[0]


def reference_trajectory(name, params, *, m, v0, separation="force", g=0.0, ts, rtol=1e-12):
    """x(ts), v(ts) for times inside the contact, from the dense output of the right phase."""
    res, s1, s2 = _solve(name, params, m, v0, separation, g, rtol)
    ts = np.asarray(ts, dtype=float)
    y = np.empty((2,) + ts.shape)
    early = ts <= res["t_max"]
    y[:, early] = s1.sol(ts[early])[:2]
    if (~early).any():
        if s2 is None:
            raise ValueError("times after t_max requested but the body stuck at x_max")
        y[:, ~early] = s2.sol(ts[~early])[:2]
    return y[0], y[1]


if __name__ == "__main__":
    m, v0 = 1.0, 2.5
    cases = [
        ("kelvin_voigt", dict(c=2e6, b=400)),
        ("kelvin_voigt_modified", dict(c=2e6, b1=4e5)),
        ("kelvin_voigt_modified", dict(c=2e6, b1=4)),
        ("bingham", dict(c=2e6, b=200, P=400)),
        ("bingham_modified", dict(c=2e6, b1=200, P=400)),
        ("bingham_compression", dict(c=2e6, P=800)),
        ("hertz_viscous", dict(c=2e6, b=40)),
        ("hertz_modified", dict(c=2e6, b=2e4)),
        ("hertz_rate", dict(c=2e6, b1=800)),
        ("hunt_crossley", dict(c=2e6, a=0.1)),
        ("maxwell", dict(c=2e6, b=2000)),
    ]
    print(
        f"{'law':22s} {'params':26s} {'sep':11s} {'e':>17s} {'T':>22s} "
        f"{'x_max':>22s} {'F_max':>12s} status"
    )
    res = {}
    for name, prm in cases:
        for sep in ("force", "penetration"):
            r = reference_impact(name, prm, m=m, v0=v0, separation=sep)
            res[name, tuple(prm.items()), sep] = r
            print(
                f"{name:22s} {str(prm):26s} {sep:11s} {r['e']:17.14f} {r['T']:22.16e} "
                f"{r['x_max']:22.16e} {r['F_max']:12.6e} {r['status']}"
            )

    def check(label, got, want, tol):
        err = abs(got / want - 1.0)
        print(f"  {label:42s} got={got:.16e} want={want:.16e} relerr={err:.2e}")
        assert err < tol, label
        return err

    print("\nverification")
    c, b = 2e6, 400.0
    w = math.sqrt(4 * m * c - b * b)
    kv = lambda sep, key=(("c", c), ("b", b)): res["kelvin_voigt", key, sep]
    check("kelvin_voigt force T", kv("force")["T"], 4 * m * math.atan(w / b) / w, 1e-10)
    check("kelvin_voigt penetration e", kv("penetration")["e"], math.exp(-math.pi * b / w), 1e-10)
    check("kelvin_voigt penetration T", kv("penetration")["T"], 2 * math.pi * m / w, 1e-10)
    c, b = 2e6, 2000.0
    q = math.sqrt(4 * b * b - c * m)
    mx = res["maxwell", (("c", c), ("b", b)), "force"]
    check("maxwell force e", mx["e"], math.exp(-math.pi * math.sqrt(c * m) / q), 1e-10)
    check("maxwell force T", mx["T"], 2 * math.pi * b * math.sqrt(c * m) / (c * q), 1e-10)
    alpha = 1.5 * 0.1 * v0
    rhs_hc = alpha - math.log1p(alpha)
    e_hc = brentq(
        lambda e: -alpha * e - math.log1p(-alpha * e) - rhs_hc, 1e-12, 1.0, xtol=1e-16, rtol=1e-15
    )
    for sep in ("force", "penetration"):
        check(
            f"hunt_crossley {sep} e",
            res["hunt_crossley", (("c", 2e6), ("a", 0.1)), sep]["e"],
            e_hc,
            1e-10,
        )
    od = dict(c=1e4, b=1000)
    rp = reference_impact("kelvin_voigt", od, m=1.0, v0=1.0, separation="penetration")
    rf = reference_impact("kelvin_voigt", od, m=1.0, v0=1.0, separation="force")
    print(f"  over-damped KV penetration: {rp}")
    print(f"  over-damped KV force:       {rf}")
    assert rp["status"] == "captured" and rp["e"] == 0.0
    assert rf["status"] == "separated" and math.isfinite(rf["T"]) and rf["e"] > 0
    xs, vs = reference_trajectory(
        "kelvin_voigt", dict(c=2e6, b=400), m=m, v0=v0, ts=np.linspace(0, kv("force")["T"], 5)
    )
    print(f"  trajectory x={xs}\n             v={vs}")
    print("all checks passed")
