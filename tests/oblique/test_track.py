"""Rebounds from a video track (`track_rebounds`, issue 27 item 4): a ball bouncing across a
floor with spin, its flights made exactly (parabolas between instants of contact, each
impact from `oblique_impact`, or from the rigid-body theory where only the reading of the
track is tested), sampled at 240 frames per second. Noise-free, the rebounds
come back to 1e-9; with the noise of a good video (0.2 mm, 0.02 rad), within a few of their
standard errors, and `fit_oblique` on them finds the tangential law (slow). Bad tracks get
one-line errors."""

import functools
import math

import jax
import numpy as np
import pytest

import jaximpact as ji

R, M, G, FPS = 0.02, 0.05, 9.81, 240.0
LAW = ji.law("hertz_rate", c=ji.hertz_stiffness(E=5e7, nu=0.45, R=R, E2=math.inf), b1=30.0)
TANGENTIAL = ji.tangential_law("linear_history", kt=2e4, mu=0.3)


@functools.cache
def synthetic_track(bounces=4, vx=1.2, y0=0.25, impacts="rigid"):
    """`(t, x, y, phi, truth)`: the frames of a ball dropped from `y0` (m, its centre) moving
    at `vx` (m/s) without spin, each contact instantaneous at the frame rate (its duration,
    0.1 ms, is not a flight), `truth` one row per impact: `(t_c, v_n, v_t, omega, v_n_out,
    v_t_out, omega_out)`. `phi` counterclockwise: a spin `omega` turns it at `-omega`.
    Each impact's outcome from `oblique_impact` with LAW and TANGENTIAL (`impacts="solve"`,
    what a fit must find back) or, for the tests of the track's reading alone, from the
    rigid-body theory with TANGENTIAL's mu and about the law's e, 0.99 (`"rigid"`: no
    solve to compile)."""
    frames, truth = [], []
    t0, x0, h0, vy, u, om, phi0 = 0.0, 0.0, y0, 0.0, vx, 0.0, 0.0

    def flight(t0, duration):
        ts = np.arange(math.ceil(t0 * FPS), math.floor((t0 + duration) * FPS) + 1) / FPS
        s = ts - t0
        return np.stack([ts, x0 + u * s, h0 + vy * s - G * s**2 / 2, phi0 - om * s], axis=1)

    for _ in range(bounces):
        tc = (vy + math.sqrt(vy**2 + 2 * G * (h0 - R))) / G
        frames.append(flight(t0, tc))
        v_n = -(vy - G * tc)
        if impacts == "solve":
            r = ji.oblique_impact(LAW, TANGENTIAL, m=M, R=R, v_n=v_n, v_t=u, omega=om, g=G)
            out = (float(r.v_n_out), float(r.v_t_out), float(r.omega_out))
        else:
            r = ji.rigid_oblique(mu=0.3, e=0.99, v_n=v_n, v_t=u, R=R, omega=om)
            out = (0.99 * v_n, float(r["v_t_out"]), float(r["omega_out"]))
        truth.append((t0 + tc, v_n, u, om, *out))
        t0, x0, h0, phi0 = t0 + tc, x0 + u * tc, R, phi0 - om * tc
        vy, u, om = out
    frames.append(flight(t0, 2 * vy / G * 0.999))
    t, x, y, phi = np.concatenate(frames).T
    keep = np.concatenate([[True], np.diff(t) > 0])  # a frame on a contact instant: once
    return t[keep], x[keep], y[keep], phi[keep], np.array(truth)


def _noisy(seed=0, impacts="rigid"):
    t, x, y, phi, truth = synthetic_track(impacts=impacts)
    rng = np.random.default_rng(seed)
    noise = rng.standard_normal((3, len(t)))
    return t, x + 2e-4 * noise[0], y + 2e-4 * noise[1], phi + 0.02 * noise[2], truth


FIELDS = ("t_impact", "v_n", "v_t", "omega", "v_n_out", "v_t_out", "omega_out")


def test_a_clean_track_gives_the_impacts_back():
    t, x, y, phi, truth = synthetic_track()
    r = ji.track_rebounds(t, x, y, phi)
    assert len(r.v_n) == 4 and r.g_track == pytest.approx(G, rel=1e-9)
    for k, name in enumerate(FIELDS):
        np.testing.assert_allclose(
            getattr(r, name), truth[:, k], rtol=1e-9, atol=1e-9, err_msg=name
        )
    np.testing.assert_allclose(r.e_t, truth[:, 5] / truth[:, 2], rtol=1e-9)
    assert "rad/s" in r.summary() and set(r.to_dict()) >= set(FIELDS)


def test_a_noisy_track_gives_the_impacts_within_their_errors():
    t, x, y, phi, truth = _noisy()
    r = ji.track_rebounds(t, x, y, phi)
    e_t = truth[:, 5] / truth[:, 2]
    assert np.all(np.abs(r.e_t - e_t) < 4 * r.sigma_e_t), (r.e_t, e_t, r.sigma_e_t)
    assert np.all(np.abs(r.omega_out - truth[:, 6]) < 4 * r.sigma_omega_out)
    e = truth[:, 4] / truth[:, 1]
    assert np.all(np.abs(r.e - e) < 4 * r.sigma_e), (r.e, e, r.sigma_e)
    inputs = r.fit_inputs()
    assert set(inputs) == {"v_n", "v_t", "omega", "e_t", "omega_out", "sigma_e_t", "sigma_omega"}


@pytest.mark.slow
def test_fit_oblique_finds_the_tangential_law_from_the_track():
    """kt and mu from the noisy track's four impacts: within three standard errors of the
    law that made it, the residuals at the noise (each kind's reduced chi-square below 4)."""
    t, x, y, phi, _ = _noisy(seed=1, impacts="solve")
    r = ji.track_rebounds(t, x, y, phi)
    start = ji.tangential_law("linear_history", kt=1e4, mu=0.2)
    fit = ji.fit_oblique(LAW, start, m=M, R=R, g=G, **r.fit_inputs())
    for name, truth in (("kt", 2e4), ("mu", 0.3)):
        value, se = float(fit.params[name]), float(fit.stderr[name])
        assert abs(value - truth) < 3 * se, (name, value, se)
    # each kind of residual at its noise (e_t and the spin apart: their units differ)
    assert float(fit.reduced_chi2_e_t) < 4.0 and float(fit.reduced_chi2_omega) < 4.0


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda t, x, y, p: (t, x, 1000 * y, p), "metres"),  # mm
        (lambda t, x, y, p: (t, x, -y, p), "y up"),  # y down: no floor below
        (lambda t, x, y, p: (t, x[:-1], y, p), "1-D array"),
        (lambda t, x, y, p: (t, x, np.where(np.arange(len(y)) == 5, np.nan, y), p), "NaN"),
        (lambda t, x, y, p: (t[::-1], x, y, p), "increase"),
        (lambda t, x, y, p: (t[:40], x[:40], y[:40], p[:40]), "impact"),  # a fall, no bounce
    ],
)
def test_bad_tracks_are_refused_in_one_line(change, message):
    t, x, y, phi, _ = synthetic_track()
    with pytest.raises(ValueError, match=message) as error:
        ji.track_rebounds(*change(t, x, y, phi))
    assert "\n" not in str(error.value)


def test_a_track_without_spin_gives_no_fit_inputs():
    t, x, y, _, truth = synthetic_track()
    r = ji.track_rebounds(t, x, y)
    np.testing.assert_allclose(r.v_t_out, truth[:, 5], rtol=1e-9)
    assert np.all(np.isnan(r.omega))
    with pytest.raises(ValueError, match="no spin") as error:
        r.fit_inputs()
    assert "\n" not in str(error.value)


def test_the_first_impact_of_a_drop_without_spin_has_none():
    t, x, y, phi, _ = _noisy()
    r = ji.track_rebounds(t, x, y, phi)
    assert abs(r.omega[0]) < 0.1  # rad/s, the noise's
    jax.block_until_ready(r.v_n)
