"""`jaximpact simulate`: one impact, its e, T, x_max, F_max, ... and a figure."""

import math
import textwrap

from .._format import format_number, format_table, terminal_width
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

# --------------------------------------------------------------------------------------
# jaximpact simulate
# --------------------------------------------------------------------------------------

_STATUS_NOTES = {
    "stuck": "a dry force held the body at rest inside the surface (e = 0); T is when it stopped",
    "captured": "the body never left the surface (e = 0); T is when the solve gave up",
    "out_of_steps": "the solver ran out of steps before the contact ended; "
    "the numbers are not to be trusted",
}


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
        data = {
            "law": law.name,
            "params": {k: float(v) for k, v in law.parameters.items()},
            "m": args.mass,
            "v0": v0,
            "separation": args.separation,
            "g": args.gravity,
            **result.to_dict(),
        }
        data["units"] = {k: u or "-" for k, u in _result_units().items()}
        runs.append(data)
    if len(runs) > 1:
        if args.plot is not None:
            title = f"{law.name}, m = {format_number(runs[0]['m'])} kg"
            e, T = ([float(r[k]) for r in runs] for k in ("e", "T"))
            plot_speed_sweep(args.plot, [r["v0"] for r in runs], e, T, title)
            for data in runs:
                data["plot"] = str(args.plot)
        emit(args, runs, lambda: _sweep_text(law, runs))
        return 0
    (data,) = runs
    if args.plot is not None:
        from .._plotting import plot_impact

        conditions = dict(m=args.mass, v0=data["v0"], separation=args.separation, g=args.gravity)
        ts = np.linspace(0.0, 1.05 * float(data["T"]), 600)
        history = impact(law, **conditions, ts=ts)
        fig = new_figure(figsize=(13.5, 4.2), layout="constrained")
        plot_impact(history, law, fig=fig)
        save_figure(fig, args.plot)
        data["plot"] = str(args.plot)
    emit(args, data, lambda: _simulate_text(law, data, result))
    return 0


def _result_units() -> dict[str, str]:
    """The impact's fields and their units as `ImpactResult` shows them (its `_SHOWN`),
    in its order; the solver's steps are said with the path."""
    from .._solve.results import _SHOWN

    return {name: unit for name, unit in _SHOWN if unit is not None}


def _head(law) -> list[str]:
    """The law with its equation, and its parameters with their units."""
    from .._fit.calibrate import law_units
    from .._fit.report import law_title

    units = law_units(law)
    params = ", ".join(
        f"{k} = {format_number(v)}" + (f" {units[k]}" if units.get(k) else "")
        for k, v in law.parameters.items()
    )
    return [f"law        {law_title(law.name)}", f"params     {params}"]


def _sweep_text(law, runs, width=None) -> str:
    """A sweep: the law and conditions, then one row per speed (SI units in the header),
    fitted to the terminal (`_format.format_table`)."""
    first = runs[0]
    lines = [
        *_head(law),
        f"impact     m = {format_number(first['m'])} kg, g = {format_number(first['g'])} "
        f"m/s^2, separation by {first['separation']}",
        "",
    ]
    units = _result_units()
    keys = [k for k in units if first[k] is not None and k != "v_out"]  # v_out = -e v0
    header = ["v0 (m/s)", *(f"{k} ({units[k]})" if units[k] else k for k in keys)]
    # status and path as columns where they change with the speed, else said once
    varying = [k for k in ("status", "path") if len({r[k] for r in runs}) > 1]
    header += varying
    rows = [
        [format_number(r["v0"]), *(f"{float(r[k]):.5g}" for k in keys), *(r[k] for k in varying)]
        for r in runs
    ]
    lines += format_table(header, rows, width=width)
    same = [f"{k} {first[k]}" for k in ("status", "path") if k not in varying]
    if same:
        lines.append(f"at every speed: {', '.join(same)}")
    notes = {r["status"] for r in runs} & set(_STATUS_NOTES)
    for status in sorted(notes):
        lines += textwrap.wrap(
            f"{status}: {_STATUS_NOTES[status]}", width or terminal_width(), subsequent_indent="  "
        )
    if "plot" in first:
        lines.append(f"plot written to {first['plot']}")
    return "\n".join(lines)


def _simulate_text(law, data, result) -> str:
    """The law and the impact's conditions, then the result's fields as it prints them."""
    _, *fields = result.summary().splitlines()  # below its title
    lines = [
        *_head(law),
        f"impact     m = {format_number(data['m'])} kg, v0 = {format_number(data['v0'])} m/s, "
        f"g = {format_number(data['g'])} m/s^2, separation by {data['separation']}",
        "",
        textwrap.dedent("\n".join(fields)),
    ]
    if data["status"] in _STATUS_NOTES:
        lines.append(f"{data['status']}: {_STATUS_NOTES[data['status']]}")
    if "plot" in data:
        lines.append(f"plot written to {data['plot']}")
    return "\n".join(lines)
