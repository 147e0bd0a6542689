"""Fuzzing the public surface with hypothesis: every input ends in a right answer or a clear
error (a one-line `ValueError`/`TypeError` in Python; exit status 2 and one line on stderr on
the command line), never a traceback, a NaN presented as a result, or an answer from input
that was silently changed.

Each property decides what is valid by itself (the rules of DESIGN.md: masses, speeds and
stiffnesses finite and > 0, dampings finite and >= 0, restitutions in (0, 1], ...) and
checks the library agrees. The laws and shapes are fixed, so every example reuses one
compiled program; the long part is marked slow.
"""

import json
import math
import warnings

import jax.numpy as jnp
import mpmath
import numpy as np
import pytest
from helpers import assert_one_line_error, run_cli
from hypothesis import HealthCheck, example, given, settings, strategies as st

import jaximpact as ji

FAST = settings(
    max_examples=12,
    deadline=None,
    # capsys is read and reset by every example (`run_cli`), so sharing it is safe
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)
# numbers a user may type: ordinary, zero, negative, huge, tiny, and not numbers at all
ANY_FLOAT = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.sampled_from([0.0, -0.0, -1.0, 1e-300, 1e300, math.nan, math.inf, -math.inf]),
)
GOOD_SPEED = st.floats(min_value=0.05, max_value=50.0)
GOOD_MASS = st.floats(min_value=1e-3, max_value=1e3)
LAW14 = dict(c=2e6, b1=800.0)


def _positive(x) -> bool:
    return math.isfinite(x) and x > 0


def _one_line(error: Exception):
    assert "\n" not in str(error).strip(), f"a multi-line error: {error}"
    assert str(error).strip(), "an empty error message"


# ----------------------------------------------------------------------------- laws


@FAST
@given(c=ANY_FLOAT, b1=ANY_FLOAT)
def test_law_builds_or_refuses(c, b1):
    valid = _positive(c) and math.isfinite(b1) and b1 >= 0
    if valid:
        law = ji.law("hertz_rate", c=c, b1=b1)
        assert float(law.parameters["c"]) == c and float(law.parameters["b1"]) == b1
    else:
        with pytest.raises(ValueError) as error:
            ji.law("hertz_rate", c=c, b1=b1)
        _one_line(error.value)


@FAST
@given(
    value=st.one_of(
        st.text(max_size=5), st.none(), st.booleans(), st.lists(ANY_FLOAT, max_size=3), ANY_FLOAT
    )
)
def test_law_takes_one_good_number_only(value):
    """A parameter is one number: text, None, a bool and any list are refused in one line
    (issue 34, item 7: `c=[1e6, 2e6]` was taken, then failed inside the solve, and
    `c=True` was taken as 1); a good float builds the law."""
    good = isinstance(value, float) and _positive(value)
    if good:
        law = ji.law("hertz_rate", c=value, b1=800.0)
        assert float(law.parameters["c"]) == value
    else:
        with pytest.raises((TypeError, ValueError)) as error:
            ji.law("hertz_rate", c=value, b1=800.0)
        _one_line(error.value)


def _refused(name: str, key: str, value: float) -> bool:
    """DESIGN.md's rule: stiffness and exponent > 0, a nominal restitution in (0, 1], the
    rest >= 0; Maxwell's dashpot > 0 (b = 0 carries no force: the body never stops),
    Thornton's yield overlap and the adhesive laws' radius > 0."""
    if not math.isfinite(value):
        return True
    positive = {
        "maxwell": ("b",),
        "thornton": ("x_y",),
        "jkr": ("R",),
        "dmt": ("R",),
        "jkr_viscoelastic": ("R",),
    }.get(name, ())
    if key in ("c", "n") or key in positive:
        return value <= 0
    if key == "e_nominal":
        return not 0 < value <= 1
    return value < 0


@FAST
@given(name=st.sampled_from(sorted(ji.LAW_NAMES)), which=st.integers(0, 3), value=ANY_FLOAT)
def test_every_law_builds_or_refuses(name, which, value):
    """One parameter of any law set to any number (the others from `starting_law`)."""
    params = {k: float(v) for k, v in _start(name).parameters.items()}
    key = sorted(params)[which % len(params)]
    params[key] = value
    if not _refused(name, key, value):
        try:
            built = ji.law(name, **params)
        except ValueError as error:  # an exponent that breaks 0 <= p <= n, said so
            _one_line(error)
            assert key in ("n", "p") and "exponents" in str(error)
            return
        assert float(built.parameters[key]) == value
    else:
        with pytest.raises(ValueError) as error:
            ji.law(name, **params)
        _one_line(error.value)


def _start(name):
    geometry = {k: 0.01 for k in ji.LAWS[name].geometry}  # JKR's radius, m
    return ji.starting_law(name, m=1.0, v0=2.5, e=0.8, T=7.8e-3, **geometry)


# ----------------------------------------------------------------------------- one impact


@FAST
@given(m=ANY_FLOAT, v0=ANY_FLOAT)
def test_impact_answers_or_refuses(m, v0):
    law = ji.law("hertz_rate", **LAW14)
    if _positive(m) and _positive(v0):
        try:
            r = ji.impact(law, m=m, v0=v0)
        except ValueError as error:  # a scale the float64 solve cannot resolve, said so
            _one_line(error)
            return
        if int(r.status) == ji.Status.separated:
            assert 0.0 < float(r.e) <= 1.0 and float(r.T) > 0.0
        else:  # not separated: a status, with e = 0, never a NaN presented as e
            assert float(r.e) == 0.0
    else:
        with pytest.raises(ValueError) as error:
            ji.impact(law, m=m, v0=v0)
        _one_line(error.value)


@FAST
@given(m=GOOD_MASS, v0=GOOD_SPEED)
def test_impact_on_the_curves_matches_the_integration(m, v0):
    """The two paths the library offers agree wherever the input is good."""
    law = ji.law("hertz_rate", **LAW14)
    fast = ji.impact(law, m=m, v0=v0)
    slow = ji.impact(law, m=m, v0=v0, method="integrate")
    assert fast.path == "similarity" and slow.path == "integrated"
    np.testing.assert_allclose(float(fast.e), float(slow.e), rtol=1e-8)
    np.testing.assert_allclose(float(fast.T), float(slow.T), rtol=1e-8)


@FAST
@given(
    option=st.sampled_from(["rtol", "atol", "rest_tol", "max_steps", "tau_max"]), value=ANY_FLOAT
)
def test_impact_options_out_of_range_are_refused(option, value):
    law = ji.law("hertz_rate", **LAW14)
    in_range = {
        "rtol": 0 < value < 1,
        "atol": 0 < value < 1,
        "rest_tol": 0 < value < 1,
        "max_steps": math.isfinite(value) and value == int(value) and value >= 1,
        "tau_max": math.isfinite(value) and value > 0,
    }[option]
    if option == "max_steps" and in_range:
        value = int(min(value, 100_000))
    if in_range:
        return  # a valid option; covered by the other tests
    with pytest.raises((ValueError, TypeError)) as error:
        ji.impact(law, m=1.0, v0=2.5, **{option: value})
    _one_line(error.value)


@settings(FAST, max_examples=6)  # one compiled solve with gravity for every example
@given(g=ANY_FLOAT)
@example(g=1e300)
def test_impact_with_any_gravity_answers_or_refuses(g):
    """Gravity along the normal: finite results (any status) or a clear refusal; g = 1e300
    once came back as T = NaN under status captured."""
    law = ji.law("hertz_rate", **LAW14)
    if not (math.isfinite(g) and g >= 0):
        with pytest.raises(ValueError) as error:
            ji.impact(law, m=1.0, v0=2.5, g=g)
        _one_line(error.value)
        return
    try:
        r = ji.impact(law, m=1.0, v0=2.5, g=g)
    except ValueError as error:
        _one_line(error)
        assert "float64" in str(error)
        return
    except RuntimeError as error:  # a failed solve is refused, never a number
        _one_line(error)
        assert "throw=False" in str(error)
        return
    for key in ("e", "T", "x_max", "F_max", "t_max", "dissipated"):
        assert math.isfinite(float(getattr(r, key))), (key, g)


def test_maxwell_without_a_dashpot_is_refused():
    """b = 0 once gave NaN results under status captured; it is a law with no force."""
    with pytest.raises(ValueError, match="maxwell: b must be a finite number > 0"):
        ji.law("maxwell", c=2e6, b=0.0)


# ----------------------------------------------------------------------------- a user's law


def _linear_with_x_damping(x, v, p):  # one module-level function: one compiled law
    return p["k"] * x + p["d"] * x * v


@settings(FAST, max_examples=6)
@given(d=st.floats(min_value=-3e3, max_value=3e3))
@example(d=-1e3)
def test_a_custom_law_that_gives_energy_is_said_to_be_unphysical(d):
    """F = k x + d x v: with d < 0 the law pushes the body out faster than it came (e > 1;
    `c x^1.5 - b x^0.5 v` once gave e = 8.4 as a plain result); a warning says so. With
    d >= 0 it takes energy: no warning, e <= 1."""
    law = ji.custom_law(_linear_with_x_damping, k=2e6, d=d)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        r = ji.impact(law, m=1.0, v0=2.5)
    said = [str(w.message) for w in caught if "gives the body energy" in str(w.message)]
    assert int(r.status) == ji.Status.separated
    if d >= 0:
        assert not said and float(r.e) <= 1.0 + 1e-9
    elif d < -10.0:
        assert float(r.e) > 1.0 and len(said) == 1, (d, float(r.e))
        assert f"e = {float(r.e):.4g}" in said[0]


BAD_FUNCTIONS = {
    "text": lambda x, v, p: "force",
    "a vector": lambda x, v, p: p["k"] * x * jnp.ones(3),
    "a complex number": lambda x, v, p: p["k"] * x + 1j,
    "NaN": lambda x, v, p: p["k"] * x + jnp.nan,
    "inf at x = 0": lambda x, v, p: p["k"] / x,
    "a missing parameter": lambda x, v, p: p["stiffness"] * x,
    "two arguments": lambda x, v: x,
}


@pytest.mark.parametrize("what", list(BAD_FUNCTIONS))
def test_a_custom_law_whose_function_is_wrong_is_refused(what):
    """Refused before any solve, in one line that says what the function gave."""
    law = ji.custom_law(BAD_FUNCTIONS[what], k=2e6)
    with pytest.raises((TypeError, ValueError)) as error:
        ji.impact(law, m=1.0, v0=2.5)
    _one_line(error.value)
    assert "custom law" in str(error.value)


@FAST
@given(k=ANY_FLOAT)
def test_custom_law_parameters_are_numbers(k):
    """Any sign (the user's law decides what it means), but finite."""
    if math.isfinite(k):
        assert float(ji.custom_law(_linear_with_x_damping, k=k, d=1.0).parameters["k"]) == k
    else:
        with pytest.raises(ValueError) as error:
            ji.custom_law(_linear_with_x_damping, k=k, d=1.0)
        _one_line(error.value)


# ----------------------------------------------------------------------------- closed forms


@settings(FAST, max_examples=6)  # each alpha is its own root solve (0.2 s)
@given(alpha=st.floats(min_value=1e-12, max_value=1e6))
def test_hunt_crossley_restitution_for_every_alpha(alpha):
    """e(alpha) in (0, 1), decreasing, for every alpha > 0 (its bracket once failed for
    some alpha, e.g. 44.7)."""
    e = float(ji.closed_forms.hunt_crossley_restitution(alpha))
    assert 0.0 < e < 1.0
    assert float(ji.closed_forms.hunt_crossley_restitution(alpha * 1.01)) <= e


def test_hunt_crossley_restitution_at_its_ends():
    """No damping: elastic; infinite damping: its limit e = 0, or a clear refusal."""
    assert float(ji.closed_forms.hunt_crossley_restitution(0.0)) == 1.0
    try:
        assert float(ji.closed_forms.hunt_crossley_restitution(math.inf)) == 0.0
    except ValueError as error:
        _one_line(error)


@FAST
@given(alpha=st.sampled_from([-1.0, -1e-300, math.nan, -math.inf]))
def test_hunt_crossley_restitution_refuses_bad_alpha(alpha):
    with pytest.raises(ValueError) as error:
        ji.closed_forms.hunt_crossley_restitution(alpha)
    _one_line(error.value)


# ----------------------------------------------------------------------------- batches


@FAST
@given(v0=st.lists(st.one_of(GOOD_SPEED, ANY_FLOAT), min_size=2, max_size=40))
def test_batch_marks_exactly_the_bad_rows(v0):
    v0 = np.asarray(v0)
    bad = ~(np.isfinite(v0) & (v0 > 0))
    if bad.all():
        with pytest.raises(ValueError) as error:
            ji.impact_batch("hertz_rate", LAW14, m=1.0, v0=v0, progress=False)
        _one_line(error.value)
        return
    with np.errstate(all="ignore"), warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        out = ji.impact_batch("hertz_rate", LAW14, m=1.0, v0=v0, progress=False)
    invalid = out["status"] == ji.Status.invalid
    # the bad rows are said; so is a valid speed float64 cannot carry (1e300), and only that
    assert bool(said) == bool(invalid.any()), [str(w.message) for w in said]
    ordinary = (v0 >= 0.05) & (v0 <= 50.0)
    assert np.all(invalid[bad]) and not np.any(invalid[ordinary])
    # the others: a result, or (a speed float64 cannot carry through, 1e-300, 1e300) invalid
    assert np.all(np.isnan(out["e"][invalid])) and np.all(np.isfinite(out["e"][~invalid]))


EXTREME = st.sampled_from([1e-300, 1e-200, 1e-30, 2.5, 1e30, 1e200, 1e300])


@FAST
@given(v0=st.lists(EXTREME, min_size=3, max_size=3), c=st.lists(EXTREME, min_size=3, max_size=3))
@example(v0=[1e-300, 2.5, 1e300], c=[2e6, 2e6, 1e300])
def test_batch_rows_float64_cannot_hold_get_a_status(v0, c):
    """Huge and tiny inputs (all valid numbers): each row has its result, or status invalid
    with NaN, never a separated row with T = 0 or NaN (v0 = 1e-300 once gave T = 0)."""
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        out = ji.impact_batch(
            "hertz_rate",
            {"c": np.asarray(c), "b1": 800.0},
            m=1.0,
            v0=np.asarray(v0),
            progress=False,
        )
    invalid = out["status"] == ji.Status.invalid
    for key in ("e", "T", "x_max", "F_max"):
        assert np.all(np.isfinite(out[key][~invalid])), (key, out)
        assert np.all(np.isnan(out[key][invalid])), (key, out)
    separated = out["status"] == ji.Status.separated
    assert np.all(out["T"][separated] > 0) and np.all(out["e"][separated] <= 1.0)


# ----------------------------------------------------------------------------- calibration


@FAST
@given(e=ANY_FLOAT, T=st.one_of(st.none(), ANY_FLOAT))
def test_calibrate_fits_or_refuses(e, T):
    law = ji.law("hertz_rate", **LAW14)
    valid = math.isfinite(e) and 0 < e <= 1 and (T is None or (math.isfinite(T) and T > 0))
    if not valid:
        with pytest.raises(ValueError) as error:
            ji.calibrate(law, m=1.0, v0=2.5, e=e, T=T)
        _one_line(error.value)
        return
    try:
        with np.errstate(all="ignore"), _maybe_warns():
            fit = ji.calibrate(law, m=1.0, v0=2.5, e=e, T=T)
    except ValueError as error:  # targets no such law meets within float64 (T = 1e-300 s)
        _one_line(error)
        assert "float64" in str(error)
        return
    params = np.asarray([float(v) for v in fit.params.values()])
    assert np.all(np.isfinite(params)) and np.all(params >= 0)
    if bool(fit.reproduces):  # the law meets the target (converged: the optimiser's verdict)
        assert abs(float(fit.e[0]) - e) < 1e-5


class _maybe_warns:
    """Warnings (a target far out of the compliant range) are allowed, not required."""

    def __enter__(self):
        import warnings

        self._catch = warnings.catch_warnings()
        self._catch.__enter__()
        warnings.simplefilter("ignore")
        return self

    def __exit__(self, *exc):
        return self._catch.__exit__(*exc)


CALIBRATE_WRONG = {  # what is wrong: (arguments, what the error must name)
    "no speed": (dict(v0=[], e=[]), "v0 is empty"),
    "two masses": (dict(m=[1.0, 2.0]), "m must be one number"),
    "free as text": (dict(free="b1"), r"free=\('b1',\)"),
    "no iterations": (dict(max_iter=0), "max_iter"),
    "a rank-2 speed": (dict(v0=[[2.5]], e=[[0.8]]), "1-D"),
    "e and v0 of different lengths": (dict(v0=[1.0, 2.0, 3.0], e=[0.8, 0.7]), "one per"),
}


@pytest.mark.parametrize("what", list(CALIBRATE_WRONG))
def test_calibrate_wrong_shapes_and_types(what):
    """Each once ended in an IndexError, an error from inside the fit, a fit of parameters
    'b' and '1', or a 'converged' fit of no iteration."""
    wrong, named = CALIBRATE_WRONG[what]
    with pytest.raises((TypeError, ValueError), match=named) as error:
        ji.calibrate(ji.law("hertz_rate", **LAW14), **(dict(m=1.0, v0=2.5, e=0.8) | wrong))
    _one_line(error.value)


@pytest.fixture(scope="module")
def drop():
    return ji.bounce(ji.law("hertz_rate", **LAW14), m=0.05, h0=0.5, t_end=1.0, g=9.81)


@pytest.mark.slow  # the histories compile in 7 s
@settings(FAST, max_examples=6)  # one compiled history for 4 times
@given(ts=st.permutations([0.05, 0.3, 0.62, 0.9]))
def test_bounce_heights_in_any_order(drop, ts):
    """The times may come in any order (unsorted ones once ended in a runtime error
    'saveat.ts must be increasing')."""
    heights = np.asarray(drop.height(np.asarray(ts)))
    np.testing.assert_allclose(
        heights, np.asarray(drop.height(np.sort(ts)))[np.argsort(np.argsort(ts))]
    )
    assert np.all(np.isfinite(heights))


@pytest.mark.parametrize("t", [math.nan, -0.1])
def test_bounce_heights_at_no_time(drop, t):
    """NaN or before the release: refused, not NaN or a parabola extrapolated backwards."""
    with pytest.raises(ValueError) as error:
        drop.height(np.array([t, 0.3, 0.62, 0.9]))
    _one_line(error.value)


# ----------------------------------------------------------------------------- impact times


@pytest.mark.filterwarnings("error::RuntimeWarning")  # inf - inf once warned, found by CI
@FAST
@given(times=st.lists(ANY_FLOAT, min_size=0, max_size=12))
@example(times=[math.inf, math.inf, 1.0])
def test_clean_impact_times_refuses_what_is_not_a_drop(times):
    array = np.asarray(times, dtype=float)
    good = array.size >= 3 and np.all(np.isfinite(array)) and np.all(np.diff(array) > 0)
    try:
        cleaned = ji.clean_impact_times(times)
    except ValueError as error:
        _one_line(error)
        assert not (good and np.all(np.diff(array) > 1e-3)), f"refused a good drop: {error}"
        return
    assert good, "accepted times that are not finite and increasing"
    assert np.all(np.isin(cleaned.times, array)), "the times were altered"


@FAST
@given(times=st.lists(st.floats(min_value=0.0, max_value=10.0), min_size=3, max_size=12))
def test_interval_restitution_of_any_clean_drop(times):
    """`e_k = D_{k+1} / D_k` from what `clean_impact_times` kept: positive and finite."""
    times = sorted(set(times))
    try:
        cleaned = ji.clean_impact_times(times)
    except ValueError as error:
        _one_line(error)
        return
    k, e = ji.interval_restitution(cleaned)
    assert len(k) == len(e) and np.all(np.isfinite(e)) and np.all(e > 0)


@pytest.mark.parametrize("given_", [[0.1, 0.5, 0.8], np.array([0.1, 0.5, 0.8]), None, "0.1"])
def test_interval_restitution_wants_cleaned_times(given_):
    """Raw times once met an AttributeError; now a TypeError that says what to pass."""
    with pytest.raises(TypeError, match="clean_impact_times") as error:
        ji.interval_restitution(given_)
    _one_line(error.value)


# ----------------------------------------------------------------------------- materials


@FAST
@given(E=ANY_FLOAT, nu=ANY_FLOAT, R=ANY_FLOAT)
@example(E=2.696539702293474e158, nu=0.0, R=9.999999999999999e299)  # c = inf, found in CI
@example(E=5e-324, nu=0.3, R=1.0)  # E* underflows to 0
def test_hertz_stiffness_answers_or_refuses(E, nu, R):
    valid = _positive(E) and _positive(R) and math.isfinite(nu) and -1 < nu < 0.5
    if valid:
        # the same material on both sides, a flat: 1/E* = 2 (1 - nu^2)/E, R* = R (exact)
        with mpmath.workdps(40):
            e_star = mpmath.mpf(E) / (2 * (1 - mpmath.mpf(nu) ** 2))
            want = 4 * e_star * mpmath.sqrt(mpmath.mpf(R)) / 3
        extreme = not all(1e-300 < abs(x) < 1e300 for x in (E, R, e_star, want))
        try:
            c = ji.hertz_stiffness(E, nu, R)
        except ValueError as error:  # only where float64 cannot hold c (or E* on the way)
            _one_line(error)
            assert "float64 cannot hold" in str(error) and extreme, (want, e_star)
            return
        assert math.isfinite(c) and c > 0
        assert extreme or abs(c / want - 1) < 1e-13, (c, want)
    else:
        with pytest.raises(ValueError) as error:
            ji.hertz_stiffness(E, nu, R)
        _one_line(error.value)


# ----------------------------------------------------------------------------- files


@FAST
@given(content=st.one_of(st.binary(max_size=200), st.text(max_size=200)))
def test_read_recording_reads_or_refuses(tmp_path_factory, content):
    path = tmp_path_factory.mktemp("rec") / "recording.csv"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    try:
        recording = ji.read_recording(path)
    except ValueError as error:
        _one_line(error)
        return
    assert recording.kind in ("trajectory", "impacts") and recording.groups


# ----------------------------------------------------------------------------- command line


WORDS = st.one_of(
    st.text(alphabet="0123456789.e-+xnaif", min_size=0, max_size=8),
    st.sampled_from(["nan", "inf", "-1", "0", "1e400", "2e6", "abc", ""]),
)


@FAST
@given(c=WORDS, v0=WORDS)
def test_cli_simulate_answers_or_says_why(capsys, c, v0):
    status, out, err = run_cli(
        capsys,
        [
            "simulate",
            "--mass",
            "1",
            "--law",
            "hertz_rate",
            "--param",
            f"c={c}",
            "--param",
            "b1=800",
            "--v0",
            v0,
            "--json",
        ],
    )
    if status == 0:
        assert err == "" and '"e"' in out
    else:
        assert_one_line_error(status, out, err)


@FAST
@given(content=st.one_of(st.binary(max_size=120), st.text(max_size=120)))
def test_cli_calibrate_on_any_file(capsys, tmp_path_factory, content):
    path = tmp_path_factory.mktemp("data") / "data.csv"
    if isinstance(content, bytes):
        path.write_bytes(content)
    else:
        path.write_text(content)
    status, out, err = run_cli(
        capsys, ["calibrate", "--mass", "1", "--law", "hertz_rate", "--data", str(path), "--json"]
    )
    if status != 0:
        assert_one_line_error(status, out, err)


@FAST
@given(
    args=st.lists(
        st.sampled_from(["--law", "nope", "--v0", "-3", "--mass", "0", "--e", "2", "--T", "x"]),
        max_size=6,
    ),
    command=st.sampled_from(["simulate", "calibrate", "fit", "export", "engine-e", "laws"]),
)
def test_cli_commands_never_show_a_traceback(capsys, command, args):
    status, out, err = run_cli(capsys, [command, *args])
    assert "Traceback" not in err
    if status != 0:
        assert status == 2, err
        assert len(err.strip().splitlines()) == 1, err


@FAST
@given(
    params=st.dictionaries(
        st.sampled_from(["solref", "timestep", "zz", "time_step"]),
        st.one_of(
            ANY_FLOAT.filter(math.isfinite),
            st.lists(st.one_of(st.floats(0.001, 1.0), st.text(max_size=2)), max_size=3),
            st.text(max_size=3),
            st.booleans(),
        ),
        max_size=3,
    )
)
@example(params={"solref": [0.02, 1.0], "time_step": 0.001})
@example(params={"solref": ["a", 1.0]})
def test_cli_engine_e_takes_only_what_it_reads(capsys, params):
    """Any JSON object: an answer only where every key is one MuJoCo's reading takes and
    every value a number (a misspelt key was once ignored, a text value a traceback)."""
    status, out, err = run_cli(
        capsys,
        [
            "engine-e",
            "--engine",
            "mujoco",
            "--params",
            json.dumps(params),
            "--mass",
            "0.05",
            "--speed",
            "1",
            "--json",
        ],
    )
    if status != 0:
        assert_one_line_error(status, out, err)
        return
    assert set(params) <= {"solref", "timestep"} and "solref" in params
    assert all(np.isfinite(json.loads(out)["e"]))


@FAST
@given(e=WORDS, T=WORDS)
@example(e="0.75", T="1e300")
@example(e="0.75", T="1e-300")
def test_cli_export_answers_or_says_why(capsys, e, T):
    """Targets e, T as typed: an export, or one line (T = 1e300 once ended in an
    OverflowError with exit status 1)."""
    status, out, err = run_cli(
        capsys,
        [
            "export",
            "--engine",
            "mujoco",
            "--e",
            e,
            "--T",
            T,
            "--mass",
            "0.05",
            "--v0",
            "1",
            "--json",
        ],
    )
    if status == 0:
        assert err == "" and json.loads(out)
    else:
        assert_one_line_error(status, out, err)


@FAST
@given(T=st.sampled_from(["1e300", "1e-300", "1e30", "7.8e-3", "nan", "-1"]))
def test_cli_calibrate_with_any_duration(capsys, T):
    """T = 1e300 s once ended in an OverflowError (exit status 1). A warning may come
    before the error: each on its own line, `jaximpact: warning: ...`."""
    status, out, err = run_cli(
        capsys,
        ["calibrate", "--mass", "1", "--law", "hertz_rate", "--v0", "2.5", "--e", "0.8", "--T", T],
    )
    lines = err.splitlines()
    assert all(line.startswith("jaximpact: warning: ") for line in lines[:-1]), err
    if status != 0:
        assert_one_line_error(status, out, lines[-1] + "\n")


@pytest.mark.parametrize("option", [["--sigma", "0"], ["--sigma", "-1"], ["--sigma", "nan"]])
def test_cli_fit_options_out_of_range(capsys, tmp_path, option):
    """--sigma 0 once ended in 'SVD did not converge'."""
    path = tmp_path / "impacts.csv"
    path.write_text("t\n0.3\n0.7\n1.0\n1.2\n")
    status, out, err = run_cli(
        capsys,
        [
            "fit",
            "--law",
            "hertz_rate",
            "--param",
            "c=2e6",
            "b1=800",
            "--mass",
            "0.05",
            *option,
            str(path),
        ],
    )
    assert_one_line_error(status, out, err, contains="sigma")


# ----------------------------------------------------------------------------- slow


@pytest.mark.slow
@settings(FAST, max_examples=40)
@given(
    name=st.sampled_from(sorted(ji.LAW_NAMES)),
    scale=st.floats(min_value=1e-3, max_value=1e3),
    v0=GOOD_SPEED,
)
@example(name="dmt", scale=696.0, v0=1.0)  # found locally: runs out of the default steps
def test_every_law_impact_is_a_result_or_a_status(name, scale, v0):
    """Every law of the table, its damping scaled by any factor, at any ordinary speed: a
    separated impact with 0 < e <= 1 and T > 0, or another status with e = 0; no NaN. A
    solve that runs out of steps (a heavily damped body creeping to rest, stiff for the
    explicit solver: `dmt` with its damping x696 at 1 m/s needs 4,138 steps) raises the
    failure rule's one line, and its advice, a larger `max_steps`, must then work."""
    law = _start(name)
    damping = ji.LAWS[name].damping
    if damping is not None and damping != "e_nominal":
        law = law.replace(**{damping: float(law.parameters[damping]) * scale})
    try:
        r = ji.impact(law, m=1.0, v0=v0)
    except RuntimeError as error:
        _one_line(error)
        assert "raise max_steps" in str(error), str(error)
        r = ji.impact(law, m=1.0, v0=v0, max_steps=65_536)
    for key in ("e", "T", "x_max", "F_max", "dissipated"):
        assert math.isfinite(float(getattr(r, key))), (name, key)
    if int(r.status) == ji.Status.separated:
        assert 0.0 < float(r.e) <= 1.0 + 1e-9 and float(r.T) > 0.0
    else:
        assert float(r.e) == 0.0


@pytest.mark.slow
@pytest.mark.parametrize(
    "argv",
    [
        "simulate --law hertz_rate --param c=2e6 b1=800 --v0 1e300",
        "calibrate --law hertz_rate --v0 2.5 --e 0.8 --T 1e300",
        "export --engine mujoco --e 0.75 --T 1e-300 --mass 1 --v0 1",
    ],
)
def test_cli_in_a_process_of_its_own(argv):
    """The console script itself: exit status 2 and one error line (after any warning
    lines), no traceback and no XLA log."""
    import shutil
    import subprocess

    script = shutil.which("jaximpact")
    assert script, "the jaximpact console script is not installed"
    run = subprocess.run([script, *argv.split()], capture_output=True, text=True, timeout=300)
    lines = run.stderr.splitlines()
    assert run.returncode == 2 and run.stdout == "", run.stderr
    assert lines and lines[-1].startswith("jaximpact: error: "), run.stderr
    assert all(line.startswith("jaximpact: warning: ") for line in lines[:-1]), run.stderr
