"""The unit damped oscillator `Y'' + 2 s Y' + Y = 0` of the exact linear impacts
(`closed_forms`, `closed_forms_linear`): its state in closed form for every damping
(under-, critically and over-damped, with no cancellation near critical damping and no
overflow at long times), the first instant it takes a given phase, and the root finders
that place an event on a known bracket or from a good start, with the implicit derivative
in their last step. Shared by both modules, importing neither.

`r = 1 - s^2` throughout (`r < 0` over-damped); `C = cos(sqrt(r) t)` and
`S = sin(sqrt(r) t)/sqrt(r)`, continued to cosh and sinh for `r < 0`.
"""

import jax
import jax.numpy as jnp


def _series_near_zero(u, coefficients):
    return sum(a * u**k for k, a in enumerate(coefficients))


def _arctan_ratio(u):
    """`atan(sqrt(u))/sqrt(u)` for `u > 0`, `atanh(sqrt(-u))/sqrt(-u)` for `-1 < u < 0`."""
    small = jnp.abs(u) < 1e-2
    root_pos = jnp.sqrt(jnp.where(u > 1e-2, u, 1.0))
    root_neg = jnp.sqrt(jnp.where(u < -1e-2, -u, 0.25))
    exact = jnp.where(u > 0, jnp.arctan(root_pos) / root_pos, jnp.arctanh(root_neg) / root_neg)
    series = _series_near_zero(u, [(-1) ** k / (2 * k + 1) for k in range(9)])
    return jnp.where(small, series, exact)


def _sin_ratio(r, t):
    """`sin(sqrt(r) t)/sqrt(r)` continued to `sinh(sqrt(-r) t)/sqrt(-r)` for `r < 0`."""
    z = r * t**2
    small = jnp.abs(z) < 1e-2
    root_pos = jnp.sqrt(jnp.where(small | (r < 0), 1.0, r))
    root_neg = jnp.sqrt(jnp.where(small | (r > 0), 1.0, -r))
    exact = jnp.where(r > 0, jnp.sin(root_pos * t) / root_pos, jnp.sinh(root_neg * t) / root_neg)
    factorials = [1, 6, 120, 5040, 362880, 39916800, 6227020800]
    series = t * _series_near_zero(-z, [1 / f for f in factorials])
    return jnp.where(small, series, exact)


def _cos_continued(r, t):
    """`cos(sqrt(r) t)`, continued to `cosh(sqrt(-r) t)` for `r < 0`."""
    z = r * t**2
    small = jnp.abs(z) < 1e-2
    root_pos = jnp.sqrt(jnp.where(small | (r < 0), 1.0, r))
    root_neg = jnp.sqrt(jnp.where(small | (r > 0), 1.0, -r))
    exact = jnp.where(r > 0, jnp.cos(root_pos * t), jnp.cosh(root_neg * t))
    factorials = [1, 2, 24, 720, 40320, 3628800, 479001600]
    series = _series_near_zero(-z, [1 / f for f in factorials])
    return jnp.where(small, series, exact)


# |r| below this: the C/S forms (no cancellation between the modes near critical damping)
_NEAR = 1e-4
_BISECTIONS = 64  # halvings of a bracket: 2^-64 of its width, below float64's resolution


def _first_zero(k, r):
    """First `tau > 0` where `C(tau) = k S(tau)` (`C = cos(sqrt(r) tau)`,
    `S = sin(sqrt(r) tau)/sqrt(r)`, continued to cosh/sinh for `r < 0`), and whether it
    exists: always when `r > 0`; for `r <= 0` only when `k > sqrt(-r)`.
    `atan(sqrt(r)/k)/sqrt(r)` for `k > 0` (through `_arctan_ratio`), `atan2(sqrt(r), k)/sqrt(r)`
    otherwise."""
    k_pos = k > 0
    k_safe = jnp.where(k_pos, k, 1.0)
    u = r / k_safe**2
    exists_pos = k_pos & (u > -1.0)
    t_pos = _arctan_ratio(jnp.where(exists_pos, u, 0.0)) / k_safe
    under = r > 0
    w = jnp.sqrt(jnp.where(under, r, 1.0))
    t_neg = jnp.arctan2(w, jnp.where(under & ~k_pos, k, -1.0)) / w
    return jnp.where(k_pos, t_pos, t_neg), exists_pos | under


def _state(s, r, y0, v0, t):
    """`(Y, V)` at `t` of `Y'' + 2 s Y' + Y = 0` (`r = 1 - s^2`) from `(y0, v0)` at 0.

    `Y = exp(-s t) (y0 C + (v0 + s y0) S)`, `V = exp(-s t) (v0 C - (y0 + s v0) S)`;
    far over-damped (`r < -1e-4`) as two single exponentials (`l2 = -s - q`, `l1 = 1/l2`),
    which neither overflow at long times nor cancel."""
    far = r < -_NEAR
    q = jnp.sqrt(jnp.where(far, -r, 1.0))
    fast = -jnp.where(far, s, 1.0) - q
    slow = 1.0 / fast
    gap = slow - fast
    a1 = (v0 - fast * y0) / gap
    a2 = (slow * y0 - v0) / gap
    t_far = jnp.where(far, t, 0.0)
    e1, e2 = jnp.exp(slow * t_far), jnp.exp(fast * t_far)
    y_far = a1 * e1 + a2 * e2
    v_far = slow * a1 * e1 + fast * a2 * e2
    r_near = jnp.where(far, 0.0, r)
    t_near = jnp.where(far, 0.0, t)
    decay = jnp.exp(-s * t_near)
    cos_, sin_ = _cos_continued(r_near, t_near), _sin_ratio(r_near, t_near)
    y_near = decay * (y0 * cos_ + (v0 + s * y0) * sin_)
    v_near = decay * (v0 * cos_ - (y0 + s * v0) * sin_)
    return jnp.where(far, y_far, y_near), jnp.where(far, v_far, v_near)


def _monotone_root(h, args, lo, hi, increasing=False, fast=None):
    """The root of `h(t, args)`, which changes sign once on `[lo, hi]` (from positive to
    negative, or the other way when `increasing`), by bisection to the last bit with the
    arguments frozen, then one Newton step with them live: its value moves by rounding
    only, and its derivative is the implicit one, `-(dh/dargs)/(dh/dt)`. A bracket without
    a root gives one of its ends, with no derivative (callers discard it; the Newton step
    from there, which may leave the bracket by far, is not taken); a flat `h` there gives
    no NaN. Elementwise on arrays. `fast`: the same function written more cheaply for the
    frozen evaluations (equal to rounding; `h`, with care for the derivatives, gives the
    last step)."""
    frozen = jax.lax.stop_gradient(args)
    lo, hi = jax.lax.stop_gradient(lo), jax.lax.stop_gradient(hi)
    width = hi - lo

    def halve(_, bounds):
        a, b = bounds
        mid = 0.5 * (a + b)
        value = (fast or h)(mid, frozen)
        left = (value < 0) if not increasing else (value > 0)
        return jnp.where(left, a, mid), jnp.where(left, mid, b)

    lo, hi = jax.lax.fori_loop(0, _BISECTIONS, halve, (lo, hi))
    t = 0.5 * (lo + hi)
    value, slope = jax.jvp(lambda t: h(t, args), (t,), (jnp.ones_like(t),))
    slope = jax.lax.stop_gradient(slope)
    good = jnp.isfinite(slope) & (jnp.abs(slope) > 1e-300)
    step = jnp.where(good, value / jnp.where(good, slope, 1.0), 0.0)
    # at a root the step is a rounding correction; a larger one means no root here
    polish = jnp.abs(jax.lax.stop_gradient(step)) <= 1e-3 * width
    return t - jnp.where(polish, step, 0.0)


def _newton_root(h, args, start, steps=40):
    """A root of `h(t, args)` by Newton from `start` (arguments frozen), then one step
    with them live (the implicit derivative). Returns `(t, converged)`."""
    frozen = jax.lax.stop_gradient(args)

    def newton(_, t):
        value, slope = jax.jvp(lambda t: h(t, frozen), (t,), (jnp.ones_like(t),))
        good = jnp.isfinite(value) & jnp.isfinite(slope) & (jnp.abs(slope) > 1e-300)
        step = jnp.where(good, value / jnp.where(good, slope, 1.0), 0.0)
        return jnp.maximum(t - step, 0.5 * t)  # never through 0 (times are > 0)

    t = jax.lax.fori_loop(0, steps, newton, jax.lax.stop_gradient(start))
    value, slope = jax.jvp(lambda t: h(t, args), (t,), (jnp.ones_like(t),))
    slope = jax.lax.stop_gradient(slope)
    converged = jnp.isfinite(value) & (jnp.abs(value) < 1e-9)
    good = converged & jnp.isfinite(slope) & (jnp.abs(slope) > 1e-300)
    return t - jnp.where(good, value / jnp.where(good, slope, 1.0), 0.0), converged
