"""Derivatives of e and T: against closed forms, central finite differences, and between
forward and reverse mode.

Automatic derivatives run at the default `rtol=1e-10` (what a user gets); finite
differences of `impact` at `rtol=1e-12`, with a relative step of 1e-5 (truncation
~1e-10, solver noise ~1e-12/1e-5 = 1e-7 in the elasticities). Derivatives are compared as
elasticities `S = (d f / d p) p / f`, which are O(0.01-1) here and dimensionless, with a
relative tolerance and an absolute floor for derivatives that vanish (Maxwell's and
Kelvin-Voigt's e and T do not depend on v0, Hunt-Crossley's e not on c).
"""

import jax
import jax.numpy as jnp
import numpy as np
import pytest
from helpers import (
    PAPER_IDS,
    PAPER_SETS,
    V0,
    M,
    assert_finite,
    assert_rel,
    e_and_T,
    jacobian,
    solver,
)

import jaximpact as ji
from jaximpact import closed_forms

FD_RTOL = 1e-12
FD_STEP = 1e-5


def as_dict(jac):
    """`(dparams, dm, dv0)` -> one dict by argument name, each value `[de, dT]`."""
    dparams, dm, dv0 = jac
    out = {k: np.asarray(v) for k, v in dparams.items()}
    out["m"], out["v0"] = np.asarray(dm), np.asarray(dv0)
    return out


def finite_differences(name, params, m=M, v0=V0, step=FD_STEP):
    """Central differences of [e, T] in every parameter, m and v0 (relative step)."""
    run = solver(name, "force", rtol=FD_RTOL)
    args = dict(params, m=m, v0=v0)

    def value(a):
        r = run({k: a[k] for k in params}, m=a["m"], v0=a["v0"])
        assert int(r["status"]) == ji.Status.separated
        return np.array([r["e"], r["T"]])

    out = {}
    for key, x in args.items():
        up, down = dict(args), dict(args)
        up[key], down[key] = x * (1 + step), x * (1 - step)
        out[key] = (value(up) - value(down)) / (2 * step * x)
    return out, value(args)


def assert_elasticities(got, want, args, values, rtol, floor, what):
    """Compare `d[e, T]/dp` as elasticities; returns the worst absolute difference."""
    worst = 0.0
    assert set(got) == set(want), (set(got), set(want))
    for key in want:
        s_got = np.asarray(got[key]) * args[key] / values
        s_want = np.asarray(want[key]) * args[key] / values
        assert np.all(np.isfinite(s_got)), f"{what} d/d{key}: {s_got}"
        diff = np.abs(s_got - s_want)
        worst = max(worst, float(np.max(diff)))
        assert np.all(diff <= rtol * np.abs(s_want) + floor), (
            f"{what} d[e, T]/d{key}: elasticities {s_got} vs {s_want} (difference {diff})"
        )
    return worst


# ------------------------------------------------------------ Kelvin-Voigt: exact


def kelvin_voigt_exact(c, b, m, v0, separation="force"):
    """[e, T] of Kelvin-Voigt: `closed_forms.kelvin_voigt` under the force criterion (eq. 5);
    the paper's formulas under the penetration criterion (under-damped only), since the
    closed form's gradients are NaN there (test_closed_form_penetration_gradients_finite)."""
    if separation == "force":
        fields = closed_forms.kelvin_voigt(c, b, m, v0, separation)
        return jnp.stack([fields["e"], fields["T"]])
    root = jnp.sqrt(4 * m * c - b**2)
    return jnp.stack([jnp.exp(-jnp.pi * b / root), 2 * jnp.pi * m / root])


# the paper's set, light damping, and (force criterion only) over-damped
KV_MEMBERS = {
    "force": [(2e6, 400.0), (1e4, 20.0), (1e4, 150.0), (1e4, 1000.0)],
    "penetration": [(2e6, 400.0), (1e4, 20.0), (1e4, 150.0)],
}


def kelvin_voigt_check(separation):
    """Per member: jacfwd (forward) and vmap(grad) (reverse) of the integrated e and T
    against jax.grad of the closed form (1e-6), and against each other (1e-9).

    Reverse mode runs as one `jax.vmap(jax.grad(w . [e, T]))` over (member, w) pairs, w the
    unit vectors: a single compilation gives both rows of every member's Jacobian."""
    f = e_and_T("kelvin_voigt", separation)
    members = KV_MEMBERS[separation]
    cs = np.repeat([c for c, _ in members], 2)
    bs = np.repeat([b for _, b in members], 2)
    ws = np.tile(np.eye(2), (len(members), 1))

    def weighted(params, m, v0, w):
        return jnp.dot(w, f(params, m, v0))

    grads = jax.vmap(jax.grad(weighted, argnums=(0, 1, 2)), in_axes=(0, None, None, 0))(
        dict(c=jnp.asarray(cs), b=jnp.asarray(bs)),
        jnp.asarray(M),
        jnp.asarray(V0),
        jnp.asarray(ws),
    )
    assert_finite(grads, "vmap(grad) Kelvin-Voigt")
    reverse_all = as_dict(grads)
    worst = {"forward": 0.0, "reverse": 0.0, "forward-reverse": 0.0}
    for k, (c, b) in enumerate(members):
        args = dict(c=c, b=b, m=M, v0=V0)
        exact = {}
        for name, j in zip(("c", "b", "m", "v0"), range(4), strict=True):
            exact[name] = np.array(
                [
                    jax.grad(lambda *a, i=i: kelvin_voigt_exact(*a, separation)[i], argnums=j)(
                        c, b, M, V0
                    )
                    for i in range(2)
                ]
            )
        values = np.asarray(kelvin_voigt_exact(c, b, M, V0, separation))
        forward = as_dict(jacobian("kelvin_voigt", "forward", separation)(dict(c=c, b=b)))
        reverse = {key: v[2 * k : 2 * k + 2] for key, v in reverse_all.items()}
        what = f"KV {separation} c={c} b={b}"
        # over-damped (b = 1000): T is ill-conditioned under the force criterion (F crosses
        # zero with slope c e v0, e = 0.009), and so is its derivative: measured 2.6e-5
        # relative in dT/dc at rtol 1e-10 (the value of T: 2e-7); else < 1e-8
        rtol = 1e-6 if b * b < 4 * c * M else 1e-4
        worst["forward"] = max(
            worst["forward"],
            assert_elasticities(forward, exact, args, values, rtol, 1e-9, f"{what} forward"),
        )
        worst["reverse"] = max(
            worst["reverse"],
            assert_elasticities(reverse, exact, args, values, rtol, 1e-9, f"{what} reverse"),
        )
        worst["forward-reverse"] = max(
            worst["forward-reverse"],
            assert_elasticities(
                forward, reverse, args, values, 1e-9, 1e-12, f"{what} forward vs reverse"
            ),
        )
    return worst


@pytest.mark.slow
def test_kelvin_voigt_gradients_match_the_closed_form():
    kelvin_voigt_check("force")


@pytest.mark.slow
def test_kelvin_voigt_gradients_match_the_closed_form_penetration():
    kelvin_voigt_check("penetration")


@pytest.mark.slow
@pytest.mark.parametrize("c, b", [(1e4, 20.0), (1e4, 100.0)])
def test_closed_form_penetration_gradients_finite(c, b):
    """Under-damped Kelvin-Voigt under the penetration criterion. NaN for damping ratios
    0.1, 0.3, 0.5 (and over-damped 5); finite for 0.05, 0.1414 (the paper's set), 0.2, 0.7."""
    exact = jax.jacrev(kelvin_voigt_exact, argnums=(0, 1))(c, b, M, V0, "penetration")

    def through_impact(c, b):
        r = ji.impact(ji.law("kelvin_voigt", c=c, b=b), m=M, v0=V0, separation="penetration")
        return jnp.stack([r.e, r.T])

    def closed_form(c, b):
        fields = closed_forms.kelvin_voigt(c, b, M, V0, "penetration")
        return jnp.stack([fields["e"], fields["T"]])

    for f in (closed_form, through_impact):
        got = jax.jacrev(f, argnums=(0, 1))(c, b)
        assert_rel(np.array(got), np.array(exact), 1e-10, f"{f.__name__} reverse")
        got = jax.jacfwd(f, argnums=(0, 1))(c, b)
        assert_rel(np.array(got), np.array(exact), 1e-10, f"{f.__name__} forward")


@pytest.mark.slow  # moved from the fast suite to keep it near 3 minutes
def test_closed_form_path_differentiates():
    """`impact` on its closed-form path (Kelvin-Voigt, the default) is differentiable too."""

    def e(c, b):
        return ji.impact(ji.law("kelvin_voigt", c=c, b=b), m=M, v0=V0).e

    grad = jax.grad(e, argnums=(0, 1))(2e6, 400.0)
    exact = jax.grad(lambda c, b: kelvin_voigt_exact(c, b, M, V0)[0], argnums=(0, 1))(2e6, 400.0)
    assert_rel(np.array(grad), np.array(exact), 1e-13, "closed-form path gradient")
    critical = jax.grad(e, argnums=(0, 1))(1e4, 200.0)  # b^2 = 4 m c: NaN-free
    assert_finite(critical, "gradient at critical damping")


# ------------------------------------------------------ every law: finite differences

FAST_FD = ("hertz_rate",)  # the x^0.5 law (maxwell, hunt_crossley and the rest: slow)


def fd_check(row):
    name, params, _, _ = row
    fd, values = finite_differences(name, params)
    ad = as_dict(jacobian(name, "forward")(params))
    args = dict(params, m=M, v0=V0)
    # measured worst elasticity difference: 1.3e-7 (hunt_crossley), else < 1e-9
    return assert_elasticities(ad, fd, args, values, 1e-5, 1e-6, f"{name} AD vs FD")


@pytest.mark.parametrize(
    "row",
    [row for row in PAPER_SETS if row[0] in FAST_FD],
    ids=[i for i, row in zip(PAPER_IDS, PAPER_SETS, strict=True) if row[0] in FAST_FD],
)
def test_forward_gradients_match_finite_differences(row):
    fd_check(row)


@pytest.mark.slow
@pytest.mark.parametrize(
    "row",
    [row for row in PAPER_SETS if row[0] not in FAST_FD + ("kelvin_voigt",)],
    ids=[
        i
        for i, row in zip(PAPER_IDS, PAPER_SETS, strict=True)
        if row[0] not in FAST_FD + ("kelvin_voigt",)
    ],
)
def test_forward_gradients_match_finite_differences_all_laws(row):
    fd_check(row)


@pytest.mark.slow
@pytest.mark.parametrize("row", PAPER_SETS, ids=PAPER_IDS)
def test_forward_and_reverse_agree_all_laws(row):
    name, params, _, _ = row
    forward = as_dict(jacobian(name, "forward")(params))
    reverse = as_dict(jacobian(name, "reverse")(params))
    r = solver(name)(params)
    values = np.array([r["e"], r["T"]])
    assert_elasticities(
        forward,
        reverse,
        dict(params, m=M, v0=V0),
        values,
        1e-9,
        1e-12,
        f"{name} forward vs reverse",
    )


# ------------------------------------------------------ vmap(grad) and reverse mode

HERTZ_RATE_BATCH = dict(c=np.array([1e6, 2e6, 2e6, 5e7]), b1=np.array([800.0, 0.0, 800.0, 3000.0]))


@pytest.mark.slow
def test_vmap_of_grad_equals_forward_mode():
    """`jax.vmap(jax.grad(...))` works (b1 = 0 in the batch), and reverse mode equals
    forward mode member by member."""
    f = e_and_T("hertz_rate")

    def e(params, m, v0):
        return f(params, m, v0)[0]

    batch = {k: jnp.asarray(v) for k, v in HERTZ_RATE_BATCH.items()}
    grads = jax.vmap(jax.grad(e, argnums=(0, 1, 2)), in_axes=({"c": 0, "b1": 0}, None, None))(
        batch, jnp.asarray(M), jnp.asarray(V0)
    )
    assert_finite(grads, "vmap(grad)")
    reverse = as_dict(grads)
    for i in range(len(HERTZ_RATE_BATCH["c"])):
        params = {k: float(v[i]) for k, v in HERTZ_RATE_BATCH.items()}
        forward = as_dict(jacobian("hertz_rate", "forward")(params))
        r = solver("hertz_rate", rtol=1e-11)(params)
        args = dict(params, m=M, v0=V0)
        member = {k: np.atleast_1d(v[i]) for k, v in reverse.items()}
        # b1 = 0: elasticity in b1 is 0 by definition; compare the derivative itself below
        assert_elasticities(
            {k: v[:1] for k, v in forward.items()},
            member,
            args,
            np.array([r["e"]]),
            1e-9,
            1e-12,
            f"hertz_rate {params}",
        )
        assert_rel(member["b1"], forward["b1"][:1], 1e-9, f"de/db1 at {params}")


# --------------------------------------------------------- zero damping: finite, exact


def one_sided(name, params, key, step):
    """Second-order one-sided difference of [e, T] in `key` at its (zero) value."""
    run = solver(name, "force", rtol=FD_RTOL)

    def value(x):
        r = run(dict(params, **{key: x}))
        return np.array([r["e"], r["T"]])

    return (-3 * value(0.0) + 4 * value(step) - value(2 * step)) / (2 * step)


@pytest.mark.slow
def test_gradients_at_zero_hertz_rate_damping():
    params = dict(c=2e6, b1=0.0)
    jac = as_dict(jacobian("hertz_rate", "forward")(params))
    assert_finite(jac, "hertz_rate at b1 = 0")
    r = solver("hertz_rate", rtol=1e-11)(params)
    assert_rel(r["e"], 1.0, 1e-9, "undamped e")  # measured 1 + 1.3e-10
    assert_rel(jac["c"][0], 0.0, 0, "de/dc at b1 = 0", atol=1e-15)
    # one-sided differences, step 1e-3 N s/m^1.5 (e = 1 - 2.3e-7 at b1 = 1e-3); dT/db1: below
    fd = one_sided("hertz_rate", params, "b1", 1e-3)
    assert_rel(jac["b1"][0], fd[0], 1e-5, "de/db1 at b1 = 0")


@pytest.mark.parametrize(
    "name, params, key, step",
    [
        ("hertz_rate", dict(c=2e6, b1=0.0), "b1", 1e-3),
        pytest.param("kelvin_voigt", dict(c=2e6, b=0.0), "b", 1e-3, marks=pytest.mark.slow),
    ],
    ids=["hertz_rate", "kelvin_voigt"],
)
def test_contact_time_derivative_at_zero_damping(name, params, key, step):
    jac = as_dict(jacobian(name, "forward")(params))
    # T is smooth through zero damping (linear in it near 0): one-sided differences are
    # converged to 1e-6 for steps from 1e-6 to 1e-1
    fd = one_sided(name, params, key, step)
    assert_rel(jac[key][1], fd[1], 1e-5, f"dT/d{key} at zero damping")


@pytest.mark.xfail(
    strict=True,
    reason="library bug: closed_forms.kelvin_voigt switches to T = pi/sqrt(r) with "
    "jnp.where(s > 0, ...) at b = 0, so dT/db = 0 there instead of -1/c",
)
def test_closed_form_contact_time_derivative_at_zero_damping():
    dT = jax.grad(lambda b: closed_forms.kelvin_voigt(2e6, b, M, V0)["T"])(0.0)
    assert_rel(dT, -1 / 2e6, 1e-9, "dT/db at b = 0")


@pytest.mark.slow
def test_gradients_at_zero_hunt_crossley_damping():
    params = dict(c=2e6, a=0.0)  # the structure of the PAPER_SETS row: the same compilation
    jac = as_dict(jacobian("hunt_crossley", "forward")(params))
    assert_finite(jac, "hunt_crossley at a = 0")
    # e = 1 - 2 alpha/3 + ..., alpha = 1.5 a v0: de/da = -v0 at a = 0, and e independent of c
    assert_rel(jac["a"][0], -V0, 1e-5, "de/da at a = 0")  # measured 1.1e-6 at rtol 1e-10
    assert abs(jac["c"][0]) * 2e6 < 1e-9
    fd = one_sided("hunt_crossley", params, "a", 1e-6)
    assert_rel(jac["a"], fd, 1e-5, "d[e, T]/da at a = 0")
