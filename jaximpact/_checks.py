"""Value checks that raise a clear error eagerly and survive `jax.jit`; `MemberChecks`,
the entry points' checks that mark a bad member of a batch instead of aborting it."""

import dataclasses

import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np


def is_traced(value) -> bool:
    """Whether `value` is a JAX tracer (inside `jit`, `vmap`, `grad`): it has no numbers, so
    a check must wait for run time and a report shows its shape. The one place that asks."""
    return isinstance(value, jax.core.Tracer)


def check_values(value, bad, message: str):
    """Return `value`; raise `ValueError(message)` where `bad(value)` holds.

    Concrete inputs are checked at once (a one-line `ValueError`); traced inputs through
    `eqx.error_if`, so the check survives `jit` (and raises at run time).
    """
    if not is_traced(value):
        try:
            array = np.asarray(value, dtype=float)
        except (TypeError, ValueError):  # a word, e.g. a number with its unit
            raise ValueError(f"{message} (give a plain number in SI units)") from None
        if array.size == 0 or np.any(~np.isfinite(array)) or np.any(bad(array)):
            raise ValueError(message)
        return value
    array = jnp.asarray(value)
    return eqx.error_if(value, jnp.any(~jnp.isfinite(array) | bad(array)), message)


def invalid_entries(value, bad) -> np.ndarray:
    """Where a concrete `value` is not finite or `bad(value)` holds (a boolean array)."""
    array = np.asarray(value, dtype=float)
    with np.errstate(invalid="ignore"):
        return ~np.isfinite(array) | bad(array)


def check_positive(name: str, value, unit: str = ""):
    """Require a finite value > 0."""
    return check_values(value, _not_positive, _positive_message(name, value, unit))


def check_nonnegative(name: str, value, unit: str = ""):
    """Require a finite value >= 0."""
    return check_values(value, _negative, _nonnegative_message(name, value, unit))


def _positive_message(name, value, unit):
    unit = f" {unit}" if unit else ""
    return f"{name} must be a finite number > 0{unit}, got {_show(value, _not_positive)}"


def _nonnegative_message(name, value, unit):
    unit = f" {unit}" if unit else ""
    return f"{name} must be a finite number >= 0{unit}, got {_show(value, _negative)}"


class MemberChecks:
    """The value checks of one call of an entry point (`impact`, `bounce`, `oblique_impact`,
    `calibrate`), and the one owner of "a bad member is NaN and `invalid`" (DESIGN.md, "Off
    the curves").

    A concrete value is checked at once: a one-line `ValueError`, as `check_values`. A
    traced one (inside `jit`, `vmap`, `grad`) is not refused, as one bad member must not
    abort a batch: where it is not finite or `bad` holds, the member is marked invalid and
    the value replaced by a harmless one, so that the member's solve runs on numbers (and
    no NaN reaches a gradient through a `jnp.where`). `refuse` then gives that member's
    results NaN, their derivatives with respect to the checked values NaN too, and its
    status `invalid`.

    **Example**: `checks = MemberChecks(); m = checks.positive("mass m", m, "kg"); ...;
    return checks.refuse(result, status=Status.invalid)`.
    """

    def __init__(self):
        self.invalid = None  # a traced boolean once a traced value was checked
        self._checked = []  # the traced values checked (their derivatives: NaN if invalid)

    def mark(self, wrong, value, harmless):
        """`value` with `harmless` where the traced boolean `wrong` holds, which makes the
        member invalid."""
        wrong = jnp.asarray(wrong)
        self.invalid = wrong if self.invalid is None else self.invalid | wrong
        if is_traced(value):
            self._checked.append(value)
        return jnp.where(wrong, harmless, value)

    def values(self, value, bad, message: str, harmless=1.0):
        """`check_values(value, bad, message)` for a concrete value; a traced one marks
        the member invalid where any entry is not finite or `bad` holds."""
        if not is_traced(value):
            return check_values(value, bad, message)
        array = jnp.asarray(value)
        return self.mark(jnp.any(~jnp.isfinite(array) | bad(array)), array, harmless)

    def positive(self, name: str, value, unit: str = "", harmless=1.0):
        """`check_positive`, or a traced value's member marked where it is not > 0."""
        return self.values(value, _not_positive, _positive_message(name, value, unit), harmless)

    def nonnegative(self, name: str, value, unit: str = "", harmless=0.0):
        """`check_nonnegative`, or a traced value's member marked where it is < 0."""
        message = _nonnegative_message(name, value, unit)
        return self.values(value, _negative, message, harmless)

    def refuse(self, result, *, keep=(), **codes):
        """`result` (an `eqx.Module`) as it is where the member is valid (or nothing traced
        was checked); for an invalid member every float field NaN (inside dicts and laws
        too) but those named in `keep`, and the fields named in `codes` set to their
        value (`status=Status.invalid`, `converged=False`)."""
        if self.invalid is None:
            return result
        invalid = self.invalid
        # 0 for a valid member (value and derivatives unchanged); NaN with NaN derivatives
        # with respect to the checked values for an invalid one
        moved = sum(
            jnp.sum(jnp.asarray(v, float) - jax.lax.stop_gradient(v)) for v in self._checked
        )
        poison = jnp.where(invalid, jnp.nan, 0.0) * moved

        def blank(leaf):
            if hasattr(leaf, "dtype") and jnp.issubdtype(leaf.dtype, jnp.inexact):
                return jnp.where(invalid, jnp.nan, leaf) + poison
            return leaf

        changes = {}
        for field in dataclasses.fields(result):
            if field.metadata.get("static", False) or field.name in keep:
                continue
            value = getattr(result, field.name)
            if field.name in codes:
                value = jnp.asarray(value)
                code = jnp.asarray(codes[field.name], value.dtype)
                changes[field.name] = jnp.where(invalid, code, value)
            else:
                changes[field.name] = jax.tree.map(blank, value)
        return dataclasses.replace(result, **changes)


def _not_positive(a):
    return a <= 0


def _negative(a):
    return a < 0


def _show(value, bad) -> str:
    """The value, or for an array its first bad entry and where it is."""
    if is_traced(value):
        return "a traced value"
    array = np.asarray(value)
    if array.dtype.kind not in "biuf":  # not numbers: a word, a number with its unit
        return repr(value)
    if array.size == 0:
        return "an empty array"
    if array.size == 1:
        return str(array.item())
    wrong = np.flatnonzero(invalid_entries(array, bad).ravel())
    if not wrong.size:
        return f"an array of {array.size} values"
    i = int(wrong[0])
    return f"{array.ravel()[i]} at index {i} (of {array.size} values; {wrong.size} bad)"


# A magnitude inside [1 / SCALE_LIMIT, SCALE_LIMIT] keeps the products of two of them (an
# energy m v0^2, a stiffness times a power of a length) inside float64's normal range
# (2.2e-308 to 1.8e308); beyond it an impact's results underflow to 0 or overflow to inf.
SCALE_LIMIT = 1e150


def out_of_scale(value) -> bool:
    """Whether a concrete number is finite, not 0, and outside [1e-150, 1e150] in size."""
    try:
        x = abs(float(value))
    except (TypeError, ValueError, OverflowError):
        return False
    return 0.0 < x < float("inf") and not (1.0 / SCALE_LIMIT <= x <= SCALE_LIMIT)


def check_scale(name: str, value, unit: str = ""):
    """Return `value`; a one-line `ValueError` if it is a concrete number whose size lies
    outside [1e-150, 1e150] (0, NaN, inf and traced values are left to the other checks):
    such an input puts an impact's scales (energy, penetration, duration, force) where
    float64 underflows or overflows, 1e-300 kg as 1e300 kg."""
    if is_traced(value):
        return value
    array = np.asarray(value, dtype=float)
    bad = [x for x in array.ravel().tolist() if out_of_scale(x)]
    if bad:
        unit = f" {unit}" if unit else ""
        raise ValueError(
            f"{name} = {bad[0]:g}{unit}: float64 cannot hold the products of an impact at "
            "this size (they under- or overflow; inputs from 1e-150 to 1e150 in SI units "
            "keep them in range); express the inputs in other units"
        )
    return value
