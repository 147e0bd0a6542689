"""`next_measurement`: which candidate speed (or incidence angle, for an oblique fit)
teaches most about a law's parameters.

For a near-Gaussian posterior of the free parameters (covariance `Sigma` of their
unbounded coordinates over the draws) and a new measurement `y = f(z) + noise` at a
candidate speed, linearised at the posterior median (`J = df/dz`), the expected
information gain (mutual information between `y` and the parameters, nats) is

    EIG = 1/2 ln det(I + S^-1/2 J Sigma J^T S^-1/2),

with `S` the new measurement's noise covariance (diagonal: `sigma_e^2`, `sigma_T^2`).
"""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._format import format_fields, format_value, jsonable
from .._xla_log import quietly_compiled
from .bands import noise_scale
from .oblique_model import ObliqueModel, oblique_sensitivities


class NextMeasurement(eqx.Module):
    """Candidates ranked by expected information gain: `v0`, best first (speeds in m/s;
    for an oblique fit's posterior the incidence angles in rad, also as `angle`), and
    their `gain` (nats, larger teaches more); `measure`: what a new measurement gives
    (`("e", "T")`, `("e",)`, `("e_t", "omega_out")`, ...); `over`: what the candidates
    are, `"v0"` or `"angle"`."""

    v0: np.ndarray
    gain: np.ndarray
    measure: tuple = eqx.field(static=True)
    over: str = eqx.field(static=True, default="v0")

    @property
    def angle(self) -> np.ndarray:
        """The candidate incidence angles (rad), best first (an oblique fit's posterior)."""
        if self.over != "angle":
            raise ValueError("these candidates are speeds (nm.v0), not incidence angles")
        return self.v0

    def summary(self) -> str:
        if self.over == "angle":
            shown = [f"angle {np.degrees(a):.4g} deg" for a in self.v0]
        else:
            shown = [f"v0 {format_value(v, 'm/s')}" for v in self.v0]
        rows = [
            (f"#{i + 1}", f"{text}, gain {g:.4g} nats")
            for i, (text, g) in enumerate(zip(shown, self.gain, strict=True))
        ]
        what = " and ".join(self.measure)
        return format_fields(f"Next measurement of {what}, best first", rows)

    def to_dict(self) -> dict:
        return {
            self.over: jsonable(self.v0),
            "gain": jsonable(self.gain),
            "measure": list(self.measure),
        }

    def __repr__(self) -> str:
        return self.summary()


@eqx.filter_jit
def _jacobians(model, z, v0):
    """`(e, T)` at `v0` and their derivatives with respect to `z`, each `(speeds, d)`."""

    def f(zz):
        e, T, _ = model.predict(model.values(zz), v0)
        return jnp.stack([e, T])

    return f(z), jax.jacfwd(f)(z)


@quietly_compiled
def next_measurement(
    post, v0=None, *, angle=None, speed=None, omega=None, measure=None
) -> NextMeasurement:
    """Rank the candidate speeds `v0` (m/s) by the expected information gain of one new
    measurement there about `post`'s free law parameters (nats; the module's formula,
    linearised at the posterior median, with the posterior covariance of the draws and
    the noise of the data: the sampled scales' medians, or the given sigmas' median,
    `sigma_T` as a fraction of T). `measure`: what the new measurement gives, default what
    the fit's data gave (`("e", "T")` when both were measured).

    The posterior of an oblique fit (`fit_oblique`) ranks incidence angles instead:
    `angle` (rad from the normal, in (0, pi/2)) at `speed` (m/s) with spin `omega` (rad/s)
    before (both default to the medians of the fit's rows); `measure` from `"e_t"`,
    `"omega_out"`; the result's `v0` (and `angle`) holds the angles, best first.

    **Example**: `next_measurement(post, v0=np.linspace(0.5, 5, 10)).v0[0]`;
    `next_measurement(oblique_post, angle=np.deg2rad([5, 15, 30, 50])).angle[0]`.
    """
    model = post.model
    if model is None:
        raise ValueError(
            "next_measurement needs a Posterior with its forward model (from posterior())"
        )
    z = np.asarray(post.z)
    center = np.median(z, axis=0)
    if isinstance(model, ObliqueModel):
        if v0 is not None:
            raise ValueError(
                "this posterior is of an oblique fit: it ranks incidence angles, "
                "next_measurement(post, angle=radians), not speeds v0"
            )
        angle, measure, jacobian, scales = oblique_sensitivities(
            post, center, angle, speed=speed, omega=omega, measure=measure
        )
        return _ranked(post, angle, jacobian, scales, measure, "angle")
    if angle is not None or speed is not None or omega is not None:
        raise ValueError(
            "angle=, speed= and omega= are for the posterior of an oblique fit "
            "(fit_oblique); this one ranks impact speeds: next_measurement(post, v0=m/s)"
        )
    if model.e is None and model.T is None:
        raise ValueError(
            "next_measurement ranks speeds for a new e or T measurement: it takes the "
            "posterior of a calibrate fit, not of a bounce fit (fit_bounces)"
        )
    v0 = np.atleast_1d(np.asarray(np.nan if v0 is None else v0, dtype=float))
    if v0.ndim != 1 or v0.size == 0 or not np.all(np.isfinite(v0) & (v0 > 0)):
        raise ValueError("v0 must be candidate speeds > 0 m/s (a number or a 1-D array)")
    measured = tuple(k for k, data in (("e", model.e), ("T", model.T)) if data is not None)
    measure = measured if measure is None else tuple(measure)
    unknown = [k for k in measure if k not in ("e", "T")]
    if unknown or not measure:
        raise ValueError(f"measure takes 'e' and/or 'T', got {measure!r}")
    for k in measure:
        given = model.sigma_e if k == "e" else model.sigma_T
        if f"sigma_{k}" not in model.names and given is None:
            raise ValueError(
                f"no noise scale for a new {k}: the fit had no {k} data; measure only "
                f"{' and '.join(measured)}"
            )
    (e_T, jac) = _jacobians(model, jnp.asarray(center), jnp.asarray(v0))
    e_T, jac = np.asarray(e_T), np.asarray(jac)  # (2, k), (2, k, d)
    rows = sorted({("e", "T").index(k) for k in measure})
    scales = []
    for r in rows:
        what = ("e", "T")[r]
        s = noise_scale(post, what, e_T[1][None, :], z)  # (draws or 1, speeds)
        scales.append(np.broadcast_to(np.median(s, axis=0), v0.shape))
    measure = tuple(("e", "T")[r] for r in rows)
    return _ranked(post, v0, jac[rows], np.stack(scales), measure, "v0")


def _ranked(post, candidates, jacobian, scales, measure, over) -> NextMeasurement:
    """The candidates ranked by the module's gain: `jacobian` of the measured quantities
    with respect to `z`, `(quantities, candidates, d)`, `scales` their noise,
    `(quantities, candidates)`."""
    model = post.model
    z = np.asarray(post.z)
    free = [model.names.index(k) for k in model.free]
    sigma = np.atleast_2d(np.cov(z[:, free], rowvar=False))
    jacobian = np.asarray(jacobian)[..., free]
    gains = np.empty(candidates.shape)
    for k in range(candidates.size):
        J = jacobian[:, k] / scales[:, k, None]  # (quantities, free)
        M = np.eye(J.shape[0]) + J @ sigma @ J.T
        gains[k] = 0.5 * np.linalg.slogdet(M)[1]
    order = np.argsort(-gains, kind="stable")
    return NextMeasurement(candidates[order], gains[order], measure, over)
