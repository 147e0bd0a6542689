"""Choosing how to differentiate through diffrax's solve.

diffrax's default `RecursiveCheckpointAdjoint` serves reverse mode (`jax.grad`) and is the
fastest for a plain solve; `ForwardMode` serves `jax.jvp` / `jax.jacfwd` and is 2-4 times
cheaper than reverse mode for a few parameters; `DirectAdjoint` serves both but makes a
plain solve about 3 times slower (measured: 63 / 86 / 182 us per Hertz contact). `auto_adjoint`
looks at the tracers it is given and picks the cheapest one that works.

Reverse mode alone (`jax.grad`, `jax.vjp`, and `jax.jit` of them) goes through
`by_forward_jacobian`: the solve is differentiated in forward mode (`ForwardMode`, one
tangent per differentiated input) and `jax.grad` transposes `J @ dtheta`. Measured for a
user's law (benchmarks/general_path.md): a jitted `jax.grad` of `e` takes 0.5 ms against
5.9 ms through `RecursiveCheckpointAdjoint`, and the first call compiles in 7.1 s against
11.6 s.

Only public JAX names are used: `jax.core.Tracer` (through `is_traced`) and
`jax.interpreters.ad.JVPTracer` (forward mode). JAX exports no name for the tracers of
reverse mode (`jax.grad`, `jax.vjp` and `jax.linearize` trace through a `LinearizeTracer`)
or of `jax.vmap` (a `BatchTracer`), so those two are recognised by their class's name, and
looked through by the attribute that holds the value they wrap (`primal`, `val`); a tracer
of any other kind (`jit`'s) ends the walk.
"""

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import jax.tree_util as jtu
from jax.interpreters.ad import JVPTracer

from .._checks import is_traced


def _is_a(leaf, class_name: str) -> bool:
    return any(cls.__name__ == class_name for cls in type(leaf).__mro__)


def _tracer_kinds(leaf, kinds: set):
    """Add to `kinds` the differentiation modes ("forward", "reverse") that `leaf` is traced
    under, looking through every transformation between it and its value."""
    while is_traced(leaf):
        if isinstance(leaf, JVPTracer):
            kinds.add("forward")
            leaf = leaf.primal
        elif _is_a(leaf, "LinearizeTracer"):
            kinds.add("reverse")
            leaf = leaf.primal
        elif _is_a(leaf, "BatchTracer"):
            leaf = leaf.val
        else:
            break
    return kinds


def differentiation_kinds(*trees) -> set:
    """The differentiation modes (`"forward"`, `"reverse"`) the leaves of `trees` are
    traced under; empty where none is differentiated."""
    kinds: set = set()
    for leaf in jax.tree_util.tree_leaves(trees):
        _tracer_kinds(leaf, kinds)
    return kinds


def reverse_only(*trees) -> bool:
    """Whether the leaves of `trees` are traced by reverse-mode differentiation and no
    forward mode (`jax.grad`, `jax.vjp`; through `vmap` too)."""
    return differentiation_kinds(*trees) == {"reverse"}


def _is_none(x) -> bool:
    return x is None


@eqx.filter_custom_jvp
def by_forward_jacobian(args, *, fn):
    """`fn(*args)` (a pytree of arrays), differentiated through the forward-mode Jacobian
    of `fn` with respect to the inputs that carry a tangent: the rule returns
    `J @ dargs`, which is linear in the tangent, so `jax.grad` transposes it. `fn` must
    differentiate in forward mode (a diffrax solve with `ForwardMode`)."""
    return fn(*args)


@by_forward_jacobian.def_jvp
def _forward_jacobian_rule(primals, tangents, *, fn):
    (args,), (t_args,) = primals, tangents
    leaves, treedef = jtu.tree_flatten(args, is_leaf=_is_none)
    t_leaves = treedef.flatten_up_to(t_args)
    moved = [i for i, t in enumerate(t_leaves) if t is not None]
    sizes = [jnp.size(leaves[i]) for i in moved]
    theta = jnp.concatenate([jnp.ravel(leaves[i]) for i in moved])
    d_theta = jnp.concatenate([jnp.ravel(t_leaves[i]) for i in moved])

    def at(flat):
        new = list(leaves)
        start = 0
        for i, size in zip(moved, sizes, strict=True):
            new[i] = jnp.reshape(flat[start : start + size], jnp.shape(leaves[i]))
            start += size
        out = fn(*jtu.tree_unflatten(treedef, new))
        return eqx.filter(out, eqx.is_inexact_array), out

    if theta.shape == (1,):  # one scalar input: one jvp, no batch over the directions
        _, column, out = jax.jvp(at, (theta,), (jnp.ones_like(theta),), has_aux=True)
        jacobian = jax.tree.map(lambda c: c[..., None], column)
    else:
        jacobian, out = jax.jacfwd(at, has_aux=True)(theta)
    return out, jax.tree.map(lambda j: j @ d_theta, jacobian)


def through_forward_jacobian(fn, *args, closes_over: bool = True):
    """`fn(*args)` differentiated in reverse mode through `by_forward_jacobian`; `fn` must
    solve with `ForwardMode`. `closes_over`: `fn` may close over traced values (a user's
    force written with one), which are then made inputs (`jax.closure_convert`, one more
    trace of `fn`); a law of the table never does."""
    if not closes_over:
        return by_forward_jacobian(args, fn=fn)
    converted, closed = jax.closure_convert(fn, *args)
    return by_forward_jacobian((*args, *closed), fn=converted)


def auto_adjoint(*trees) -> dfx.AbstractAdjoint:
    """The adjoint for a solve whose inputs are `trees`.

    Forward-mode tracers only: `ForwardMode`; forward and reverse (e.g. `jax.hessian`):
    `DirectAdjoint`; otherwise `RecursiveCheckpointAdjoint`. Pass `adjoint=` to `impact`
    to choose yourself (needed for `jax.jacfwd(jax.jit(f))`, where the solve is traced
    before the transformation is known).
    """
    kinds = differentiation_kinds(*trees)
    if kinds == {"forward"}:
        return dfx.ForwardMode()
    if "forward" in kinds:
        return dfx.DirectAdjoint()
    return dfx.RecursiveCheckpointAdjoint()
