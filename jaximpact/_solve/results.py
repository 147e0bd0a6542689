"""What one impact gives: `ImpactResult`."""

import equinox as eqx
from jaxtyping import Array

from .._checks import is_traced
from .._format import format_fields, format_value, jsonable
from .._status import Status

# the fields of an impact as `summary()` shows them: name, unit (None: a count or a word)
_SHOWN = (
    ("e", ""),
    ("T", "s"),
    ("x_max", "m"),
    ("t_max", "s"),
    ("F_max", "N"),
    ("dissipated", "J"),
    ("v_out", "m/s"),
    ("num_steps", None),
)
_HISTORIES = ("ts", "x", "v", "F")


class ImpactResult(eqx.Module):
    """What one impact gives (SI units).

    - `e`: coefficient of restitution `-v_out / v0` (0 unless `status == separated`).
    - `T`: contact duration (s), from first touch to separation; for `stuck` the time at
      which the body came to rest; for `captured` the time the solve gave up (the horizon
      `tau_max t*`, or the instant its speed and net force fell below `rest_tol`; in closed
      form for over-damped Kelvin-Voigt under `"penetration"` and for over-damped Maxwell,
      `mu = sqrt(m c)/b >= 2` without gravity, which never reaches maximum compression).
      Its derivatives are those of that instant (finite); `e` of a captured member is 0
      with derivative 0.
    - `x_max` (m), `t_max` (s): maximum penetration and when it is reached.
    - `F_max` (N): largest contact force (at first touch, at the first force peak in
      compression, or at maximum compression, whichever is largest).
    - `dissipated` (J): kinetic energy taken by the contact, `m v0^2 (1 - e^2)/2` plus the
      work of gravity over the final penetration.
    - `v_out` (m/s): velocity at separation (negative: leaving).
    - `status`: a `jaximpact.Status` as an integer array; `num_steps`: solver steps.
    - `x_max`, `t_max`, `F_max` are `None` under `impact(..., peaks=False)`, which skips the
      events that find them (a law split at maximum compression still gives `x_max`).
    - `path`: `"similarity"` (read off the universal curves), `"closed_form"` or
      `"integrated"`; a row of `impact_batch` (its field `"path"`, one string per row) may
      also say `"grid"`: served by the fixed grid of the phase-plane angle (`_solve.grid`).
    - `ts`, `x`, `v`, `F`: time histories, only when `impact(..., ts=...)` asked for them.
    """

    e: Array
    T: Array
    dissipated: Array
    v_out: Array
    status: Array
    num_steps: Array
    path: str = eqx.field(static=True)
    x_max: Array | None = None
    F_max: Array | None = None
    t_max: Array | None = None
    ts: Array | None = None
    x: Array | None = None
    v: Array | None = None
    F: Array | None = None

    @property
    def separated(self) -> Array:
        return self.status == Status.separated

    @property
    def status_name(self) -> str:
        """The status as a word (for a single impact, not a batch)."""
        return Status(int(self.status)).name

    def _status_text(self) -> str:
        """`separated`, or for a batch the count of each status (`separated 9, stuck 1`)."""
        return status_text(self.status)

    def summary(self) -> str:
        """The impact as text, every number with its unit (`T = 7.845 ms`); a batch of
        impacts (arrays) by the range of each field and the count of each status; inside
        `jit` the shapes (`traced f64[]`), as there are no numbers yet."""
        rows = [
            (name, format_value(getattr(self, name), unit))
            for name, unit in _SHOWN
            if getattr(self, name) is not None
        ]
        rows.append(("status", self._status_text()))
        rows.append(("path", self.path))
        if self.ts is not None:
            rows.append(("histories", f"ts, x, v, F at {format_value(self.ts, 's')}"))
        return format_fields("ImpactResult (SI units)", rows)

    def to_dict(self) -> dict:
        """The fields as plain numbers and lists (SI units: s, m, N, J, m/s), NaN as None,
        `status` as its name (a list of names for a batch), `path`; the time histories
        only when they were asked for. Concrete results only (not inside `jit`)."""
        out = {name: jsonable(getattr(self, name)) for name, _ in _SHOWN}
        out["status"] = status_names(self.status)
        out["path"] = self.path
        out.update(
            {k: jsonable(getattr(self, k)) for k in _HISTORIES if getattr(self, k) is not None}
        )
        return out

    def __repr__(self) -> str:
        return self.summary()


def status_text(status, kinds=Status) -> str:
    """A status array as words: `separated`, or for a batch the count of each status
    (`separated 9, stuck 1`); inside `jit` its shape. `kinds`: the enum of the codes
    (`Status`, or `BounceStatus` for a drop)."""
    if is_traced(status):
        return format_value(status)
    import numpy as np

    codes = np.asarray(status).ravel()
    names = {int(s): s.name for s in kinds}
    if np.ndim(status) == 0:
        return names.get(int(codes[0]), str(int(codes[0])))
    found, counts = np.unique(codes, return_counts=True)
    return ", ".join(
        f"{names.get(int(c), str(int(c)))} {n}" for c, n in zip(found, counts, strict=True)
    )


def status_names(status, kinds=Status):
    """A concrete status array as its names: one word, or a list of words for a batch."""
    import numpy as np

    names = {int(s): s.name for s in kinds}
    codes = np.asarray(status)
    if codes.ndim == 0:
        return names.get(int(codes), int(codes))
    return [names.get(int(c), int(c)) for c in codes.ravel()]


# what `jaximpact simulate` says below an impact that ended so
STATUS_NOTES = {
    "stuck": "a dry force held the body at rest inside the surface (e = 0); T is when it stopped",
    "captured": "the body never left the surface (e = 0); T is when the solve gave up",
    "out_of_steps": "the solver ran out of steps before the contact ended; "
    "the numbers are not to be trusted",
}
# the fields with a unit, as `summary()` shows them, in its order
UNITS = {name: unit for name, unit in _SHOWN if unit is not None}


def impact_record(law, result: ImpactResult, **conditions) -> dict:
    """One impact as `jaximpact simulate --json` prints it: the law by its name and
    parameters, the `conditions` (`m`, `v0`, `separation`, `g`), `result.to_dict()` and
    the units of its fields."""
    params = {k: float(v) for k, v in law.parameters.items()}
    units = {k: u or "-" for k, u in UNITS.items()}
    return {"law": law.name, "params": params, **conditions, **result.to_dict(), "units": units}


def _closing(records, width=None, *, wrap: bool = True) -> list[str]:
    """The notes on the statuses of `records` (with `wrap`, wrapped to `width` columns,
    default the terminal's) and the line of the plot written."""
    import textwrap

    from .._format import terminal_width

    lines = []
    for name in sorted({r["status"] for r in records} & set(STATUS_NOTES)):
        note = f"{name}: {STATUS_NOTES[name]}"
        lines += (
            textwrap.wrap(note, width or terminal_width(), subsequent_indent="  ")
            if wrap
            else [note]
        )
    if "plot" in records[0]:
        lines.append(f"plot written to {records[0]['plot']}")
    return lines


def impact_text(result: ImpactResult, record: dict, head: list[str]) -> str:
    """An `impact_record` as text: the `head` lines (the law), the conditions, then the
    result's fields as `summary()` prints them and a note on how it ended."""
    import textwrap

    from .._format import format_number

    _, *fields = result.summary().splitlines()  # below its title
    lines = [
        *head,
        f"impact     m = {format_number(record['m'])} kg, v0 = {format_number(record['v0'])} "
        f"m/s, g = {format_number(record['g'])} m/s^2, separation by {record['separation']}",
        "",
        textwrap.dedent("\n".join(fields)),
    ]
    return "\n".join(lines + _closing([record], wrap=False))


def sweep_text(records: list[dict], head: list[str], width=None) -> str:
    """A sweep of `impact_record`s over the speed: the `head` lines and the conditions,
    then one row per speed (SI units in the header) fitted to `width` columns (default the
    terminal's; `_format.format_table`)."""
    from .._format import format_number, format_table

    first = records[0]
    lines = [
        *head,
        f"impact     m = {format_number(first['m'])} kg, g = {format_number(first['g'])} "
        f"m/s^2, separation by {first['separation']}",
        "",
    ]
    keys = [k for k in UNITS if first[k] is not None and k != "v_out"]  # v_out = -e v0
    header = ["v0 (m/s)", *(f"{k} ({UNITS[k]})" if UNITS[k] else k for k in keys)]
    # status and path as columns where they change with the speed, else said once
    varying = [k for k in ("status", "path") if len({r[k] for r in records}) > 1]
    rows = [
        [format_number(r["v0"]), *(f"{float(r[k]):.5g}" for k in keys), *(r[k] for k in varying)]
        for r in records
    ]
    lines += format_table([*header, *varying], rows, width=width)
    same = [f"{k} {first[k]}" for k in ("status", "path") if k not in varying]
    if same:
        lines.append(f"at every speed: {', '.join(same)}")
    return "\n".join(lines + _closing(records, width))
