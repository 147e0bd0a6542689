"""`Fit.from_dict`: the inverse of `Fit.to_dict`, through JSON, and the reading of what
`jaximpact calibrate --json` writes (the law by name, the speeds as rows), which the command
line's `export --from` and `fit-oblique --from` go through."""

import json

import numpy as np
import pytest

import jaximpact as ji
from jaximpact._laws import CustomLaw


@pytest.fixture(scope="module")
def fit():
    """Law 14 at two speeds, e at both and T at one: per-speed values with a NaN target,
    a goodness of fit with one degree of freedom."""
    law = ji.law("hertz_rate", c=2e6, b1=800.0)
    e = [float(ji.impact(law, m=1.0, v0=v).e) for v in (1.0, 2.5)]
    T = [float(ji.impact(law, m=1.0, v0=2.5).T)]
    start = ji.law("hertz_rate", c=1e6, b1=400.0)
    return ji.calibrate(start, m=1.0, v0=[1.0, 2.5], e=e, T=[None, *T], g=0.0)


def test_round_trip_through_json(fit):
    """`from_dict(to_dict())` gives the same dict back, the same text, the same law; the
    goodness of fit is recomputed from the residuals it holds."""
    record = json.loads(json.dumps(fit.to_dict(), allow_nan=False))
    back = ji.Fit.from_dict(record)
    assert back.to_dict() == record
    # the same lines; the parameters in the law's own order (a compiled fit sorts them)
    assert sorted(back.summary().splitlines()) == sorted(fit.summary().splitlines())
    assert back.law.name == "hertz_rate" and back.law.parameters == pytest.approx(
        {k: float(v) for k, v in fit.law.parameters.items()}
    )
    assert back.setup is None  # the compiled fit's options are not in a dict
    assert float(back.reduced_chi2) != float(back.reduced_chi2)  # NaN: no sigmas
    np.testing.assert_array_equal(np.isnan(back.T_target), [True, False])


def test_reads_the_command_line_s_record():
    """`calibrate --json`: `law` a name with `params`, each speed a row (measured `e` and
    `T`, fitted `e_fit` and `T_fit`); a field it lacks is None, a value NaN."""
    record = {
        "law": "kelvin_voigt",
        "params": {"c": 2e6, "b": 400.0},
        "m": 0.05,
        "g": 9.81,
        "converged": True,
        "free": ["c", "b"],
        "rows": [{"v0": 2.5, "e": 0.8, "e_fit": 0.79, "T": None, "T_fit": 2e-3}],
    }
    fit = ji.Fit.from_dict(record)
    assert fit.law.name == "kelvin_voigt" and float(fit.law.parameters["b"]) == 400.0
    assert fit.v0.tolist() == [2.5] and fit.e_target.tolist() == [0.8]
    assert fit.e.tolist() == [0.79] and np.isnan(fit.T_target[0])
    assert float(fit.m) == 0.05 and fit.g == 9.81 and bool(fit.converged)
    assert fit.residuals is None and fit.n_data is None and np.isnan(fit.x_max[0])
    # simulate --json: one speed as a number
    one = ji.Fit.from_dict({"law": "kelvin_voigt", "params": {"c": 2e6, "b": 400.0}, "v0": 2.5})
    assert one.v0.tolist() == [2.5] and one.converged is None


def test_a_user_s_law_is_passed_in():
    """A user's law has a name that no table rebuilds: its object is passed as `law=`."""
    mine = ji.custom_law(lambda x, v, p: p["k"] * x, k=5.0)
    fit = ji.Fit.from_dict({"law": "mine.py:spring", "params": {"k": 5.0}}, law=mine)
    assert isinstance(fit.law, CustomLaw) and fit.params["k"] == 5.0


@pytest.mark.parametrize(
    "record, message",
    [
        ({"params": {"c": 1.0}}, "no law name ('law')"),
        ({"law": "hertz", "params": {"c": 1.0}}, "law 'hertz' is not one of"),
        ({"law": "kelvin_voigt"}, "no parameters ('params'"),
        ({"law": "kelvin_voigt", "params": {"c": "big"}}, "parameter c = 'big' is not a finite"),
        ({"law": "kelvin_voigt", "params": {"c": 1.0, "b": 1.0, "k": 1.0}}, "has no parameter k"),
        ({"law": "kelvin_voigt", "params": {"c": 1.0, "b": 1.0}, "m": -1}, "mass m = -1"),
        (
            {"law": "kelvin_voigt", "params": {"c": 1.0, "b": 1.0}, "rows": [{"v0": "fast"}]},
            "a speed",
        ),
    ],
)
def test_a_dict_that_is_no_fit_is_one_value_error(record, message):
    with pytest.raises(ValueError, match="^[^\n]*$") as caught:
        ji.Fit.from_dict(record)
    assert message in str(caught.value)
