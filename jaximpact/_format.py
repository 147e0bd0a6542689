"""Numbers and quantities as people read them, and values as JSON can hold them: shared by
the library's tables and reports, the results' `repr`, `summary()` and `to_dict()`
(`ImpactResult`, `Fit`, `Ranking`) and the command line; and tables that fit the terminal
(`format_table`, `wrap_text`, `terminal_width`); and what to give instead of a number
written with a unit (`unit_hint`)."""

import math
import re
import textwrap

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


# tables that fit the terminal

NARROWEST = 60  # columns: below this a table is not made narrower
KEEP_TOGETHER = "\xa0"  # a space that `format_table` does not wrap at (printed as a space)


def wrap_text(text: str, width: int, *, first: str = "", then: str | None = None) -> list[str]:
    """`text` in lines of at most `width` characters, broken at spaces only (a longer word,
    such as a path, on a line of its own): the first after `first`, the others after
    `then` (default: as many spaces as `first`)."""
    then = " " * len(first) if then is None else then
    return textwrap.wrap(
        text,
        width,
        initial_indent=first,
        subsequent_indent=then,
        break_long_words=False,
        break_on_hyphens=False,
    )


def terminal_width(default: int = 88) -> int:
    """The columns text output may fill: `COLUMNS`, else the terminal's width, else
    `default` (88) where stdout is not a terminal (a pipe, a file); never below 60."""
    import shutil

    return max(NARROWEST, shutil.get_terminal_size((default, 24)).columns)


def format_table(header, rows, *, width=None, wrap=(), keep=1, notes=None, note_column=1):
    """`rows` (lists of strings) under `header` as lines of at most `width` characters
    (default `terminal_width()`), where that can be done without cutting a word.

    The columns are two spaces apart, the header cells wrapped at spaces. A table wider
    than `width` has the cells of the columns in `wrap` (indices of free text) wrapped
    at spaces; if it is still too wide, its other columns go to further tables, each
    repeating the first `keep` columns (the row's names). `notes` (one string or None per
    row): a line under the row, from column `note_column` on, wrapped alike. Words joined
    by `KEEP_TOGETHER` (a no-break space) stay on one line.

    **Example**: `format_table(["law", "e"], [["kelvin_voigt", "0.5"]], width=80)`."""
    width = terminal_width() if width is None else width
    header = [str(h) for h in header]
    rows = [[str(c) for c in row] for row in rows]
    n = len(header)

    def longest_word(text):
        return max((len(w) for w in text.split()), default=0)

    natural = [max([len(r[i]) for r in rows] + [len(header[i])]) for i in range(n)]
    # narrowest each column can go: its longest word where it wraps, else its longest cell;
    # a header wraps at its spaces
    least = [
        max(
            [longest_word(r[i]) if i in wrap else len(r[i]) for r in rows]
            + [longest_word(header[i])]
        )
        for i in range(n)
    ]
    widths = list(natural)
    excess = sum(widths) + 2 * (n - 1) - width
    cells = [max([len(r[i]) for r in rows] + [least[i]]) for i in range(n)]
    while excess > 0:  # first wrap the headers wider than their cells, the most so first
        i = max(range(n), key=lambda k: widths[k] - cells[k])
        if widths[i] <= cells[i]:
            break
        widths[i] -= 1
        excess -= 1
    while excess > 0:  # then the free-text columns, the widest first, a character at a time
        room = [i for i in wrap if widths[i] > least[i]]
        if not room:
            break
        widths[max(room, key=lambda k: widths[k])] -= 1
        excess -= 1
    if excess > 0 and n > keep + 1:  # too wide still: further tables of the other columns
        sections, current = [], []
        fixed = sum(widths[:keep]) + 2 * keep
        for i in range(keep, n):
            if current and fixed + sum(widths[k] + 2 for k in current) + widths[i] > width:
                sections.append(current)
                current = []
            current.append(i)
        sections.append(current)
        if len(sections) > 1:
            out = []
            for number, section in enumerate(sections):
                columns = [*range(keep), *section]
                if number:
                    out.append("")
                out += format_table(
                    [header[i] for i in columns],
                    [[r[i] for i in columns] for r in rows],
                    width=width,
                    wrap=[columns.index(i) for i in wrap if i in columns],
                    keep=keep,
                    notes=notes if number == len(sections) - 1 else None,
                    note_column=min(note_column, len(columns) - 1),
                )
            return out

    def cell_lines(text, i):
        if len(text) <= widths[i]:
            return [text]
        return wrap_text(text, widths[i]) or [""]

    def render(cells, wrapped):
        parts = [cell_lines(c, i) if (i in wrapped) else [c] for i, c in enumerate(cells)]
        height = max(len(p) for p in parts)
        lines = []
        for k in range(height):
            line = "  ".join(
                (p[k] if k < len(p) else "").ljust(widths[i]) for i, p in enumerate(parts)
            )
            lines.append(line.rstrip())
        return lines

    out = render(header, range(n))
    out.append("  ".join("-" * w for w in widths))
    indent = sum(widths[:note_column]) + 2 * note_column
    for index, row in enumerate(rows):
        out += render(row, wrap)
        note = None if notes is None else notes[index]
        if note:  # from `note_column`, or further left where a word would not fit there
            at = max(0, min(indent, width - max(map(len, note.split()))))
            out += wrap_text(note, width, first=" " * at)
    return [line.replace(KEEP_TOGETHER, " ") for line in out]


# a number written with a unit on the command line (`--radius 5mm`): what to give instead
SI_NUMBERS = "numbers are given without a unit, in the units --help gives (SI: kg, m, s, N, Pa)"
UNIT_WORD = re.compile(r"(?:[GMkcmuµn]?(?:m|g|s|N|Pa)|m/s|N/m(?:\^?1\.5)?|deg|rad(?:/s)?)")
_SI_PREFIX = {
    "G": 1e9,
    "M": 1e6,
    "k": 1e3,
    "": 1.0,
    "c": 1e-2,
    "m": 1e-3,
    "u": 1e-6,
    "µ": 1e-6,
    "n": 1e-9,
}


def unit_hint(text: str) -> str | None:
    """For a number written with a unit (`"5mm"`, `"2.5 m/s"`, `"10g"`), what to give
    instead (`"... 5mm is 0.005 (m)"`, converted where the unit is a prefixed kg, m, s, N or
    Pa); None for text that is no such number."""
    match = re.fullmatch(r"\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(\S+)\s*", text)
    if match is None or not UNIT_WORD.fullmatch(match.group(2)):
        return None
    number, unit = float(match.group(1)), match.group(2)
    simple = re.fullmatch(r"([GMkcmuµn]?)(m|g|s|N|Pa)", unit)
    if simple and unit not in ("ms", "mm", "mg", "cm") and simple.group(1) == "m":
        simple = None  # a prefix m is milli only in the units above ("mN": no guess)
    if simple is None:
        return f"{SI_NUMBERS}: give {match.group(1)} if it is in that unit"
    prefix, base = simple.groups()
    scale, base = (_SI_PREFIX[prefix] * 1e-3, "kg") if base == "g" else (_SI_PREFIX[prefix], base)
    return f"{SI_NUMBERS}: {text.strip()} is {number * scale:.6g} ({base})"
