"""The values of a table of bodies checked before any work: every mass `m` (kg) and speed `v0`
(m/s) finite and > 0, gravity `g` (m/s^2) finite and >= 0, every law parameter as the law
table requires it (stiffness > 0, dampings >= 0, ...; a user's law's: finite), `separation`
one of its two words. The first bad value is one line naming its place (line or row) and
column."""

import numpy as np

KINEMATICS = ("m", "v0", "g")
SEPARATIONS = ("force", "penetration")
_POSITIVE = ("m", "v0")


def _rule(key, positive, signed=()):
    def bad(a):
        with np.errstate(invalid="ignore"):
            if key in signed:  # a user's law's parameter: any finite number
                return ~np.isfinite(a)
            return ~np.isfinite(a) | ((a <= 0) if key in positive else (a < 0))

    return bad


def _need(key, positive, signed) -> str:
    return "" if key in signed else (" > 0" if key in positive else " >= 0")


def _signed(law, keys) -> tuple:
    """The parameters among `keys` that may take any sign: a user's law's (it decides)."""
    return tuple(k for k in keys if k not in KINEMATICS) if law.user else ()


def check_fixed(law, fixed: dict):
    """The values given for every row (`--param`, `--mass`, ...): numbers in range (`law`:
    a `JobLaw`)."""
    positive, signed = (*_POSITIVE, *law.positive), _signed(law, fixed)
    for key, value in fixed.items():
        if key == "separation":
            if value not in SEPARATIONS:
                raise ValueError(f"separation must be 'force' or 'penetration', got {value!r}")
            continue
        try:
            number = float(value)
        except (TypeError, ValueError):
            raise ValueError(f"fixed value {key}: {value!r} is not a number") from None
        if _rule(key, positive, signed)(np.asarray(number)):
            need = _need(key, positive, signed)
            raise ValueError(f"fixed value {key}: {key} = {value!s} must be a finite number{need}")


# how a value given for every row is named: the command line's option (Python's argument)
_OPTIONS = {
    "m": "--mass (m=)",
    "v0": "--v0 (v0=)",
    "g": "--g (g=)",
    "separation": "--separation (separation=)",
}


def option_name(key: str) -> str:
    """The option (and argument) that gives `key` to every row, for messages."""
    return _OPTIONS.get(key, f"--param {key}= (params={{{key!r}: ...}})")


def check_rows(law, values: dict, fixed: dict, where, options=None):
    """Raise a one-line `ValueError` at the first row (file order) with a bad value in
    `values` (column -> array), or whose column disagrees with the value `options` (name ->
    value, the options the caller gave for every row) holds for it: a column and an option
    that disagree are refused, never settled silently. `law`: a `JobLaw`; `fixed` completes
    its parameters; `where(i)` says where row `i` is."""
    positive, signed = (*_POSITIVE, *law.positive), _signed(law, {**fixed, **values})
    options = options or {}
    rows = len(next(iter(values.values())))
    first, message = rows, None
    for key, column in values.items():
        if key == "separation":
            bad = ~np.isin(column, SEPARATIONS)
        else:
            bad = _rule(key, positive, signed)(column)
        if bad[:first].any():
            i = int(np.argmax(bad))
            if key == "separation":
                text = f"{column[i]!r} is not 'force' or 'penetration'"
            else:
                need = _need(key, positive, signed)
                text = f"{key} = {float(column[i])!r} must be a finite number{need}"
            first, message = i, f"{where(i)}, column {key}: {text}"
        if key in options:
            given = options[key]
            if key == "separation":
                other = np.asarray(column, object) != given
            else:
                with np.errstate(invalid="ignore"):
                    other = ~bad & (np.asarray(column, float) != float(given))
            if other[:first].any():
                i = int(np.argmax(other))
                shown = repr(column[i]) if key == "separation" else f"{float(column[i])!r}"
                text = (
                    f"{key} = {shown} disagrees with {option_name(key)} {given!r} given for "
                    "every row; drop the column or the option"
                )
                first, message = i, f"{where(i)}, column {key}: {text}"
    params = {
        k: np.broadcast_to(np.asarray(v, float), (rows,))
        for k, v in {**fixed, **values}.items()
        if k in law.parameters
    }
    bad = law.invalid_rows(params)
    if bad[:first].any():  # a rule of the law table beyond the signs (e_nominal <= 1, p <= n)
        i = int(np.argmax(bad))
        text = law.refusal({k: float(v[i]) for k, v in params.items()})
        first, message = i, f"{where(i)}: {text}"
    if message is not None:
        raise ValueError(message)
