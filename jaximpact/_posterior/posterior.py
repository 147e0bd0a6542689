"""`posterior`: from a fit to the distribution of its parameters."""

import warnings

import jax
import jax.numpy as jnp
import numpy as np

from .._checks import is_traced
from .._fit.bounce_fit import BounceFit
from .._fit.calibrate import Fit, law_units
from .._oblique.fit import ObliqueFit
from .._xla_log import quietly_compiled
from .bounce import bounce_setup, reproduces
from .laplace import gaussian_draws, laplace
from .likelihood import NOISES, build_model
from .nuts import diagnostics, poor, run_chains
from .oblique_model import oblique_setup
from .priors import default_prior, noise_prior, parse_prior
from .result import Posterior

METHODS = ("nuts", "laplace")


class PosteriorWarning(UserWarning):
    """A posterior whose sampler or mode search did poorly (see `Posterior.diagnostics`)."""


@quietly_compiled
def posterior(
    fit,
    *,
    prior: dict | None = None,
    method: str = "nuts",
    num_samples: int = 2000,
    num_warmup: int = 500,
    chains: int = 4,
    key=None,
    noise: str = "normal",
    nu: float = 4.0,
    target_accept: float = 0.8,
) -> Posterior:
    """The posterior of `fit`'s free parameters given its data, `p(theta | y)`.

    `fit`: the result of `calibrate`, of `fit_bounces` (one `BounceFit`: for several
    drops, one posterior per drop) or of `fit_oblique` (an `ObliqueFit`). The likelihood
    solves every impact with the fit's own forward model (on the universal curves where
    they served the fit, else the closed form or the integrated solve), compiled once.

    A bounce fit (`_posterior.bounce`): the likelihood is `fit_bounces`'s own chain
    (`bounce_model.chain_residuals`, its default solve options; a `PosteriorWarning` where
    it does not reproduce the fit's residuals), one term per detection (or track sample)
    the fit kept; sampled are the law's free parameters, the nuisance (`t_impact` s,
    `v_impact` m/s, a fitted `drag` 1/m, a track's `floor` and fitted `length_scale` in
    its units) and, where `fit_bounces` estimated it, the noise `sigma` (s, or y units).
    Default priors: the law's and the positive nuisance's as below (loguniform over
    three decades either side of the fit), `t_impact` uniform within one first flight
    (`2 v_impact / g`) of the fit, `floor` uniform within the track's span of it, `sigma`
    loguniform over 1e-6 to 0.1 times that flight (s) or the track's span. Its Laplace
    approximation uses the Gauss-Newton Hessian of the likelihood (the chain's
    forward-mode Jacobian, as the fit's standard errors; exact in the priors and noise
    scale); NUTS its exact gradient. `predict(v0=...)` gives the law's bands of e and T of
    single impacts at new speeds (the chain's contact solve, the fit's gravity and
    separation); bands of heights, `observed=True` and `next_measurement` are not
    offered for a bounce posterior (ValueError).

    An oblique fit (`_posterior.oblique_model`): the likelihood is `fit_oblique`'s own
    solve of its rows (the normal law held, forward-mode derivatives through the
    stick-slip transitions), one term per measured `e_t` and `omega_out`; sampled are the
    tangential law's free parameters and, for each measured kind whose sigma was not
    given, its noise scale `sigma_e_t` (default prior loguniform(1e-4, 0.5)) or
    `sigma_omega` (rad/s; loguniform over 1e-4 to 0.5 times the largest measured
    `|omega_out|`). Laplace uses the Gauss-Newton Hessian (the fit's standard errors'
    curvature), NUTS the exact gradient. `predict(angle=...)` gives bands of e_t, the spin
    and the rebound angle at new incidence angles (rad), `next_measurement(post,
    angle=...)` ranks candidate angles.

    - `prior`: `{name: (kind, a, b)}` with kind `"loguniform"` (lo, hi), `"uniform"`
      (lo, hi), `"normal"` (mean, sd) or `"lognormal"` (mu, sigma of ln x), SI units. A
      free parameter without one gets the weakly informative default: loguniform over
      three decades either side of its fitted value (uniform on (0, 1) for `e_nominal`).
    - Noise: with `sigma_e` (`sigma_T`) given to `calibrate`, each residual
      `(prediction - measured) / sigma` is standard normal. Without, the noise scale is
      a parameter of its own, sampled with the law's: `sigma_e` (absolute) with the
      default prior loguniform(1e-4, 0.5), `sigma_T` (s) loguniform over 1e-4 to 0.5
      times the median measured T; `prior=` may set them too. `noise="student_t"`: a
      Student-t of `nu` (4) degrees of freedom instead of the normal, for data with
      outliers (`sigma` is then its scale).
    - `method="nuts"`: blackjax's NUTS with Stan's window adaptation (`num_warmup` steps,
      a dense mass matrix seeded by the Laplace covariance, `target_accept`), `chains`
      chains of `num_samples` draws each, started from draws of the Laplace
      approximation. Diagnostics: rank-normalised split `r_hat`, bulk `ess` and the
      divergent transitions; a `PosteriorWarning` when `r_hat > 1.05`, `ess < 100` or
      any transition diverged.
    - `method="laplace"`: the Gaussian at the mode in the unbounded coordinates
      (`H = -` the Hessian of the log posterior, `jax.hessian`), `num_samples * chains`
      independent draws of it: fast, and exact for a Gaussian posterior only.
    - `log_evidence` (both methods): the Laplace approximation at the mode,
      `ln Z = ln p(y, z*) + d/2 ln 2 pi - 1/2 ln det H`.

    Sampling is in unbounded coordinates `z` (`_posterior.priors`): the logit of the
    position in a uniform or loguniform prior's range, the standardised value or
    logarithm for a normal or lognormal one, with the Jacobian in the density.

    **Example**: `posterior(calibrate(law, m=1.0, v0=v0s, e=es, T=Ts, sigma_e=0.01,
    sigma_T=0.02 * Ts), prior={"c": ("loguniform", 1e5, 1e8)}, key=jax.random.key(0))`.
    """
    kind = _check_fit(fit)
    if method not in METHODS:
        raise ValueError(f"method must be 'nuts' or 'laplace', got {method!r}")
    if noise not in NOISES:
        raise ValueError(f"noise must be 'normal' or 'student_t', got {noise!r}")
    if not (isinstance(nu, (int, float)) and nu > 0):
        raise ValueError(f"nu (Student-t degrees of freedom) must be > 0, got {nu!r}")
    for name, value, least in (
        ("num_samples", num_samples, 1),
        ("chains", chains, 1),
        ("num_warmup", num_warmup, 0),
    ):
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
            raise ValueError(f"{name} must be an integer >= {least}, got {value!r}")
    if not 0 < target_accept < 1:
        raise ValueError(f"target_accept must lie in (0, 1), got {target_accept!r}")
    key = jax.random.key(0) if key is None else key

    law = fit.tangential if kind == "oblique" else fit.law
    if kind == "oblique":
        model, starts, units = oblique_setup(fit, prior, noise=noise, nu=nu)
    elif kind == "bounce":
        model, starts, units = bounce_setup(fit, prior, noise=noise, nu=nu)
        off = reproduces(model, fit, starts)
        if not off <= REPRODUCED:
            warnings.warn(
                f"the bounce fit's model, rebuilt with fit_bounces's default solve options, "
                f"misses the fit's own residuals by up to {off:.3g} noise scales (a fit with "
                "other rtol, max_steps or options?): the posterior is of the rebuilt model",
                PosteriorWarning,
                stacklevel=2,
            )
    else:
        priors, starts = _priors(fit, prior)
        model = build_model(fit, priors, noise=noise, nu=nu)
    z0 = jnp.asarray(model.coordinates(starts))
    mode = laplace(model, z0)
    if not bool(mode.converged):
        warnings.warn(
            "the posterior's mode was not found to tolerance (its Hessian is not negative "
            "definite, or the search stopped): the Laplace approximation and log_evidence "
            "are unreliable; check the priors and the data",
            PosteriorWarning,
            stacklevel=2,
        )
    draw_key, chain_key = jax.random.split(key)
    covariance = np.asarray(mode.covariance)
    usable = bool(np.all(np.isfinite(covariance)))
    usable = usable and bool(np.all(np.linalg.eigvalsh(covariance) > 0))
    d = len(model.names)
    if method == "laplace":
        if not usable:
            raise ValueError(
                "the Laplace approximation does not exist here (the posterior's Hessian is "
                "not negative definite at the mode): use method='nuts' or narrower priors"
            )
        z = gaussian_draws(mode, draw_key, num_samples * chains)
        diag = {
            "r_hat": float("nan"),
            "ess": float(z.shape[0]),
            "divergences": 0,
            "chains": 1,
            "draws_per_chain": int(z.shape[0]),
        }
    else:
        inverse_mass = jnp.asarray(covariance if usable else np.eye(d))
        if usable:
            starts_z = gaussian_draws(mode, draw_key, chains)
        else:
            jitter = np.asarray(jax.random.normal(draw_key, (chains, d)))
            starts_z = np.asarray(mode.z)[None, :] + 0.1 * jitter
        result = run_chains(
            model,
            jnp.asarray(starts_z),
            inverse_mass,
            chain_key,
            int(num_warmup),
            int(num_samples),
            float(target_accept),
        )
        diag = diagnostics(result, model.names)
        z = np.asarray(result.z).reshape(-1, d)
        why = poor(diag)
        if why is not None:
            warnings.warn(
                f"the NUTS draws may not represent the posterior: {why}; run longer "
                "(num_warmup, num_samples), raise target_accept, or narrow the priors",
                PosteriorWarning,
                stacklevel=2,
            )
    values = model.values(jnp.asarray(z))
    samples = {k: np.asarray(values[k]) for k in model.names}
    at_mode = model.values(mode.z)
    if kind == "calibrate":
        units = law_units(fit.law)
        units = {k: units.get(k, "") for k in model.free}
        units.update({k: u for k, u in (("sigma_e", ""), ("sigma_T", "s")) if k in model.names})
    return Posterior(
        samples=samples,
        z=z,
        names=model.names,
        free=model.free,
        method=method,
        law_name=law.name,
        noise=noise,
        nu=float(nu),
        units=units,
        priors={k: p.as_tuple() for k, p in zip(model.names, model.priors, strict=False)},
        map={k: float(v) for k, v in at_mode.items()},
        log_evidence=float(mode.log_evidence),
        diagnostics=diag,
        model=model,
        law_parameters={k: float(v) for k, v in law.parameters.items()},
    )


# the largest difference (noise scales) between a rebuilt bounce model's residuals at the
# fit and the fit's own before a warning
REPRODUCED = 1e-3


def _check_fit(fit) -> str:
    """What `fit` is, `"calibrate"`, `"bounce"` or `"oblique"`; TypeError for what
    `posterior` does not take (an `ObliqueFit` without its data among them), ValueError
    for a traced or batched calibration."""
    if isinstance(fit, BounceFit):
        return "bounce"
    if isinstance(fit, ObliqueFit):
        if getattr(fit, "problem", None) is None:
            raise TypeError(
                "this ObliqueFit keeps no rebounds (built by hand, not by fit_oblique): "
                "fit_oblique results are not supported without the data they were fitted "
                "to; fit again with ji.fit_oblique(...)"
            )
        return "oblique"
    if isinstance(fit, (list, tuple)) and fit and all(isinstance(f, BounceFit) for f in fit):
        raise TypeError(
            "posterior takes one fit; fit_bounces gave a list (one fit per drop): "
            "[posterior(f) for f in fits]"
        )
    if not isinstance(fit, Fit) or fit.setup is None:
        raise TypeError(
            "posterior takes the result of calibrate (a Fit), of fit_oblique (an "
            f"ObliqueFit) or of fit_bounces (a BounceFit), got {type(fit).__name__}"
        )
    if is_traced(fit.loss) or np.ndim(fit.loss) != 0:
        raise ValueError("posterior takes one concrete fit, not a traced or vmapped batch")
    return "calibrate"


def _priors(fit, prior):
    """The checked priors of every sampled name and the start values (the fit's, and the
    residuals' RMS for a sampled noise scale)."""
    prior = {} if prior is None else prior
    if not isinstance(prior, dict):
        raise TypeError(f"prior takes a dict {{name: (kind, a, b)}}, got {type(prior).__name__}")
    free = tuple(fit.free)
    law_parameters = tuple(fit.law.parameters)
    noise_names = []
    if fit.setup.has_e and fit.sigma_e is None:
        noise_names.append("sigma_e")
    if fit.setup.has_T and fit.sigma_T is None:
        noise_names.append("sigma_T")
    for name in prior:
        if name in free or name in noise_names:
            continue
        if name in ("sigma_e", "sigma_T"):
            raise ValueError(
                f"prior on {name!r}: {name} was given to calibrate (or its quantity was not "
                "measured), so it is not sampled"
            )
        if name in law_parameters:
            raise ValueError(
                f"prior on {name!r}: {name} is held fixed by this fit (free = "
                f"{', '.join(free)}); calibrate with free=(..., {name!r}) to sample it"
            )
        raise ValueError(
            f"prior on {name!r}: the law {fit.law.name} has no parameter {name!r} (its "
            f"parameters: {', '.join(law_parameters)}; noise scales: "
            f"{', '.join(noise_names) or 'none sampled'})"
        )
    priors, starts = {}, {}
    for name in free:
        value = float(fit.params[name])
        given = name in prior
        priors[name] = parse_prior(name, prior[name]) if given else default_prior(name, value)
        starts[name] = value
    e_target = np.asarray(fit.e_target, float)
    T_target = np.asarray(fit.T_target, float)
    for name in noise_names:
        if name == "sigma_e":
            scale = 1.0
            rms = float(np.sqrt(np.mean((np.asarray(fit.e) - e_target) ** 2)))
        else:
            known = np.isfinite(T_target)
            scale = float(np.median(T_target[known]))
            rms = float(np.sqrt(np.mean((np.asarray(fit.T)[known] - T_target[known]) ** 2)))
        priors[name], starts[name] = noise_prior(name, prior.get(name), rms, scale)
    return priors, starts
