"""Oblique rebounds as `jaximpact fit-oblique` reads and reports them: the measured
rebounds of a CSV file (`read_rebounds`: incidences and what was measured, or a video
track's frames through `track_rebounds`), what the normal law implies for the sphere's mass
(`normal_check`) and the fit's text (`fit_oblique_text`: `ObliqueFit.summary()` with the
measured and fitted values at each incidence). Bad input is a one-line `ValueError`."""

import math
from pathlib import Path

from .._files import read_table
from .._format import format_quantity

INCIDENCE = ("theta_deg", "v_n", "v_t", "omega")
MEASURED = ("e_t", "omega_out")
COLUMNS = INCIDENCE + MEASURED
TRACK = ("t", "x", "y", "phi")
# SI units of the columns a header may give in others (`v_n (mm/s)`, `t [ms]`, `x (mm)`)
UNITS = dict(v_n="m/s", v_t="m/s", t="s", x="m", y="m")


def read_track(path: Path, header, rows, g: float) -> dict:
    """The rebounds (as `read_rebounds`, with `sigma_e_t` and `sigma_omega`) of the video
    track in the CSV at `path` (`t, x, y, phi`), through `track_rebounds`."""
    import numpy as np

    from .track import track_rebounds

    if set(header) != set(TRACK):
        raise ValueError(f"{path}: a track has the columns {', '.join(TRACK)} (one row per frame)")
    for line, values in rows:
        for name in header:
            if math.isnan(values[name]):
                raise ValueError(f"{path}, line {line}: no {name}; drop frames not tracked")
    try:
        track = track_rebounds(*(np.asarray([v[k] for _, v in rows]) for k in TRACK), g=g)
        inputs = track.fit_inputs()
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    out = {k: list(map(float, v)) for k, v in inputs.items()}
    pairs = zip(out["v_n"], out["v_t"], strict=True)
    out["theta"] = [math.degrees(math.atan2(t, n)) for n, t in pairs]
    return out


def read_rebounds(path: Path, speed: float | None, g: float = 9.81) -> dict:
    """`{v_n, v_t, omega, e_t, omega_out, theta}` (lists; NaN where not measured) from the
    CSV at `path`, rebounds or a video track (`read_track`, gravity `g` in m/s^2), in SI
    units or those its header gives (`UNITS`: `v_n (mm/s)`, `t [ms]`); one-line
    `CLIError`s for what is missing or not a number."""
    hint = f"{', '.join(COLUMNS)} (rebounds) or {', '.join(TRACK)} (a track)"
    header, rows = read_table(path, COLUMNS + TRACK, label=str(path), hint=hint, units=UNITS)
    if "t" in header:
        if speed is not None:
            raise ValueError(f"{path} is a video track: --speed is not used; leave it out")
        return read_track(path, header, rows, g)
    by_angle = "theta_deg" in header
    if by_angle == ("v_n" in header or "v_t" in header) or (
        not by_angle and not {"v_n", "v_t"} <= set(header)
    ):
        raise ValueError(f"{path}: give the incidence as theta_deg or as v_n,v_t (not both)")
    if by_angle and speed is None:
        raise ValueError(f"{path} gives theta_deg: pass the impact speed --speed (m/s)")
    if not by_angle and speed is not None:
        raise ValueError(f"{path} gives v_n,v_t: --speed is not used; leave it out")
    if not set(MEASURED) & set(header):
        raise ValueError(f"{path}: no measured column (e_t and/or omega_out)")
    columns = {name: [] for name in COLUMNS}
    for number, given in rows:
        values = dict.fromkeys(COLUMNS, math.nan) | {"omega": 0.0} | given
        if by_angle:
            theta = values["theta_deg"]
            if not 0.0 <= theta < 90.0:
                raise ValueError(
                    f"{path}, line {number}: theta_deg = {theta:g} must lie in [0, 90) degrees "
                    "from the normal"
                )
            values["v_n"] = speed * math.cos(math.radians(theta))
            values["v_t"] = speed * math.sin(math.radians(theta))
        for name in ("v_n", "v_t", "omega"):
            if math.isnan(values[name]):
                raise ValueError(f"{path}, line {number}: no {name}; every row needs its incidence")
        if all(math.isnan(values[name]) for name in MEASURED):
            raise ValueError(f"{path}, line {number}: neither e_t nor omega_out is given")
        values["theta"] = math.degrees(math.atan2(values["v_t"], values["v_n"]))
        for name in (*COLUMNS, "theta"):
            columns.setdefault(name, []).append(values[name])
    if not columns["v_n"]:
        raise ValueError(f"{path} has no rows")
    if by_angle and len(columns["v_n"]) > 1 and max(columns["theta_deg"]) <= math.pi / 2:
        raise ValueError(
            f"{path}: every theta_deg is at most {math.pi / 2:.4f}: radians? the column "
            "takes degrees from the normal"
        )
    return columns


def normal_check(law, m: float, v_n: float) -> dict:
    """What the normal law implies for mass `m` (kg) at the largest normal speed `v_n`
    (m/s): contact time, penetration and peak force, so that a mass in the wrong unit shows
    (e_t and the spin do not depend on it: both springs scale alike)."""
    from .._solve.impact import impact

    r = impact(law, m=m, v0=v_n)
    return {"v_n": v_n, "T": float(r.T), "x_max": float(r.x_max), "F_max": float(r.F_max)}


def fit_oblique_text(fit, rows, check, normal=None) -> str:
    """`jaximpact fit-oblique`'s report: the normal law taken from a fit (`normal`, the
    record `--json` prints), the fit as it prints itself (`ObliqueFit.summary()`), what the
    normal law implies for the mass (`check`, `normal_check`'s) and, at each incidence of
    `rows` (`read_rebounds`' columns as arrays), the measured and fitted e_t and spin."""
    import numpy as np

    lines = [
        *(
            [
                f"normal law {normal['law']} from {normal['from']} ("
                + ", ".join(f"{k} = {v:g}" for k, v in normal["params"].items())
                + f"; separation by {normal['separation']})"
            ]
            if normal
            else []
        ),
        fit.summary(),
        f"check: at v_n = {check['v_n']:.4g} m/s the normal law with this mass gives a contact "
        f"time of {format_quantity(check['T'], 's')}, x_max {format_quantity(check['x_max'], 'm')}"
        f", F_max {format_quantity(check['F_max'], 'N')}: if these look wrong, check the units "
        "(--mass in kg; e_t and the spin do not depend on the mass)",
        "",
        "  theta [deg]   e_t meas   e_t fit   omega_out meas   fit [rad/s]",
    ]
    for i, theta in enumerate(rows["theta"]):
        e_m, w_m = rows["e_t"][i], rows["omega_out"][i]
        e_f, w_f = float(np.asarray(fit.e_t)[i]), float(np.asarray(fit.omega_out)[i])
        lines.append(
            f"  {theta:11.2f}   {_cell(e_m, '.3f'):>8}   {e_f:7.3f}   {_cell(w_m, '.1f'):>14}"
            f"   {w_f:11.1f}"
        )
    if not bool(fit.converged):
        lines.append("the fit did not converge (see the notes): try other start values (--tparam)")
    return "\n".join(lines)


def _cell(value: float, spec: str) -> str:
    """A measured value formatted by `spec`, or `-` where it was not measured (NaN)."""
    return "-" if math.isnan(value) else format(value, spec)


# the fields of `jaximpact simulate`'s table of oblique impacts, one row per angle (their
# units the result's own, `ObliqueResult`'s `_SHOWN`; angles in degrees)
_TABLE = (
    "e",
    "e_t",
    "e_t_contact",
    "v_t_out",
    "omega_out",
    "angle_out",
    "angle_out_contact",
    "T",
    "num_switches",
)


# what the oblique fields mean, printed under them
_OBLIQUE_LEGEND = (
    "e_t = v_t_out / v_t (the centre's), e_t_contact = u_out / u (the contact point's slip, "
    "u = v_t - R omega; Chung & Ooi's beta = -e_t_contact); angle_out from the normal: the "
    "centre's rebound, angle_out_contact the contact point's"
)


def _table_cell(data: dict, name: str, unit: str | None) -> str:
    """One field of an oblique run in the table: a plain number (angles in degrees), a
    count, or `-` where missing (NaN)."""
    value = data[f"{name}_deg"] if unit == "deg" else data[name]
    if value is None:
        return "-"
    return str(int(value)) if unit is None else f"{value:.4g}" if unit == "deg" else f"{value:.5g}"


def oblique_runs_text(runs, results) -> list[str]:
    """The lines of `jaximpact simulate --tangential`'s oblique impacts, one per angle
    (`runs`: each impact's `to_dict()` with `angle_deg` and the angles out in degrees;
    `results`: the `ObliqueResult`s): one result as it prints itself after its incidence,
    several as a table (angles in degrees), then what the fields mean."""
    import textwrap

    from .._format import format_table
    from .results import _SHOWN

    if len(runs) == 1:
        lines = [f"{'angle':<17} = {runs[0]['angle_deg']:g} deg", results[0].summary()]
    else:
        units = {name: "deg" if unit == "rad" else unit for name, unit in _SHOWN}
        header = [f"{n} ({units[n]})" if units[n] else n for n in _TABLE]
        rows = [
            [f"{d['angle_deg']:g}", *(_table_cell(d, n, units[n]) for n in _TABLE), d["status"]]
            for d in runs
        ]
        lines = format_table(["angle (deg)", *header, "status"], rows)
    return [*lines, "", *textwrap.wrap(_OBLIQUE_LEGEND, 92)]


def tangential_rows() -> list[dict]:
    """Every tangential law as plain data: `name`, `formula`, `parameters` (each `name`,
    `unit`, `default`), `also` (other inputs), `engines` and `reference`."""
    from .tangential import TANGENTIAL_LAWS

    return [
        dict(
            name=spec.name,
            formula=spec.formula,
            parameters=[
                dict(name=p, unit=spec.units.get(p, "-"), default=spec.defaults.get(p))
                for p in spec.parameters
            ],
            also=list(spec.inputs),
            engines=spec.engines,
            reference=spec.reference,
        )
        for spec in TANGENTIAL_LAWS.values()
    ]


def tangential_text(rows, width: int) -> list[str]:
    """The tangential laws' table (`--tangential`), the engines and reference under each."""
    import textwrap

    from .._format import format_table
    from .._laws.listing import params_text

    table = [
        (
            r["name"],
            r["formula"],
            params_text(r) + (f" (or {', '.join(r['also'])})" if r["also"] else ""),
        )
        for r in rows
    ]
    notes = [f"engines: {r['engines']}; ref.: {r['reference']}" for r in rows]
    intro = (
        "Tangential laws (--tangential NAME --tparam ...): F_t in N on the sphere at its "
        "contact point, u its slip (m/s), delta the spring's stretch (m), x the overlap (m), "
        "m the sphere's mass (kg), R its radius (m)."
    )
    lines = format_table(
        ("name", "F_t [N]", "parameters"),
        table,
        width=width,
        wrap=(1, 2),
        notes=notes,
        note_column=1,
    )
    return [*textwrap.wrap(intro, width), "", *lines]
