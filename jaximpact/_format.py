"""Numbers and quantities as people read them, and values as JSON can hold them: shared by
the library's tables and reports and by the command line."""

import math

_MULTIPLE_UNITS = {"N", "Pa", "W"}
_PREFIXES = [(1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n")]


def format_number(value, digits: int = 6) -> str:
    """`2e6` -> `"2e6"`, `800.0` -> `"800"`, `1.5e-05` -> `"1.5e-5"` (compact, for humans)."""
    text = f"{float(value):.{digits}g}"
    mantissa, sep, exponent = text.partition("e")
    return mantissa + (f"e{int(exponent)}" if sep else "")


def format_quantity(value, unit: str, digits: int = 4) -> str:
    """`0.007845, "s"` -> `"7.845 ms"`: an SI prefix that puts the number in [1, 1000)
    (multiples such as kN only for forces: a long time stays `1250 s`)."""
    value = float(value)
    if not math.isfinite(value) or value == 0.0:
        return f"{value:g} {unit}"
    prefixes = [(s, p) for s, p in _PREFIXES if s <= 1.0 or unit in _MULTIPLE_UNITS]
    threshold = 1 - 0.5 * 10.0**-digits  # 0.99996 s rounds to 1 s, not 1000 ms
    scale, prefix = next(((s, p) for s, p in prefixes if abs(value) >= s * threshold), prefixes[-1])
    return f"{value / scale:.{digits}g} {prefix}{unit}"


def jsonable(value):
    """Arrays and numpy scalars as plain floats, ints and lists; NaN and inf as null."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    if value is None or isinstance(value, (str, bool)):
        return value
    if hasattr(value, "tolist"):  # jax and numpy arrays and scalars
        return jsonable(value.tolist())
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    return str(value)
