"""Prediction bands: the quantiles over the posterior draws of `e` and `T` at new speeds,
each draw's law solved by the fit's own forward model (all draws in one compiled,
vmapped call)."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._format import format_fields, format_value, jsonable


class Bands(eqx.Module):
    """`e` and `T` (s) at the speeds `v0` (m/s) over the posterior: `e`, `T` the medians,
    `e_lo`, `e_hi`, `T_lo`, `T_hi` the `(1 - level)/2` and `(1 + level)/2` quantiles,
    over `draws` draws; `observed`: with the measurement noise added (a band for a new
    measurement) or not (the band of the law itself, what an engine would be given)."""

    v0: np.ndarray
    e: np.ndarray
    e_lo: np.ndarray
    e_hi: np.ndarray
    T: np.ndarray
    T_lo: np.ndarray
    T_hi: np.ndarray
    level: float = eqx.field(static=True)
    draws: int = eqx.field(static=True)
    observed: bool = eqx.field(static=True)

    def summary(self) -> str:
        pct = f"{100 * self.level:g} %"
        rows = [("v0", format_value(self.v0, "m/s"))]
        for k in range(len(self.v0)):
            rows.append(
                (
                    f"at {format_value(self.v0[k], 'm/s')}",
                    f"e = {format_value(self.e[k])} [{format_value(self.e_lo[k])}, "
                    f"{format_value(self.e_hi[k])}], T = {format_value(self.T[k], 's')} "
                    f"[{format_value(self.T_lo[k], 's')}, {format_value(self.T_hi[k], 's')}]",
                )
            )
        what = "a new measurement's" if self.observed else "the law's"
        return format_fields(f"Bands of {what} e and T (median [{pct}], SI units)", rows)

    def to_dict(self) -> dict:
        names = ("v0", "e", "e_lo", "e_hi", "T", "T_lo", "T_hi", "level", "draws", "observed")
        return {k: jsonable(getattr(self, k)) for k in names}

    def __repr__(self) -> str:
        return self.summary()


@eqx.filter_jit
def draw_predictions(model, z, v0):
    """`(e, T)`, each `(draws, speeds)`, of the laws at the draws `z` (rows)."""

    def one(z_row):
        e, T, _ = model.predict(model.values(z_row), v0)
        return e, T

    return jax.vmap(one)(z)


def thinned(z: np.ndarray, max_draws: int) -> np.ndarray:
    """At most `max_draws` rows of `z`, evenly spaced."""
    if z.shape[0] <= max_draws:
        return z
    return z[np.linspace(0, z.shape[0] - 1, max_draws).astype(int)]


def prediction_bands(post, v0, *, level=0.9, observed=False, max_draws=1000, key=None) -> Bands:
    """The bands of `post` (a `Posterior`) at `v0` (m/s); see `Posterior.predict`."""
    model = post.model
    if model is None:
        raise ValueError(
            "this Posterior has no forward model (read from a dict of a user's law): "
            "predictions need the fit it came from"
        )
    if not 0 < level < 1:
        raise ValueError(f"level must lie in (0, 1), e.g. 0.9, got {level!r}")
    if observed and model.e is None and model.T is None:
        raise ValueError(
            "observed=True adds the noise of measured e and T: this posterior's fit (a "
            "bounce) measured neither; its bands (observed=False) are the law's"
        )
    v0 = np.atleast_1d(np.asarray(v0, dtype=float))
    if v0.ndim != 1 or not np.all(np.isfinite(v0) & (v0 > 0)):
        raise ValueError("v0 must be finite speeds > 0 m/s (a number or a 1-D array)")
    z = thinned(np.asarray(post.z), int(max_draws))
    e, T = (np.asarray(a) for a in draw_predictions(model, jnp.asarray(z), jnp.asarray(v0)))
    if observed:
        key = jax.random.key(1) if key is None else key
        e = e + noise_scale(post, "e", T, z) * noise_draws(model, key, e.shape)
        T_key = jax.random.fold_in(key, 1)
        T = T + noise_scale(post, "T", T, z) * noise_draws(model, T_key, T.shape)
    lo, hi = (1 - level) / 2, (1 + level) / 2
    q = lambda a: np.nanquantile(a, [0.5, lo, hi], axis=0)  # noqa: E731
    (e_med, e_lo, e_hi), (T_med, T_lo, T_hi) = q(e), q(T)
    return Bands(v0, e_med, e_lo, e_hi, T_med, T_lo, T_hi, float(level), z.shape[0], observed)


def noise_scale(post, what: str, T_pred, z) -> np.ndarray:
    """The noise scale `sigma_{what}` of a new measurement of `what` ("e" or "T" of a
    calibration, "e_t" or "omega" of an oblique fit), per draw (rows of `z`) and speed:
    the sampled scale of each draw, or else the given sigmas' median (for `T` as a
    fraction of the measured T, times the predicted T `T_pred`)."""
    model = post.model
    name = f"sigma_{what}"
    if name in model.names:
        i = model.names.index(name)
        return np.asarray(model.priors[i].value(jnp.asarray(z[:, i])))[:, None]
    given = getattr(model, name)
    if given is None:
        return np.zeros((1, 1))
    if what != "T":
        return np.full((1, 1), float(np.median(given)))
    known = np.isfinite(model.T)
    return float(np.median(given[known] / model.T[known])) * np.asarray(T_pred)


def noise_draws(model, key, shape):
    """Standard draws of `model`'s noise (normal, or Student-t of `model.nu`)."""
    if model.noise == "normal":
        return np.asarray(jax.random.normal(key, shape))
    return np.asarray(jax.random.t(key, model.nu, shape))
