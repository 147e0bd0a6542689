"""Choosing how to differentiate through diffrax's solve.

diffrax's default `RecursiveCheckpointAdjoint` serves reverse mode (`jax.grad`) and is the
fastest for a plain solve; `ForwardMode` serves `jax.jvp` / `jax.jacfwd` and is 2-4 times
cheaper than reverse mode for a few parameters; `DirectAdjoint` serves both but makes a
plain solve about 3 times slower (measured: 63 / 86 / 182 us per Hertz contact). `auto_adjoint`
looks at the tracers it is given and picks the cheapest one that works.

Only public JAX names are used: `jax.core.Tracer` (through `is_traced`) and
`jax.interpreters.ad.JVPTracer` (forward mode). JAX exports no name for the tracers of
reverse mode (`jax.grad`, `jax.vjp` and `jax.linearize` trace through a `LinearizeTracer`)
or of `jax.vmap` (a `BatchTracer`), so those two are recognised by their class's name, and
looked through by the attribute that holds the value they wrap (`primal`, `val`); a tracer
of any other kind (`jit`'s) ends the walk.
"""

import diffrax as dfx
import jax
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


def auto_adjoint(*trees) -> dfx.AbstractAdjoint:
    """The adjoint for a solve whose inputs are `trees`.

    Forward-mode tracers only: `ForwardMode`; forward and reverse (e.g. `jax.hessian`):
    `DirectAdjoint`; otherwise `RecursiveCheckpointAdjoint`. Pass `adjoint=` to `impact`
    to choose yourself (needed for `jax.jacfwd(jax.jit(f))`, where the solve is traced
    before the transformation is known).
    """
    kinds: set = set()
    for leaf in jax.tree_util.tree_leaves(trees):
        _tracer_kinds(leaf, kinds)
    if kinds == {"forward"}:
        return dfx.ForwardMode()
    if "forward" in kinds:
        return dfx.DirectAdjoint()
    return dfx.RecursiveCheckpointAdjoint()
