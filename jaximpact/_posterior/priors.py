"""Priors of a posterior, each with the unbounded coordinate `z` a sampler moves in.

A prior is `(kind, a, b)`:

- `("loguniform", lo, hi)`: `ln x` uniform on `[ln lo, ln hi]`; `z = logit(u)`,
  `u = (ln x - ln lo) / (ln hi - ln lo)`.
- `("uniform", lo, hi)`: `x` uniform on `[lo, hi]`; `z = logit((x - lo) / (hi - lo))`.
- `("normal", mean, sd)`: `z = (x - mean) / sd`.
- `("lognormal", mu, sigma)`: `ln x` normal; `z = (ln x - mu) / sigma`.

In every case the density of `z` (the prior times the Jacobian `|dx/dz|`) is normalised:
`u (1 - u)` with `u = sigmoid(z)` for the bounded kinds, the standard normal for the
others, so that `log_density(z)` integrates to one and the evidence is the same in `z` as
in `x`.
"""

import math

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

KINDS = ("loguniform", "uniform", "normal", "lognormal")

# the weakly informative default: loguniform over this factor either side of the fit
DEFAULT_DECADES = 3.0
# noise scales sampled when no sigma was given: `sigma_e` (absolute) loguniform over
# [1e-4, 0.5], `sigma_T` (s) loguniform over [1e-4, 0.5] times the median measured T
NOISE_RANGE = (1e-4, 0.5)
_HALF_LOG_2PI = 0.5 * math.log(2.0 * math.pi)


class Prior(eqx.Module):
    """One parameter's prior (`kind`, `a`, `b` as in the module's list) and its map to the
    unbounded coordinate `z`. `a` and `b` are leaves (numpy floats, traced under `jit`):
    a posterior of another fit of the same shape, whose default priors differ, reuses the
    compiled sampler."""

    kind: str = eqx.field(static=True)
    a: float = eqx.field(converter=np.float64)
    b: float = eqx.field(converter=np.float64)

    @property
    def bounded(self) -> bool:
        return self.kind in ("loguniform", "uniform")

    def value(self, z):
        """The parameter (SI) at `z`."""
        if self.kind == "loguniform":
            lo, hi = jnp.log(self.a), jnp.log(self.b)
            return jnp.exp(lo + (hi - lo) * jax.nn.sigmoid(z))
        if self.kind == "uniform":
            return self.a + (self.b - self.a) * jax.nn.sigmoid(z)
        if self.kind == "normal":
            return self.a + self.b * z
        return jnp.exp(self.a + self.b * z)

    def coordinate(self, x):
        """`z` of the parameter value `x` (numpy; a value on or outside a bound is moved
        just inside it)."""
        x = np.asarray(x, dtype=float)
        if self.bounded:
            if self.kind == "loguniform":
                lo, hi = math.log(self.a), math.log(self.b)
                u = (np.log(np.maximum(x, 1e-300)) - lo) / (hi - lo)
            else:
                u = (x - self.a) / (self.b - self.a)
            u = np.clip(u, 1e-9, 1.0 - 1e-9)
            return np.log(u) - np.log1p(-u)
        if self.kind == "normal":
            return (x - self.a) / self.b
        return (np.log(np.maximum(x, 1e-300)) - self.a) / self.b

    def log_density(self, z):
        """Log density of `z` (the prior with its Jacobian), normalised."""
        if self.bounded:  # ln u + ln(1 - u), u = sigmoid(z)
            return -jax.nn.softplus(-z) - jax.nn.softplus(z)
        return -0.5 * z**2 - _HALF_LOG_2PI

    def describe(self) -> str:
        return f"{self.kind}({self.a:.4g}, {self.b:.4g})"

    def as_tuple(self) -> tuple:
        return (self.kind, float(self.a), float(self.b))


def parse_prior(name: str, spec) -> Prior:
    """`Prior` from `("loguniform", lo, hi)` and the like, or one clear `ValueError`."""
    if isinstance(spec, Prior):
        return spec
    example = "e.g. ('loguniform', 1e5, 1e8)"
    if not isinstance(spec, (tuple, list)) or len(spec) != 3 or not isinstance(spec[0], str):
        raise ValueError(f"prior of {name!r} must be (kind, a, b), {example}; got {spec!r}")
    kind = spec[0]
    if kind not in KINDS:
        raise ValueError(f"unknown prior kind {kind!r} for {name!r}: use one of {', '.join(KINDS)}")
    try:
        a, b = float(spec[1]), float(spec[2])
    except (TypeError, ValueError):
        raise ValueError(
            f"prior of {name!r} needs two numbers after the kind, got {spec!r}"
        ) from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise ValueError(f"prior of {name!r} needs finite numbers, got {spec!r}")
    if kind in ("loguniform", "uniform") and not a < b:
        raise ValueError(f"prior of {name!r}: lo must be < hi, got {kind}({a:g}, {b:g})")
    if kind == "loguniform" and a <= 0:
        raise ValueError(f"prior of {name!r}: loguniform needs 0 < lo, got lo = {a:g}")
    if kind in ("normal", "lognormal") and b <= 0:
        raise ValueError(f"prior of {name!r}: the spread of a {kind} must be > 0, got {b:g}")
    return Prior(kind, a, b)


def default_prior(name: str, value: float) -> Prior:
    """The weakly informative default of a law parameter fitted at `value`: loguniform over
    three decades either side of it; a restitution `e_nominal` in (0, 1): uniform."""
    if name == "e_nominal":
        return Prior("uniform", 0.0, 1.0)
    if not (math.isfinite(value) and value > 0):
        raise ValueError(
            f"no default prior for {name!r}: its fitted value is {value:g}; "
            f"give prior={{{name!r}: ...}}"
        )
    factor = 10.0**DEFAULT_DECADES
    return Prior("loguniform", value / factor, value * factor)


def default_noise_prior(name: str, scale: float = 1.0) -> Prior:
    """The default prior of a sampled noise scale: loguniform over `NOISE_RANGE` times
    `scale` (1 for `sigma_e`, the median measured T in s for `sigma_T`)."""
    lo, hi = NOISE_RANGE
    return Prior("loguniform", lo * scale, hi * scale)


def noise_prior(name: str, given, rms: float, scale: float = 1.0) -> tuple[Prior, float]:
    """The prior of a sampled noise scale `name` (the user's `given` spec, else
    `default_noise_prior` of `scale`) and where its sampling starts: the fit's RMS residual
    `rms`, moved inside a bounded prior's range, away from a bound that the RMS of an exact
    fit meets (10 times the lower bound, at most half the upper)."""
    p = parse_prior(name, given) if given is not None else default_noise_prior(name, scale)
    start = rms
    if p.bounded:
        floor = 10.0 * p.a if p.a > 0 else 0.01 * p.b
        start = min(max(rms, floor), 0.5 * p.b)
    return p, start
