"""`auto_adjoint`: the diffrax adjoint picked for the transformation a solve is traced under,
read through public JAX names only. The solves themselves are differentiated in
test_gradients.py (jacfwd, vmap(grad)), test_bounce.py and fit/test_fit_bounces.py."""

import ast
import inspect

import diffrax as dfx
import jax
import jax.numpy as jnp
import pytest

from jaximpact._solve import adjoint
from jaximpact._solve.adjoint import auto_adjoint

FORWARD, REVERSE, BOTH = dfx.ForwardMode, dfx.RecursiveCheckpointAdjoint, dfx.DirectAdjoint


def chosen(transform):
    """The adjoint `auto_adjoint` picks inside `transform(f)`, `f` a scalar function of a
    vector."""
    seen = []

    def f(x):
        seen.append(type(auto_adjoint({"x": x}, 1.0)))
        return jnp.sum(jnp.sin(x) ** 2)

    transform(f)
    return seen[-1]


X = jnp.arange(1.0, 4.0)
TRANSFORMS = {
    "none": (lambda f: f(X), REVERSE),
    "jit": (lambda f: jax.jit(f)(X), REVERSE),
    "vmap": (lambda f: jax.vmap(f)(X[:, None]), REVERSE),
    "jvp": (lambda f: jax.jvp(f, (X,), (X,)), FORWARD),
    "jacfwd": (lambda f: jax.jacfwd(f)(X), FORWARD),
    "grad": (lambda f: jax.grad(f)(X), REVERSE),
    "jacrev": (lambda f: jax.jacrev(f)(X), REVERSE),
    "vjp": (lambda f: jax.vjp(f, X)[1](1.0), REVERSE),
    "linearize": (lambda f: jax.linearize(f, X), REVERSE),
    "hessian": (lambda f: jax.hessian(f)(X), BOTH),
    "jacrev(jacfwd)": (lambda f: jax.jacrev(jax.jacfwd(f))(X), BOTH),
    "vmap(grad)": (lambda f: jax.vmap(jax.grad(f))(X[:, None]), REVERSE),
    "grad(vmap)": (lambda f: jax.grad(lambda x: jnp.sum(jax.vmap(f)(x)))(X[:, None]), REVERSE),
    "vmap(jacfwd)": (lambda f: jax.vmap(jax.jacfwd(f))(X[:, None]), FORWARD),
    "jacfwd(vmap)": (lambda f: jax.jacfwd(lambda x: jax.vmap(f)(x))(X[:, None]), FORWARD),
    "jit(jacfwd)": (lambda f: jax.jit(jax.jacfwd(f))(X), FORWARD),
    # traced by jit before jacfwd is known: the documented case for `adjoint=`
    "jacfwd(jit)": (lambda f: jax.jacfwd(jax.jit(f))(X), REVERSE),
}


@pytest.mark.parametrize("name", TRANSFORMS)
def test_the_adjoint_follows_the_transformation(name):
    transform, expected = TRANSFORMS[name]
    assert chosen(transform) is expected


def test_only_the_inputs_tracers_count():
    """A closed-over traced value that is not passed does not change the choice; one that
    is passed does."""

    def g(x, y):
        seen = (type(auto_adjoint(1.0)), type(auto_adjoint(x)), type(auto_adjoint((1.0, x))))
        assert seen == (REVERSE, FORWARD, FORWARD)
        return x * y

    jax.jvp(lambda x: g(x, 2.0), (1.0,), (1.0,))


def test_no_private_jax_import():
    """The module reads tracers through public JAX names (not `jax._src`)."""
    tree = ast.parse(inspect.getsource(adjoint))
    modules = [
        node.module if isinstance(node, ast.ImportFrom) else alias.name
        for node in ast.walk(tree)
        if isinstance(node, (ast.Import, ast.ImportFrom))
        for alias in node.names
    ]
    assert not [m for m in modules if m and m.startswith("jax._src")], modules
