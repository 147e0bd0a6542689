"""A user's clamp read as data: the force a law computes before its last clamp at zero.

People write "the surface never pulls" as `jnp.maximum(F, 0)`, `jnp.clip(F, 0, None)`,
`jax.nn.relu(F)` or `jnp.where(F > 0, F, 0)`. The clamped force is what the body feels,
and it is integrated as written. But it reaches zero with a flat tail, so a root finder
cannot place the end of contact on it (Newton's step is 0/0 there). The unclamped `F`
crosses zero transversally at the same instant: the force criterion's event is set on it.

`unclamped(fn)` reads the function's jaxpr: where its result is a clamp at zero (`max`
with a zero, `clamp` with a zero floor, `select_n` with a zero case, inside `jit` or
`custom_jvp` calls as `jnp.clip` and `jax.nn.relu` write them), it returns a function that
evaluates everything else as written and returns the clamped operand. Otherwise `None`.
"""

from collections.abc import Callable

import jax
import numpy as np
from jax.extend import core as jex_core

from .fast_powers import call_body

# primitives that pass a zero through unchanged
_ZERO_PRESERVING = ("convert_element_type", "broadcast_in_dim", "reshape", "copy", "squeeze")
# call primitives, with the parameter that holds their body
_CALLS = {
    "jit": "jaxpr",
    "pjit": "jaxpr",
    "closed_call": "call_jaxpr",
    "custom_jvp_call": "call_jaxpr",
}


def unclamped(fn: Callable, params: dict) -> Callable | None:
    """`fn(x, v, params)` without its final clamp at zero, where its result (traced with
    `params`) is one; `None` otherwise (then the force itself ends contact). The returned
    function is traced like `fn`: it composes with `jit`, `vmap` and `grad`."""
    try:
        closed = jax.make_jaxpr(fn)(0.5, 0.5, params)
    except Exception:  # the law's own errors surface where it is evaluated
        return None
    if len(closed.jaxpr.outvars) != 1 or not _peel_target(closed.jaxpr, closed.consts):
        return None

    def peeled(x, v, params):
        closed = jax.make_jaxpr(fn)(x, v, params)
        flat = jax.tree_util.tree_leaves((x, v, params))
        return _peel(closed.jaxpr, closed.consts, flat, [False] * len(flat))

    return peeled


def _is_literal_zero(atom, consts_by_var, zeros) -> bool:
    if isinstance(atom, jex_core.Literal):
        return bool(np.all(np.asarray(atom.val) == 0))
    if atom in consts_by_var:
        value = consts_by_var[atom]
        if isinstance(value, jax.core.Tracer):  # a traced value closed over: not known zero
            return False
        return bool(np.all(np.asarray(value) == 0))
    return zeros.get(atom, False)


def _zero_flags(jaxpr, consts, invar_zeros):
    """Which variables of `jaxpr` are known to hold zeros (structurally)."""
    consts_by_var = dict(zip(jaxpr.constvars, consts, strict=False))
    zeros = dict(zip(jaxpr.invars, invar_zeros, strict=False))
    for eqn in jaxpr.eqns:
        if eqn.primitive.name in _ZERO_PRESERVING and len(eqn.invars) >= 1:
            zeros[eqn.outvars[0]] = _is_literal_zero(eqn.invars[0], consts_by_var, zeros)
    return zeros, consts_by_var


def _clamped_operand(eqn, consts_by_var, zeros):
    """The index of the operand that `eqn` clamps at zero, or `None`."""
    zero = [_is_literal_zero(a, consts_by_var, zeros) for a in eqn.invars]
    name = eqn.primitive.name
    if name == "max" and len(zero) == 2 and zero[0] != zero[1]:
        return 1 if zero[0] else 0
    if name == "clamp" and len(zero) == 3 and zero[0] and not zero[1]:
        return 1
    if name == "select_n" and len(zero) == 3 and zero[1] != zero[2]:
        return 1 if zero[2] else 2
    return None


def _peel_target(jaxpr, consts, invar_zeros=None):
    """Whether the result of `jaxpr` is a clamp at zero (looking through calls)."""
    invar_zeros = invar_zeros or [False] * len(jaxpr.invars)
    zeros, consts_by_var = _zero_flags(jaxpr, consts, invar_zeros)
    out = jaxpr.outvars[0]
    for eqn in jaxpr.eqns:
        if out not in eqn.outvars:
            continue
        if _clamped_operand(eqn, consts_by_var, zeros) is not None:
            return True
        body = _call_body(eqn)
        if body is not None and len(eqn.outvars) == 1:
            inner, inner_consts = body
            inner_zeros = [_is_literal_zero(a, consts_by_var, zeros) for a in eqn.invars]
            return _peel_target(inner, inner_consts, inner_zeros)
        return False
    return False


def _call_body(eqn):
    """A call's body, `custom_jvp` calls included (`jax.nn.relu` is one)."""
    return call_body(eqn, _CALLS)


def _peel(jaxpr, consts, args, invar_zeros):
    """Evaluate `jaxpr` at `args`, returning the operand of its final clamp at zero."""
    zeros, consts_by_var = _zero_flags(jaxpr, consts, invar_zeros)
    env = dict(zip(jaxpr.constvars, consts, strict=False))
    env.update(zip(jaxpr.invars, args, strict=False))

    def read(atom):
        return atom.val if isinstance(atom, jex_core.Literal) else env[atom]

    out = jaxpr.outvars[0]
    for eqn in jaxpr.eqns:
        invals = [read(a) for a in eqn.invars]
        if out in eqn.outvars:
            index = _clamped_operand(eqn, consts_by_var, zeros)
            if index is not None:
                return invals[index]
            body = _call_body(eqn)
            inner, inner_consts = body
            inner_zeros = [_is_literal_zero(a, consts_by_var, zeros) for a in eqn.invars]
            return _peel(inner, inner_consts, invals, inner_zeros)
        values = eqn.primitive.bind(*invals, **eqn.primitive.get_bind_params(eqn.params))
        if not eqn.primitive.multiple_results:
            values = [values]
        env.update(zip(eqn.outvars, values, strict=False))
    raise AssertionError("the clamp was found when the law was read, but not evaluated")
