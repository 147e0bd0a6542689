"""`Law`, a law of the table with its parameters, and `law(name, **params)` that builds
one after checking the parameters."""

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np
from jaxtyping import Array

from .._checks import check_nonnegative, check_positive, check_values, invalid_entries
from .._powers import contact_pow
from .base import AbstractLaw, LawSpec
from .dynamics import maxwell_dynamics, power_dynamics
from .table import LAW_NAMES, LAWS


class Law(AbstractLaw):
    """A law of the table `LAWS`, built by `jaximpact.law(name, **params)`.

    **Example**: `jaximpact.law("hertz_rate", c=2e6, b1=800.0).force(1e-3, 1.0)`.
    """

    name: str = eqx.field(static=True)
    params: dict[str, Array]

    @property
    def spec(self) -> LawSpec:
        return LAWS[self.name]

    @property
    def parameters(self):
        return dict(self.params)

    def replace(self, **params):
        unknown = sorted(set(params) - set(self.params))
        if unknown:
            raise ValueError(
                f"law {self.name!r} has no parameter {', '.join(unknown)}; "
                f"it has {', '.join(self.params)}"
            )
        return law(self.name, **{**self.params, **params})

    def dynamics(self, *, m, v0, g):
        if self.spec.coefficients is None:  # Maxwell: the force is a state
            return maxwell_dynamics(self.params["c"], self.params["b"], m=m, v0=v0, g=g)
        c, n, b, p, p_in, p_out = self.spec.coefficients(self.params, v0)
        gap = self.spec.gap
        if gap == "power":
            gap = _power_gap(n, p)
        return power_dynamics(
            c,
            n,
            b,
            p,
            p_in,
            p_out,
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
        variants need the impact speed `v0`. Not defined for Maxwell, whose force is a state.
        """
        if self.spec.coefficients is None:
            raise ValueError(
                "the Maxwell force is a state, not a function of (x, v): "
                "read it from impact(..., ts=...).F"
            )
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


def as_arrays(params, numbers=()):
    """The parameters as JAX arrays; those named in `numbers` (a law's shape exponents)
    stay numpy arrays when given as numbers, so that they are still known numbers when the
    law is built inside `jax.jit` (where `jnp.asarray` of a constant is a traced value)."""
    arrays = {}
    for key, value in params.items():
        if isinstance(value, (str, bytes)) or value is None:
            raise TypeError(
                f"parameter {key} must be a number or an array of numbers, got {value!r}"
            )
        if key in numbers and isinstance(value, (int, float, np.number, np.ndarray)):
            arrays[key] = np.asarray(value, dtype=jnp.result_type(float))
        else:
            arrays[key] = jnp.asarray(value, dtype=float)
    return arrays


def _parameter_rule(key, spec):
    """What makes a law parameter's value invalid, besides not being finite."""
    if key in spec.positive:
        return lambda a: a <= 0
    if key == "e_nominal":
        return lambda a: (a <= 0) | (a > 1)
    return lambda a: a < 0


def _check_law_parameters(name, params):
    """The parameters, each passed through its value check (eager `ValueError`, or
    `eqx.error_if` under `jit`, whose result must be used)."""
    checked, units = {}, LAWS[name].units
    for key, value in params.items():
        if key == "c":
            checked[key] = check_positive(f"{name}: stiffness c", value, units["c"])
        elif key == "n":
            checked[key] = check_positive(f"{name}: exponent n", value)
        elif key in LAWS[name].positive:
            checked[key] = check_positive(f"{name}: {key}", value, units.get(key, ""))
        elif key == "e_nominal":
            checked[key] = check_values(
                value,
                _parameter_rule(key, LAWS[name]),
                f"{name}: e_nominal must lie in (0, 1], got {value}",
            )
        else:
            checked[key] = check_nonnegative(f"{name}: {key}", value, units.get(key, ""))
    return checked


def invalid_parameter_rows(name: str, params: dict) -> np.ndarray:
    """Rows of 1-D parameter arrays that `law(name, ...)` would refuse: not finite, out of
    range (the law's `positive` parameters > 0; e_nominal in (0, 1]; the rest >= 0), or
    free exponents with p > n."""
    spec = LAWS[name]
    rows = np.zeros(np.shape(next(iter(params.values()))), bool)
    for key, value in params.items():
        rows |= invalid_entries(value, _parameter_rule(key, spec))
    n, p = (params[q] if isinstance(q, str) else q for q in spec.shape or (1.0, 0.0))
    with np.errstate(invalid="ignore"):
        rows |= ~(np.asarray(p, float) <= np.asarray(n, float))
    return rows


def _concrete_numbers(*values) -> bool:
    return all(not isinstance(v, jax.core.Tracer) and jnp.ndim(v) == 0 for v in values)


def law(name: str, **params) -> Law:
    """Build the law `name` of `LAW_NAMES` with its parameters (SI units).

    Parameter names are the seed paper's: `c` stiffness, `b` or `b1` damping, `P` dry force,
    `a` Hunt-Crossley damping, `n` exponent, `e_nominal` the restitution a published
    Hunt-Crossley damping formula is asked for. `jaximpact laws` lists them all.

    **Example**: `law("kelvin_voigt", c=2e6, b=400.0)`.
    """
    if name not in LAWS:
        raise ValueError(f"unknown law {name!r}; choose one of: {', '.join(LAW_NAMES)}")
    spec = LAWS[name]
    unknown = sorted(set(params) - set(spec.parameters))
    if unknown:
        raise ValueError(
            f"law {name!r} has no parameter {', '.join(unknown)}; "
            f"it takes {', '.join(spec.parameters)}"
        )
    given = {**spec.defaults, **params}
    missing = [k for k in spec.parameters if k not in given]
    if missing:
        raise ValueError(
            f"law {name!r} needs {', '.join(missing)}; it takes {', '.join(spec.parameters)}"
            + (f" (defaults: {spec.defaults})" if spec.defaults else "")
        )
    given = {k: given[k] for k in spec.parameters}
    n, p = (given[q] if isinstance(q, str) else q for q in spec.shape or (1.0, 0.0))
    if _concrete_numbers(n, p) and not 0 <= float(p) <= float(n):  # a row with free exponents
        raise ValueError(f"law {name!r} needs exponents 0 <= p <= n, got n={n}, p={p}")
    return Law(name, as_arrays(_check_law_parameters(name, given), spec.shape_parameters))
