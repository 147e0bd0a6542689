"""Choosing how to differentiate through diffrax's solve.

diffrax's default `RecursiveCheckpointAdjoint` serves reverse mode (`jax.grad`) and is the
fastest for a plain solve; `ForwardMode` serves `jax.jvp` / `jax.jacfwd` and is 2-4 times
cheaper than reverse mode for a few parameters; `DirectAdjoint` serves both but makes a
plain solve about 3 times slower (measured: 63 / 86 / 182 us per Hertz contact). `auto_adjoint`
looks at the tracers it is given and picks the cheapest one that works.
"""

import diffrax as dfx
import jax
from jax._src.interpreters import ad as _ad, batching as _batching

from .._checks import is_traced


def _tracer_kinds(leaf, kinds: set):
    while is_traced(leaf):
        if isinstance(leaf, _ad.JVPTracer):
            kinds.add("forward")
        elif type(leaf).__name__ == "LinearizeTracer":
            kinds.add("reverse")
        if isinstance(leaf, (_ad.JVPTracer,)) or type(leaf).__name__ == "LinearizeTracer":
            leaf = leaf.primal
        elif isinstance(leaf, _batching.BatchTracer):
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
