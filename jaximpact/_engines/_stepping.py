"""Replicas of the engines' time stepping for one head-on contact, in numpy.

They predict what an engine realises (its discretisation included) without running it; the
engine tests check them against the engines themselves. Each contact is started at several
phases inside a time step (the first touch falls `phase * h` after a step's start), since
the realised e depends on it at first order in the step.
"""

import numpy as np

PHASES = (np.arange(16) + 0.5) / 16


def _finish(x, v, h, v0, force_of, update, max_steps):
    steps = np.zeros_like(x)
    started = np.zeros(x.shape, bool)
    done = np.zeros(x.shape, bool)
    for _ in range(max_steps):
        x, v, pushing = update(x, v, done)
        started |= pushing
        done |= started & ~pushing
        steps += pushing & ~done
        if done.all():
            return -v / v0, steps * h
    raise RuntimeError("the replica did not finish the contact; the time step is far too small")


def semi_implicit_euler(accel, h, v0, phases=PHASES, max_steps=2_000_000):
    """MuJoCo's Euler: `a_k = accel(x_k, v_k)`, `v += h a`, `x += h v`; the contact is
    active while `x > 0` at a step's start. `accel(x, v)` is the contact acceleration along
    the penetration `x` (<= 0, it never pulls). Returns `(e, T)` per phase, `T` the number of
    steps with a non-zero force times `h`."""
    x = -v0 * h * np.asarray(phases, float)
    v = np.full_like(x, v0)

    def update(x, v, done):
        a = np.where(x > 0, accel(np.maximum(x, 0.0), v), 0.0)
        v_new = np.where(done, v, v + h * a)
        return np.where(done, x, x + h * v_new), v_new, a != 0

    return _finish(x, v, h, v0, accel, update, max_steps)


def velocity_verlet(accel, h, v0, phases=PHASES, max_steps=2_000_000):
    """LAMMPS's `fix nve` (and `nve/sphere`): half kick, drift, force from the new
    positions and the half-step velocities, half kick. `accel(x, v)` as above."""
    x = -v0 * h * np.asarray(phases, float)
    v = np.full_like(x, v0)
    a = np.zeros_like(x)

    def update(x, v, done):
        nonlocal a
        v_half = v + 0.5 * h * a
        x_new = x + h * v_half
        a_new = np.where(x_new > 0, accel(np.maximum(x_new, 0.0), v_half), 0.0)
        v_new = v_half + 0.5 * h * a_new
        pushing = a_new != 0
        a = np.where(done, 0.0, a_new)
        return np.where(done, x, x_new), np.where(done, v, v_new), pushing

    return _finish(x, v, h, v0, accel, update, max_steps)
