"""An independent reference for the curves: scipy's DOP853 in the plain variables.

Used by `docs/similarity_accuracy.py` and the tests (scipy is a test dependency, imported
here only). `scipy_impact(beta, n, p, separation)` solves `X'' = -X^n - beta X^p X'` from
`(0, 1)` at rtol 1e-13 and returns `(e, T/t*, x_max/x*, t_max/t*, F_max/(c x*^n))`: `T` at
the separation event, `x_max`, `t_max` at `V = 0`, `F_max` the largest of the force at first
touch, at maximum compression and at every root of `dF/dt` in compression.
"""

import math

RTOL = 1e-13


def scipy_impact(beta, n, p, separation, gamma=0.0):
    """(e, tau, x_max, t_max, F_max) of X'' = -X^n - beta X^p X' + gamma from (0, 1)
    (`gamma = g x*/v0^2`: gravity pushing in); e = 0 where gravity holds the body (its
    speed comes back to 0 before separation)."""

    def power(x, q):
        return 1.0 if q == 0 else max(x, 0.0) ** q

    def force(y):
        return power(y[0], n) + beta * power(y[0], p) * y[1]

    def rhs(t, y):
        return [y[1], -force(y) + gamma]

    def stop_at(fun, direction):
        fun.terminal, fun.direction = True, direction
        return fun

    def peak(t, y):  # dF/dt, times x^(1-q) where an exponent q < 1 would make it infinite
        x, v = max(y[0], 0.0), y[1]
        a = -force(y) + gamma
        q = min(n, 1.0) if p == 0 else min(n, p, 1.0)
        s = lambda k: power(x, k + 1.0 - q)
        damping = beta * (p * s(p - 1) * v * v + s(p) * a) if p else beta * s(0.0) * a
        return n * s(n - 1) * v + damping

    peak.direction = -1
    from scipy.integrate import solve_ivp

    kw = dict(method="DOP853", rtol=RTOL, atol=1e-16, dense_output=False)
    one = solve_ivp(rhs, (0, 1e7), [0.0, 1.0], events=[stop_at(lambda t, y: y[1], -1), peak], **kw)
    t_max, y_max = one.t_events[0][0], one.y_events[0][0]
    forces = [force([0.0, 1.0]), power(y_max[0], n)]
    forces += [force(y) for y in one.y_events[1]]
    if separation == "force" and n != p:
        k = n - p
        if p == 0:
            gap = lambda t, y: force(y)
        elif k >= 1:
            gap = lambda t, y: min(y[0], power(y[0], k) + beta * y[1])
        else:
            gap = lambda t, y: min(y[0], y[0] + math.copysign((beta * abs(y[1])) ** (1 / k), y[1]))
    else:
        gap = lambda t, y: y[0]
    events = [stop_at(gap, -1)]
    if gamma:
        events.append(stop_at(lambda t, y: y[1], 1))
    two = solve_ivp(rhs, (t_max, 1e7), [y_max[0], 0.0], events=events, **kw)
    if gamma and len(two.t_events[1]):
        return 0.0, two.t_events[1][0], y_max[0], t_max, max(forces)
    return -two.y_events[0][0][1], two.t_events[0][0], y_max[0], t_max, max(forces)
