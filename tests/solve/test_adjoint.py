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
from jaximpact._solve.adjoint import auto_adjoint, reverse_only

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


@pytest.mark.parametrize("name", TRANSFORMS)
def test_reverse_only_is_reverse_mode_alone(name):
    """`impact` differentiates through the forward Jacobian exactly where the adjoint
    would be diffrax's reverse one because of a reverse-mode tracer."""
    seen = []

    def f(x):
        seen.append(reverse_only({"x": x}, 1.0))
        return jnp.sum(jnp.sin(x) ** 2)

    TRANSFORMS[name][0](f)
    traced_by_reverse = name in {"grad", "jacrev", "vjp", "linearize", "vmap(grad)", "grad(vmap)"}
    assert seen[-1] is traced_by_reverse


@pytest.mark.slow
def test_grad_goes_through_the_forward_jacobian(monkeypatch):
    """`jax.grad` of an integrated impact (a user's law) is the forward-mode Jacobian,
    transposed: equal to central differences of the eager impact (rtol 1e-13), for the
    law's parameters, the mass and the speed, and for a value the force closes over
    (elasticities within 1e-5 relative, 1e-6 absolute)."""
    import jaximpact as ji

    calls = []
    wrapped = adjoint.by_forward_jacobian
    monkeypatch.setattr(
        adjoint, "by_forward_jacobian", lambda *a, **k: calls.append(1) or wrapped(*a, **k)
    )

    def e_and_T(c, a, m, v0, k):
        law = ji.custom_law(lambda x, v, p: k * p["c"] * x**1.5 * (1 + p["a"] * v), c=c, a=a)
        r = ji.impact(law, m=m, v0=v0, rtol=1e-13)
        return jnp.stack([r.e, r.T])

    point = (2e6, 0.3, 1.0, 2.5, 1.0)
    with jax.enable_x64(True):
        got = jax.jacrev(e_and_T, argnums=tuple(range(5)))(*point)
        assert calls, "jax.jacrev did not go through the forward Jacobian"
        for i, value in enumerate(point):
            h = 1e-6 * value
            up, down = list(point), list(point)
            up[i], down[i] = value + h, value - h
            fd = (e_and_T(*up) - e_and_T(*down)) / (2 * h)
            # as elasticities (d ln out / d ln value): de/dc is 0 (e depends on a v0)
            scale = value / jnp.abs(e_and_T(*point))
            assert jnp.allclose(got[i] * scale, fd * scale, rtol=1e-5, atol=1e-6), (i, got[i], fd)


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
