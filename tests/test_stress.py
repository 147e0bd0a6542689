"""Stress tests: extreme stiffness, mass, speed and damping; no NaN anywhere, the right
status, and the closed forms / one-group scaling laws (see `stress_cases.py`).

The default suite runs a fast subset (a few members of three batches, one compilation
each); `-m slow` runs the whole sweep of `benchmarks/stress.py` law by law, in float64 and
(through a subprocess with x64 off) float32.
"""

import json
import os
import subprocess
import sys
import zlib

import numpy as np
import pytest
import stress_cases as sc

import jaximpact as ji

# e is a number in [0, 1]: absolute error; T: relative error. At the default rtol 1e-10,
# e is good to ~3e-9; T is ill-conditioned for heavily damped Hertz laws (the separation
# event is crossed slowly: 1.2e-6 at beta = 30 for hertz_rate), hence the looser bound.
E_TOL = 1e-7
T_TOL = 1e-5


def _check(summary, gradients=True):
    where = f"{summary['law']} / {summary['separation']}"
    assert summary["nan_values"] == 0, f"{where}: NaN in values: {summary['nan_members']}"
    if gradients:
        assert summary["nan_jacfwd"] == 0, f"{where}: NaN in jacfwd: {summary['nan_members']}"
        if summary.get("nan_grad") is not None:
            assert summary["nan_grad"] == 0, f"{where}: NaN in grad: {summary['nan_members']}"
    assert summary["counts"]["out_of_steps"] == 0, f"{where}: out of steps {summary}"
    assert summary["status_mismatch"] == 0, f"{where}: {summary['mismatch_examples']}"
    if summary["e_err_max"] is not None:
        assert summary["e_err_max"] < E_TOL, f"{where}: e error {summary['e_err_max']}"
        assert summary["T_err_max"] < T_TOL, f"{where}: T error {summary['T_err_max']}"


def _sweep(name, separation, n, method="integrate", gradients=("jacfwd",)):
    members = sc.sample(name, n, seed=zlib.crc32(name.encode()))
    refs = sc.references(name, separation, members)
    out, _, _ = sc.run_sweep(name, separation, members, method=method, gradients=gradients)
    return sc.summarise(name, separation, members, out, refs)


FAST = [
    # Hertz with x^0.5 damping: fractional powers, the Lienard variable, the force criterion
    ("hertz_rate", "force", "integrate"),
    # a dry force: split phases, stuck members, the penetration criterion
    ("bingham", "penetration", "integrate"),
    # the closed-form default path, over-damped members captured
    ("kelvin_voigt", "penetration", "auto"),
]


@pytest.mark.parametrize("name, separation, method", FAST)
def test_stress_fast(name, separation, method):
    summary = _sweep(name, separation, 4, method=method)
    # the corners of the (c, m, v0) box at both ends of the damping range are all there
    assert summary["members"] >= 16
    _check(summary)


def test_stress_covers_the_range():
    """The sweep really spans the ranges the issue asks for."""
    members = sc.sample("hertz_rate", 4)
    for key, (lo, hi) in (("c", sc.C_RANGE), ("m", sc.M_RANGE), ("v0", sc.V_RANGE)):
        assert np.isclose(members[key].min(), lo) and np.isclose(members[key].max(), hi)
    e, _, status = sc.references("kelvin_voigt", "penetration", sc.sample("kelvin_voigt", 4))
    assert e.max() > 0.999 and np.any(status == sc.STATUS["captured"])


ALL = [(name, sep) for name in ji.LAW_NAMES for sep in ("force", "penetration")]


@pytest.mark.slow
@pytest.mark.parametrize("name, separation", ALL)
def test_stress_full_float64(name, separation):
    summary = _sweep(name, separation, 64, gradients=("jacfwd", "grad"))
    _check(summary)
    if summary.get("fwd_rev_max_separated") is not None:
        assert summary["fwd_rev_max_separated"] < 1e-6


@pytest.mark.slow
@pytest.mark.parametrize("name", ji.LAW_NAMES)
def test_stress_full_float32(name, tmp_path):
    """float32 (x64 off, in a subprocess): no NaN, no lost impact, e to ~1e-5."""
    out = tmp_path / "rows.json"
    script = os.path.join(os.path.dirname(os.path.dirname(__file__)), "benchmarks", "stress.py")
    cmd = [sys.executable, script, "--worker32", str(out), "--n", "16", "--laws", name]
    cmd += ["--gradients", "jacfwd"]
    env = dict(os.environ, JAX_ENABLE_X64="0")
    subprocess.run(cmd, env=env, check=True, capture_output=True)
    for summary in json.loads(out.read_text()):
        where = f"{name} / {summary['separation']}"
        assert summary["nan_values"] == 0 and summary["nan_jacfwd"] == 0, where
        assert summary["counts"]["out_of_steps"] == 0, where
        if summary["e_err_max"] is not None:
            assert summary["e_err_max"] < 1e-4, where
