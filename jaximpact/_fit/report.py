"""A calibration as `jaximpact calibrate` reports it: one law's record (`fit_record`,
`Fit.to_dict()` with the law by its name and one row per speed) and its text (`fit_text`),
the text of a ranking of laws (`ranking_text`), the figure of the fitted curves over the
data (`plot_calibration`), and a fit read back from that JSON (`fit_from_json`). The text
is rendered from the record alone, so that the words and `--json` give the same numbers."""

import math

from .._format import (
    KEEP_TOGETHER,
    format_number,
    format_quantity,
    format_table,
    terminal_width,
    wrap_text,
)
from .._laws.listing import law_title, law_units
from .calibrate import goodness_text

# the column of the labels of `fit_text`'s lines, and the width it wraps them to
_LABEL, _WIDTH = 11, 100
# the narrowest a ranking's table is wrapped to
_RANKING_WIDTH = 120


def fit_record(name: str, fit, order=None) -> dict:
    """What one fit (`Fit`, concrete) of the law `name` found: `Fit.to_dict()` with the law
    by its name, its parameters in its order (`order`: a user's law's as given; a law of
    the table has its own), `sum_sq`, `max_residual`, `goodness` and one row per speed
    (measured and fitted e and T, the sigmas, x_max and F_max)."""
    from .._laws import LAWS

    record = fit.to_dict()
    order = LAWS[name].parameters if name in LAWS else (order or fit.law.parameters)
    sigma_e, sigma_T = (
        None if s is None else [float(x) for x in s] for s in (fit.sigma_e, fit.sigma_T)
    )
    rows = [
        dict(
            v0=v0,
            e=record["e_target"][i],
            e_fit=record["e"][i],
            T=record["T_target"][i],
            T_fit=record["T"][i],
            sigma_e=None if sigma_e is None else sigma_e[i],
            sigma_T=None if sigma_T is None or record["T_target"][i] is None else sigma_T[i],
            x_max=record["x_max"][i],
            F_max=record["F_max"][i],
        )
        for i, v0 in enumerate(record["v0"])
    ]
    return {
        **record,
        "law": name,
        "params": {k: record["params"][k] for k in order if k in record["params"]},
        "sum_sq": record["chi2"],
        "max_residual": float(fit.max_residual),
        "goodness": goodness_text(fit),
        "rows": rows,
    }


def _params_text(law, params, stderr=None) -> str:
    """Each parameter of `params` with its unit (`law_units`) and standard error, one a line."""
    units = law_units(law)
    width = max(len(k) for k in params)
    lines = []
    for key, value in params.items():
        unit = units.get(key, "")
        text = f"{key:<{width}} = {format_number(value)}" + (f" {unit}" if unit else "")
        if stderr and key in stderr:
            relative = abs(stderr[key] / value) if value else math.inf
            text += f"  +- {format_number(stderr[key], 3)} ({100 * relative:.2g}%)"
        lines.append(text)
    return ("\n" + " " * _LABEL).join(lines)


def _rows_text(rows) -> str:
    """The measured and fitted e and T at each speed, with the x_max and F_max implied."""
    has_T = any(row["T"] is not None for row in rows)
    has_sigma = rows[0]["sigma_e"] is not None
    header = ["v0 [m/s]", "e", "e fit"] + (["T", "T fit"] if has_T else ["T fit"])
    header += ["x_max fit", "F_max fit"]
    if has_sigma:
        header.insert(2, "sigma_e")
    table = [header]
    for row in rows:
        cells = [format_number(row["v0"], 4), f"{row['e']:.4f}"]
        if has_sigma:
            cells.append(format_number(row["sigma_e"], 3))
        cells.append(f"{row['e_fit']:.4f}")
        if has_T:
            cells.append("-" if row["T"] is None else format_quantity(row["T"], "s"))
        cells.append(format_quantity(row["T_fit"], "s"))
        cells += [format_quantity(row["x_max"], "m"), format_quantity(row["F_max"], "N")]
        table.append(cells)
    widths = [max(len(line[i]) for line in table) for i in range(len(header))]
    return "\n".join(
        "  " + "  ".join(c.rjust(w) for c, w in zip(line, widths, strict=True)) for line in table
    )


def _status_text(record) -> str:
    """Whether the optimiser converged, after how many iterations, and what is undetermined."""
    if record["converged"]:
        text = f"optimiser converged after {record['iterations']} iterations"
        if record["iterations"] == 0:
            text += ", the start solving the equations"
    else:
        text = (
            f"optimiser NOT converged after {record['iterations']} iterations (or an impact "
            "of the fitted law does not separate): the best point reached is shown"
        )
    if record.get("undetermined"):
        text += (
            f"; {' and '.join(record['undetermined'])} NOT determined by these data (give T, "
            "more speeds, or hold one with --free): their values are not estimates"
        )
    return text


def _reproduces_text(record) -> str:
    """Whether every residual is within `target_tol`, and what that tolerance means."""
    tol = format_number(record["target_tol"])
    if record["weighted"]:
        meaning = f"{tol} standard deviations"
    else:
        meaning = f"{tol}, the data to numerical precision (no sigmas given)"
    if record["reproduces"]:
        return f"reproduces the data: every residual within {meaning}"
    largest = format_number(record["max_residual"], 3)
    return f"does not reproduce the data within {meaning}: largest residual {largest}"


def _span(rows, key, unit) -> str:
    """`key`'s least and largest value over `rows` with its unit (one value if they agree)."""
    values = sorted({row[key] for row in rows})
    if len(values) == 1:
        return format_quantity(values[0], unit)
    return f"{format_quantity(values[0], unit)} to {format_quantity(values[-1], unit)}"


def _sanity_text(record) -> str:
    """The sizes the fitted law implies at the measured speeds, with the mass and the
    kinetic energy: a mass typed in grams as kilograms shows as a force and an energy a
    thousand times too large, a time in ms as s as an absurd penetration."""
    m, rows = record["m"], record["rows"]
    energies = [{"E": 0.5 * m * row["v0"] ** 2} for row in rows]
    peak_g = max(row["F_max"] for row in rows) / (m * 9.80665)
    mass = f"{format_number(m * 1e3, 4)} g" if m < 1 else f"{format_number(m, 4)} kg"
    fixed_c = "c" in record["params"] and "c" not in record["free"]
    return (
        f"m = {mass}, kinetic energy {_span(energies, 'E', 'J')} at v0 = "
        f"{_span(rows, 'v0', 'm/s')}: the fitted law implies a penetration x_max of "
        f"{_span(rows, 'x_max', 'm')}, a peak force F_max of {_span(rows, 'F_max', 'N')} "
        f"(deceleration up to {format_number(peak_g, 3)} g) and a contact time of "
        f"{_span(rows, 'T_fit', 's')}: if these look wrong, check the units (--mass in kg)"
        + (
            " (c was not fitted: x_max, F_max and the contact time follow from its fixed value)"
            if fixed_c
            else ""
        )
    )


def _labelled(label: str, text: str) -> list[str]:
    """`text` wrapped after `label` (padded to the labels' column), the rest aligned."""
    return wrap_text(text, _WIDTH, first=f"{label:<{_LABEL}}")


def fit_text(fit, record) -> str:
    """One law's calibration as text: the law, the data, the fitted and fixed parameters
    (with units and standard errors), the optimiser, the goodness of fit, the sizes the law
    implies (`check`), the notes and a row per speed; `record`: `fit_record(...)` with
    `m`, `separation`, `g`, `optimizer`, `init` and `given` (the names set by `--param`)."""
    fitted = {k: v for k, v in record["params"].items() if k in record["free"]}
    kept = {k: v for k, v in record["params"].items() if k not in record["free"]}
    rows = len(record["rows"])
    lines = [
        f"law        {law_title(record['law'])}",
        f"data       {rows} impact{'s' if rows > 1 else ''}, m = {format_number(record['m'])} kg, "
        f"separation by {record['separation']}"
        + (f", g = {format_number(record['g'])} m/s^2" if record["g"] else ""),
        f"fitted     {_params_text(fit.law, fitted, record['stderr'])}",
    ]
    if kept:
        given = [k for k in kept if k in record.get("given", ())]
        assumed = [k for k in kept if k not in given]
        why = []
        if given:
            why.append(f"{', '.join(given)} as given by --param")
        if assumed:
            no_T = all(row["T"] is None for row in record["rows"])
            origin = "jaximpact.starting_law's start value" + (
                ", which assumes T = 1 ms as no T was measured" if no_T else ""
            )
            why.append(f"{', '.join(assumed)}: {origin}")
        lines.append(f"fixed      {_params_text(fit.law, kept)}")
        why = f"(not fitted: {'; '.join(why)}; --param sets a value, --free fits it)"
        lines += _labelled("", why)
    status = f"{_status_text(record)} ({record['optimizer']}, start {record['init']})"
    lines += _labelled("fit", f"{status}, loss {format_number(record['loss'], 3)}")
    lines += _labelled("goodness", record["goodness"])
    lines += _labelled("", _reproduces_text(record))
    if record["stderr"] is not None:
        source = "the sigmas" if record["weighted"] else "the residuals' scatter (no sigmas given)"
        lines.append(f"           +- one standard error, from the Jacobian and {source}")
    lines += _labelled("check", _sanity_text(record))
    for note in record["notes"]:
        lines += _labelled("note", note)
    lines += ["", _rows_text(record["rows"])]
    if "plot" in record:
        lines.append(f"plot written to {record['plot']}")
    return "\n".join(lines)


def ranking_text(result, evidence=None) -> str:
    """The ranking of `jaximpact calibrate --law all` (`result`: its JSON record, each
    law's `fit_record` in `ranking`) as a table, the best law and what failed;
    `evidence`: the Bayes factors' table (`--by evidence`)."""
    ranking = result["ranking"]
    weighted = ranking[0]["weighted"]
    rows = ranking[0]["rows"]
    has_T = any(row["T"] is not None for row in rows)
    by = (
        "AIC = chi2 + 2k (chi2: the sum of squared normalised residuals)"
        if weighted
        else "sum_sq, the sum of squared residuals e_fit - e and (T_fit - T)/T (no sigmas)"
    )
    if evidence is not None:
        by = "the evidence, each law's marginal likelihood (Laplace at the mode)"
    lines = [
        f"model choice: {result['n_data']} measurements at {len(rows)} speed"
        f"{'s' if len(rows) > 1 else ''}, m = {format_number(result['m'])} kg; "
        f"ranked by {by}",
        "",
    ]
    if weighted:
        header = ["rank", "law", "k", "chi2", "chi2/dof", "AIC", "BIC"]
    else:
        header = ["rank", "law", "k", "sum_sq", "rms_e"] + (["rms_T"] if has_T else [])
    header += ["converged", "parameters"]

    def number(value, digits):
        return "-" if value is None else format_number(value, digits)

    table = []
    for r in ranking:
        params = ", ".join(
            f"{k} = {format_number(v, 4)}".replace(" ", KEEP_TOGETHER)
            for k, v in r["params"].items()
        )
        cells = [str(r["rank"]), r["law"], str(r["k"]), format_number(r["sum_sq"], 3)]
        if weighted:
            cells += [number(r["reduced_chi2"], 3), number(r["aic"], 4), number(r["bic"], 4)]
        else:
            cells.append(number(r["rms_e"], 3))
            if has_T:
                cells.append("-" if r["rms_T"] is None else f"{100 * r['rms_T']:.3g}%")
        table.append([*cells, "yes" if r["converged"] else "no", params])
    # one line per law where the terminal allows, and at least as wide as the command
    # printed it before the table came from `format_table` (a pipe counts 88 columns)
    width = max(terminal_width(), _RANKING_WIDTH)
    lines += format_table(header, table, width=width, wrap=(len(header) - 1,))
    meaning = (
        "chi2/dof: reduced chi-square, about 1 for a law that fits within the sigmas"
        if weighted
        else "rms_e: RMS of e_fit - e" + ("; rms_T: RMS of (T_fit - T)/T" if has_T else "")
    )
    lines += ["", f"  {meaning}; converged: the optimiser reached a minimum"]
    lines += ["", evidence, ""] if evidence is not None else [""]
    lines.append(f"best: {result['best']}")
    if result["bad_fit"]:
        lines.append(
            f"warning: the best law, {result['best']}, fits these data badly: "
            f"{result['bad_fit']}; no law tried describes them"
        )
    k_max = max(r["k"] for r in ranking)
    if result["n_data"] <= k_max:
        lines.append(
            f"note: {result['n_data']} measurements for up to {k_max} free parameters: a law "
            "that fits them exactly is not thereby supported; measure more speeds"
        )
    lines += [f"failed: {name} ({message})" for name, message in result["failed"].items()]
    if result["skipped"]:
        lines.append(f"skipped (more free parameters than data): {', '.join(result['skipped'])}")
    if "plot" in result:
        lines.append(f"plot written to {result['plot']}")
    return "\n".join(lines)


def _curve(law, speeds, **conditions):
    """e and T (NaN where the body does not separate) of `law` at `speeds` (m/s)."""
    from .._solve.impact import impact
    from .._status import Status

    es, Ts = [], []
    for v in speeds:
        r = impact(law, v0=float(v), peaks=False, **conditions)
        ok = int(r.status) == Status.separated
        es.append(float(r.e) if ok else math.nan)
        Ts.append(float(r.T) if ok else math.nan)
    return es, Ts


def plot_calibration(path, data, fits, *, m: float, separation: str, g: float):
    """e (and T) against the impact speed, written to `path`: the measured `data` (`v0`,
    `e`, `T`, `sigma_e`, `sigma_T`: lists or None), with error bars from the sigmas, and
    the curve of each fitted law of `fits` (`(name, Fit)`) for mass `m` (kg)."""
    import numpy as np

    from .._plotting import plot_fitted_speeds

    v0 = np.asarray(data["v0"])
    low, high = (
        (v0.min() / 3, v0.max() * 3) if np.ptp(v0) == 0 else (v0.min() / 1.5, v0.max() * 1.5)
    )
    speeds = np.geomspace(low, high, 41)
    conditions = dict(m=m, separation=separation, g=g)
    curves = [(name, *_curve(fit.law, speeds, **conditions)) for name, fit in fits]
    names = ", ".join(name for name, _ in fits)
    title = f"{names} fitted; m = {format_number(m)} kg, separation by {separation}"
    plot_fitted_speeds(path, data, speeds, curves, title)


def fit_from_json(data, law: str | None = None, *, source: str, user_law=None):
    """`(record, fit)`: the one fit in `data`, the JSON object that `jaximpact calibrate
    --json` writes (one law; of `--law all`'s ranking its best, or the law `law` names,
    with the ranking's `m`, `g` and `separation`), and that fit read back (`Fit.from_dict`;
    `user_law(name)`: None for a law of the table, else what builds the user's law from
    its parameters). What is no such fit is a one-line `ValueError` naming `--from source`."""
    from .._laws.custom import LawFileError
    from .calibrate import Fit

    where = f"--from {source}"
    if not isinstance(data, dict):
        raise ValueError(f"{where}: expected the JSON object of 'jaximpact calibrate --json'")
    record = data
    if isinstance(data.get("ranking"), list):  # calibrate --law all: its m, g, separation
        ranked = {r.get("law"): {**data, **r} for r in data["ranking"] if isinstance(r, dict)}
        wanted = law if law is not None else data.get("best", next(iter(ranked), None))
        if wanted not in ranked:
            raise ValueError(
                f"{where}: its ranking has no law {wanted!r}; it has {', '.join(map(str, ranked))}"
            )
        record = ranked[wanted]
    name = record.get("law")
    if law is not None and law != name and isinstance(name, str):
        raise ValueError(f"--law {law} but {source} holds a fit of {name}")
    try:
        return record, Fit.from_dict(record, law=None if user_law is None else user_law(name))
    except LawFileError:  # its own one line, as `--law FILE.py:NAME` says it
        raise
    except ValueError as error:
        raise ValueError(f"{where}: {error}") from None
