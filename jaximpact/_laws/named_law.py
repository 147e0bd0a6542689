"""`Law`, a law of the table's family `F = c x^n + b x^p v + P d(v)` with its parameters,
and `law(name, **params)` that builds any law of the table (the row's own class where its
force is a state) after checking the parameters."""

from typing import ClassVar

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._checks import invalid_entries
from .._choices import unknown_name
from .._powers import contact_pow
from .base import AbstractLaw, LawSpec
from .dynamics import PowerCoefficients, power_dynamics
from .parameters import checked_parameters, parameter_rule
from .table import LAW_NAMES, LAWS


class Law(AbstractLaw):
    """A law of the table `LAWS`, built by `jaximpact.law(name, **params)`.

    **Example**: `jaximpact.law("hertz_rate", c=2e6, b1=800.0).force(1e-3, 1.0)`.
    """

    name: str = eqx.field(static=True)
    params: dict[str, Array]
    has_state: ClassVar[bool] = False

    def __check_init__(self):
        if LAWS[self.name].state is not None:
            raise TypeError(
                f"law {self.name!r} carries a state, so it is not a `Law`: "
                f"build it with jaximpact.law({self.name!r}, ...)"
            )

    @property
    def spec(self) -> LawSpec:
        return LAWS[self.name]

    def coefficients(self, v0):
        return self.spec.coefficients(self.params, v0)

    def replace(self, **params):
        self._refuse_unknown(params)
        return law(self.name, **{**self.params, **params})

    def dynamics(self, *, m, v0, g):
        coefficients = PowerCoefficients(*self.spec.coefficients(self.params, v0))
        gap = self.spec.gap
        if gap == "power":
            gap = _power_gap(coefficients.n, coefficients.p)
        return power_dynamics(
            coefficients,
            m=m,
            v0=v0,
            g=g,
            gap=gap,
            split=self.spec.split,
            can_stick=self.spec.dry,
        )

    def force(self, x, v, *, v0=None, compressing=None):
        """Contact force (N) at penetration `x` (m) and velocity `v` (m/s).

        The dry force's sign follows `compressing` (default: `v > 0`); the Hunt-Crossley
        variants need the impact speed `v0`.
        """
        if v0 is None and self.spec.nominal is not None:
            raise ValueError(f"law {self.name!r} needs the impact speed: pass v0=...")
        c, n, b, p, p_in, p_out = self.spec.coefficients(self.params, v0)
        x, v = jnp.asarray(x, dtype=float), jnp.asarray(v, dtype=float)
        compressing = v > 0 if compressing is None else compressing
        dry = jnp.where(compressing, p_in, p_out)
        return c * contact_pow(x, n) + b * contact_pow(x, p) * v + dry


def _power_gap(n, p):
    """`PowerDynamics.gap` of the power law: `"x"` where `n = p` (the force vanishes at
    `x = 0` only), else `n - p`; the force itself if the exponents are traced values."""
    try:
        k = float(n) - float(p)
    except (TypeError, jax.errors.ConcretizationTypeError, jax.errors.TracerArrayConversionError):
        return "force"
    return "x" if k == 0 else k


def invalid_parameter_rows(name: str, params: dict) -> np.ndarray:
    """Rows of 1-D parameter arrays that `law(name, ...)` would refuse: not finite, out of
    range (the law's `positive` parameters > 0; e_nominal in (0, 1]; the rest >= 0), or
    free exponents with p > n."""
    spec = LAWS[name]
    rows = np.zeros(np.shape(next(iter(params.values()))), bool)
    for key, value in params.items():
        rows |= invalid_entries(value, parameter_rule(key, spec))
    n, p = (params[q] if isinstance(q, str) else q for q in spec.shape or (1.0, 0.0))
    with np.errstate(invalid="ignore"):
        rows |= ~(np.asarray(p, float) <= np.asarray(n, float))
    return rows


def law(name: str, **params) -> AbstractLaw:
    """Build the law `name` of `LAW_NAMES` with its parameters (SI units).

    Parameter names are the seed paper's: `c` stiffness, `b` or `b1` damping, `P` dry force,
    `a` Hunt-Crossley damping, `n` exponent, `e_nominal` the restitution a published
    Hunt-Crossley damping formula is asked for. `jaximpact laws` lists them all. Each is one
    number (an array of several values is refused: `jax.vmap` over the law's construction,
    or `impact_batch`, computes many).

    **Example**: `law("kelvin_voigt", c=2e6, b=400.0)`.
    """
    if name not in LAWS:
        raise ValueError(unknown_name("law", name, LAW_NAMES))
    return table_law(name, checked_parameters(LAWS[name], params))


def batch_law(name: str, **params) -> AbstractLaw:
    """`law(name, **params)` for the library's own batches (`impact_batch`'s checks, the
    restitution maps): its parameters may be 1-D arrays, one value per member, each value
    checked as `law` checks it. `law` itself takes one number per parameter."""
    if name not in LAWS:
        raise ValueError(unknown_name("law", name, LAW_NAMES))
    return table_law(name, checked_parameters(LAWS[name], params, batch=True))


def table_law(name: str, params: dict) -> AbstractLaw:
    """The law of the row `name` from parameters already checked (arrays, complete): the
    row's own class where its force is a state (`LawSpec.state`), else the family's `Law`."""
    state = LAWS[name].state
    return Law(name, params) if state is None else state(params)
