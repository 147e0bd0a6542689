"""Oblique impacts on the phase-angle grid (`jaximpact/_oblique/grid.py`) and the batch
entry that uses it (`oblique_impact_batch`), against the independent scipy oracle
(DOP853 rtol 1e-12, event-handled stick-slip transitions).

Over incidence angles from 2 to 70 degrees (sticking, micro-slip reversals, gross
sliding) and friction coefficients from 0.05 to 0.5, for both tangential laws, undamped
and damped (Hunt-Crossley's normal damping, Mindlin's damper): every row the grid serves
has the oracle's switches and e, v_t_out, omega_out and T within 1e-8 of the oracle's
(`test_oblique_impact.py::test_against_scipy`'s tolerances); every row it declines comes
back from the integrated pass (`solve_oblique`, the event-terminated solve) as right; and
every row whose transitions the grid miscounts is declined by the transition rules alone
(`DIP_TOL`: a condition below zero at a stage inside a step; `MIN_GAP`: two transitions
within one grid step), whatever the error estimate says.

One compiled grid and one compiled integrated solve per case (module-scope fixtures,
about 40 s each to compile and to run the oracle on an idle machine), shared by the
tests: all slow (the fast suite keeps the one-line refusals)."""

import jax
import numpy as np
import oblique_oracle as oracle_module
import pytest

import jaximpact as ji
from jaximpact._oblique import oblique_impact_batch, tangential_law
from jaximpact._oblique.batch import batch_options
from jaximpact._oblique.grid import DIP_TOL, MIN_GAP, OBLIQUE_STEPS, grid_outcome
from jaximpact._oblique.impact import ObliqueInputs, solve_oblique

E, NU, RHO, R = 380e9, 0.23, 4000.0, 2.5e-3
M = RHO * 4.0 / 3.0 * np.pi * R**3
C = 4.0 / 3.0 * E / (1 - NU**2) * np.sqrt(R)
G_STAR = E / (2 * (1 + NU)) / (2 - NU)
SPEED = 3.9
DEGREES = np.array([2, 3, 4, 5, 6, 8, 10, 12, 14, 16, 18, 20, 25, 30, 35, 45, 55, 70.0])
MUS = np.array([0.05, 0.092, 0.2, 0.5])
LAWS = {
    "mindlin": (dict(G_star=G_STAR), dict(G_star=G_STAR, history="displacement")),
    "linear_history": (dict(kt=2e7), dict(kt=2e7)),
}
# (tangential law, Hunt-Crossley's normal damping a (s/m), Mindlin's damping beta): the
# elastic sphere of Kharaz's tests, then a damped normal contact (e about 0.6) and a
# damped Mindlin spring
CASES = {
    "mindlin": ("mindlin", 0.0, 0.0),
    "linear_history": ("linear_history", 0.0, 0.0),
    "mindlin, damped normal": ("mindlin", 0.1, 0.0),
    "mindlin, damped both": ("mindlin", 0.1, 0.2),
    "linear_history, damped normal": ("linear_history", 0.1, 0.0),
}
KEYS = ("e", "v_t_out", "omega_out", "T")
# the oracle's largest step, a share of the contact: scipy looks for events at its steps'
# ends only, and with its own steps (up to a tenth of the contact near the end) it missed
# a stick of 1.4 % of the contact (linear_history, damped normal, 16 degrees, mu 0.2:
# 2 switches instead of 4, v_t_out 3.7e-4 off) that both jaximpact paths find
ORACLE_STEP = 1.0 / 500


def oblique_oracle(**kwargs):
    """`oblique_oracle` with its steps at most `ORACLE_STEP` of Hertz's contact duration,
    and `instant`: whether two of its transitions fell at one instant (a segment shorter
    than 1e-9 of the contact: modes that take turns, where its answer is not a reference:
    mindlin, damped both, 4 degrees, mu 0.05, where the integrated solve gives 5 switches
    at rtol 1e-11 and 3 at 1e-12, the oracle 4)."""
    hertz = 2.94 * (kwargs["m"] ** 2 / (kwargs["c"] ** 2 * kwargs["v_n"])) ** 0.2
    solve, lengths = oracle_module.solve_ivp, []

    def stepped(fun, t_span, y0, **options):
        sol = solve(fun, t_span, y0, max_step=ORACLE_STEP * hertz, **options)
        if sol.t_events[1].size:
            lengths.append(sol.t_events[1][0] - t_span[0])
        return sol

    oracle_module.solve_ivp = stepped
    try:
        out = oracle_module.oblique_oracle(**kwargs)
    finally:
        oracle_module.solve_ivp = solve
    return {**out, "instant": any(length <= 1e-9 * hertz for length in lengths[1:])}


def _rows():
    """(v_n, v_t, mu): every angle at every friction coefficient."""
    degrees, mus = (grid.ravel() for grid in np.meshgrid(DEGREES, MUS))
    angles = np.deg2rad(degrees)
    return SPEED * np.cos(angles), SPEED * np.sin(angles), mus, degrees


def _error(result, k, o):
    """The largest relative error of row `k` of `result` against the oracle's `o`."""
    return max(abs(float(getattr(result, key)[k]) - o[key]) / abs(o[key]) for key in KEYS)


@pytest.fixture(
    scope="module",
    params=[pytest.param(k, marks=pytest.mark.slow) for k in CASES],
)
def case(request):
    """The grid's outcome, the integrated solve's result and the oracle's for `_rows()`
    (one compiled program each per case)."""
    name, damping, beta = CASES[request.param]
    params, oracle_params = LAWS[name]
    if beta:
        params, oracle_params = {**params, "beta": beta}, {**oracle_params, "beta": beta}
    law = ji.law("hunt_crossley", c=C, a=damping)
    v_n, v_t, mu, degrees = _rows()
    options = batch_options(separation="force", contact_point="surface", rtol=1e-11)

    @jax.jit
    def grid(v_n, v_t, mu):
        def one(a, b, f):
            tl = tangential_law(name, mu=f, **params)
            return grid_outcome(law, tl, M, R, a, b, 0.0, 0.4, options)

        return jax.vmap(one)(v_n, v_t, mu)

    @jax.jit
    def integrated(v_n, v_t, mu):
        def one(a, b, f):
            tl = tangential_law(name, mu=f, **params)
            return solve_oblique(law, tl, ObliqueInputs(M, R, a, b, 0.0, 0.4, 0.0), options)

        return jax.vmap(one)(v_n, v_t, mu)

    result, served, out = grid(v_n, v_t, mu)
    again = integrated(v_n, v_t, mu)
    oracle = [
        oblique_oracle(
            c=C,
            a=damping,
            m=M,
            R=R,
            inertia=0.4,
            v_n=float(a),
            v_t=float(b),
            omega=0.0,
            mu=float(f),
            **oracle_params,
        )
        for a, b, f in zip(v_n, v_t, mu, strict=True)
    ]
    return dict(
        name=request.param,
        result=result,
        served=np.asarray(served),
        out=out,
        integrated=again,
        oracle=oracle,
        degrees=degrees,
        mu=mu,
    )


def _what(case, k):
    return f"{case['name']}, {case['degrees'][k]:g} degrees, mu {case['mu'][k]:g}"


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_every_row_the_grid_serves_agrees_with_scipy(case):
    """Sticking, micro-slip with reversals, gross sliding, mu 0.05 to 0.5: each row the
    grid serves has scipy's switches and e, v_t_out, omega_out and T within 1e-8 of
    scipy's, and says it came from the grid."""
    result, served, oracle = case["result"], case["served"], case["oracle"]
    assert result.path == "grid"
    # the grid serves a share of the rows (the rest are the integrated pass's: below)
    assert served.sum() >= len(served) // 3, (case["name"], served.sum())
    switched = 0
    for k, o in enumerate(oracle):
        if not served[k]:
            continue
        assert not o["instant"], _what(case, k)
        assert int(result.num_switches[k]) == o["switches"], _what(case, k)
        switched += o["switches"] > 0
        assert _error(result, k, o) <= 1e-8, _what(case, k)
    assert switched >= 8, case["name"]  # stick-slip transitions were served on the grid


def _spin_error(result, k, o, v_t):
    """Row `k`'s error in `R omega_out` relative to its incoming tangential speed."""
    return R * abs(float(result.omega_out[k]) - o["omega_out"]) / abs(v_t)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_every_row_the_grid_declines_is_right_from_the_integrated_pass(case):
    """The rows the grid declines (modes that take turns, transitions a step apart or
    closer, damping its estimate does not resolve): the integrated solve gives them
    scipy's switches, e, v_t_out and T within 1e-8, and the spin within 1e-8 in the
    scale of the tangential speed (`R omega_out` against `v_t`): at a first touch near
    the limit the integrated solve's small outgoing spins are up to 2e-6 off relative
    to themselves, 1e-8 of the sphere's tangential speed (the grid's rows are not). Rows
    where the oracle's own transitions take turns at one instant have no reference."""
    again, served, oracle = case["integrated"], case["served"], case["oracle"]
    v_t = _rows()[1]
    for k, o in enumerate(oracle):
        if served[k] or o["instant"]:
            continue
        assert int(again.num_switches[k]) == o["switches"], _what(case, k)
        for key in ("e", "v_t_out", "T"):
            got = float(getattr(again, key)[k])
            assert got == pytest.approx(o[key], rel=1e-8), (_what(case, k), key)
        assert _spin_error(again, k, o, v_t[k]) <= 1e-8, _what(case, k)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_every_miscounted_row_is_seen_by_the_transition_rules(case):
    """Where the grid's transitions are not scipy's (a pair inside one step that its ends
    do not show, a chatter of transitions a step apart), the transition rules decline the
    row by themselves: a condition below `-DIP_TOL` at a stage inside a step taken, or two
    transitions closer than `MIN_GAP` of a grid step. The error estimate is not needed."""
    result, out, oracle = case["result"], case["out"], case["oracle"]
    dip, gap = np.asarray(out["dip"]), np.asarray(out["gap"])
    seen = (dip < -DIP_TOL) | (gap < MIN_GAP / OBLIQUE_STEPS)
    for k, o in enumerate(oracle):
        if int(result.num_switches[k]) != o["switches"]:
            assert seen[k], (_what(case, k), dip[k], gap[k])


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_gross_sliding_on_the_grid_is_the_impulse_result(case):
    """Where the contact slides throughout, the tangential impulse is mu times the normal
    one to rounding: the grid steps the two with the same stages."""
    result, served, mu = case["result"], case["served"], case["mu"]
    for k in range(len(served)):
        if not served[k] or int(result.num_switches[k]):
            continue
        impulse_n, impulse_t = float(result.impulse_n[k]), float(result.impulse_t[k])
        if abs(impulse_t) > 0.999 * mu[k] * impulse_n:
            assert abs(impulse_t) == pytest.approx(mu[k] * impulse_n, rel=1e-12), _what(case, k)


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore::RuntimeWarning")
# the same code for each case; with a damped normal contact the grid declines rows at
# every mu (undamped, since MAX_LANDINGS = 4 it serves all of them but one)
@pytest.mark.parametrize("case", ["mindlin, damped normal"], indirect=True)
def test_the_batch_serves_what_the_grid_serves(case):
    """`oblique_impact_batch` at one friction coefficient, the first of `MUS` at which
    the grid declines some rows: `path` is "grid" exactly on the rows the grid serves,
    with the grid's numbers there and the integrated solve's elsewhere."""
    name, damping, _ = CASES[case["name"]]
    both = [f for f in MUS if 0 < case["served"][case["mu"] == f].sum() < len(DEGREES)]
    assert both, "the grid served every row at every mu: no second pass to test"
    pick = np.flatnonzero(case["mu"] == both[0])
    v_n, v_t, _, _ = _rows()
    law = ji.law("hunt_crossley", c=C, a=damping)
    tl = tangential_law(name, mu=float(both[0]), **LAWS[name][0])
    r = oblique_impact_batch(law, tl, m=M, R=R, v_n=v_n[pick], v_t=v_t[pick], rtol=1e-11)
    served = case["served"][pick]
    assert r.path == tuple("grid" if s else "integrated" for s in served)
    assert 0 < served.sum() < len(pick)  # both passes ran
    for j, k in enumerate(pick):
        source = case["result"] if served[j] else case["integrated"]
        assert int(r.num_switches[j]) == int(source.num_switches[k])
        for key in (*KEYS, "e_t"):
            assert float(getattr(r, key)[j]) == pytest.approx(
                float(getattr(source, key)[k]), rel=1e-12
            ), (key, _what(case, k))


def test_the_batch_refuses_bad_input_in_one_line():
    law = ji.law("hunt_crossley", c=C, a=0.0)
    tl = tangential_law("linear_history", kt=2e7, mu=0.1)
    for kwargs, match in (
        (dict(v_n=np.array([1.0, -1.0])), "normal speed"),
        (dict(method="grid"), "method must be one of"),
        (dict(separation="contact"), "separation must be one of"),
    ):
        with pytest.raises(ValueError, match=match) as info:
            oblique_impact_batch(law, tl, **{**dict(m=M, R=R, v_n=3.0, v_t=1.0), **kwargs})
        assert "\n" not in str(info.value)


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore:overflow encountered:RuntimeWarning")
def test_the_batch_equals_the_vmap_of_oblique_impact():
    """`oblique_impact_batch` over 64 angles (a row or two the grid leaves, integrated in
    the second pass) against a `jax.vmap` of `oblique_impact`: e, e_t, the spin and T to
    1e-9, the switches alike, `path` per row; a rescaled history and gravity are never on
    the grid."""
    law = ji.law("hunt_crossley", c=C, a=0.0)
    tl = tangential_law("mindlin", G_star=G_STAR, mu=0.092)
    angles = np.arctan(np.linspace(0.05, 3.0, 64))
    v_n, v_t = 3.9 * np.cos(angles), 3.9 * np.sin(angles)
    batch = oblique_impact_batch(law, tl, m=M, R=R, v_n=v_n, v_t=v_t)
    vmapped = jax.jit(jax.vmap(lambda a, b: ji.oblique_impact(law, tl, m=M, R=R, v_n=a, v_t=b)))(
        v_n, v_t
    )
    assert len(batch.path) == 64 and batch.path.count("grid") >= 60
    np.testing.assert_array_equal(np.asarray(batch.num_switches), np.asarray(vmapped.num_switches))
    # undamped Hertz: the normal contact, independent of the tangential one, gives e = 1
    np.testing.assert_allclose(batch.e, 1.0, rtol=1e-9)
    # each path is within 1e-9 of the truth, so within 2e-9 of the other (a row the grid
    # serves since MAX_LANDINGS = 4, v_t / v_n = 0.565: e 1 - 1.2e-12 on the grid,
    # 1 + 1.16e-9 integrated; e_t 1.3e-11 and 5.6e-10 from the scipy oracle's)
    for key in ("e", "e_t", "T"):
        np.testing.assert_allclose(getattr(batch, key), getattr(vmapped, key), rtol=2e-9)
    np.testing.assert_allclose(
        R * np.asarray(batch.omega_out), R * np.asarray(vmapped.omega_out), atol=2e-9 * 3.9
    )
    rescaled = tangential_law("mindlin_rescale", G_star=G_STAR, mu=0.092)
    r = oblique_impact_batch(law, rescaled, m=M, R=R, v_n=v_n[:2], v_t=v_t[:2])
    assert r.path == ("integrated", "integrated")
    r = oblique_impact_batch(law, tl, m=M, R=R, v_n=v_n[-2:], v_t=v_t[-2:], g=[0.0, 9.81])
    assert r.path == ("grid", "integrated")
