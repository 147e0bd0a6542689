"""The posterior of a `fit_oblique` fit: its own forward model (the `problem` the
`ObliqueFit` keeps: the oblique impacts of its rows solved with forward-mode derivatives
and landed events, the normal law held), as one log density of the unbounded coordinates
`z` that `posterior` samples, and the bands of e_t, the spin and the rebound angle at new
incidence angles.

What is sampled: the tangential law's `free` parameters (SI), then, for each measured kind
whose sigma was not given to `fit_oblique`, its noise scale: `sigma_e_t` (absolute) and
`sigma_omega` (rad/s), one for every row.

Likelihood: one term per measured value (a row with NaN in `e_t` or `omega_out` is left
out of that kind, as in the fit), `r = (prediction - measured) / sigma`, normal or
Student-t (`likelihood.log_noise`). The fit's residuals are computed by the fit's own
`problem.residuals` (in units of its scales `s_e`, `s_w`), every derivative through one
forward-mode Jacobian of the solves (`bounce.gauss_newton`: NUTS's gradient exact, the
Laplace Hessian Gauss-Newton's, the curvature of the fit's standard errors).

Default priors: the tangential parameters loguniform over three decades either side of
the fit (`priors.default_prior`); `sigma_e_t` loguniform(1e-4, 0.5), `sigma_omega`
loguniform over 1e-4 to 0.5 times the largest measured `|omega_out|` (rad/s).
"""

from typing import NamedTuple

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._format import format_fields, format_value, jsonable
from .._oblique.fit import ObliqueFit
from .._oblique.impact import incidence
from .._oblique.tangential import AbstractTangentialLaw
from .bands import noise_draws, noise_scale, thinned
from .bounce import gauss_newton
from .likelihood import log_noise
from .priors import default_prior, noise_prior, parse_prior


class Kind(NamedTuple):
    """A measured kind of an oblique fit: the `quantity`, the `noise` suffix of its noise
    scale's name (`sigma_e_t`, `sigma_omega`: as `fit_oblique` names its sigma), the
    noise scale's `unit`, and the `problem`'s fields of its data and residual scale."""

    quantity: str
    noise: str
    unit: str
    data: str
    scale: str

    @property
    def sigma(self) -> str:
        return f"sigma_{self.noise}"


KINDS = (
    Kind("e_t", "e_t", "", "e_t", "s_e"),
    Kind("omega_out", "omega", "rad/s", "omega_out", "s_w"),
)


class ObliqueModel(eqx.Module):
    """What an oblique fit's posterior samples (`names`: the tangential law's `free`
    parameters, then the sampled noise scales, in the order of `z`), their `priors`, the
    fitted tangential `law` (its other parameters as fitted with) and the fit's `problem`
    (rows, measured values, normal law, sphere, solve options); `sigma_e_t`,
    `sigma_omega`: the given sigmas per row (None: sampled, or the kind not measured)."""

    law: AbstractTangentialLaw
    names: tuple = eqx.field(static=True)
    free: tuple = eqx.field(static=True)
    priors: tuple
    problem: eqx.Module
    sigma_e_t: np.ndarray | None
    sigma_omega: np.ndarray | None
    noise: str = eqx.field(static=True)
    nu: float = eqx.field(static=True)

    @property
    def measured(self) -> tuple:
        """The kinds measured, `("e_t", "omega_out")` or one of them."""
        has = (self.problem.has_e, self.problem.has_w)
        return tuple(kind.quantity for kind, h in zip(KINDS, has, strict=True) if h)

    # ------------------------------------------------------------------ coordinates

    def values(self, z) -> dict:
        """`{name: value}` (SI) at `z` (last axis: the names)."""
        return {
            k: p.value(z[..., i])
            for i, (k, p) in enumerate(zip(self.names, self.priors, strict=True))
        }

    def coordinates(self, values: dict) -> np.ndarray:
        return np.stack(
            [p.coordinate(values[k]) for k, p in zip(self.names, self.priors, strict=True)], axis=-1
        )

    def theta(self, values: dict):
        """The fit's own coordinates: the logarithms of the free parameters."""
        return jnp.stack([jnp.log(values[k]) for k in self.free])

    # ------------------------------------------------------------------ forward model

    def residuals(self, values: dict):
        """`problem.residuals` at `values`: `(e_t_fit - e_t) / s_e` then `(omega_fit -
        omega_out) / s_w` of the kinds measured (0 where a row has none)."""

        def raw(theta, problem):
            return problem.residuals(problem.predict(theta))

        return gauss_newton(raw)(self.theta(values), self.problem)

    def predict(self, values: dict, v_n, v_t, omega):
        """The `ObliqueResult`s (a batch) of the law at `values` for the rows `v_n`, `v_t`
        (m/s), `omega` (rad/s): the fit's solve, differentiable in forward mode."""
        rows = (jnp.asarray(v_n, float), jnp.asarray(v_t, float), jnp.asarray(omega, float))
        problem = eqx.tree_at(lambda p: (p.v_n, p.v_t, p.omega), self.problem, rows)
        return problem.predict(self.theta(values))

    # ------------------------------------------------------------------ densities

    def log_prior(self, z):
        return sum(p.log_density(z[i]) for i, p in enumerate(self.priors))

    def log_likelihood(self, z):
        values = self.values(z)
        r = self.residuals(values)
        n = self.problem.v_n.shape[0]
        total = 0.0
        kinds = [k for k in KINDS if k.quantity in self.measured]
        for i, kind in enumerate(kinds):
            known = jnp.isfinite(getattr(self.problem, kind.data))
            given = getattr(self, kind.sigma)
            s = given if given is not None else values[kind.sigma]
            # the fit's residuals in the data's units, standardised by this noise scale
            standard = r[i * n : (i + 1) * n] * getattr(self.problem, kind.scale) / s
            terms = log_noise(standard, jnp.broadcast_to(s, (n,)), self.noise, self.nu)
            total = total + jnp.sum(jnp.where(known, terms, 0.0))
        return jnp.where(jnp.isfinite(total), total, -jnp.inf)

    def log_posterior(self, z):
        value = self.log_likelihood(z) + self.log_prior(z)
        return jnp.where(jnp.isnan(value), -jnp.inf, value)


def oblique_setup(fit: ObliqueFit, prior, *, noise: str, nu: float):
    """`(model, starts, units)` of a concrete `fit_oblique` fit: the checked priors, the
    fit's forward model, the start values (the fit's; each sampled noise scale at the RMS
    of its kind's residuals, inside its prior) and each sampled name's unit."""
    prior = {} if prior is None else prior
    if not isinstance(prior, dict):
        raise TypeError(f"prior takes a dict {{name: (kind, a, b)}}, got {type(prior).__name__}")
    problem, free = fit.problem, tuple(fit.free)
    given = {"sigma_e_t": fit.sigma_e_t, "sigma_omega": fit.sigma_omega}
    measured = [
        kind for kind, has in zip(KINDS, (problem.has_e, problem.has_w), strict=True) if has
    ]
    noise_names = tuple(k.sigma for k in measured if given[k.sigma] is None)
    names = free + noise_names
    for name in prior:
        if name in names:
            continue
        if name in given:
            raise ValueError(
                f"prior on {name!r}: {name} was given to fit_oblique (or its quantity was "
                "not measured), so it is not sampled"
            )
        if name in fit.tangential.params:
            raise ValueError(
                f"prior on {name!r}: {name} is held fixed by this fit (free = "
                f"{', '.join(free)}); fit_oblique with free=(..., {name!r}) to sample it"
            )
        raise ValueError(
            f"prior on {name!r}: not a parameter of this oblique fit (sampled: {', '.join(names)})"
        )
    priors, starts = {}, {}
    for name in free:
        starts[name] = float(fit.params[name])
        given_prior = name in prior
        priors[name] = (
            parse_prior(name, prior[name]) if given_prior else default_prior(name, starts[name])
        )
    n = int(problem.v_n.shape[0])
    r = np.asarray(fit.residuals, float)
    for i, kind in enumerate(measured):
        name = kind.sigma
        if name not in noise_names:
            continue
        measured_values = np.asarray(getattr(problem, kind.data), float)
        known = np.isfinite(measured_values)
        physical = r[i * n : (i + 1) * n] * np.asarray(getattr(problem, kind.scale), float)
        rms = float(np.sqrt(np.mean(physical[known] ** 2)))
        size = float(np.max(np.abs(measured_values[known]))) if kind.unit else 1.0
        priors[name], starts[name] = noise_prior(name, prior.get(name), rms, size)

    def rows(sigma):
        return None if sigma is None else np.broadcast_to(np.asarray(sigma, float), (n,))

    model = ObliqueModel(
        law=fit.tangential,
        names=names,
        free=free,
        priors=tuple(priors[k] for k in names),
        problem=problem,
        sigma_e_t=rows(fit.sigma_e_t) if problem.has_e else None,
        sigma_omega=rows(fit.sigma_omega) if problem.has_w else None,
        noise=noise,
        nu=float(nu),
    )
    spec_units = fit.tangential.spec.units
    units = {k: "" if spec_units.get(k, "-") == "-" else spec_units[k] for k in free}
    units.update({k.sigma: k.unit for k in measured if k.sigma in noise_names})
    return model, starts, units


# ---------------------------------------------------------------------- new incidences


def incidences(model: ObliqueModel, angle, speed, omega, what: str):
    """`(angle, v_n, v_t, omega)` rows (numpy) of new impacts at incidence `angle` (rad
    from the normal, in (0, pi/2)) and `speed` (m/s), spin `omega` (rad/s) before; the
    speed and spin default to the medians of the fit's rows. One-line ValueErrors."""
    if angle is None:
        raise ValueError(
            f"{what} of an oblique posterior takes incidence angles: angle=... (radians from "
            "the normal, e.g. np.deg2rad(degrees)), with speed= (m/s) and omega= (rad/s)"
        )
    angle = np.atleast_1d(np.asarray(angle, dtype=float))
    bad = ~(np.isfinite(angle) & (angle > 0) & (angle < 0.5 * np.pi))
    if angle.ndim != 1 or angle.size == 0 or np.any(bad):
        raise ValueError(
            "angle must be incidence angles in radians in (0, pi/2) (a number or a 1-D "
            "array; e_t has no meaning at 0): pass np.deg2rad(degrees)"
        )
    problem = model.problem
    v_n, v_t = np.asarray(problem.v_n, float), np.asarray(problem.v_t, float)
    if speed is None:
        speed = float(np.median(np.hypot(v_n, v_t)))
    if omega is None:
        omega = float(np.median(np.asarray(problem.omega, float)))
    for name, value, unit in (("speed", speed, "m/s"), ("omega", omega, "rad/s")):
        if np.ndim(value) != 0 or not np.isfinite(value):
            raise ValueError(f"{name} must be one finite number ({unit}), got {value!r}")
    if not speed > 0:
        raise ValueError(f"speed must be > 0 m/s, got {speed!r}")
    new_n, new_t = (np.asarray(a) for a in incidence(float(speed), angle))
    return angle, new_n, new_t, np.full(angle.shape, float(omega)), float(speed)


class ObliqueBands(eqx.Module):
    """The posterior's bands at incidence angles `angle` (rad from the normal) for impacts
    at `speed` (m/s) with spin `omega` (rad/s) before: `e_t`, `omega_out` (rad/s) and the
    rebound angle `angle_out` (rad), each the median with its `_lo`, `_hi` the `(1 -
    level)/2` and `(1 + level)/2` quantiles over `draws` draws; `observed`: with the
    measurement noise of e_t and the spin added (a band for a new measurement; the rebound
    angle, not fitted, keeps the law's band) or not (the band of the law itself)."""

    angle: np.ndarray
    e_t: np.ndarray
    e_t_lo: np.ndarray
    e_t_hi: np.ndarray
    omega_out: np.ndarray
    omega_out_lo: np.ndarray
    omega_out_hi: np.ndarray
    angle_out: np.ndarray
    angle_out_lo: np.ndarray
    angle_out_hi: np.ndarray
    speed: float = eqx.field(static=True)
    omega: float = eqx.field(static=True)
    level: float = eqx.field(static=True)
    draws: int = eqx.field(static=True)
    observed: bool = eqx.field(static=True)

    def summary(self) -> str:
        pct = f"{100 * self.level:g} %"
        rows = [("speed, omega", f"{format_value(self.speed, 'm/s')}, {self.omega:g} rad/s")]
        for k, a in enumerate(self.angle):
            rows.append(
                (
                    f"at {np.degrees(a):.4g} deg",
                    f"e_t = {format_value(self.e_t[k])} [{format_value(self.e_t_lo[k])}, "
                    f"{format_value(self.e_t_hi[k])}], omega_out = "
                    f"{format_value(self.omega_out[k], 'rad/s')} ["
                    f"{format_value(self.omega_out_lo[k], 'rad/s')}, "
                    f"{format_value(self.omega_out_hi[k], 'rad/s')}], angle_out = "
                    f"{np.degrees(self.angle_out[k]):.4g} [{np.degrees(self.angle_out_lo[k]):.4g}"
                    f", {np.degrees(self.angle_out_hi[k]):.4g}] deg",
                )
            )
        what = "a new measurement's" if self.observed else "the law's"
        title = f"Bands of {what} oblique rebound (median [{pct}], SI units)"
        return format_fields(title, rows)

    def to_dict(self) -> dict:
        names = ("angle", "e_t", "e_t_lo", "e_t_hi", "omega_out", "omega_out_lo")
        names += ("omega_out_hi", "angle_out", "angle_out_lo", "angle_out_hi", "speed")
        names += ("omega", "level", "draws", "observed")
        return {k: jsonable(getattr(self, k)) for k in names}

    def __repr__(self) -> str:
        return self.summary()


@eqx.filter_jit
def _draw_rebounds(model, z, v_n, v_t, omega):
    """`(e_t, omega_out, angle_out)`, each `(draws, rows)`, of the laws at the draws `z`."""

    def one(z_row):
        result = model.predict(model.values(z_row), v_n, v_t, omega)
        return result.e_t, result.omega_out, result.angle_out

    return jax.vmap(one)(z)


def oblique_bands(
    post, angle, *, speed=None, omega=None, level=0.9, observed=False, max_draws=1000, key=None
) -> ObliqueBands:
    """The bands of `post` (the posterior of an oblique fit) at incidence angles `angle`
    (rad); see `Posterior.predict`."""
    model = post.model
    if not 0 < level < 1:
        raise ValueError(f"level must lie in (0, 1), e.g. 0.9, got {level!r}")
    angle, v_n, v_t, omega, speed = incidences(model, angle, speed, omega, "predict")
    z = thinned(np.asarray(post.z), int(max_draws))
    rows = (jnp.asarray(v_n), jnp.asarray(v_t), jnp.asarray(omega))
    e_t, spin, out = (np.asarray(a) for a in _draw_rebounds(model, jnp.asarray(z), *rows))
    if observed:
        key = jax.random.key(1) if key is None else key
        e_t = e_t + noise_scale(post, "e_t", None, z) * noise_draws(model, key, e_t.shape)
        scale = noise_scale(post, "omega", None, z)
        spin = spin + scale * noise_draws(model, jax.random.fold_in(key, 1), spin.shape)
    q = (0.5, (1 - level) / 2, (1 + level) / 2)
    bands = {}
    for name, draws in (("e_t", e_t), ("omega_out", spin), ("angle_out", out)):
        bands[name], bands[f"{name}_lo"], bands[f"{name}_hi"] = np.nanquantile(draws, q, axis=0)
    return ObliqueBands(
        angle=angle,
        **bands,
        speed=speed,
        omega=float(omega[0]),
        level=float(level),
        draws=int(z.shape[0]),
        observed=bool(observed),
    )


@eqx.filter_jit
def _rebound_jacobians(model, z, v_n, v_t, omega):
    """`(e_t, omega_out)` at the rows and their derivatives with respect to `z`, shapes
    `(2, rows)` and `(2, rows, d)`."""

    def f(zz):
        result = model.predict(model.values(zz), v_n, v_t, omega)
        return jnp.stack([result.e_t, result.omega_out])

    return f(z), jax.jacfwd(f)(z)


def oblique_sensitivities(post, center, angle, *, speed, omega, measure):
    """For `next_measurement`: `(angle, measure, jacobian, scales)`: the candidate angles,
    what a new measurement gives (default what the fit measured), the derivatives of those
    quantities at the candidates with respect to `z` at `center` (`(quantities,
    candidates, d)`) and their noise scales (`(quantities, candidates)`)."""
    model = post.model
    angle, v_n, v_t, omega, _ = incidences(model, angle, speed, omega, "next_measurement")
    kinds = tuple(k.quantity for k in KINDS)
    measure = model.measured if measure is None else tuple(measure)
    unknown = [k for k in measure if k not in kinds]
    if unknown or not measure:
        raise ValueError(f"measure takes 'e_t' and/or 'omega_out', got {measure!r}")
    for k in measure:
        if k not in model.measured:
            raise ValueError(
                f"no noise scale for a new {k}: the fit had no {k} data; measure only "
                f"{' and '.join(model.measured)}"
            )
    rows = (jnp.asarray(v_n), jnp.asarray(v_t), jnp.asarray(omega))
    _, jacobian = _rebound_jacobians(model, jnp.asarray(center), *rows)
    index = sorted(kinds.index(k) for k in measure)
    z = np.asarray(post.z)
    scales = [
        np.broadcast_to(np.median(noise_scale(post, KINDS[i].noise, None, z), axis=0), angle.shape)
        for i in index
    ]
    return angle, tuple(kinds[i] for i in index), np.asarray(jacobian)[index], np.stack(scales)
