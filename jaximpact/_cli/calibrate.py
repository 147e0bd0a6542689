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
from .._fit.measurements import COLUMNS, measured, read_measurements
from .._interrupt import check_interrupt, set_note
from .._progress import metered
from .common import (
    LAW_HELP,
    MASS_HELP,
    CLIError,
    add_contact_arguments,
    add_free_argument,
    add_law_arguments,
    add_output_arguments,
    add_words_argument,
    check_plot_path,
    command_parser,
    emit,
    free_names,
    heartbeat_meter,
    parse_params,
    require_mass,
)

ALL = "all"


def add_calibrate(subparsers):
    parser = command_parser(
        subparsers,
        "calibrate",
        help="fit a law's parameters to measured e (and T) at one or several impact speeds",
        description="Fit the parameters of the force law --law (stiffness c, damping b, b1 or "
        "a, dry force P ...) to a measured coefficient of restitution e and, if known, contact "
        "duration T of a body of mass --mass (kg): one impact at --v0 (m/s), or one row per "
        "impact speed from --data FILE.csv with columns v0,e[,T,sigma_e,sigma_T] in SI units, "
        "or in those its header gives ('T (ms)', 'v0 [mm/s]'); an empty cell is a missing "
        "value: a row may have e without T. --free names the parameters "
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
    add_words_argument(
        parser,
        "--prior",
        "NAME=KIND:A:B",
        "with --posterior: a parameter's prior, SI units, KIND one of loguniform "
        "(A, B: the range), uniform, normal (mean, sd), lognormal (mu, sigma of ln x), e.g. "
        "--prior c=loguniform:1e5:1e8 (default: loguniform over three decades either side "
        "of the fitted value)",
    )


def posterior_options(args) -> dict | None:
    """The checked `--posterior` options (None without `--posterior`), before any fit:
    `posterior`'s `method`, `num_samples` and `prior` ({name: (kind, a, b)}, or None), and
    the random `seed`."""
    if args.posterior is None:
        flags = {"--prior": args.prior, "--draws": args.draws != 2000, "--seed": args.seed != 0}
        given = [flag for flag, v in flags.items() if v]
        if given:
            raise CLIError(f"{' and '.join(given)} need --posterior")
        return None
    if args.draws < 1:
        raise CLIError(f"--draws must be at least 1, got {args.draws}")
    from .._posterior.command import priors_from_words  # blackjax: only with --posterior

    prior = priors_from_words(args.prior)  # checked before any fit
    return dict(method=args.posterior, num_samples=args.draws, seed=args.seed, prior=prior or None)


def sample_posterior(fit, sampling):
    """`(posterior, record)`: the posterior of `fit` (`jaximpact.posterior`) and its JSON
    record with its draws thinned (`_posterior.command.thinned_record`)."""
    import jax

    from .._posterior.command import thinned_record
    from .._posterior.posterior import posterior

    with metered(heartbeat_meter(), 1, f"posterior ({sampling['method']})") as bar:
        options = {k: v for k, v in sampling.items() if k != "seed"}
        post = posterior(fit, **options, key=jax.random.key(sampling["seed"]))
        bar.update(1, "done")
    return post, thinned_record(post)


# --------------------------------------------------------------------------- the data


def read_data(path: Path) -> dict:
    """`{column: [float, ...]}` of the CSV `--data path` (`_fit.measurements`)."""
    return read_measurements(path, label=f"--data {path}")


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
    data = measured(columns)
    check_targets(
        args.mass,
        np.asarray(data["v0"]),
        np.asarray(data["e"]),
        *(None if data[k] is None else np.asarray(data[k]) for k in ("T", "sigma_e", "sigma_T")),
        sticks=args.law in LAWS and LAWS[args.law].captures,  # e = 0: stuck, data
    )  # the library's own messages, before the start values need sane numbers
    return data


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
    from .._fit.report import fit_record, fit_text
    from .._jobs.file_law import file_law, is_file_law
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
    result = fit_record(args.law, fit, order=tuple(start.parameters))
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

    def text():  # the posterior's summary under the fit's
        return fit_text(fit, result) + ("" if post is None else "\n\n" + post.summary())

    emit(args, result, text)
    return 0


def _run_all(args, data):
    """`--law all`: every law of the seed paper fitted and ranked (`compare_laws`, by
    `--by`), a law whose fit fails reported beside the others' ranking."""
    from .._fit.model_choice import PAPER_LAWS, fits_badly
    from .._fit.report import fit_record, ranking_text
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
        ranked.append({**fit_record(item.name, item.fit), **extra, "rank": rank})
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
    emit(args, result, lambda: ranking_text(result, table))
    return 0


def _plot(args, data, fits):
    from .._fit.report import plot_calibration

    plot_calibration(args.plot, data, fits, m=args.mass, separation=args.separation, g=args.gravity)
