"""`jaximpact fit-oblique`: bad files and options get one line before any solve; a real
fit (slow) prints the parameters, the goodness of fit and the table of rebounds."""

import json

import pytest
from helpers import assert_one_line_error, run_cli

BASE = [
    "--mass",
    "2.618e-4",
    "--radius",
    "2.5e-3",
    "--law",
    "tsuji",
    "--param",
    "c=4.1968e9",
    "b=15.134",
    "--tangential",
    "linear_history",
    "--tparam",
    "kt=1e6",
    "mu=0.1",
]


@pytest.fixture(autouse=True)
def _no_persistent_cache(monkeypatch):
    monkeypatch.setenv("JAXIMPACT_CACHE_DIR", "")


def _write(tmp_path, text, name="rebounds.csv"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


@pytest.mark.parametrize(
    "text, extra, message",
    [
        ("theta_deg,e_t\n20,0.6\n", [], "pass the impact speed --speed"),
        ("v_n,v_t,e_t\n3,1,0.6\n", ["--speed", "3.9"], "--speed is not used"),
        ("theta_deg,v_n,e_t\n20,3,0.6\n", ["--speed", "3.9"], "theta_deg or as v_n,v_t"),
        ("v_n,e_t\n3,0.6\n", [], "theta_deg or as v_n,v_t"),
        ("theta,e_t\n20,0.6\n", ["--speed", "3.9"], "unknown column 'theta'"),
        ("theta_deg\n20\n", ["--speed", "3.9"], "no measured column"),
        ("theta_deg,e_t\n20,0.6,1\n", ["--speed", "3.9"], "line 2: 3 cells for 2 columns"),
        ("theta_deg,e_t\n20,abc\n", ["--speed", "3.9"], "column e_t: 'abc' is not a number"),
        ("theta_deg,e_t\n95,0.6\n", ["--speed", "3.9"], "must lie in [0, 90) degrees"),
        ("theta_deg,e_t,omega_out\n20,,\n", ["--speed", "3.9"], "neither e_t nor omega_out"),
        ("theta_deg,e_t\n", ["--speed", "3.9"], "has no rows"),
        ("theta_deg,e_t\n0.35,0.6\n0.7,0.7\n", ["--speed", "3.9"], "radians?"),
        ("theta_deg,e_t\n20,0.6\n", ["--speed", "-1"], "--speed must be > 0"),
        ("theta_deg,e_t\n20,0.6\n", ["--speed", "3.9", "--tparam", "kt"], "--tparam 'kt' must"),
        ("theta_deg,e_t\n20,0.6\n", ["--speed", "3.9", "--free", "G_star"], "free must name"),
    ],
)
def test_bad_input_is_one_line(capsys, tmp_path, text, extra, message):
    status, out, err = run_cli(capsys, ["fit-oblique", _write(tmp_path, text), *BASE, *extra])
    assert_one_line_error(status, out, err, contains=message)


def test_a_missing_file_and_a_plot_that_is_the_input(capsys, tmp_path):
    status, out, err = run_cli(capsys, ["fit-oblique", str(tmp_path / "none.csv"), *BASE])
    assert_one_line_error(status, out, err, contains="cannot read")
    data = _write(tmp_path, "theta_deg,e_t\n20,0.6\n")
    status, out, err = run_cli(
        capsys, ["fit-oblique", data, *BASE, "--speed", "3.9", "--plot", data]
    )
    assert_one_line_error(status, out, err, contains="input")


def test_the_fit_shows_the_clock_while_it_compiles(capsys, tmp_path, monkeypatch):
    """fit-oblique's first call compiles for 40-75 s: a bar shows the time going (it printed
    nothing until the end); here the fit itself is a stand-in that takes 0.5 s and fails."""
    import time

    import jaximpact._oblique as oblique
    from jaximpact._cli import common

    def stand_in(*args, **kwargs):
        time.sleep(0.5)
        raise ValueError("the stand-in fit")

    monkeypatch.setenv("JAXIMPACT_PROGRESS", "on")
    monkeypatch.setattr(common.heartbeat_meter, "__defaults__", (0.0,))  # no delay
    monkeypatch.setattr(oblique, "fit_oblique", stand_in)
    data = _write(tmp_path, "theta_deg,e_t\n10,0.6\n20,0.55\n30,0.6\n")
    status, out, err = run_cli(capsys, ["fit-oblique", data, *BASE, "--speed", "3.9"])
    assert status == 2 and out == ""
    assert err.startswith("fitting linear_history to 3 rebounds [---")
    assert err.strip().splitlines()[-1] == "jaximpact: error: the stand-in fit"


@pytest.mark.slow
def test_fits_rebounds_made_by_the_library(capsys, tmp_path):
    """e_t and spin made by `oblique_impact` with kt = 5e6 N/m, mu = 0.12 at five angles,
    fitted from kt = 1e6, mu = 0.1 through the command: the parameters back to 1e-6, the
    table and the figure written, and --json one object with the goodness of fit."""
    import numpy as np

    import jaximpact as ji

    law = ji.law("tsuji", c=4.1968e9, b=15.134)
    truth = ji.tangential_law("linear_history", kt=5e6, mu=0.12)
    rows = ["theta_deg,e_t,omega_out"]
    for theta in (5.0, 15.0, 25.0, 40.0, 60.0):
        v_n, v_t = (float(v) for v in ji.incidence(3.9, np.deg2rad(theta)))
        r = ji.oblique_impact(law, truth, m=2.618e-4, R=2.5e-3, v_n=v_n, v_t=v_t)
        rows.append(f"{theta},{float(r.e_t)!r},{float(r.omega_out)!r}")
    data = _write(tmp_path, "\n".join(rows) + "\n")
    plot = tmp_path / "fit.png"
    argv = ["fit-oblique", data, *BASE, "--speed", "3.9"]
    status, out, err = run_cli(capsys, [*argv, "--plot", str(plot)])
    assert status == 0, err
    assert "kt" in out and "rms e_t" in out and "theta [deg]" in out and plot.stat().st_size > 0
    status, out, err = run_cli(capsys, [*argv, "--json"])
    assert status == 0, err
    fit = json.loads(out)
    assert fit["converged"] is True and fit["n_data"] == 10 and fit["dof"] == 8
    assert fit["params"]["kt"] == pytest.approx(5e6, rel=1e-6)
    assert fit["params"]["mu"] == pytest.approx(0.12, rel=1e-6)


def _track_csv(tmp_path, scale=1.0, columns=("t", "x", "y", "phi"), solved=False):
    """A track as a CSV, `y` times `scale`: with `solved`, the synthetic track of
    tests/oblique/test_track.py (its impacts from `oblique_impact`), else three flights of
    a ball reflected with e = 0.9, e_t = 0.8 (for the refusals: no solve)."""
    import sys
    from pathlib import Path

    import numpy as np

    if solved:
        sys.path.insert(0, str(Path(__file__).parents[1] / "oblique"))
        from test_track import synthetic_track

        t, x, y, phi, _ = synthetic_track(impacts="solve")
    else:
        frames, t0, x0, vx, vy, h0 = [], 0.0, 0.0, 1.0, 0.0, 0.25
        for _ in range(3):
            tc = (vy + np.sqrt(vy**2 + 2 * 9.81 * (h0 - 0.02))) / 9.81
            s = np.arange(np.ceil(t0 * 240), np.floor((t0 + tc) * 240) + 1) / 240 - t0
            frames.append(np.stack([t0 + s, x0 + vx * s, h0 + vy * s - 4.905 * s**2], 1))
            t0, x0, h0, vy, vx = t0 + tc, x0 + vx * tc, 0.02, 0.9 * (9.81 * tc - vy), 0.8 * vx
        t, x, y = np.concatenate(frames).T
        t, keep = np.unique(t, return_index=True)
        x, y = x[keep], y[keep]
        phi = -x / 0.02
    values = {"t": t, "x": x, "y": y * scale, "phi": phi}
    lines = [",".join(columns)]
    lines += [",".join(repr(float(values[c][i])) for c in columns) for i in range(len(t))]
    return _write(tmp_path, "\n".join(lines) + "\n", "track.csv")


TRACK_BASE = [
    "--mass",
    "0.05",
    "--radius",
    "0.02",
    "--law",
    "hertz_rate",
    "--param",
    "c=1.32e7",
    "b1=30",
    "--tangential",
    "linear_history",
    "--tparam",
    "kt=1e4",
    "mu=0.2",
]


@pytest.mark.parametrize(
    "scale, columns, extra, message",
    [
        (1000.0, ("t", "x", "y", "phi"), [], "give the positions in metres"),
        (1.0, ("t", "x", "y"), [], "a track has the columns t, x, y, phi"),
        (1.0, ("t", "x", "y", "phi"), ["--speed", "2"], "--speed is not used"),
        (1.0, ("t", "x", "y", "phi"), ["--g", "-9.81"], "--g must be"),
    ],
)
def test_a_bad_track_is_one_line(capsys, tmp_path, scale, columns, extra, message):
    data = _track_csv(tmp_path, scale, columns)
    status, out, err = run_cli(capsys, ["fit-oblique", data, *TRACK_BASE, *extra])
    assert_one_line_error(status, out, err, contains=message)


@pytest.mark.slow
def test_fits_a_video_track(capsys, tmp_path):
    """The clean synthetic track (kt = 2e4 N/m, mu = 0.3; its normal law's c is
    hertz_stiffness(5e7, 0.45, 0.02, inf) = 1.3173e7): the command reads its four impacts
    and finds kt and mu to 1e-3 (the track's impacts are exact to 1e-9; the normal law is
    given to five digits)."""
    import jaximpact as ji

    c = ji.hertz_stiffness(E=5e7, nu=0.45, R=0.02, E2=float("inf"))
    argv = ["fit-oblique", _track_csv(tmp_path, solved=True), *TRACK_BASE, "--json"]
    argv[argv.index("c=1.32e7")] = f"c={c!r}"
    status, out, err = run_cli(capsys, argv)
    assert status == 0, err
    fit = json.loads(out)
    assert fit["params"]["kt"] == pytest.approx(2e4, rel=1e-3)
    assert fit["params"]["mu"] == pytest.approx(0.3, rel=1e-3)


# ----------------------------------------------------- jaximpact simulate --tangential

SIMULATE = [
    "simulate",
    "--law",
    "hunt_crossley",
    "--param",
    "c=4.2e9",
    "a=0",
    "--mass",
    "2.618e-4",
    "--v0",
    "3.9",
]
MINDLIN = ["--tangential", "mindlin", "--tparam", "G_star=1.35e10", "mu=0.092"]


def test_the_command_line_s_tangential_names_are_the_library_s():
    import jaximpact as ji
    from jaximpact._cli.common import TANGENTIAL_CHOICES

    assert set(TANGENTIAL_CHOICES) == set(ji.TANGENTIAL_LAW_NAMES)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--angle", "30"], "--angle is for an oblique impact: add --tangential NAME"),
        (["--tparam", "mu=0.1"], "--tparam is for an oblique impact"),
        (["--omega", "3"], "--omega is for an oblique impact"),
        ([*MINDLIN, "--angle", "30"], "needs --radius"),
        ([*MINDLIN, "--radius", "2.5e-3"], "needs --angle"),
        ([*MINDLIN, "--radius", "2.5e-3", "--angle", "95"], "in degrees from the normal"),
        ([*MINDLIN, "--radius", "-1", "--angle", "5"], "--radius must be"),
        ([*MINDLIN, "--radius", "2.5e-3", "--angle", "5", "--v0", "1", "2"], "one --v0"),
        ([*MINDLIN, "--radius", "2.5e-3", "--angle", "5", "--inertia", "0"], "--inertia"),
        (
            [*MINDLIN, "--radius", "2.5e-3", "--angle", "5", "--max-segments", "0"],
            "--max-segments must be at least 1",
        ),
        (["--max-segments", "40"], "--max-segments is for an oblique impact"),
        (["--tangential", "coulomb", "--radius", "2.5e-3", "--angle", "5"], "invalid choice"),
        (
            [
                "--tangential",
                "mindlin",
                "--tparam",
                "G_star=1e10",
                "mu=-0.1",
                "--radius",
                "2.5e-3",
                "--angle",
                "5",
            ],
            "mu must be",
        ),
    ],
)
def test_simulate_oblique_bad_input_is_one_line(capsys, extra, message):
    status, out, err = run_cli(capsys, [*SIMULATE, *extra])
    assert_one_line_error(status, out, err, contains=message)


@pytest.mark.slow  # an oblique solve's compiling (the fast suite: 3 minutes)
def test_simulate_an_oblique_impact_is_the_library_s(capsys, tmp_path):
    """One angle as a line per field (angles in degrees), a sweep as a table and as JSON,
    with the numbers of `oblique_impact` at the same incidence, and the plot."""
    import math

    import jaximpact as ji

    want = ji.oblique_impact(
        ji.law("hunt_crossley", c=4.2e9, a=0.0),
        ji.tangential_law("mindlin", G_star=1.35e10, mu=0.092),
        m=2.618e-4,
        R=2.5e-3,
        v_n=3.9 * math.cos(math.radians(20)),
        v_t=3.9 * math.sin(math.radians(20)),
    )
    status, out, err = run_cli(capsys, [*SIMULATE, *MINDLIN, "--radius", "2.5e-3", "--angle", "20"])
    assert status == 0 and err == ""
    assert "angle             = 20 deg" in out and "status            = separated" in out
    assert f"e_t               = {float(want.e_t):.4g}" in out
    assert f"{math.degrees(float(want.angle_out)):.4g} deg" in out
    assert "e_t_contact = u_out / u (the contact point's slip" in out  # the fields explained
    plot = tmp_path / "sweep.png"
    status, out, err = run_cli(
        capsys,
        [
            *SIMULATE,
            *MINDLIN,
            "--radius",
            "2.5e-3",
            "--angle",
            "5",
            "20",
            "--json",
            "--plot",
            str(plot),
        ],
    )
    runs = json.loads(out)
    assert status == 0 and [r["angle_deg"] for r in runs] == [5.0, 20.0]
    assert runs[1]["e_t"] == pytest.approx(float(want.e_t), rel=1e-12)
    assert runs[1]["omega_out"] == pytest.approx(float(want.omega_out), rel=1e-12)
    assert runs[1]["angle_out_deg"] == pytest.approx(math.degrees(float(want.angle_out)))
    assert plot.stat().st_size > 0


@pytest.mark.slow  # an oblique solve's compiling
def test_simulate_says_which_angles_ran_out_of_segments(capsys):
    """A sphere whose tangential spring is far stiffer than its normal one (a 5 m radius,
    from a wrong unit) switches between stick and slip 16 times: with the default 16
    segments the solve ends out_of_steps. The command prints the status and what to raise,
    exits 1 (it said `internal error, RuntimeError` before), and --max-segments 64 ends it."""
    argv = [
        "simulate",
        "--law",
        "hertz_rate",
        "--param",
        "c=1e9",
        "b1=0",
        "--mass",
        "0.01",
        "--v0",
        "1",
        "--tangential",
        "mindlin",
        "--tparam",
        "G_star=1e10",
        "mu=0.3",
        "--radius",
        "5",
        "--angle",
        "30",
    ]
    status, out, err = run_cli(capsys, argv)
    assert status == 1 and "internal error" not in err
    assert "status            = out_of_steps" in out
    assert out.strip().splitlines()[-1] == (
        "the solve ended out_of_steps at --angle 30 (after 16 stick-slip switches): raise "
        "--max-segments (16)"
    )
    status, out, err = run_cli(capsys, [*argv, "--max-segments", "64", "--json"])
    assert status == 0 and json.loads(out)["status"] == "separated"


@pytest.mark.parametrize(
    "m, R, warned",
    [
        (2.618e-4, 2.5e-3, False),  # Kharaz's alumina sphere, 3.99 g/cm^3
        (2.7e-3, 0.02, False),  # a ping-pong ball, hollow: 80 kg/m^3
        (2.618e-4, 2.5, True),  # the radius in mm given as m
        (261.8, 2.5e-3, True),  # the mass in mg given as kg: 4e9 kg/m^3
    ],
)
def test_a_sphere_of_implausible_density_is_warned(capsys, m, R, warned):
    """A wrong unit in --mass or --radius (found by using the commands as a new user: a
    radius of 2.5 "m" for a 5 mm ball gave a plausible-looking table) is said in one
    warning line before any work; here the tangential law's refusal follows it."""
    argv = [
        "simulate",
        "--law",
        "hunt_crossley",
        "--param",
        "c=4.2e9",
        "a=0",
        "--mass",
        str(m),
        "--v0",
        "3.9",
        "--tangential",
        "mindlin",
        "--tparam",
        "G_star=1.35e10",
        "mu=-0.1",
        "--radius",
        str(R),
        "--angle",
        "30",
    ]
    status, out, err = run_cli(capsys, argv)
    lines = err.strip().splitlines()
    assert status == 2 and out == "" and "mu must be" in lines[-1]
    if warned:
        assert len(lines) == 2 and "check the units (--mass in kg, --radius in m)" in lines[0]
    else:
        assert len(lines) == 1


def test_a_spin_of_a_wrong_unit_is_warned_before_any_work():
    """`--omega 1e9` (rad/s) on a 2.5 mm sphere turns its surface at 2.5e6 m/s: a warning
    that names the units, before the solve (it ran without a word); a spin of 100 rad/s
    does not warn."""
    import argparse
    import warnings

    from jaximpact._cli.oblique import check_oblique_arguments

    def args(omega):
        return argparse.Namespace(
            tangential="mindlin",
            radius=2.5e-3,
            angle=[30.0],
            v0=[3.9],
            omega=omega,
            inertia=0.4,
            max_segments=16,
            tparam=[],
            mass=2.6e-4,
        )

    with pytest.warns(UserWarning, match=r"--omega 1e\+09 rad/s turns the sphere's surface"):
        check_oblique_arguments(args(1e9))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_oblique_arguments(args(100.0))


def test_a_friction_coefficient_far_above_real_contacts_is_warned():
    """`mu=100` (a slip of a digit) warns that no real dry contact has it; 0.9 does not."""
    import warnings

    import jaximpact as ji

    with pytest.warns(UserWarning, match="mu = 100 is far above the friction of real dry"):
        ji.tangential_law("linear_history", kt=1e7, mu=100.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ji.tangential_law("linear_history", kt=1e7, mu=0.9)
