"""`jaximpact simulate`: one impact, its e, T, x_max, F_max, ... and a figure."""

from .._format import format_number, format_quantity
from .._plotting import new_figure, save_figure
from .common import (
    add_impact_arguments,
    add_law_arguments,
    add_output_arguments,
    check_contact_scales,
    check_plot_path,
    command_parser,
    emit,
    law_from_args,
    parse_params,
)
from .laws import concrete_units

# --------------------------------------------------------------------------------------
# jaximpact simulate
# --------------------------------------------------------------------------------------

# field of ImpactResult -> SI unit, in the order printed
_RESULT_UNITS = {
    "e": "",
    "T": "s",
    "x_max": "m",
    "F_max": "N",
    "t_max": "s",
    "dissipated": "J",
    "v_out": "m/s",
}
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
        help="integrate one impact and print e, T, x_max, F_max, ...",
        description="Integrate one impact of a body of mass --mass (kg) hitting the surface "
        "at --v0 (m/s) under the force law --law with parameters --param (SI units, see "
        "'jaximpact laws'), and print the coefficient of restitution e, the contact "
        "duration T, the maximum penetration x_max and when it is reached (t_max), the "
        "largest force F_max, the energy dissipated and how the contact ended.",
        example="jaximpact simulate --law hertz_rate --param c=2e6 --param b1=800 --v0 2.5\n"
        "jaximpact simulate --law kelvin_voigt --param c=2e6 b=400 --mass 1 --v0 2.5 "
        "--separation penetration --json\n"
        "jaximpact simulate --law bingham --param c=2e6 b=200 P=400 --v0 2.5 --plot bingham.png",
    )
    add_law_arguments(parser)
    add_impact_arguments(parser)
    add_output_arguments(parser)
    parser.set_defaults(handler=_run_simulate)


def _run_simulate(args):
    check_plot_path(args.plot)
    import numpy as np

    from .._solve.impact import impact

    law = law_from_args(args)
    check_contact_scales(args.law, parse_params(args.param), args.mass, args.v0)
    conditions = dict(m=args.mass, v0=args.v0, separation=args.separation, g=args.gravity)
    result = impact(law, **conditions)
    status = result.status_name
    data = {
        "law": law.name,
        "params": {k: float(v) for k, v in law.parameters.items()},
        "m": args.mass,
        "v0": args.v0,
        "separation": args.separation,
        "g": args.gravity,
    }
    data.update({k: getattr(result, k) for k in _RESULT_UNITS})
    data.update(status=status, path=result.path, num_steps=result.num_steps)
    data["units"] = {k: u or "-" for k, u in _RESULT_UNITS.items()}
    if args.plot is not None:
        from .._plotting import plot_impact

        ts = np.linspace(0.0, 1.05 * float(result.T), 600)
        history = impact(law, **conditions, ts=ts)
        fig = new_figure(figsize=(13.5, 4.2), layout="constrained")
        plot_impact(history, law, fig=fig)
        save_figure(fig, args.plot)
        data["plot"] = str(args.plot)
    emit(args, data, lambda: _simulate_text(law, data))
    return 0


def _simulate_text(law, data) -> str:
    from .._laws import LAWS

    spec = LAWS.get(law.name)
    units = concrete_units(spec, data["params"]) if spec is not None else {}
    params = ", ".join(
        f"{k} = {format_number(v)}" + (f" {units[k]}" if units.get(k, "-") != "-" else "")
        for k, v in data["params"].items()
    )
    eq = f"eq. {spec.equation}: " if spec is not None and spec.equation != "-" else ""
    formula = f" ({eq}F = {spec.formula})" if spec is not None else ""
    lines = [
        f"law        {law.name}{formula}",
        f"params     {params}",
        f"impact     m = {format_number(data['m'])} kg, v0 = {format_number(data['v0'])} m/s, "
        f"g = {format_number(data['g'])} m/s^2, separation by {data['separation']}",
        "",
    ]
    for key, unit in _RESULT_UNITS.items():
        value = data[key]
        if value is None:
            continue
        shown = f"{float(value):.4f}" if not unit else format_quantity(value, unit)
        lines.append(f"{key:<10} = {shown}")
    note = _STATUS_NOTES.get(data["status"])
    lines.append(f"{'status':<10} = {data['status']}" + (f"  ({note})" if note else ""))
    lines.append(f"{'path':<10} = {data['path']} ({int(data['num_steps'])} solver steps)")
    if "plot" in data:
        lines.append(f"plot written to {data['plot']}")
    return "\n".join(lines)
