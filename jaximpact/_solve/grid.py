"""The grid path: one contact stepped on a fixed grid of its phase-plane angle, with no
event search (shared/notes/performance-4.md, design (b); DESIGN.md, "Off the curves").

In the contact's natural units (`X = x/x*`, `V = v/v0`, `tau = t/t*`, the force in units
of `m v0^2/x*`) the angle `theta = atan2(X, V)` rises from 0 at first touch through
`pi/2` at maximum compression (`V = 0`) to `pi` where the body leaves the surface
(`X = 0`), as long as the force pushes: `dtheta/dtau = (V^2 + X F)/(X^2 + V^2) > 0`.
Graded as `theta = pi (1 - cos(pi s))/2`, `s` in [0, 1], it is the independent variable:

    d(X, V, tau)/ds = theta_s (V, -F, 1) / theta_dot,   theta_s = pi^2 sin(pi s)/2,

stepped by `GRID_STEPS` uniform steps of the 8th-order Runge-Kutta tableau of
`diffrax.Dopri8` (13 stages) in a `lax.scan`. Maximum compression is `s = 1/2` and the
end of contact at `X = 0` is `s = 1` exactly, so neither needs an event; near the surface
`X ~ s^2`, which turns the `x^(k/2)` of the Hertz-type laws into polynomials in `s` (a
step fixed in time loses the solver's order there). The steps before `s = 1/2` are
compression and the law sees `V >= 0`, the others restitution with `V <= 0` (a law with
`sign(v)` is then exact at its kink). Under the force criterion the force's first zero
inside the surface is placed by Newton's iteration on the length of the Runge-Kutta step
itself, from the step's start, with the force's rate along the solution; the first force
peak in compression by false position on the same step. No derivative is taken through a
Runge-Kutta step (Newton through one ran 3x slower and compiled 3x longer: measured).

A fixed grid cannot serve every contact: heavy damping squeezes the restitution into a
thin layer near the surface, a force that pulls stalls the angle (`theta_dot <= 0`), a
dry force can hold the body. `grid_contact` therefore says for each member whether it
`served` it: its error estimate (the tableau's embedded 7th-order solution, summed over
the steps) within `GRID_ACCEPT` of the contact's scales, `e` above `E_FLOOR`, the angle
rising at every stage, the end and peak roots converged, every value finite, and not
stuck. A member it did not serve must be recomputed by the event-terminated solve
(`impact_batch` does so in a second batched pass); its numbers here are not results.
"""

import functools
import math

import jax
import jax.numpy as jnp

from .._status import Status
from .._tracing import anchors

GRID_STEPS = 24
# the `ImpactResult` fields a contact on the grid gives
GRID_FIELDS = ("e", "T", "x_max", "t_max", "F_max", "dissipated", "v_out", "status", "num_steps")
# the estimate (sum over the steps of the embedded solution's difference, in units of
# x_max, e and the contact's duration) a member may have and still be served. Measured
# against scipy's DOP853 at rtol 1e-13 over Hunt-Crossley, Kuwabara-Kono (with and without
# a speed-dependent damping), Kelvin-Voigt, viscous Hertz and dry sign(v) laws under both
# criteria, e from 0.001 to 0.998 (160 contacts): the errors of e, T and x_max were 6 to
# 100 times below the estimate, and the members served within 2.5e-10
GRID_ACCEPT = 4e-9
# below this restitution the grid is not trusted, whatever its estimate (the note's heavy
# damping rows: e = 0.2 is 3e-5 off at 24 steps, e = 0.05 wrong)
E_FLOOR = 0.3
# a batch asking a finer rtol than this is integrated: the grid meets 1e-9 in e, T and
# x_max, the contract of the default tolerances (1e-11, a user's law 1e-12)
GRID_RTOL = 1e-12

_ROOT_ITERS = 8  # Newton on one step: the end to 1e-10 of the step
_PEAK_ITERS = 6  # false position: a peak's force is second order in its place


@functools.cache
def _tableau():
    """The 13 stages of diffrax's `Dopri8` (Prince and Dormand's RK8(7)13M): the rows of
    `a`, the weights of the 8th-order solution and of its difference from the embedded
    7th-order one, the nodes `c` (the 14th stage only serves diffrax's interpolation).
    Read at the first trace, so that importing this module does not import diffrax."""
    import diffrax as dfx

    tab = dfx.Dopri8.tableau
    a = [tuple(float(q) for q in row) for row in tab.a_lower[:12]]
    b = tuple(float(q) for q in tab.b_sol[:13])
    b_err = tuple(float(q) for q in tab.b_error[:13])
    c = tuple(float(q) for q in tab.c[:12])
    assert tab.b_sol[13] == 0 and tab.b_error[13] == 0
    return a, b, b_err, c


@jax.custom_jvp
def _on_branch(V, compressing):
    """`V` held on its branch's side of 0 (at least the smallest positive float in
    compression, at most its negative in restitution), with the derivative of `V` itself:
    the branch's force and its one-sided slope, so that `dF/dtau` near maximum compression
    is the branch's (a clamp's zero slope put a peak at `V = 0`)."""
    tiny = jnp.finfo(jnp.result_type(float)).tiny
    return jnp.where(compressing, jnp.maximum(V, tiny), jnp.minimum(V, -tiny))


@_on_branch.defjvp
def _on_branch_jvp(primals, tangents):
    V, compressing = primals
    return _on_branch(V, compressing), tangents[0]


def _combine(weights, ks):
    terms = [w * k for w, k in zip(weights, ks, strict=False) if w != 0.0]
    return sum(terms[1:], terms[0])


class _Contact:
    """One contact in natural units: the force `F(X, V, compressing)` with `V` held on its
    branch's side of 0, the force whose first zero inside the surface ends contact under
    the force criterion (a user's clamp at zero peeled off: `CustomLaw.edge_force`), and
    the grid's right-hand side."""

    def __init__(self, law, m, v0):
        dynamics = law.dynamics(m=m, v0=v0, g=0.0)
        self.law, self.v0 = law, v0
        self.x_star, self.t_star = dynamics.x_star, dynamics.t_star
        self.scale = dynamics.force_scale
        self.user = law.spec is None  # a user's law: its own edge force

    def force(self, X, V, compressing):
        V = _on_branch(V, compressing)
        x, v = self.x_star * X, self.v0 * V
        return self.law.force(x, v, v0=self.v0, compressing=compressing) / self.scale

    def edge(self, X, V):
        """Positive while the contact pushes in restitution, negative past the force's own
        zero: the force inside the surface; at and below it, the force's limit at the
        surface where that pulls, else +1 (`ScaledDynamics.force_gap`)."""
        V = _on_branch(V, False)

        def at(X):
            x, v = self.x_star * X, self.v0 * V
            if self.user:
                return self.law.edge_force(x, v) / self.scale
            return self.law.force(x, v, v0=self.v0, compressing=False) / self.scale

        surface = at(jnp.zeros_like(X))
        return jnp.where(X > 0, at(X), jnp.where(surface < 0, surface, 1.0))

    def edge_rate(self, s, y):
        """The edge force and its rate along the solution in `s` (restitution)."""
        dy = self.rhs(s, y, False)[0]
        return jax.jvp(self.edge, (y[0], y[1]), (dy[0], dy[1]))

    def force_rate(self, y, compressing):
        """`dF/dtau` along the motion (zero at a force peak)."""
        X, V = y[0], y[1]
        F = self.force(X, V, compressing)
        return jax.jvp(lambda a, b: self.force(a, b, compressing), (X, V), (V, -F))[1]

    def rhs(self, s, y, compressing):
        """`d(X, V, tau)/ds` and `theta_dot` (positive while the angle rises)."""
        X, V = y[0], y[1]
        F = self.force(X, V, compressing)
        theta_dot = (V * V + X * F) / (X * X + V * V)
        w = 0.5 * math.pi**2 * jnp.sin(math.pi * s) / theta_dot
        return jnp.stack([V * w, -F * w, w]), theta_dot

    def step(self, s, y, h, compressing):
        """One step of length `h` from `(s, y)`: the 8th-order state, the difference from
        the embedded 7th-order one, and the least `theta_dot` met at its stages."""
        a, b, b_err, c = _tableau()
        k, least = self.rhs(s, y, compressing)
        ks = [k]
        for row, node in zip(a, c, strict=True):
            k, theta_dot = self.rhs(s + node * h, y + h * _combine(row, ks), compressing)
            ks.append(k)
            least = jnp.minimum(least, theta_dot)
        return y + h * _combine(b, ks), h * _combine(b_err, ks), least


def _false_position(g, h, g0, g1, start, iters):
    """The zero of `g(sigma) -> (value, state)` on `[0, h]` where `g0 = g(0) > 0 >= g1 =
    g(h)` (`start`: the state at 0), by false position with the Illinois rule (values
    only, superlinear, for a `g` regular at both ends). Returns the root, the state there,
    and the bracket's width (its convergence)."""
    zero = jnp.zeros_like(h)

    def body(_, carry):
        a, fa, b, fb, side, sigma, state = carry
        value, state = g(sigma)
        after = value <= 0
        keep_a, keep_b = after & (side == 1), ~after & (side == -1)  # Illinois: halve
        fa = jnp.where(after, jnp.where(keep_a, 0.5 * fa, fa), value)
        a = jnp.where(after, a, sigma)
        fb = jnp.where(after, value, jnp.where(keep_b, 0.5 * fb, fb))
        b = jnp.where(after, sigma, b)
        side = jnp.where(after, 1, -1)
        return a, fa, b, fb, side, _secant(a, fa, b, fb), state

    init = (zero, g0, zero + h, g1, jnp.asarray(0), _secant(zero, g0, zero + h, g1), start)
    a, _, b, _, _, sigma, state = jax.lax.fori_loop(0, iters, body, init)
    return sigma, state, b - a


def _newton_from_left(g, h, g0, slope0, start, iters):
    """The first zero of `g(sigma) -> (value, slope, state)` on `[0, h]`, where `g0 = g(0)
    > 0 >= g(h)` and `slope0` its slope at 0: Newton's iteration from the left end, kept in
    the bracket (bisection where a step would leave it). The slope is the caller's, along
    the solution (the right-hand side, not a derivative through the Runge-Kutta step: equal
    to it to the step's order, quick to compile and run). From the left, a force that
    falls to its zero (a square root of the penetration times a linear term near the
    surface) is approached without overshoot; `g(h)` may be a degenerate zero at the
    surface, which a secant would take for the root. Returns the root, the state there,
    and the last step's size."""
    zero = jnp.zeros_like(h)
    first = jnp.where(slope0 < 0, -g0 / jnp.where(slope0 < 0, slope0, -1.0), 0.5 * h)
    first = jnp.where(jnp.isfinite(first) & (first <= h), jnp.maximum(first, 0.0), 0.5 * h)

    def body(_, carry):
        a, b, sigma, state, _ = carry
        value, slope, state = g(sigma)
        after = value <= 0
        a, b = jnp.where(after, a, sigma), jnp.where(after, sigma, b)
        nxt = sigma - value / jnp.where(slope == 0, 1.0, slope)
        inside = (nxt >= a) & (nxt <= b) & jnp.isfinite(nxt)
        nxt = jnp.where(inside, nxt, 0.5 * (a + b))
        return a, b, nxt, state, jnp.abs(nxt - sigma)

    init = (zero, zero + h, first, start, zero + h)
    _, _, sigma, state, moved = jax.lax.fori_loop(0, iters, body, init)
    return sigma, state, moved


def _secant(a, fa, b, fb):
    """The zero of the line through `(a, fa)` and `(b, fb)`, kept in `[a, b]`."""
    sigma = jnp.clip(b - fb * (b - a) / jnp.where(fb == fa, 1.0, fb - fa), a, b)
    return jnp.where(jnp.isfinite(sigma), sigma, 0.5 * (a + b))


def _first_crossing(track, flips, y, k, value):
    """`track = (y, k, (value before, value after), found, last value)` of the step where
    a condition first crossed (the force peak, the force's end), updated by this step:
    where `flips`, the state `y` and index `k` at its start and the values either side."""
    y_at, k_at, pair, found, last = track
    return (
        jnp.where(flips, y, y_at),
        jnp.where(flips, k, k_at),
        jnp.where(flips, jnp.stack([last, value]), pair),
        found | flips,
        value,
    )


def grid_contact(law, m, v0, *, separation: str, steps: int = GRID_STEPS) -> dict:
    """One contact of `law` (a force `law.force(x, v)`, `has_state` False) without gravity
    on the grid: a dict of `ImpactResult` fields (SI units; `e`, `T`, `x_max`, `t_max`,
    `F_max`, `dissipated`, `v_out`, `status`, `num_steps`), `served` (whether the grid
    served it: otherwise the fields are not results, and the member must be integrated)
    and `estimate` (the error estimate, relative to the contact's scales).

    `separation`: `"force"` ends contact at the force's first zero inside the surface or
    at `x = 0`, `"penetration"` at `x = 0` (`s = 1`). `steps`: the grid's steps, even.
    Under `vmap` every member runs the same steps; `jax.jacfwd` differentiates the fixed
    discretisation (as exact as the values).

    **Example**: `grid_contact(custom_law(lambda x, v, p: p["c"] * x**1.5 * (1 + p["a"] *
    v), c=2e6, a=0.1), 1.0, 2.5, separation="force")["e"]` is 0.856851017 (Hunt-Crossley's
    closed form).
    """
    if steps % 2:
        raise ValueError(f"the grid needs an even number of steps, got {steps}")
    m = jnp.asarray(m, dtype=float)
    v0 = jnp.asarray(v0, dtype=float)
    contact = _Contact(law, m, v0)
    force_end = separation == "force"
    h = jnp.asarray(1.0 / steps, dtype=float)
    half = steps // 2
    # the carry starts as it leaves a step, batched and with a tangent (`_tracing`)
    anchor, false = anchors(contact)
    zero = anchor + jnp.zeros_like(v0)
    y0 = jnp.stack([zero, zero + 1.0, zero])

    def body(carry, k):
        y, err, least, y_mid, peak, end = carry
        s = k * h
        compressing = k < half
        y1, dy, low = contact.step(s, y, h, compressing)
        # the first force peak in compression: dF/dtau turns from > 0 to <= 0 in this step
        rate, rate1 = peak[4], contact.force_rate(y1, compressing)
        turns = compressing & ~peak[3] & (rate > 0) & (rate1 <= 0)
        peak = _first_crossing(peak, turns, y, k, rate1)
        ended = end[3]
        live = ~ended  # after the end nothing counts (a pulling force may stall the angle)
        err = err + jnp.where(live, jnp.abs(dy), 0.0)
        least = jnp.where(live, jnp.minimum(least, low), least)
        if force_end:  # the force's own zero inside the surface, in restitution
            edge1 = contact.edge(y1[0], y1[1])
            crosses = live & ~compressing & (edge1 < 0)
            end = _first_crossing(end, crosses, y, k, edge1)
            y1 = jnp.where(ended | crosses, y, y1)  # frozen at the step that holds the end
        y_mid = jnp.where(k == half - 1, y1, y_mid)
        return (y1, err, least, y_mid, peak, end), None

    pair = jnp.stack([zero, zero])
    rate0 = contact.force_rate(y0, True)
    init = (
        y0,
        zero + jnp.zeros(3),
        zero + jnp.inf,
        y0,
        (y0, zero, pair, false, rate0),
        (y0, zero, pair, false, zero + 1.0),
    )
    carry, _ = jax.lax.scan(body, init, jnp.arange(steps, dtype=float))
    y_last, err, least, y_mid, peak, end = carry
    y_pk, k_pk, rates, found_pk, _ = peak

    # the first force peak in compression (a force that falls from first touch, as with a
    # viscous term b v, has its largest value there or at a later peak)
    def rate_along(sigma):
        y = contact.step(k_pk * h, y_pk, sigma, True)[0]
        return contact.force_rate(y, True), y

    _, y_at, width_pk = _false_position(rate_along, h, rates[0], rates[1], y_pk, _PEAK_ITERS)
    y_peak = jnp.where(found_pk, y_at, y_mid)
    peaks = jnp.stack(
        [
            contact.force(y0[0], y0[1], True),
            contact.force(y_peak[0], y_peak[1], True),
            contact.force(y_mid[0], zero, True),
        ]
    )
    converged = ~found_pk | (width_pk <= 1e-4 * h)

    y_end = y_last
    if force_end:
        y_from, k_end, edges, ended, _ = end

        def edge_along(sigma):
            y = contact.step(k_end * h, y_from, sigma, False)[0]
            return (*contact.edge_rate(k_end * h + sigma, y), y)

        _, slope0 = contact.edge_rate(k_end * h, y_from)
        _, y_at, moved_end = _newton_from_left(edge_along, h, edges[0], slope0, y_from, _ROOT_ITERS)
        y_end = jnp.where(ended, y_at, y_last)
        converged = converged & (~ended | (moved_end <= 1e-10 * h))

    e = -y_end[1]
    tau_end = y_end[2]
    x_max = y_mid[0]
    estimate = jnp.max(jnp.stack([err[0] / x_max, err[1] / jnp.abs(e), err[2] / jnp.abs(tau_end)]))
    stuck = contact.force(x_max, zero, False) <= 0  # nothing pushes the body out at x_max
    values = jnp.stack([e, tau_end, x_max, y_mid[2], *peaks])
    served = (
        jnp.all(jnp.isfinite(values))
        & jnp.isfinite(estimate)
        & (estimate <= GRID_ACCEPT)
        & (least > 0)
        & (e >= E_FLOOR)
        & ~stuck
        & converged
    )
    return dict(
        e=e,
        T=tau_end * contact.t_star,
        x_max=x_max * contact.x_star,
        t_max=y_mid[2] * contact.t_star,
        F_max=jnp.max(peaks) * contact.scale,
        dissipated=0.5 * m * v0**2 * (1.0 - e**2),
        v_out=-e * v0,
        status=jnp.full(jnp.shape(e), Status.separated, jnp.int32),
        num_steps=jnp.full(jnp.shape(e), steps, jnp.int32),
        served=served,
        estimate=estimate,
    )


def grid_serves(path, law, *, method: str, solver, rtol: float, gravity: bool) -> bool:
    """Whether a batch on `path` (`choose_path`'s, `"integrated"`) tries the grid first:
    a law whose force is a function of `(x, v)` (`has_state` False), no gravity, `method`
    `"auto"` with no `solver` chosen and `rtol` not finer than `GRID_RTOL`."""
    return (
        path.name == "integrated"
        and not law.has_state
        and not gravity
        and method == "auto"
        and solver is None
        and rtol >= GRID_RTOL
    )
