"""What a fit varies: the free parameters by default, and the unbounded coordinates the
optimisers move in (`theta = ln value`, or the logit of a restitution in (0, 1)), so that
every step gives a physical law."""

import equinox as eqx
import jax
import jax.numpy as jnp

from .._laws import damping_parameter, stiffness_parameter


def to_unbounded(name: str, value):
    """`ln value`; for `e_nominal` (in (0, 1)) its logit."""
    if name == "e_nominal":
        return jnp.log(value) - jnp.log1p(-jnp.minimum(value, 1 - 1e-12))
    return jnp.log(value)


def from_unbounded(name: str, theta):
    """The inverse of `to_unbounded`."""
    if name == "e_nominal":
        return jax.nn.sigmoid(theta)
    return jnp.exp(theta)


def law_with(law, free, theta):
    """`law` with its free parameters set from `theta` (physical by construction, so no
    value checks, which would put host callbacks in the compiled fit)."""
    params = dict(law.params)
    params.update({k: from_unbounded(k, theta[i]) for i, k in enumerate(free)})
    return eqx.tree_at(lambda item: item.params, law, params)


def default_free(law, *, stiffness: bool, dry: bool = False) -> tuple[str, ...]:
    """What a fit frees when the caller does not say: the damping parameter
    (`damping_parameter`, else the law's last parameter), with the stiffness
    (`stiffness_parameter`: `c`, or a user's `k` beside a damping `c`) first when
    `stiffness` (data that see a time scale), and the dry force `P` when `dry` (data enough
    for it)."""
    params = tuple(law.parameters)
    damping = damping_parameter(law)
    free = [damping] if damping in params else list(params[-1:])
    stiff = stiffness_parameter(law)
    if stiffness and stiff is not None and stiff not in free:
        free.insert(0, stiff)
    if dry and "P" in params and "P" not in free:
        free.append("P")
    return tuple(free)
