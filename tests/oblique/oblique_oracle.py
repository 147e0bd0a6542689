"""An independent oracle for oblique impacts: the same equations as `oblique_impact`,
written again in SI units with numpy and integrated by scipy's `solve_ivp` (DOP853,
rtol 1e-12), the stick-slip transitions handled by scipy's own events (terminal, then a
restart in the other mode). Nothing of jaximpact is imported here.

Normal law: Hunt-Crossley `F_n = c x^1.5 (1 + 1.5 a v)` (Hertz for a = 0), plus Tsuji's
`b x^0.25 v` where given, contact ending at x = 0. Tangential: a spring `k(x)` (constant
`kt`, or Mindlin's `8 G* sqrt(R x)`), with
displacement history (`q' = u`, `F_t = -k q`) or force history (`q' = -k u`, `F_t = q`),
undamped, limited by `mu F_n`. The first-touch mode comes from the leading powers of t,
derived by hand (not from the library's rule): the contact sticks where the spring's force
grows slower than the limit,

- constant spring: `F_t ~ kt u t` against `mu c (1 + 1.5 a v) (v t)^1.5`: slides (u != 0);
- Mindlin, displacement: `8 G* sqrt(R v t) u t` against the limit: sticks where
  `8 G* sqrt(R) u < mu c (1 + 1.5 a v) v`;
- Mindlin, force: `(2/3) 8 G* sqrt(R v) u t^1.5`: sticks where
  `(16/3) G* sqrt(R) u < mu c (1 + 1.5 a v) v` (Maw et al.'s psi_1 < 1 at a = 0).
"""

import math

import numpy as np
from scipy.integrate import solve_ivp


def oblique_oracle(
    *,
    c,
    a=0.0,
    m,
    R,
    inertia,
    v_n,
    v_t,
    omega,
    mu,
    kt=None,
    G_star=None,
    history="displacement",
    beta=0.0,
    rtol=1e-12,
    max_switches=40,
    share=0.0,
    b_tsuji=0.0,
    kelvin_voigt=None,
    end="penetration",
    rescale=False,
):
    """Returns dict(e, v_t_out, omega_out, T, switches). `beta` (Mindlin only): the damper
    `2 (5/6)^0.5 beta (m k_t)^0.5` on the slip while sticking, left out of Coulomb's test
    (LIGGGHTS' convention), so the switches are the undamped ones' formulas. `share` f: the
    tangential force acts inside the overlap `x`, lever arm `R - f x` in the slip and the
    torque (0: `R`). `b_tsuji`: Tsuji's damping `b x^0.25 v` added to the normal force
    (N s/m^1.25), which pulls before the overlap closes. `kelvin_voigt=(k, b)`: the
    normal force is `k x + b v` instead (N/m, N s/m; it starts at `b v_n`, so the contact
    sticks at first touch); `end="force"`: contact ends where the normal force falls to 0
    (else at x = 0). `rescale` (Mindlin): LAMMPS's `mindlin_rescale` rule, the history
    scaled by `a_new / a_old` wherever the contact radius `a = (R x)^0.5` shrinks: while
    sticking `q' += q min(x', 0) / (2x)`."""
    moment = inertia * m * R**2
    mindlin = G_star is not None

    def lever(x):
        return R - share * max(x, 0.0)

    def damper(x):
        xp = max(x, 0.0)
        if not mindlin:
            return 0.0
        return 2.0 * math.sqrt(5.0 / 6.0) * beta * math.sqrt(m * 8.0 * G_star * math.sqrt(R * xp))

    def normal(x, v):
        xp = max(x, 0.0)
        v = v if xp > 0 else 0.0  # outside the surface: no force, no rate
        if kelvin_voigt is not None:
            k_n, b_n = kelvin_voigt
            f = k_n * xp + b_n * v if xp > 0 else 0.0
            return f, k_n * v + b_n * (-f / m)
        f = c * xp**1.5 * (1.0 + 1.5 * a * v) + b_tsuji * xp**0.25 * v
        acc = -f / m
        df = 1.5 * c * math.sqrt(xp) * v * (1.0 + 1.5 * a * v) + c * xp**1.5 * 1.5 * a * acc
        if b_tsuji and xp > 0:
            df += b_tsuji * (0.25 * xp**-0.75 * v * v + xp**0.25 * acc)
        return f, df

    def stiffness(x, v):
        if not mindlin:
            return kt, 0.0
        xp = max(x, 0.0)
        k = 8.0 * G_star * math.sqrt(R * xp)
        dk = 0.0 if xp == 0 else 4.0 * G_star * math.sqrt(R / xp) * v
        return k, dk

    def spring(state):
        x, v, q, vt, w = state
        k, _ = stiffness(x, v)
        return -k * q if history == "displacement" else q

    def force_t(state, mode, s):
        x, v, q, vt, w = state
        f, _ = normal(x, v)
        if mode == "slip":
            return -s * mu * abs(f)
        return spring(state) - damper(x) * (vt - lever(x) * w)

    def rhs(t, state, mode, s):
        x, v, q, vt, w = state
        f, _ = normal(x, v)
        ft = force_t(state, mode, s)
        u = vt - lever(x) * w
        k, _ = stiffness(x, v)
        dq = 0.0
        if mode == "stick":
            dq = u if history == "displacement" else -k * u
            dq += shrink(x, v) * q
        return [v, -f / m, dq, ft / m, -lever(x) * ft / moment]

    def shrink(x, v):
        """`a'/a` where the contact radius shrinks (rescaled histories), else 0."""
        return 0.5 * min(v, 0.0) / x if rescale and x > 0 else 0.0

    def held(state, s):
        x, v, q, vt, w = state
        f, _ = normal(x, v)
        k, _ = stiffness(x, v)
        if history == "displacement":
            return s * mu * abs(f) / k
        return -s * mu * abs(f)

    def slide_rate(state, s):
        """s times the sliding speed of a spring held at the limit (displacement), or the
        trial force's rate minus the limit's (force history), divided by k."""
        x, v, q, vt, w = state
        f, df = normal(x, v)
        k, dk = stiffness(x, v)
        u = vt - lever(x) * w
        if k == 0:  # outside the surface (scipy's last trial points): no contact
            return 1.0
        # the limit is mu |F_n|: its rate carries the normal force's sign (the force turns
        # to pulling before the overlap closes, under this oracle's end at x = 0)
        f, df = abs(f), math.copysign(1.0, f) * df
        if history == "displacement":
            dheld = s * mu * (df * k - f * dk) / k**2
            # the spring held at s mu f / k, shrunk as the contact radius where rescaled
            return s * (u + shrink(x, v) * s * mu * f / k - dheld)
        return s * u + shrink(x, v) * mu * f / k - mu * df / k

    # first touch at t0 (tiny): leading-order state
    T_scale = (m**2 / (c**2 * v_n)) ** 0.2 if kelvin_voigt is None else (m / kelvin_voigt[0]) ** 0.5
    t0 = 1e-9 * T_scale
    x0 = v_n * t0
    u0 = v_t - R * omega
    limit = mu * c * (1.0 + 1.5 * a * v_n) * v_n
    # Tsuji's limit grows as t^0.25, faster than any spring; Kelvin-Voigt's starts at b v_n
    if u0 == 0 or b_tsuji > 0 or kelvin_voigt is not None:
        mode = "stick"
    elif not mindlin:
        mode = "slip"
    elif history == "displacement":
        mode = "stick" if 8.0 * G_star * math.sqrt(R) * abs(u0) < limit else "slip"
    else:
        mode = "stick" if 16.0 / 3.0 * G_star * math.sqrt(R) * abs(u0) < limit else "slip"
    s = math.copysign(1.0, u0) if u0 else 1.0
    if mode == "stick":
        if mindlin and history == "displacement":
            q0 = u0 * t0
        elif mindlin:
            q0 = -8.0 * G_star * math.sqrt(R * v_n) * u0 * (2.0 / 3.0) * t0**1.5
        else:
            q0 = u0 * t0
    else:
        q0 = 0.0
    state = np.array([x0, v_n, q0, v_t, omega])
    t = t0
    switches = 0
    for _ in range(max_switches):
        if end == "force":
            ev_sep = lambda t, y, *args: normal(y[0], y[1])[0] if y[0] > 0 else y[0]  # noqa: E731
        else:
            ev_sep = lambda t, y, *args: y[0]  # noqa: E731
        ev_sep.terminal, ev_sep.direction = True, -1
        if mode == "stick":

            def ev_switch(t, y, mode, s):
                f, _ = normal(y[0], y[1])
                return mu * abs(f) - abs(spring(y))

        else:

            def ev_switch(t, y, mode, s):
                return slide_rate(y, s)

        ev_switch.terminal, ev_switch.direction = True, -1
        sol = solve_ivp(
            rhs,
            (t, 1e3 * T_scale),
            state,
            method="DOP853",
            rtol=rtol,
            atol=1e-14 * np.maximum(1.0, np.abs(state)),
            args=(mode, s),
            events=(ev_sep, ev_switch),
            dense_output=False,
        )
        if sol.t_events[0].size:
            t_end, y_end = sol.t_events[0][0], sol.y_events[0][0]
            return dict(
                e=-y_end[1] / v_n,
                v_t_out=y_end[3],
                omega_out=y_end[4],
                T=t_end,
                switches=switches,
            )
        x_last = sol.y[0, -1]
        if rescale and mode == "stick" and not sol.success and 0 <= x_last < 1e-12 * v_n * T_scale:
            # a rescaled spring sticking to the surface: `q' = q x'/(2x)` outgrows any step
            # within 1e-12 of the overlap's scale, where the spring's force, `(R x)^0.5`
            # small, gives no impulse that counts; the last x travels at the speed reached
            t_end, y_end = sol.t[-1] + x_last / abs(sol.y[1, -1]), sol.y[:, -1]
            return dict(
                e=-y_end[1] / v_n, v_t_out=y_end[3], omega_out=y_end[4], T=t_end, switches=switches
            )
        assert sol.t_events[1].size, (
            f"oracle: the contact neither ended nor switched ({sol.message} at x = "
            f"{x_last:.3e}, mode {mode})"
        )
        t, state = sol.t_events[1][0], sol.y_events[1][0].copy()
        switches += 1
        if mode == "stick":
            s = -math.copysign(1.0, spring(state))
            mode = "slip"
        else:
            state[2] = held(state, s)
            mode = "stick"
    raise RuntimeError("oracle: too many switches")
