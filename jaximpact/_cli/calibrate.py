"""`jaximpact calibrate`: fit a law's parameters to measured restitution and contact duration.

One impact from the flags (`--v0`, `--e`, `--T`), or one row per impact speed from
`--data FILE.csv` (columns `v0,e[,T,sigma_e,sigma_T]`, an empty cell a missing value).
`--law all` fits every law of the seed paper and ranks them (`jaximpact.compare_laws`).
Without start values (`--param`), each law starts from `jaximpact.starting_law` and then from
its nondimensional restitution table (`calibrate(..., init="auto")`).
"""

import math
from pathlib import Path

from .._choices import unknown_name
from .._files import read_table
from .._format import format_number, format_quantity, wrap_text
from .._interrupt import check_interrupt, set_note
from .._plotting import plot_fitted_speeds
from .._progress import metered
from .common import (
    LAW_HELP,
    MASS_HELP,
    CLIError,
    add_contact_arguments,
    add_free_argument,
    add_law_arguments,
    add_output_arguments,
    check_plot_path,
    command_parser,
    emit,
    file_law,
    free_names,
    heartbeat_meter,
    is_file_law,
    parse_params,
    require_mass,
)
from .laws import law_title, law_units

COLUMNS = ("v0", "e", "T", "sigma_e", "sigma_T")
ALL = "all"


def add_calibrate(subparsers):
    parser = command_parser(
        subparsers,
        "calibrate",
        help="fit a law's parameters to measured e (and T) at one or several impact speeds",
        description="Fit the parameters of the force law --law (stiffness c, damping b, b1 or "
        "a, dry force P ...) to a measured coefficient of restitution e and, if known, contact "
        "duration T of a body of mass --mass (kg): one impact at --v0 (m/s), or one row per "
        "impact speed from --data FILE.csv with columns v0,e[,T,sigma_e,sigma_T] (an empty "
        "cell is a missing value: a row may have e without T). --free names the parameters "
        "to fit (default: c when T is given, and the damping); --param gives start values "
        "(and the values of the parameters kept fixed); without them the start comes from "
        "the law's nondimensional restitution table. With sigmas the residuals are weighted "
        "and the standard errors of the parameters are printed. --law all fits every law of "
        "the seed paper and ranks them (by AIC with sigmas, else by the sum of squared "
        "residuals; --by evidence: by their evidence, with Bayes factors). The first fit of "
        "a law compiles it (10-30 s); later runs reuse JAX's persistent compilation cache.",
        example="jaximpact calibrate --law hertz_rate --mass 1 --v0 2.5 --e 0.85 --T 7.8e-3\n"
        "jaximpact calibrate --law kelvin_voigt --mass 1 --v0 2.5 --e 0.7 --T 2e-3 --free c,b "
        "--json\n"
        "jaximpact calibrate --law hertz_rate --mass 0.0027 --data drops.csv --plot fit.png\n"
        "jaximpact calibrate --law all --mass 0.0027 --data drops.csv --by evidence",
    )
    add_law_arguments(
        parser,
        law=f"{LAW_HELP}, or '{ALL}' to fit every law of the seed paper and rank them",
        param="start value of a parameter (or value of a fixed one), SI units, e.g. --param "
        "c=1e6 b1=100 (default: jaximpact.starting_law, then the law's restitution table "
        "where it has one)",
    )
    parser.add_argument("--mass", type=float, metavar="KG", help=MASS_HELP)
    parser.add_argument("--v0", type=float, metavar="M/S", help="impact speed, m/s (> 0)")
    parser.add_argument("--e", type=float, metavar="E", help="measured restitution, in (0, 1]")
    parser.add_argument("--T", type=float, metavar="S", help="measured contact duration, s")
    parser.add_argument(
        "--sigma-e", dest="sigma_e", type=float, metavar="SE", help="standard deviation of e"
    )
    parser.add_argument(
        "--sigma-T", dest="sigma_T", type=float, metavar="ST", help="standard deviation of T, s"
    )
    parser.add_argument(
        "--data",
        type=Path,
        metavar="FILE.csv",
        help="measurements, one impact speed per row: a header with v0,e and optionally "
        "T,sigma_e,sigma_T (SI units); instead of --v0/--e/--T",
    )
    add_free_argument(
        parser, "parameters to fit, e.g. --free c,b1 (default: c if T is given, and the damping)"
    )
    add_contact_arguments(parser)
    parser.add_argument(
        "--optimizer",
        choices=("auto", "lbfgs", "lm"),
        default="auto",
        help="auto (default): Levenberg-Marquardt driven from Python around one compiled "
        "program; lbfgs: optax L-BFGS inside the compiled fit (compiles longer)",
    )
    parser.add_argument(
        "--init",
        choices=("auto", "given"),
        help="start from the restitution table (auto) or from the --param values (given); "
        "default: given if --param names a fitted parameter, else auto",
    )
    parser.add_argument(
        "--max-iter", type=int, default=100, metavar="N", help="iteration limit (default 100)"
    )
    parser.add_argument(
        "--by",
        choices=("aic", "evidence"),
        default="aic",
        help="with --law all: rank by AIC (the default; by the sum of squared residuals "
        "without sigmas) or by the evidence, each law's marginal likelihood (the Laplace "
        "approximation of its posterior, default priors), printed with its Bayes factors",
    )
    add_posterior_arguments(parser)
    add_output_arguments(parser)
    parser.set_defaults(handler=run_calibrate)


def add_posterior_arguments(parser):
    """`--posterior [nuts|laplace]`, `--draws`, `--seed`, `--prior` (`jaximpact.posterior`)."""
    parser.add_argument(
        "--posterior",
        nargs="?",
        const="nuts",
        choices=("nuts", "laplace"),
        metavar="METHOD",
        help="also sample the posterior of the fitted parameters (jaximpact.posterior): "
        "'nuts' (the default; 4 chains) or 'laplace' (the Gaussian at the mode, fast); "
        "prints medians with 90 %% intervals and the diagnostics, --plot writes the pairs "
        "plot and the bands over the data, --json adds the posterior's summary and 200 of "
        "its draws (what 'jaximpact export --from' reads for the engine's band)",
    )
    parser.add_argument(
        "--draws",
        type=int,
        default=2000,
        metavar="N",
        help="with --posterior: draws per chain (default 2000, 4 chains)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        metavar="N",
        help="with --posterior: the random seed (default 0)",
    )
    parser.add_argument(
        "--prior",
        action="extend",
        nargs="+",
        default=[],
        metavar="NAME=KIND:A:B",
        help="with --posterior: a parameter's prior, SI units, KIND one of loguniform "
        "(A, B: the range), uniform, normal (mean, sd), lognormal (mu, sigma of ln x), e.g. "
        "--prior c=loguniform:1e5:1e8 (default: loguniform over three decades either side "
        "of the fitted value)",
    )


def posterior_options(args) -> dict | None:
    """The checked `--posterior` options (None without `--posterior`), before any fit:
    `method`, `draws`, `seed`, `prior` ({name: (kind, a, b)})."""
    from .._posterior.priors import parse_prior

    if args.posterior is None:
        given = [
            f
            for f, v in (
                ("--prior", args.prior),
                ("--draws", args.draws != 2000),
                ("--seed", args.seed != 0),
            )
            if v
        ]
        if given:
            raise CLIError(f"{' and '.join(given)} need --posterior")
        return None
    if args.draws < 1:
        raise CLIError(f"--draws must be at least 1, got {args.draws}")
    prior = {}
    for item in args.prior:
        name, sep, spec = item.partition("=")
        parts = spec.split(":")
        if not sep or not name.strip() or len(parts) != 3:
            raise CLIError(f"--prior {item!r} must be NAME=KIND:A:B, e.g. c=loguniform:1e5:1e8")
        name = name.strip()
        if name in prior:
            raise CLIError(f"--prior {name} is given twice")
        try:
            prior[name] = parse_prior(name, (parts[0], parts[1], parts[2])).as_tuple()
        except ValueError as error:
            raise CLIError(f"--prior {item!r}: {error}") from None
    return dict(method=args.posterior, draws=args.draws, seed=args.seed, prior=prior)


# the draws the JSON of a posterior holds: enough for the engine's band of `export --from`
JSON_DRAWS = 200


def sample_posterior(fit, options):
    """`(posterior, record)`: the posterior of `fit` (`jaximpact.posterior`) and its JSON
    record, `Posterior.to_dict(samples=False)` with `JSON_DRAWS` evenly thinned draws
    (`samples`, `z`) and `thinned` (how many, of how many); the statistics are those of
    all the draws."""
    import jax

    from .._posterior import posterior

    with metered(heartbeat_meter(), 1, f"posterior ({options['method']})") as bar:
        key = jax.random.key(options["seed"])
        post = posterior(
            fit,
            prior=options["prior"] or None,
            method=options["method"],
            num_samples=options["draws"],
            key=key,
        )
        bar.update(1, "done")
    record = post.to_dict(samples=False)
    rows = post.draw_indices(JSON_DRAWS)
    record["samples"] = {k: [float(x) for x in v[rows]] for k, v in post.samples.items()}
    record["z"] = [[float(x) for x in row] for row in post.z[rows]]
    record["thinned"] = {"draws": int(len(rows)), "of": post.num_draws}
    return post, record


# --------------------------------------------------------------------------- the data


def read_data(path: Path) -> dict:
    """`{column: [float, ...]}` from a CSV with a header naming some of `COLUMNS`; empty
    cells are NaN; blank lines and lines starting with `#` are skipped."""
    label, hint = f"--data {path}", "v0,e[,T,sigma_e,sigma_T]"
    header, rows = read_table(path, COLUMNS, label=label, hint=hint, needed=("v0", "e"))
    for line, values in rows:
        for name in ("v0", "e"):
            if math.isnan(values[name]):
                what = "impact speed" if name == "v0" else "restitution (T may be left empty)"
                raise CLIError(f"{label}, line {line}: no {name}; every row needs its {what}")
    if not rows:
        raise CLIError(f"{label} has a header but no rows")
    return {name: [values[name] for _, values in rows] for name in header}


def measurements(args) -> dict:
    """The rows to fit: `v0`, `e` (lists), `T`, `sigma_e`, `sigma_T` (lists or None; T
    NaN where a row has none, sigma_T 1 there)."""
    import numpy as np

    from .._fit.calibrate import check_targets
    from .._laws import LAWS

    flags = [f"--{k}" for k in ("v0", "e", "T") if getattr(args, k) is not None]
    flags += [
        f"--{k.replace('_', '-')}" for k in ("sigma_e", "sigma_T") if getattr(args, k) is not None
    ]
    if args.data is not None:
        if flags:
            raise CLIError(f"give either --data or {', '.join(flags)}, not both")
        columns = read_data(args.data)
    else:
        if args.v0 is None or args.e is None:
            raise CLIError("give --v0 and --e (and --T if measured), or --data FILE.csv")
        columns = {k: [getattr(args, k)] for k in COLUMNS if getattr(args, k, None) is not None}
    rows = len(columns["v0"])
    T = columns.get("T")
    if T is not None and all(math.isnan(t) for t in T):
        T = None
    sigma_e, sigma_T = columns.get("sigma_e"), columns.get("sigma_T")
    if sigma_e is not None and any(math.isnan(s) for s in sigma_e):
        raise CLIError("sigma_e is missing on some rows: give it on every row or on none")
    if sigma_T is not None:
        if T is None:
            raise CLIError("sigma_T is given without any T")
        if any(math.isnan(s) and not math.isnan(t) for s, t in zip(sigma_T, T, strict=True)):
            raise CLIError("sigma_T is missing on a row with a T: give both or neither")
        sigma_T = [1.0 if math.isnan(t) else s for s, t in zip(sigma_T, T, strict=True)]
    if T is not None and (sigma_e is None) != (sigma_T is None):
        raise CLIError(
            "the residuals are weighted by the sigmas: give sigma_e and sigma_T together "
            "(or neither) when T is measured"
        )
    if sigma_e is None and sigma_T is not None:
        raise CLIError("give sigma_e with sigma_T")
    check_targets(
        args.mass,
        np.asarray(columns["v0"]),
        np.asarray(columns["e"]),
        None if T is None else np.asarray(T),
        None if sigma_e is None else np.asarray(sigma_e),
        None if sigma_T is None else np.asarray(sigma_T),
        sticks=args.law in LAWS and LAWS[args.law].captures,  # e = 0: stuck, data
    )  # the library's own messages, before the start values need sane numbers
    return dict(v0=columns["v0"], e=columns["e"], T=T, sigma_e=sigma_e, sigma_T=sigma_T, rows=rows)


def _middle(data):
    """The row whose speed is the median (where the start values are computed)."""
    order = sorted(range(data["rows"]), key=lambda i: data["v0"][i])
    return order[data["rows"] // 2]


# ------------------------------------------------------------------------- running


def run_calibrate(args):
    check_plot_path(args.plot, inputs=[args.data])
    require_mass(args)
    if not (math.isfinite(args.mass) and args.mass > 0):
        raise CLIError(f"--mass must be a finite number > 0 kg, got {args.mass:g}")
    if args.max_iter < 1:
        raise CLIError("--max-iter must be at least 1")
    sampling = posterior_options(args)
    if args.by != "aic" and args.law != ALL:
        raise CLIError(f"--by {args.by} ranks the laws of --law all: give --law all")
    data = measurements(args)
    if args.law == ALL:
        if args.free or args.param:
            raise CLIError(
                "--law all chooses each law's free parameters and start itself: "
                "drop --free and --param"
            )
        if args.posterior is not None:
            raise CLIError(
                "--posterior takes one law: give --law NAME (the ranking of --law "
                "all has no posterior)"
            )
        return _run_all(args, data)
    return _run_one(args, data, sampling)


def _fit_kwargs(args, data):
    return dict(
        m=args.mass,
        v0=data["v0"],
        e=data["e"],
        T=data["T"],
        sigma_e=data["sigma_e"],
        sigma_T=data["sigma_T"],
        separation=args.separation,
        g=args.gravity,
        optimizer=args.optimizer,
        max_iter=args.max_iter,
    )


def _run_one(args, data, sampling=None):
    import jax

    from .._fit.calibrate import calibrate
    from .._fit.model_choice import starting_law
    from .._fit.parameters import default_free
    from .._laws import LAW_NAMES, LAWS

    given = parse_params(args.param)
    if is_file_law(args.law):  # a user's law starts from --param, all its parameters
        start = file_law(args.law, given)
    else:
        if args.law not in LAWS:
            raise CLIError(unknown_name("law", args.law, LAW_NAMES, also=ALL))
        row = _middle(data)
        T_row = None if data["T"] is None else data["T"][row]
        start = starting_law(
            args.law,
            m=args.mass,
            v0=data["v0"][row],
            e=data["e"][row],
            T=None if T_row is None or math.isnan(T_row) else T_row,
            **{k: given[k] for k in LAWS[args.law].geometry if k in given},  # JKR's radius
        )
        if given:
            start = start.replace(**given)
    free = free_names(args.free)
    fitted_names = free or default_free(start, stiffness=data["T"] is not None)
    init = args.init or ("given" if set(given) & set(fitted_names) else "auto")
    with metered(heartbeat_meter(), 1, f"calibrating {args.law}") as bar:
        fit = calibrate(start, free=free, init=init, **_fit_kwargs(args, data))
        jax.block_until_ready(fit)
        bar.update(1, "done")
    result = _fit_record(args.law, fit, data, order=tuple(start.parameters))
    result.update(
        m=args.mass,
        separation=args.separation,
        g=args.gravity,
        optimizer=fit.optimizer,  # the one that ran (auto: lm for an eager fit)
        init=init,
        start={k: float(v) for k, v in start.parameters.items()},
        given=sorted(given),
    )
    post = None
    if sampling is not None:
        post, result["posterior"] = sample_posterior(fit, sampling)
    if args.plot is not None:
        if post is None:
            _plot(args, data, [(args.law, fit)])
        else:  # the pairs plot and the bands over the data
            post.plot(args.plot)
        result["plot"] = str(args.plot)
    text = lambda: _one_text(result, data)  # noqa: E731
    if post is not None:
        text = lambda: _one_text(result, data) + "\n\n" + post.summary()  # noqa: E731
    emit(args, result, text)
    return 0


def _fit_record(name, fit, data, order=None):
    """What one fit of the law `name` found, for --json and the text: `Fit.to_dict()` with
    the law by its name, its parameters in its order (`order`: a user's law's as given; a
    law of the table has its own), `sum_sq`, `max_residual`, `goodness` and one row per
    speed (measured and fitted e and T, the sigmas, x_max and F_max)."""
    from .._fit.calibrate import goodness_text
    from .._laws import LAWS

    record = fit.to_dict()
    order = LAWS[name].parameters if name in LAWS else (order or fit.law.parameters)
    rows = []
    for i, v0 in enumerate(data["v0"]):
        T = record["T_target"][i]
        rows.append(
            dict(
                v0=v0,
                e=data["e"][i],
                e_fit=record["e"][i],
                T=T,
                T_fit=record["T"][i],
                sigma_e=None if data["sigma_e"] is None else data["sigma_e"][i],
                sigma_T=None if data["sigma_T"] is None or T is None else data["sigma_T"][i],
                x_max=record["x_max"][i],
                F_max=record["F_max"][i],
            )
        )
    return {
        **record,
        "law": name,
        "params": {k: record["params"][k] for k in order if k in record["params"]},
        "sum_sq": record["chi2"],
        "max_residual": float(fit.max_residual),
        "goodness": goodness_text(fit),
        "rows": rows,
    }


def _run_all(args, data):
    """`--law all`: every law of the seed paper fitted and ranked (`compare_laws`, by
    `--by`), a law whose fit fails reported beside the others' ranking."""
    from .._fit.model_choice import PAPER_LAWS, fits_badly
    from .._posterior.evidence import compare_laws

    failed, skipped, seen = {}, {}, []

    def note():  # what an interrupt says
        done = f"{len(seen)} of {len(PAPER_LAWS)} laws fitted"
        set_note(f"{done}, nothing written (the ranking is printed at the end)")

    def done(index, name, result):  # after each law: a safe point for Ctrl-C
        check_interrupt()  # also where JAX reported an interrupt as the fit's error
        seen.append(name)
        if isinstance(result, Exception):
            failed[index] = (name, f"{type(result).__name__}: {str(result).splitlines()[0]}")
        elif result is None:
            skipped[index] = name
        note()

    note()
    rankings = compare_laws(
        laws=PAPER_LAWS,
        by=args.by,
        progress=heartbeat_meter(),
        warn=False,
        errors="skip",
        callback=done,
        **_fit_kwargs(args, data),
    )
    set_note(None)
    failed = dict(failed[i] for i in sorted(failed))
    if not rankings:
        raise CLIError(
            "no law could be fitted: "
            + ("; ".join(f"{k}: {v}" for k, v in failed.items()) or "more parameters than data")
        )
    ranked = []
    for rank, item in enumerate(rankings, start=1):
        extra = {k: v for k, v in item.to_dict().items() if k not in ("name", "fit")}
        ranked.append({**_fit_record(item.name, item.fit, data), **extra, "rank": rank})
    n_data = len(data["e"]) + (
        0 if data["T"] is None else sum(not math.isnan(t) for t in data["T"])
    )
    weighted = data["sigma_e"] is not None
    result = dict(
        m=args.mass,
        separation=args.separation,
        g=args.gravity,
        optimizer=rankings[0].fit.optimizer,
        criterion="evidence" if args.by == "evidence" else "aic" if weighted else "sum_sq",
        bad_fit=fits_badly(rankings[0].fit),
        n_data=n_data,
        skipped=[skipped[i] for i in sorted(skipped)],
        failed=failed,
        best=ranked[0]["law"],
        ranking=ranked,
    )
    if args.plot is not None:
        _plot(args, data, [(r.name, r.fit) for r in rankings[:3]])
        result["plot"] = str(args.plot)
    table = rankings.table() if args.by == "evidence" else None
    emit(args, result, lambda: _all_text(result, data, table))
    return 0


# ---------------------------------------------------------------------------- text


def _params_text(name, params, stderr=None, indent=11):
    units = law_units(name, params)
    width = max(len(k) for k in params)
    lines = []
    for key, value in params.items():
        unit = units.get(key, "-")
        text = f"{key:<{width}} = {format_number(value)}" + (f" {unit}" if unit != "-" else "")
        if stderr and key in stderr:
            relative = abs(stderr[key] / value) if value else math.inf
            text += f"  +- {format_number(stderr[key], 3)} ({100 * relative:.2g}%)"
        lines.append(text)
    return ("\n" + " " * indent).join(lines)


def _rows_text(data, rows):
    has_T = data["T"] is not None
    header = ["v0 [m/s]", "e", "e fit"] + (["T", "T fit"] if has_T else ["T fit"])
    header += ["x_max fit", "F_max fit"]
    if data["sigma_e"] is not None:
        header.insert(2, "sigma_e")
    table = [header]
    for row in rows:
        cells = [format_number(row["v0"], 4), f"{row['e']:.4f}"]
        if data["sigma_e"] is not None:
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


def _status_text(record):
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


def _reproduces_text(record):
    tol = format_number(record["target_tol"])
    if record["weighted"]:
        meaning = f"{tol} standard deviations"
    else:
        meaning = f"{tol}, the data to numerical precision (no sigmas given)"
    if record["reproduces"]:
        return f"reproduces the data: every residual within {meaning}"
    largest = format_number(record["max_residual"], 3)
    return f"does not reproduce the data within {meaning}: largest residual {largest}"


def _sanity_text(record):
    """The sizes the fitted law implies at the measured speeds, with the mass and the
    kinetic energy: a mass typed in grams as kilograms shows as a force and an energy a
    thousand times too large, a time in ms as s as an absurd penetration."""
    m = record["m"]
    rows = sorted(record["rows"], key=lambda row: row["v0"])
    low, high = rows[0], rows[-1]

    def span(key, unit):
        values = sorted({row[key] for row in rows})
        if len(values) == 1:
            return format_quantity(values[0], unit)
        return f"{format_quantity(values[0], unit)} to {format_quantity(values[-1], unit)}"

    speeds = span("v0", "m/s")
    energy = (
        format_quantity(0.5 * m * low["v0"] ** 2, "J")
        if len(rows) == 1 or low["v0"] == high["v0"]
        else f"{format_quantity(0.5 * m * low['v0'] ** 2, 'J')} to "
        f"{format_quantity(0.5 * m * high['v0'] ** 2, 'J')}"
    )
    peak_g = max(row["F_max"] for row in rows) / (m * 9.80665)
    mass = f"{format_number(m * 1e3, 4)} g" if m < 1 else f"{format_number(m, 4)} kg"
    return (
        f"m = {mass}, kinetic energy "
        f"{energy} at v0 = {speeds}: the fitted law implies a penetration x_max of "
        f"{span('x_max', 'm')}, a peak force F_max of {span('F_max', 'N')} "
        f"(deceleration up to {format_number(peak_g, 3)} g) and a contact time of "
        f"{span('T_fit', 's')}: if these look wrong, check the units (--mass in kg)"
        + (
            " (c was not fitted: x_max, F_max and the contact time follow from its fixed value)"
            if "c" in record["params"] and "c" not in record["free"]
            else ""
        )
    )


def _one_text(result, data):
    fitted = {k: v for k, v in result["params"].items() if k in result["free"]}
    kept = {k: v for k, v in result["params"].items() if k not in result["free"]}
    rows = data["rows"]
    lines = [
        f"law        {law_title(result['law'])}",
        f"data       {rows} impact{'s' if rows > 1 else ''}, m = {format_number(result['m'])} kg, "
        f"separation by {result['separation']}"
        + (f", g = {format_number(result['g'])} m/s^2" if result["g"] else ""),
        f"fitted     {_params_text(result['law'], fitted, result['stderr'])}",
    ]
    if kept:
        given = [k for k in kept if k in result.get("given", ())]
        assumed = [k for k in kept if k not in given]
        why = []
        if given:
            why.append(f"{', '.join(given)} as given by --param")
        if assumed:
            origin = "jaximpact.starting_law's start value" + (
                ", which assumes T = 1 ms as no T was measured" if data["T"] is None else ""
            )
            why.append(f"{', '.join(assumed)}: {origin}")
        lines.append(f"fixed      {_params_text(result['law'], kept)}")
        why = f"(not fitted: {'; '.join(why)}; --param sets a value, --free fits it)"
        lines += wrap_text(why, 100, first=" " * 11)
    status = f"{_status_text(result)} ({result['optimizer']}, start {result['init']})"
    lines += wrap_text(
        f"{status}, loss {format_number(result['loss'], 3)}", 100, first="fit        "
    )
    lines += wrap_text(result["goodness"], 100, first="goodness   ")
    lines += wrap_text(_reproduces_text(result), 100, first=" " * 11)
    if result["stderr"] is not None:
        source = "the sigmas" if result["weighted"] else "the residuals' scatter (no sigmas given)"
        lines.append(f"           +- one standard error, from the Jacobian and {source}")
    lines += wrap_text(_sanity_text(result), 100, first="check      ")
    for note in result["notes"]:
        lines += wrap_text(note, 100, first="note       ")
    lines += ["", _rows_text(data, result["rows"])]
    if "plot" in result:
        lines.append(f"plot written to {result['plot']}")
    return "\n".join(lines)


def _all_text(result, data, evidence=None):
    """The ranking as a table; `evidence`: the Bayes factors' (`--by evidence`)."""
    weighted = result["ranking"][0]["weighted"]
    by = (
        "AIC = chi2 + 2k (chi2: the sum of squared normalised residuals)"
        if weighted
        else "sum_sq, the sum of squared residuals e_fit - e and (T_fit - T)/T (no sigmas)"
    )
    if evidence is not None:
        by = "the evidence, each law's marginal likelihood (Laplace at the mode)"
    lines = [
        f"model choice: {result['n_data']} measurements at {data['rows']} speed"
        f"{'s' if data['rows'] > 1 else ''}, m = {format_number(result['m'])} kg; "
        f"ranked by {by}",
        "",
    ]
    has_T = data["T"] is not None
    if weighted:
        header = ["rank", "law", "k", "chi2", "chi2/dof", "AIC", "BIC", "converged"]
    else:
        header = ["rank", "law", "k", "sum_sq", "rms_e"] + (["rms_T"] if has_T else [])
        header += ["converged"]
    header += ["parameters"]
    table = [header]

    def number(value, digits):
        return "-" if value is None else format_number(value, digits)

    for r in result["ranking"]:
        params = ", ".join(f"{k} = {format_number(v, 4)}" for k, v in r["params"].items())
        cells = [str(r["rank"]), r["law"], str(r["k"]), format_number(r["sum_sq"], 3)]
        if weighted:
            cells += [number(r["reduced_chi2"], 3), number(r["aic"], 4), number(r["bic"], 4)]
        else:
            cells.append(number(r["rms_e"], 3))
            if has_T:
                cells.append("-" if r["rms_T"] is None else f"{100 * r['rms_T']:.3g}%")
        cells += ["yes" if r["converged"] else "no", params]
        table.append(cells)
    widths = [max(len(line[i]) for line in table) for i in range(len(header) - 1)]
    for line in table:
        cells = [c.ljust(w) for c, w in zip(line[:-1], widths, strict=True)]
        lines.append("  ".join(cells) + "  " + line[-1])
    lines.append("")
    meaning = (
        "chi2/dof: reduced chi-square, about 1 for a law that fits within the sigmas"
        if weighted
        else "rms_e: RMS of e_fit - e" + ("; rms_T: RMS of (T_fit - T)/T" if has_T else "")
    )
    lines.append(f"  {meaning}; converged: the optimiser reached a minimum")
    lines += ["", evidence, ""] if evidence is not None else [""]
    lines.append(f"best: {result['best']}")
    if result["bad_fit"]:
        lines.append(
            f"warning: the best law, {result['best']}, fits these data badly: "
            f"{result['bad_fit']}; no law tried describes them"
        )
    k_max = max(r["k"] for r in result["ranking"])
    if result["n_data"] <= k_max:
        lines.append(
            f"note: {result['n_data']} measurements for up to {k_max} free parameters: a law "
            "that fits them exactly is not thereby supported; measure more speeds"
        )
    for name, message in result["failed"].items():
        lines.append(f"failed: {name} ({message})")
    if result["skipped"]:
        lines.append(f"skipped (more free parameters than data): {', '.join(result['skipped'])}")
    if "plot" in result:
        lines.append(f"plot written to {result['plot']}")
    return "\n".join(lines)


# ---------------------------------------------------------------------------- plot


def _curve(fit, args, speeds):
    """e and T (NaN where the body does not separate) of a fitted law at `speeds`."""
    from .._solve.impact import impact
    from .._status import Status

    es, Ts = [], []
    for v in speeds:
        r = impact(
            fit.law,
            m=args.mass,
            v0=float(v),
            separation=args.separation,
            g=args.gravity,
            peaks=False,
        )
        ok = int(r.status) == Status.separated
        es.append(float(r.e) if ok else math.nan)
        Ts.append(float(r.T) if ok else math.nan)
    return es, Ts


def _plot(args, data, fits):
    """e (and T) against the impact speed: the data, with error bars from the sigmas, and
    the fitted curve of each law of `fits` (name, Fit)."""
    import numpy as np

    v0 = np.asarray(data["v0"])
    low, high = (
        (v0.min() / 3, v0.max() * 3) if np.ptp(v0) == 0 else (v0.min() / 1.5, v0.max() * 1.5)
    )
    speeds = np.geomspace(low, high, 41)
    curves = [(name, *_curve(fit, args, speeds)) for name, fit in fits]
    names = ", ".join(name for name, _ in fits)
    title = f"{names} fitted; m = {format_number(args.mass)} kg, separation by {args.separation}"
    plot_fitted_speeds(args.plot, data, speeds, curves, title)
