"""`jaximpact simulate`: one impact, its e, T, x_max, F_max, ... and a figure."""

import math

from .._format import format_number
from .._plotting import new_figure, plot_speed_sweep, save_figure
from .common import (
    MASS_HELP,
    CLIError,
    add_contact_arguments,
    add_law_arguments,
    add_output_arguments,
    check_plot_path,
    command_parser,
    emit,
    law_from_args,
    parse_params,
    require_mass,
)
from .oblique import add_oblique_impact_arguments, check_oblique_arguments, run_oblique_impact


def add_simulate(subparsers):
    parser = command_parser(
        subparsers,
        "simulate",
        help="integrate one impact (or a sweep of speeds) and print e, T, x_max, F_max, ...",
        description="Integrate one impact of a body of mass --mass (kg) hitting the surface "
        "at --v0 (m/s) under the force law --law with parameters --param (SI units, see "
        "'jaximpact laws'), and print the coefficient of restitution e, the contact "
        "duration T, the maximum penetration x_max and when it is reached (t_max), the "
        "largest force F_max, the energy dissipated and how the contact ended. Several "
        "speeds (--v0 0.5 1 2 4) give a sweep: one row per speed with units in the header "
        "(--json: a list of the one-speed objects; --plot: e and T against v0).",
        example="jaximpact simulate --law hertz_rate --param c=2e6 --param b1=800 --v0 2.5 "
        "--mass 1\n"
        "jaximpact simulate --law kelvin_voigt --param c=2e6 b=400 --mass 1 --v0 2.5 "
        "--separation penetration --json\n"
        "jaximpact simulate --law bingham --param c=2e6 b=200 P=400 --v0 2.5 --mass 1 --plot "
        "bingham.png\n"
        "jaximpact simulate --law hertz_rate --param c=2e6 b1=800 --mass 1 --v0 0.5 1 2 4",
    )
    add_law_arguments(parser)
    parser.add_argument("--mass", type=float, metavar="KG", help=MASS_HELP)
    parser.add_argument(
        "--v0",
        type=float,
        nargs="+",
        required=True,
        metavar="M/S",
        help="impact speed, m/s (> 0); several for a sweep of e(v0), T(v0)",
    )
    add_contact_arguments(parser)
    add_output_arguments(parser)
    add_oblique_impact_arguments(parser)
    parser.set_defaults(handler=_run_simulate)


def _run_simulate(args):
    check_plot_path(args.plot)
    import numpy as np

    from .._laws.scales import check_contact_scales
    from .._solve.impact import impact
    from .._solve.results import impact_record, impact_text, sweep_text

    check_oblique_arguments(args)
    law = law_from_args(args)
    speeds = list(args.v0)
    for v0 in speeds:  # every speed checked before any work
        if not (math.isfinite(v0) and v0 > 0):
            raise CLIError(f"--v0 {v0:g}: the impact speed v0 must be a finite number > 0 (m/s)")
    require_mass(args)  # after the law and the speeds: their mistakes are told first
    for v0 in speeds:
        check_contact_scales(args.law, parse_params(args.param), args.mass, v0)
    if args.tangential is not None:
        return run_oblique_impact(args, law, _head(law))
    runs = []
    for v0 in speeds:
        conditions = dict(m=args.mass, v0=v0, separation=args.separation, g=args.gravity)
        result = impact(law, **conditions)
        runs.append(impact_record(law, result, **conditions))
    if len(runs) > 1:
        if args.plot is not None:
            title = f"{law.name}, m = {format_number(runs[0]['m'])} kg"
            e, T = ([float(r[k]) for r in runs] for k in ("e", "T"))
            plot_speed_sweep(args.plot, [r["v0"] for r in runs], e, T, title)
            for data in runs:
                data["plot"] = str(args.plot)
        emit(args, runs, lambda: sweep_text(runs, _head(law)))
        return 0
    (data,) = runs
    if args.plot is not None:
        from .._plotting import plot_impact

        ts = np.linspace(0.0, 1.05 * float(data["T"]), 600)
        history = impact(law, **conditions, ts=ts)  # the one speed's
        fig = new_figure(figsize=(13.5, 4.2), layout="constrained")
        plot_impact(history, law, fig=fig)
        save_figure(fig, args.plot)
        data["plot"] = str(args.plot)
    emit(args, data, lambda: impact_text(result, data, _head(law)))
    return 0


def _head(law) -> list[str]:
    """The law with its equation, and its parameters with their units."""
    from .._laws.listing import law_title, law_units

    units = law_units(law)
    params = ", ".join(
        f"{k} = {format_number(v)}" + (f" {units[k]}" if units.get(k) else "")
        for k, v in law.parameters.items()
    )
    return [f"law        {law_title(law.name)}", f"params     {params}"]
