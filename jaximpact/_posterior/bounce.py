"""The posterior of a `fit_bounces` fit: its own forward model (`jaximpact._fit.bounce_model`'s
`chain_residuals`: `bounce`'s chain of closed-form flights and impact solves, started at the
first impact), rebuilt from the `BounceFit` at its optimum, as one log density of the
unbounded coordinates `z` that `posterior` samples.

What is sampled: the law's `free` parameters, then the fit's nuisance parameters, in SI
(`t_impact` s, `v_impact` m/s, `drag` 1/m where it was fitted; for a trajectory `floor` and,
where it was fitted, `length_scale`, both in the data's units), then the noise scale
`sigma` (s for impact times, y units for a trajectory) where none was given to the fit.

Likelihood: one term per datum used by the fit (the detections it kept, or the samples of
the track it kept), `r = (model - datum) / sigma`, normal or Student-t as for a
calibration (`likelihood.log_noise`).

What a `BounceFit` records, and so what the rebuilt model assumes:
- the solve options are `fit_bounces`'s defaults (its `rtol`, `max_steps`, `options` are
  not recorded): the model is checked against the fit's residuals at the optimum, with a
  `PosteriorWarning` where it does not reproduce them;
- whether `sigma` was given: read off the fit (an estimated noise makes the residuals'
  sum of squares equal the degrees of freedom; a given one makes it twice the loss);
- whether the drag (the length scale) was fitted: a held one has a zero standard error.
"""

import dataclasses
import math

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._fit.bounce_fit import BounceFit
from .._fit.bounce_model import BounceProblem, chain_residuals, round_up, with_impacts
from .._fit.calibrate import law_units
from .._fit.fit_bounces import fit_bounces
from .._fit.forward_jacobian import with_forward_jacobian
from .._fit.parameters import law_with, to_unbounded
from .._laws import AbstractLaw
from .._solve.bounce import _contact, bounce_options
from .._solve.options import FIT_DECIDES, solve_options
from .likelihood import log_noise
from .priors import Prior, default_prior, parse_prior

# nuisance parameters a bounce fit may have, their units, and whether they are moved as
# logarithms (the others as offsets)
NUISANCE_UNITS = {
    "t_impact": "s",
    "v_impact": "m/s",
    "drag": "1/m",
    "floor": "",
    "length_scale": "",
}
_LOG = ("v_impact", "drag", "length_scale")
# the default prior of a sampled `sigma`: loguniform over this range times the first flight's
# duration `2 v_impact / g` (s, impact times) or the track's span (y units, a trajectory)
BOUNCE_NOISE_RANGE = (1e-6, 0.1)


class BounceModel(eqx.Module):
    """What a bounce fit's posterior samples (`names`: the law's `free` parameters, the
    `nuisance`, then `sigma` where sampled, in the order of `z`), their `priors`, and the
    fit's forward model: the `law`, `m` (kg), `g`, the chain's `data` (the data used,
    reference values at the fit, `sigma` 1 so that residuals are in the data's units)
    and `spec`; `sigma`: the given noise (None: sampled). `v0`: the fitted impact speeds
    (m/s), over which `predict` and the plot give bands of e and T; `e`, `T`,
    `sigma_e`, `sigma_T` are None (a bounce measures neither)."""

    law: AbstractLaw
    names: tuple = eqx.field(static=True)
    free: tuple = eqx.field(static=True)
    nuisance: tuple = eqx.field(static=True)
    priors: tuple
    m: jax.Array
    g: jax.Array
    data: dict
    reference: dict
    spec: eqx.Module
    kind: str = eqx.field(static=True)
    sigma: float | None = eqx.field(static=True)
    noise: str = eqx.field(static=True)
    nu: float = eqx.field(static=True)
    v0: np.ndarray
    e: None = None
    T: None = None
    sigma_e: None = None
    sigma_T: None = None

    # ------------------------------------------------------------------ coordinates

    def values(self, z) -> dict:
        """`{name: value}` (SI, data units for a track's floor and scale) at `z`."""
        return {
            k: p.value(z[..., i])
            for i, (k, p) in enumerate(zip(self.names, self.priors, strict=False))
        }

    def coordinates(self, values: dict) -> np.ndarray:
        return np.stack(
            [p.coordinate(values[k]) for k, p in zip(self.names, self.priors, strict=False)],
            axis=-1,
        )

    def theta(self, values: dict):
        """The fit's own coordinates of `values`: `to_unbounded` of the law's, the
        nuisance as offsets (logarithms of ratios) from the reference values at the fit."""
        parts = [to_unbounded(k, values[k]) for k in self.free]
        for k in self.nuisance:
            ref = self.reference[k]
            parts.append(jnp.log(values[k] / ref) if k in _LOG else values[k] - ref)
        return jnp.stack(parts)

    # ------------------------------------------------------------------ forward model

    def residuals(self, values: dict):
        """`model - datum` (s, or y units) of every datum used, `chain_residuals` at
        `values`; every derivative through one forward-mode Jacobian of the chain."""
        law, m, g, spec = self.law, self.m, self.g, self.spec

        def raw(theta, data):
            return chain_residuals(theta, law, m, g, data, spec)[0]

        return gauss_newton(raw)(self.theta(values), self.data)

    def predict(self, values: dict, v0):
        """`(e, T, status)` of single impacts at the speeds `v0` (m/s) with the fit's
        gravity and separation, the contact solve of the chain (`_contact`)."""
        law = law_with(
            self.law, self.free, jnp.stack([to_unbounded(k, values[k]) for k in self.free])
        )
        v0 = jnp.asarray(v0, dtype=float)

        def one(v):
            result, _ = _contact(law, self.m, v, self.g, None, self.spec.options.impact)
            return result.e, result.T, result.status

        return jax.vmap(one)(v0)

    # ------------------------------------------------------------------ densities

    def log_prior(self, z):
        return sum(p.log_density(z[i]) for i, p in enumerate(self.priors))

    def log_likelihood(self, z):
        values = self.values(z)
        r = self.residuals(values)
        s = self.sigma if self.sigma is not None else values["sigma"]
        total = jnp.sum(log_noise(r / s, s, self.noise, self.nu))
        return jnp.where(jnp.isfinite(total), total, -jnp.inf)

    def log_posterior(self, z):
        value = self.log_likelihood(z) + self.log_prior(z)
        return jnp.where(jnp.isnan(value), -jnp.inf, value)


def gauss_newton(residuals):
    """`residuals(theta, data) -> r` whose derivatives, in every AD mode, go through one
    forward-mode Jacobian `J` of the chain (`jax.jacfwd`), held constant: the gradient of
    any function of `r` is exact, and its Hessian (`jax.hessian`, the Laplace
    approximation's) the Gauss-Newton one in `r`, `J^T (d^2 f / dr^2) J` (the curvature the
    fit's standard errors use), without a second derivative through the solves."""
    return with_forward_jacobian(residuals, held=True)


def sigma_was_given(fit: BounceFit) -> bool:
    """Whether `fit_bounces` was given `sigma` (see the module docstring): the residuals'
    sum of squares nearer twice the loss (given) than the degrees of freedom (estimated)."""
    ss = float(np.sum(np.asarray(fit.residuals, float) ** 2))
    given_off = abs(ss - 2.0 * float(fit.loss)) / max(ss, 1e-300)
    estimated_off = abs(ss - float(fit.dof)) / max(float(fit.dof), 1e-300)
    return given_off < estimated_off


def fitted_nuisance(fit: BounceFit) -> tuple:
    """The nuisance parameters `fit` fitted, in `fit_bounces`'s order."""
    names = ["t_impact", "v_impact"]
    if fit.kind == "trajectory":
        names.append("floor")
        if fit.stderr.get("length_scale", 0.0) != 0.0:
            names.append("length_scale")
    if "drag" in fit.nuisance and fit.stderr.get("drag", 0.0) != 0.0:
        names.append("drag")
    return tuple(names)


def bounce_setup(fit: BounceFit, prior, *, noise: str, nu: float):
    """`(model, starts, units)` of a concrete `fit_bounces` fit: the checked priors, the
    rebuilt forward model, the start values (the fit's; the fit's noise for `sigma`) and
    each sampled name's unit."""
    prior = {} if prior is None else prior
    if not isinstance(prior, dict):
        raise TypeError(f"prior takes a dict {{name: (kind, a, b)}}, got {type(prior).__name__}")
    free, nuisance = tuple(fit.free), fitted_nuisance(fit)
    given = sigma_was_given(fit)
    names = free + nuisance + (() if given else ("sigma",))
    law_parameters = tuple(fit.law.parameters)
    for name in prior:
        if name in names:
            continue
        if name == "sigma":
            raise ValueError(
                "prior on 'sigma': sigma was given to fit_bounces, so it is not sampled"
            )
        if name in law_parameters:
            raise ValueError(
                f"prior on {name!r}: {name} is held fixed by this fit (free = "
                f"{', '.join(free)}); fit_bounces with free=(..., {name!r}) to sample it"
            )
        raise ValueError(
            f"prior on {name!r}: not a parameter of this bounce fit (sampled: {', '.join(names)})"
        )
    q = fit.nuisance
    g = float(fit.g)
    flight = 2.0 * float(q["v_impact"]) / g  # the first flight's duration, s
    span = float(np.ptp(fit.y)) if fit.kind == "trajectory" else flight
    span = span if span > 0 else 1.0
    starts, priors = {}, {}
    for name in names:
        if name in free:
            value = float(fit.params[name])
        elif name == "sigma":
            value = float(fit.sigma)
        else:
            value = float(q[name])
        starts[name] = value
        if name in prior:
            priors[name] = parse_prior(name, prior[name])
        elif name == "t_impact":
            priors[name] = Prior("uniform", value - flight, value + flight)
        elif name == "floor":
            priors[name] = Prior("uniform", value - span, value + span)
        elif name == "sigma":
            lo, hi = BOUNCE_NOISE_RANGE
            priors[name] = Prior("loguniform", lo * span, hi * span)
        else:
            priors[name] = default_prior(name, value)
    p = priors.get("sigma")
    if p is not None and p.bounded:  # inside the range, away from its bounds
        floor = 10.0 * p.a if p.a > 0 else 0.01 * p.b
        starts["sigma"] = min(max(starts["sigma"], floor), 0.5 * p.b)
    model = _model(
        fit, names, free, nuisance, priors, None if not given else float(fit.sigma), noise, nu
    )
    units = law_units(fit.law)
    units = {k: units.get(k, "") for k in free}
    units.update({k: NUISANCE_UNITS[k] for k in nuisance})
    if not given:
        units["sigma"] = "s" if fit.kind == "impacts" else ""
    return model, starts, units


def _model(fit, names, free, nuisance, priors, sigma, noise, nu) -> BounceModel:
    """The `BounceModel` of `fit`: `fit_bounces`'s problem rebuilt at the optimum."""
    q = fit.nuisance
    solve = solve_options(fit_bounces, None, rtol=None, max_steps=4096, refused=FIT_DECIDES)
    solve = dataclasses.replace(solve, adjoint=dfx.ForwardMode(), peaks=False)
    options = bounce_options(fit.law, solve, separation=fit.separation, max_impacts=8)
    data = dict(
        sigma=np.asarray(1.0),
        t1=np.asarray(q["t_impact"]),
        t_unit=np.asarray(1.0),
        v1=np.asarray(q["v_impact"]),
        y_unit=np.asarray(1.0),
    )
    if "drag" in q:
        data["drag"] = np.asarray(q["drag"])
    if fit.kind == "impacts":
        times = np.asarray(fit.times, float)
        index = np.asarray(fit.index, int)
        options = with_impacts(options, round_up(int(index.max()) + 4, 8))
        data.update(
            times=times,
            floor=np.asarray(0.0),
            scale=np.asarray(1.0),
            t_end=np.asarray(np.inf),
            min_flight=np.asarray(0.0),
        )
        data["index"] = np.minimum(index, options.max_impacts - 1)
        n = times.size
    else:
        t, y = np.asarray(fit.t, float), np.asarray(fit.y, float)
        options = with_impacts(options, round_up(fit.num_impacts + 1, 8))
        data.update(
            t=t,
            y=y,
            floor=np.asarray(q["floor"]),
            scale=np.asarray(q["length_scale"]),
            t_end=np.asarray(float(t.max())),
            min_flight=np.asarray(0.5 * float(np.median(np.diff(t)))),
        )
        n = t.size
    data["mask"] = np.ones(n, dtype=bool)
    problem = BounceProblem(
        law=fit.law,
        free=free,
        m=float(fit.m),
        g=float(fit.g),
        kind=fit.kind,
        y_sign=float(fit.y_sign),
        options=options,
        nuisance=nuisance,
        data=data,
    )
    reference = {k: float(q[k]) for k in nuisance}
    speeds = np.asarray(fit.impact_speeds, float)
    return BounceModel(
        law=fit.law,
        names=names,
        free=free,
        nuisance=nuisance,
        priors=tuple(priors[k] for k in names),
        m=jnp.asarray(fit.m, dtype=float),
        g=jnp.asarray(fit.g, dtype=float),
        data={k: np.asarray(v) for k, v in data.items()},
        reference=reference,
        spec=problem.spec(),
        kind=fit.kind,
        sigma=sigma,
        noise=noise,
        nu=float(nu),
        v0=speeds[np.isfinite(speeds)],
    )


@eqx.filter_jit
def _residuals_at(model, values):
    return model.residuals(values)


def reproduces(model: BounceModel, fit: BounceFit, starts: dict) -> float:
    """The largest difference, in units of the fit's noise, between the rebuilt model's
    residuals at the fit and the fit's own (`residuals * sigma`)."""
    values = {k: jnp.asarray(v, dtype=float) for k, v in starts.items()}
    r = np.asarray(_residuals_at(model, values))
    expected = np.asarray(fit.residuals, float) * float(fit.sigma)
    if r.shape != expected.shape:
        return math.inf
    return float(np.max(np.abs(r - expected), initial=0.0) / float(fit.sigma))
