"""NUTS through the forward model: blackjax's No-U-Turn sampler after its window
adaptation (Stan's: step size to a target acceptance, then a dense mass matrix), every
chain started from its own draw of the Laplace approximation, all chains in one compiled
program (`jax.vmap`), with the diagnostics a user must see: the rank-normalised split
r-hat, the effective sample size and the divergent transitions."""

import blackjax
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._compiling import quick_jit


class Chains(eqx.Module):
    """The draws `z`, shape `(chains, num_samples, d)`, and per draw whether the
    transition diverged and the tree's number of steps."""

    z: jax.Array
    divergent: jax.Array
    steps: jax.Array


@eqx.filter_jit
def run_chains(
    model, z0, inverse_mass, key, num_warmup: int, num_samples: int, target_accept: float
) -> Chains:
    """Warm up and sample every chain (one row of `z0` each) with NUTS on
    `model.log_posterior`; `inverse_mass` seeds the adaptation (the Laplace covariance)."""
    logdensity = model.log_posterior

    def one_chain(z_start, chain_key):
        warm_key, sample_key = jax.random.split(chain_key)
        warmup = blackjax.window_adaptation(
            blackjax.nuts,
            logdensity,
            is_mass_matrix_diagonal=False,
            initial_inverse_mass_matrix=inverse_mass,
            target_acceptance_rate=target_accept,
            adaptation_info_fn=lambda *_: None,
        )
        (state, parameters), _ = warmup.run(warm_key, z_start, num_steps=num_warmup)
        kernel = blackjax.nuts(logdensity, **parameters).step

        def step(state, step_key):
            state, info = kernel(step_key, state)
            return state, (state.position, info.is_divergent, info.num_integration_steps)

        keys = jax.random.split(sample_key, num_samples)
        _, (z, divergent, steps) = jax.lax.scan(step, state, keys)
        return z, divergent, steps

    keys = jax.random.split(key, z0.shape[0])
    z, divergent, steps = jax.vmap(one_chain)(z0, keys)
    return Chains(z, divergent, steps)


def diagnostics(chains: Chains, names) -> dict:
    """`r_hat` (the worst, largest, over the parameters; NaN with one chain), `ess` (the
    worst, smallest, bulk effective sample size over all chains), `divergences` (count),
    each also per parameter (`r_hat_by_parameter`, `ess_by_parameter`), and the
    `chains`, `draws_per_chain` and mean `tree_steps`."""
    z = jnp.asarray(chains.z)
    n_chains, n_draws, _ = z.shape
    r_hat, ess = _r_hat_and_ess(z)
    # blackjax gives a 0-d array for one parameter: one value per parameter, always
    r_hat, ess = (np.asarray(a).reshape(z.shape[-1]) for a in (r_hat, ess))
    return {
        "r_hat": float(np.max(r_hat)),
        "ess": float(np.min(ess)),
        "divergences": int(np.sum(np.asarray(chains.divergent))),
        "r_hat_by_parameter": {k: float(r_hat[i]) for i, k in enumerate(names)},
        "ess_by_parameter": {k: float(ess[i]) for i, k in enumerate(names)},
        "chains": int(n_chains),
        "draws_per_chain": int(n_draws),
        "tree_steps": float(np.mean(np.asarray(chains.steps))),
    }


@quick_jit
def _r_hat_and_ess(z):
    """blackjax's split r-hat (NaN with one chain) and bulk effective sample size of the
    draws `z` `(chains, draws, d)`, in one compiled program: run op by op, their FFTs and
    ranks compiled some hundred small programs, 8 s of a first call against 1.6 s
    (measured, 4 x 400 draws; the values agree to 3e-12)."""
    # blackjax broadcasts by rank promotion, which a strict caller's config would refuse
    with jax.numpy_rank_promotion("allow"):
        if z.shape[0] > 1:
            r_hat = blackjax.diagnostics.rhat(z, chain_axis=0, sample_axis=1)
        else:
            r_hat = jnp.full(z.shape[-1], jnp.nan)
        ess = blackjax.diagnostics.ess_bulk(z, chain_axis=0, sample_axis=1)
    return r_hat, ess


# a warning below these: r-hat above, effective sample size below, any divergence
MAX_R_HAT = 1.05
MIN_ESS = 100


def poor(diag: dict) -> str | None:
    """What is poor in `diag`, or `None`."""
    reasons = []
    if np.isfinite(diag["r_hat"]) and diag["r_hat"] > MAX_R_HAT:
        reasons.append(f"r_hat = {diag['r_hat']:.3g} > {MAX_R_HAT:g} (the chains disagree)")
    if not diag["ess"] >= MIN_ESS:
        reasons.append(f"effective sample size {diag['ess']:.0f} < {MIN_ESS}")
    if diag["divergences"]:
        reasons.append(f"{diag['divergences']} divergent transitions")
    return "; ".join(reasons) or None
