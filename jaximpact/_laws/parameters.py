"""A law's parameters checked against its row of the table (`checked_parameters`) and held
as arrays (`as_arrays`): what `law(name, ...)` and every table law's `replace` build from."""

import jax.numpy as jnp
import numpy as np

from .._checks import check_nonnegative, check_positive, check_values, is_traced
from .base import LawSpec


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


def parameter_rule(key, spec: LawSpec):
    """What makes a law parameter's value invalid, besides not being finite."""
    if key in spec.positive:
        return lambda a: a <= 0
    if key == "e_nominal":
        return lambda a: (a <= 0) | (a > 1)
    return lambda a: a < 0


def _check_values(spec: LawSpec, params):
    """The parameters, each passed through its value check (eager `ValueError`, or
    `eqx.error_if` under `jit`, whose result must be used)."""
    checked, name, units = {}, spec.name, spec.units
    for key, value in params.items():
        if key == "c":
            checked[key] = check_positive(f"{name}: stiffness c", value, units["c"])
        elif key == "n":
            checked[key] = check_positive(f"{name}: exponent n", value)
        elif key in spec.positive:
            checked[key] = check_positive(f"{name}: {key}", value, units.get(key, ""))
        elif key == "e_nominal":
            checked[key] = check_values(
                value,
                parameter_rule(key, spec),
                f"{name}: e_nominal must lie in (0, 1], got {value}",
            )
        else:
            checked[key] = check_nonnegative(f"{name}: {key}", value, units.get(key, ""))
    return checked


def _concrete_numbers(*values) -> bool:
    return all(not is_traced(v) and jnp.ndim(v) == 0 for v in values)


def _check_number(name: str, key: str, value, batch: bool):
    """A parameter is a number: a bool is refused (`TypeError`), and so is an array of
    several values (`ValueError`) unless `batch` (the library's own batches of laws).
    Inside `jax.vmap` a parameter is a traced scalar, which passes."""
    if isinstance(value, (str, bytes)) or value is None:
        return  # `as_arrays` says what it must be
    try:
        array = value if hasattr(value, "shape") and hasattr(value, "dtype") else np.asarray(value)
    except Exception:  # e.g. a list of traced values: left to `jnp.asarray`
        return
    if array.dtype == bool:
        raise TypeError(f"law {name!r}: {key} must be a number, got {value!r}")
    if array.shape != () and not batch:
        raise ValueError(
            f"law {name!r}: {key} must be one number, got an array of shape {array.shape}; "
            "for many values use jax.vmap or jaximpact.impact_batch"
        )


def checked_parameters(spec: LawSpec, params: dict, *, batch: bool = False) -> dict:
    """The parameters of the row `spec`'s law, complete (its defaults filled in), in the
    row's order, each checked, as arrays: a `ValueError` names an unknown or missing
    parameter, an array of several values (unless `batch`: the library's own batches,
    one law whose parameters are 1-D arrays, `named_law.batch_law`), exponents outside
    `0 <= p <= n`, or a value out of range; a `TypeError` a bool."""
    name = spec.name
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
    for key, value in params.items():
        _check_number(name, key, value, batch)
    n, p = (given[q] if isinstance(q, str) else q for q in spec.shape or (1.0, 0.0))
    if _concrete_numbers(n, p) and not 0 <= float(p) <= float(n):  # a row with free exponents
        raise ValueError(f"law {name!r} needs exponents 0 <= p <= n, got n={n}, p={p}")
    return as_arrays(_check_values(spec, given), spec.shape_parameters)
