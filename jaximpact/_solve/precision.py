"""Tolerances that the working float type can meet."""

import warnings

import jax.numpy as jnp

# Finest tolerances worth asking for in float32 (eps = 1.2e-7): below them the step-size
# controller chases rounding noise (about 700 steps instead of 20 per impact, measured in
# benchmarks/stress.py) and a creeping body's speed plus force never settles below the
# rest threshold (out of steps instead of captured).
FLOAT32_FLOORS = dict(rtol=1e-7, atol=1e-7, rest_tol=1e-5)


def resolvable_tolerances(rtol: float, atol: float, rest_tol: float) -> tuple:
    """`(rtol, atol, rest_tol)`, each raised to `FLOAT32_FLOORS` when JAX computes in
    float32 (x64 off), with a warning that says so; unchanged in float64."""
    if jnp.result_type(float) != jnp.float32:
        return rtol, atol, rest_tol
    given = dict(rtol=rtol, atol=atol, rest_tol=rest_tol)
    raised = {k: max(v, FLOAT32_FLOORS[k]) for k, v in given.items()}
    changed = [f"{k} {given[k]:g} -> {raised[k]:g}" for k in given if raised[k] != given[k]]
    if changed:
        warnings.warn(
            "float32 cannot resolve these tolerances, so they are raised: "
            + ", ".join(changed)
            + " (for tighter ones enable float64: jax.config.update('jax_enable_x64', True))",
            stacklevel=3,
        )
    return raised["rtol"], raised["atol"], raised["rest_tol"]
