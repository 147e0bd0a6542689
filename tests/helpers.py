"""Shared test helpers: tolerance checks, the seed paper's parameter sets, and compiled solves.

Compilation dominates the cost of this suite (1.5-5 s per distinct trace, 5-20 s for a
gradient), so every test that needs an impact goes through the same few option sets
(see `solver`): a law compiles once per session, whatever parameter values, masses and
speeds the tests ask for.
"""

import jax
import jax.numpy as jnp
import numpy as np

import jaximpact as ji
from jaximpact._paper.cases import LOOPS, V0, M  # noqa: F401 (M, V0: for the tests)

# (law name, parameters, e printed in the paper or None, figure), from the library's one copy
# of the paper's conditions (Polukoshko et al. 2007), plus one under-damped point of fig. 7,
# a map of T(b, c), e(b, c) with no single parameter set
PAPER_SETS = [
    (case.law, case.params, case.printed, case.figure + (" (text)" if "text" in case.note else ""))
    for case in LOOPS
]
PAPER_SETS.insert(6, ("maxwell", dict(c=2e6, b=2000.0), None, "7"))


def paper_id(row) -> str:
    """A readable pytest id for a `PAPER_SETS` row."""
    name, params, _, figure = row
    return f"{name}[fig{figure.split()[0]}{'-text' if 'text' in figure else ''}]"


PAPER_IDS = [paper_id(row) for row in PAPER_SETS]


# --------------------------------------------------------------------------- tolerances


def rel_err(actual, expected) -> float:
    """Largest relative error `|a - b| / |b|` (`|a - b|` where `b == 0`)."""
    a = np.asarray(actual, dtype=float)
    b = np.asarray(expected, dtype=float)
    scale = np.where(b == 0, 1.0, np.abs(b))
    return float(np.max(np.abs(a - b) / scale))


def assert_rel(actual, expected, rtol, what="value", atol=0.0):
    """Assert `|actual - expected| <= rtol |expected| + atol` elementwise, with a message that
    names the quantity and gives the achieved relative error."""
    a = np.asarray(actual, dtype=float)
    b = np.asarray(expected, dtype=float)
    assert a.shape == b.shape or a.size == b.size == 1, f"{what}: shape {a.shape} != {b.shape}"
    assert np.all(np.isfinite(a)), f"{what}: not finite: {a}"
    bad = np.abs(a - b) > rtol * np.abs(b) + atol
    assert not np.any(bad), (
        f"{what}: relative error {rel_err(a, b):.3e} > rtol {rtol:.1e} (atol {atol:.1e}); "
        f"got {a}, expected {b}"
    )
    return rel_err(a, b)


def assert_finite(tree, what="result"):
    """Assert that every array leaf of `tree` is finite (no NaN, no inf)."""
    for path, leaf in jax.tree_util.tree_flatten_with_path(tree)[0]:
        arr = np.asarray(leaf)
        if arr.dtype.kind in "fc":
            assert np.all(np.isfinite(arr)), f"{what}{jax.tree_util.keystr(path)}: {arr}"


# --------------------------------------------------------------------------- solves
#
# `impact` compiles itself (an `eqx.filter_jit` keyed by the law's name, the options and
# the shapes), with the law's parameters, m, v0 and g as traced arguments. The helpers
# below call it eagerly with the same options everywhere, so that each (law, separation,
# rtol, peaks) compiles once per session, for these tests and any other test alike; the
# tolerance `rtol` is a static option (a new compilation per value): the suite uses
# 1e-10 (the default), 1e-11 and 1e-12 only.

FIELDS = ("e", "T", "x_max", "t_max", "F_max", "dissipated", "v_out", "status", "num_steps")


def result_fields(result):
    return {k: getattr(result, k) for k in FIELDS if getattr(result, k) is not None}


def solver(name, separation="force", method="integrate", peaks=True, rtol=1e-10):
    """`f(params, m=M, v0=V0, g=0.0) -> dict` of numpy values of the `ImpactResult` fields."""

    def call(params, m=M, v0=V0, g=0.0):
        law = ji.law(name, **params)
        result = ji.impact(
            law, m=m, v0=v0, g=g, rtol=rtol, separation=separation, method=method, peaks=peaks
        )
        return {k: np.asarray(v) for k, v in result_fields(result).items()}

    return call


def e_and_T(name, separation="force", rtol=1e-10):
    """`f(params, m, v0) -> [e, T]` with `peaks=False` (what fitting uses), for `jax.jacfwd`,
    `jax.grad`, `jax.vmap`."""

    def f(params, m, v0):
        law = ji.law(name, **params)
        r = ji.impact(
            law, m=m, v0=v0, rtol=rtol, separation=separation, peaks=False, method="integrate"
        )
        return jnp.stack([r.e, r.T])

    return f


def jacobian(name, mode="forward", separation="force", rtol=1e-10):
    """`J(params, m=M, v0=V0) -> (dparams, dm, dv0)` (numpy), each leaf of shape (2,) for
    (e, T): `jax.jacfwd` (`mode="forward"`) or `jax.jacrev` (`"reverse"`) of `e_and_T`."""
    transform = {"forward": jax.jacfwd, "reverse": jax.jacrev}[mode]
    jac = transform(e_and_T(name, separation, rtol), argnums=(0, 1, 2))

    def call(params, m=M, v0=V0):
        params = {k: jnp.asarray(v, dtype=float) for k, v in params.items()}
        out = jac(params, jnp.asarray(m, dtype=float), jnp.asarray(v0, dtype=float))
        return jax.tree_util.tree_map(np.asarray, out)

    return call


# ------------------------------------------------------------------ the command line


def run_cli(capsys, argv):
    """Run `jaximpact argv` in-process: (exit status, stdout, stderr)."""
    from jaximpact._cli import main

    try:
        status = main(argv)
    except SystemExit as exit:
        status = exit.code
    out, err = capsys.readouterr()
    return status, out, err


def assert_one_line_error(status, out, err, expected_status=2, contains=""):
    """The command line's bad-input contract: nothing on stdout, one line on stderr
    (`jaximpact: error: ...`, holding `contains`), exit status 2, no traceback."""
    assert status == expected_status, err
    assert out == "" and "Traceback" not in err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("jaximpact: error: "), err
    assert contains in lines[0], lines[0]


def primitive_names(fn, *args) -> list:
    """The primitive names of `fn`'s jaxpr in order, the bodies of calls, loops and
    branches included."""
    names = []

    def walk(jaxpr):
        for eqn in jaxpr.eqns:
            names.append(eqn.primitive.name)
            for value in eqn.params.values():
                for inner in value if isinstance(value, list | tuple) else [value]:
                    inner = getattr(inner, "jaxpr", inner)
                    if hasattr(inner, "eqns"):
                        walk(inner)

    walk(jax.make_jaxpr(fn)(*args).jaxpr)
    return names
