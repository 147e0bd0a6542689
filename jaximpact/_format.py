"""Numbers and quantities as people read them, and values as JSON can hold them: shared by
the library's tables and reports, the results' `repr`, `summary()` and `to_dict()`
(`ImpactResult`, `Fit`, `Ranking`) and the command line."""

import math

_MULTIPLE_UNITS = {"N", "Pa", "W"}
_PREFIXES = [
    (1e9, "G"),
    (1e6, "M"),
    (1e3, "k"),
    (1.0, ""),
    (1e-3, "m"),
    (1e-6, "µ"),
    (1e-9, "n"),
    (1e-12, "p"),
    (1e-15, "f"),
]


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
    if unit == "kg" and abs(value) < 1 - 0.5 * 10.0**-digits:  # 4 g, not 4 mkg
        return format_quantity(value * 1e3, "g", digits)
    prefixes = [(s, p) for s, p in _PREFIXES if s <= 1.0 or unit in _MULTIPLE_UNITS]
    threshold = 1 - 0.5 * 10.0**-digits  # 0.99996 s rounds to 1 s, not 1000 ms
    scale, prefix = next(((s, p) for s, p in prefixes if abs(value) >= s * threshold), prefixes[-1])
    return f"{format_number(value / scale, digits)} {prefix}{unit}"


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


def _shape_text(value) -> str:
    dtype = str(getattr(value, "dtype", "float"))
    short = {"float64": "f64", "float32": "f32", "int32": "i32", "int64": "i64", "bool": "bool"}
    return f"{short.get(dtype, dtype)}[{','.join(map(str, getattr(value, 'shape', ())))}]"


def format_value(value, unit: str | None = "", digits: int = 4) -> str:
    """One field of a result as text, whatever it holds:

    - a number with its unit (`0.007845, "s"` -> `7.845 ms`; `unit=""`: a pure number,
      `unit=None`: as it is, a word or a count);
    - an array of several, as a batch of results is: `5 values, 7.1 ms to 8.2 ms` (the
      smallest and largest finite ones; all of them up to 4; NaN counted apart);
    - `traced f64[5]` for a tracer (inside `jit` or `vmap` there are no numbers to show);
    - `-` for None.
    """
    if value is None:
        return "-"
    from ._checks import is_traced  # here: the command line imports this module without JAX

    if is_traced(value):
        return f"traced {_shape_text(value)}"
    if isinstance(value, str):
        return value
    import numpy as np

    try:
        array = np.asarray(value)
    except Exception:  # something that is not an array of numbers
        return str(value)
    if array.dtype.kind not in "biuf":
        return str(value)

    def one(x):
        if unit is None or array.dtype.kind in "biu":
            return str(x.item() if hasattr(x, "item") else x)
        if unit == "":
            return format_number(x, digits)
        return format_quantity(x, unit, digits)

    if array.ndim == 0:
        return one(array)
    flat = array.ravel()
    if flat.size <= 4:
        return "[" + ", ".join(one(x) for x in flat) + "]"
    shown = flat[np.isfinite(flat)] if flat.dtype.kind == "f" else flat
    missing = flat.size - shown.size
    text = f"{flat.size} values"
    if shown.size:
        text += f", {one(shown.min())} to {one(shown.max())}"
    return text + (f" ({missing} not finite)" if missing else "")


def call_text(call: str, first: str, params: dict, units: dict) -> str:
    """A law as the call that builds it, with its values in their units:
    `law('thornton', c=2.176e10 N/m^1.5, x_y=598.6 nm)` (`first`: the call's first argument,
    as written; a unit `-` or missing: a pure number; a traced value: its shape)."""
    shown = [first]
    for name, value in params.items():
        unit = units.get(name, "-")
        shown.append(f"{name}={format_value(value, '' if unit == '-' else unit)}")
    return f"{call}({', '.join(shown)})"


def format_fields(title: str, rows) -> str:
    """`title`, then one aligned line `name = text` per `(name, text)` of `rows` (texts
    from `format_value`): the `summary()` of the results."""
    rows = list(rows)
    width = max((len(name) for name, _ in rows), default=0)
    return "\n".join([title, *(f"  {name:<{width}} = {text}" for name, text in rows)])


def concrete_units(spec, params: dict | None = None) -> dict[str, str]:
    """The parameter units of one law (its row `spec` of the law table), with the family
    exponents n and p filled in (`N/m^n` -> `N/m^1.5` for Hertz); an exponent that is itself
    a parameter is filled in only from its value in `params`."""
    units = {name: spec.units.get(name, "-") for name in spec.parameters}
    if not spec.shape:  # a law outside the family: its units hold no exponent
        return units
    if "n" in spec.parameters:
        if params is None or "n" not in params:
            return units
        n, p = float(params["n"]), None
    else:
        n, p = spec.shape

    def power(unit, exponent):
        exponent = float(exponent)
        return unit + ("" if exponent == 1 else f"^{exponent:g}")

    for name, unit in units.items():
        if unit == "N/m^n":
            units[name] = power("N/m", n)
        elif unit == "N s/m^(p+1)" and p is not None:
            units[name] = power("N s/m", float(p) + 1)
    return units


class PrintedFields:
    """`summary()`, `to_dict()` and `repr` for a result whose class lists `_SHOWN`, the
    fields a reader wants as `(name, unit)` (`unit`: "" a pure number, None a word or a
    count; a callable: the unit read off the result, e.g. a law's), under `_TITLE`.
    `to_dict()` gives every field (`_SHOWN` first), NaN as None."""

    _TITLE = "result (SI units)"
    _SHOWN: tuple = ()

    def summary(self) -> str:
        rows = []
        for name, unit in self._SHOWN:
            unit = unit(self) if callable(unit) else unit
            rows.append((name, format_value(getattr(self, name), unit)))
        return format_fields(self._TITLE, rows)

    def to_dict(self) -> dict:
        import dataclasses

        names = [n for n, _ in self._SHOWN]
        names += [f.name for f in dataclasses.fields(self) if f.name not in names]
        return {name: jsonable(getattr(self, name)) for name in names}

    def __repr__(self) -> str:
        return self.summary()
