"""A user's law with its constant powers made cheap: `x**1.5` as `x * sqrt(x)`.

People write force laws with `x**1.5`, `jnp.power(x, 2.5)` or `x**0.5`, which JAX traces
as XLA's `pow` with a literal exponent. On CPU, `pow` with a non-integer exponent costs
about 10x a square root and a multiply, and a law is evaluated hundreds of times per
impact: the law, not the solver, bounds a batch (shared/notes/performance-4.md).

`fast_powers(fn)` reads the function's jaxpr, as `clamps.unclamped` does, and evaluates
it equation by equation, every primitive bound as traced except `pow` whose exponent is a
constant multiple of 1/2 (`|p| <= 8`): that one becomes `_powers.half_power`, a square
root and multiplies (`x^1.5 = x sqrt(x)`, `x^2.5 = x (x sqrt(x))`, `x^2.0 = x x`), whose
value and derivative are within a few ulps of `pow`'s. `integer_pow`, `sqrt` and `rsqrt`
stay as they are; an exponent that is traced (`jnp.power(x, p["n"])`) or general (0.25,
1.3) stays `pow`. The bodies of `jit` calls (`jnp.where`, `jnp.clip`, a user's jitted
helper) are evaluated inline with the same rule; other higher-order primitives (`cond`,
`scan`, `custom_jvp_call`) are bound as they are.
"""

from collections.abc import Callable

import jax
import numpy as np
from jax.extend import core as jex_core

from .._powers import half_power, half_steps

# call primitives whose body is evaluated inline, with the parameter that holds it
_CALLS = {"jit": "jaxpr", "pjit": "jaxpr", "closed_call": "call_jaxpr", "core_call": "call_jaxpr"}


def fast_powers(fn: Callable) -> Callable:
    """`fn(*args)` with `pow(x, p)` of a constant `p = k/2` evaluated by `half_power`.

    The returned function takes and returns what `fn` does and composes with `jit`,
    `vmap` and `grad`. The values are `fn`'s to a few ulps for `x >= 0` (where `pow` is
    real; for `x < 0` both are NaN). Where `fn` cannot be traced (it reads a concrete
    value), it is called as it is.

    **Example**: `fast_powers(lambda x, v, p: p["c"] * x**1.5)(4.0, 0.0, {"c": 2.0})` is
    `16.0`, computed as `2 * (4 * sqrt(4))`.
    """

    def rewritten(*args):
        try:
            closed, out_shape = jax.make_jaxpr(fn, return_shape=True)(*args)
        except Exception:  # not traceable: the function as written (its own errors surface)
            return fn(*args)
        flat = jax.tree_util.tree_leaves(args)
        out = _evaluate(closed.jaxpr, closed.consts, flat)
        return jax.tree_util.tree_unflatten(jax.tree_util.tree_structure(out_shape), out)

    return rewritten


def constant_half_steps(eqn, constants) -> int | None:
    """`2 p` for an equation `pow(x, p)` whose exponent `p` is a constant multiple of 1/2
    (a literal, a concrete scalar constant of the jaxpr, or a call's argument that is
    one: `constants`, by variable); `None` otherwise."""
    if eqn.primitive.name != "pow" or not np.issubdtype(eqn.outvars[0].aval.dtype, np.floating):
        return None
    value = _constant(eqn.invars[1], constants)
    if value is None:
        return None
    value = np.asarray(value)
    if value.ndim != 0 or not np.issubdtype(value.dtype, np.floating):
        return None
    return half_steps(float(value))


def _constant(atom, constants):
    """The value of `atom` where it is known when the law is read, else `None`."""
    if isinstance(atom, jex_core.Literal):
        return atom.val
    value = constants.get(atom)
    return None if isinstance(value, jax.core.Tracer) else value


def _evaluate(jaxpr, consts, args, constants=None):
    """Evaluate `jaxpr` at `args` (its flat inputs), with the rewrite (see the module);
    `constants`: the inputs known when the law is read (the literals of a call)."""
    constants = {**dict(zip(jaxpr.constvars, consts, strict=False)), **(constants or {})}
    env = dict(zip(jaxpr.constvars, consts, strict=False))
    env.update(zip(jaxpr.invars, args, strict=False))

    def read(atom):
        return atom.val if isinstance(atom, jex_core.Literal) else env[atom]

    for eqn in jaxpr.eqns:
        invals = [read(a) for a in eqn.invars]
        k = constant_half_steps(eqn, constants)
        body = call_body(eqn)
        with eqn.ctx.manager:
            if k is not None:
                values = [_as(half_power(invals[0], k), eqn.outvars[0].aval.dtype)]
            elif body is not None:
                inner, inner_consts = body
                known = {
                    var: value
                    for var, atom in zip(inner.invars, eqn.invars, strict=False)
                    if (value := _constant(atom, constants)) is not None
                }
                values = _evaluate(inner, inner_consts, invals, known)
            else:
                values = eqn.primitive.bind(*invals, **eqn.primitive.get_bind_params(eqn.params))
                if not eqn.primitive.multiple_results:
                    values = [values]
        env.update(zip(eqn.outvars, values, strict=False))
    return [read(a) for a in jaxpr.outvars]


def _as(value, dtype):
    return value if value.dtype == dtype else value.astype(dtype)


def call_body(eqn, calls=None):
    """`(jaxpr, consts)` of the body of a call primitive named in `calls` (primitive name
    -> the parameter that holds its body; default: the `jit` calls evaluated inline here),
    or `None`."""
    key = (_CALLS if calls is None else calls).get(eqn.primitive.name)
    if key is None or key not in eqn.params:
        return None
    body = eqn.params[key]
    if hasattr(body, "jaxpr"):  # a ClosedJaxpr
        return body.jaxpr, body.consts
    return body, []
