"""The log posterior of a calibration: the library's own forward model for `e` and `T`
(the one `calibrate` fitted with, on the universal curves where they serve), a noise model,
and the priors, as one function of the unbounded coordinates `z`.

Likelihood, one term per measured value: `r = (prediction - measured) / sigma`, with
`sigma` the given `sigma_e` (`sigma_T`, s) or, where none was given, a sampled noise scale
(`sigma_e` absolute, `sigma_T` in s, one for every row). Normal noise:
`ln p = -r^2/2 - ln sigma - ln(2 pi)/2`; Student-t noise with `nu` degrees of freedom
(heavy tails, for data with outliers; `sigma` is then its scale):
`ln p = ln G((nu+1)/2) - ln G(nu/2) - ln(nu pi)/2 - (nu+1)/2 ln(1 + r^2/nu) - ln sigma`.
"""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jax.scipy.special import gammaln

from .._curves.shapes import CurveKey
from .._fit.calibrate import ForwardModel, _residual_function
from .._fit.forward_jacobian import with_forward_jacobian
from .._fit.parameters import to_unbounded
from .._laws import AbstractLaw
from .priors import Prior

NOISES = ("normal", "student_t")


class Model(eqx.Module):
    """What a posterior samples: the free law parameters `free` then the sampled noise
    scales (`names` lists both, in the order of `z`), their `priors`, the data (`v0` m/s,
    `e`, `T` s with NaN for a row without one, `sigma_e`, `sigma_T` s per row or `None`
    where the scale is sampled) and the forward model of the fit (`setup`, `m` kg, `g`)."""

    law: AbstractLaw
    names: tuple = eqx.field(static=True)
    free: tuple = eqx.field(static=True)
    priors: tuple
    m: jax.Array
    g: object
    v0: np.ndarray
    e: np.ndarray | None
    T: np.ndarray | None
    sigma_e: np.ndarray | None
    sigma_T: np.ndarray | None
    noise: str = eqx.field(static=True)
    nu: float = eqx.field(static=True)
    setup: eqx.Module

    # ------------------------------------------------------------------ coordinates

    def values(self, z) -> dict:
        """`{name: value}` (SI) at `z` (last axis: the names)."""
        return {
            k: p.value(z[..., i])
            for i, (k, p) in enumerate(zip(self.names, self.priors, strict=True))
        }

    def coordinates(self, values: dict) -> np.ndarray:
        """`z` of `{name: value}` (numpy)."""
        return np.stack(
            [p.coordinate(values[k]) for k, p in zip(self.names, self.priors, strict=True)], axis=-1
        )

    # ------------------------------------------------------------------ forward model

    def predict(self, values: dict, v0):
        """`(e, T, status)` at the speeds `v0` (m/s) of the law with the free parameters
        in `values`: `calibrate`'s own forward model, differentiable in both modes."""
        theta = jnp.stack([to_unbounded(k, values[k]) for k in self.free])
        return _forward(self, theta, jnp.asarray(v0, dtype=float))

    # ------------------------------------------------------------------ densities

    def log_prior(self, z):
        return sum(p.log_density(z[i]) for i, p in enumerate(self.priors))

    def log_likelihood(self, z):
        values = self.values(z)
        e_fit, T_fit, _ = self.predict(values, self.v0)
        total = 0.0
        if self.e is not None:
            s = self.sigma_e if self.sigma_e is not None else values["sigma_e"]
            total = total + jnp.sum(self._log_noise((e_fit - self.e) / s, s))
        if self.T is not None:
            known = jnp.isfinite(self.T)
            target = jnp.where(known, self.T, 1.0)
            s = self.sigma_T if self.sigma_T is not None else values["sigma_T"]
            s = jnp.broadcast_to(s, target.shape)
            terms = self._log_noise((T_fit - target) / s, s)
            total = total + jnp.sum(jnp.where(known, terms, 0.0))
        # a forward solve that failed (NaN) is a point of zero likelihood
        return jnp.where(jnp.isfinite(total), total, -jnp.inf)

    def log_posterior(self, z):
        """Unnormalised log posterior density of `z` (likelihood, prior and Jacobian)."""
        value = self.log_likelihood(z) + self.log_prior(z)
        return jnp.where(jnp.isnan(value), -jnp.inf, value)

    def _log_noise(self, r, s):
        return log_noise(r, s, self.noise, self.nu)


def log_noise(r, s, noise: str, nu: float):
    """Log density of one datum whose standardised residual is `r` under noise of scale
    `s`: normal, or Student-t of `nu` degrees of freedom (`noise="student_t"`)."""
    if noise == "normal":
        return -0.5 * r**2 - jnp.log(s) - 0.5 * math.log(2.0 * math.pi)
    const = gammaln((nu + 1.0) / 2.0) - gammaln(nu / 2.0) - 0.5 * math.log(nu * math.pi)
    return const - 0.5 * (nu + 1.0) * jnp.log1p(r**2 / nu) - jnp.log(s)


def _forward(model: Model, theta, v0):
    """`calibrate`'s residual function at `theta` (its unbounded coordinates), its
    predictions only. Off the curves the solves are differentiated in forward mode only
    (`calibrate`'s `ForwardMode` adjoint), so every derivative goes through one
    `jax.jacfwd` (`with_forward_jacobian`), held: the gradient is exact and a second
    derivative (the Laplace step's Hessian) is Gauss-Newton's, with no second derivative
    through the solves (diffrax's event search has none: `nextafter`); on the curves
    directly."""
    setup = model.setup
    raw = _residual_function(
        model.law,
        model.free,
        ForwardModel.of(setup),
        m=model.m,
        g=model.g,
        has_e=True,
        has_T=False,
    )
    ones = jnp.ones_like(v0)
    data = (v0, ones, ones, ones, ones)
    if isinstance(setup.curves, CurveKey):
        _, (e, T, status) = raw(theta, data)
        return e, T, status

    def stacked(t, d):
        _, (e, T, _) = raw(t, d)
        return jnp.concatenate([e, T])

    both = with_forward_jacobian(stacked, held=True)(theta, data)
    _, (_, _, status) = raw(jax.lax.stop_gradient(theta), data)
    n = v0.shape[0]
    return both[:n], both[n:], status


def build_model(fit, priors: dict[str, Prior], *, noise: str, nu: float) -> Model:
    """The `Model` of a concrete `calibrate` fit with the priors already checked."""
    has_e = bool(fit.setup.has_e)
    has_T = bool(fit.setup.has_T)
    names = tuple(fit.free)
    if has_e and fit.sigma_e is None:
        names += ("sigma_e",)
    if has_T and fit.sigma_T is None:
        names += ("sigma_T",)

    def rows(a):
        return None if a is None else np.broadcast_to(np.asarray(a, float), np.shape(fit.v0))

    return Model(
        law=fit.law,
        names=names,
        free=tuple(fit.free),
        priors=tuple(priors[k] for k in names),
        m=jnp.asarray(fit.m, dtype=float),
        g=fit.g,
        v0=np.asarray(fit.v0, dtype=float),
        e=np.asarray(fit.e_target, float) if has_e else None,
        T=np.asarray(fit.T_target, float) if has_T else None,
        sigma_e=rows(fit.sigma_e) if has_e else None,
        sigma_T=rows(fit.sigma_T) if has_T else None,
        noise=noise,
        nu=float(nu),
        setup=fit.setup,
    )
