"""`jaximpact fit-oblique`: fit a tangential law (friction, tangential stiffness) to measured
oblique rebounds, the tangential restitution and/or the spin after impact, read from a CSV.

Columns (a header names them; an empty cell is a value not measured):
- the incidence: `theta_deg` (from the normal, degrees; with `--speed`) or `v_n,v_t` (m/s);
- optionally `omega` (spin before impact, rad/s; default 0);
- what was measured: `e_t` (the centre's tangential restitution) and/or `omega_out` (rad/s).

Or a video track of the ball bouncing across a floor, one row per frame: `t` (s), `x`, `y`
(m, `y` up) and `phi` (a mark's angle, rad, counterclockwise), read by `track_rebounds`
(each impact's speeds and spin before and after, with their standard errors) under `--g`.
"""

import math
from pathlib import Path

from .._plotting import plot_oblique
from .._progress import metered
from .._status import Status
from .common import (
    CLIError,
    add_free_argument,
    add_law_arguments,
    add_output_arguments,
    add_tangential_arguments,
    check_plot_path,
    command_parser,
    emit,
    free_names,
    heartbeat_meter,
    law_from_args,
    read_fit,
    tangential_from_args,
)


def add_fit_oblique(subparsers):
    parser = command_parser(
        subparsers,
        "fit-oblique",
        help="fit friction and tangential stiffness to oblique rebounds (e_t, spin)",
        description="Fit the tangential law --tangential (mindlin: G_star, mu; "
        "linear_history: kt, mu, ct) of a sphere of mass --mass (kg) and radius --radius "
        "(m) to rebounds measured at several incidences, read from FILE.csv: columns "
        "theta_deg (with --speed) or v_n,v_t, optionally omega (spin before, rad/s), and "
        "e_t and/or omega_out (an empty cell: not measured); a header may give v_n, v_t, t, "
        "x, y another unit ('v_n (mm/s)', 't [ms]'). The normal law --law with "
        "--param (or --from FIT.json, the output of 'jaximpact calibrate --json') is held "
        "fixed (fit it first with 'jaximpact calibrate'). Each impact is "
        "integrated with stick and slip as segments ended by events, so the fit's "
        "derivatives are exact through the transitions. Prints the parameters with "
        "standard errors and the goodness of fit (rms of e_t and of the spin). Or FILE.csv "
        "is a video track, one row per frame: t (s), x, y (m, y up) and phi (a mark's angle, "
        "rad, counterclockwise), whose impacts are read off its flights (with --g).",
        example="jaximpact fit-oblique rebounds.csv --speed 3.9 --mass 2.6e-4 --radius 2.5e-3 "
        "--law tsuji --param c=1.1e9 b=0.5 --tangential mindlin --tparam G_star=1.35e10 "
        "mu=0.092\n"
        "jaximpact fit-oblique rebounds.csv --mass 2.6e-4 --radius 2.5e-3 --law hunt_crossley "
        "--param c=1.1e9 a=0 --tangential linear_history --tparam kt=1e6 mu=0.1 --json\n"
        "jaximpact calibrate --law tsuji --mass 2.6e-4 --v0 3.9 --e 0.98 --T 1.3e-5 --json "
        "> normal.json; jaximpact fit-oblique rebounds.csv --speed 3.9 --from normal.json "
        "--mass 2.6e-4 --radius 2.5e-3 --tangential mindlin --tparam G_star=1.35e10 mu=0.1",
    )
    parser.add_argument("file", type=Path, metavar="FILE.csv", help="the measured rebounds")
    add_law_arguments(parser, required=False)
    parser.add_argument(
        "--from",
        dest="source",
        metavar="FIT.json",
        help="the normal law from a fit: the JSON of 'jaximpact calibrate --json' (one "
        "law, or --law all's ranking: its best, or the one --law names), instead of --law "
        "and --param; its mass must be --mass",
    )
    add_tangential_arguments(
        parser,
        required=True,
        help="the tangential law to fit",
        tparam_help="the tangential law's start values in SI units, e.g. --tparam "
        "G_star=1.35e10 mu=0.092 (mindlin also takes G=... nu=...)",
    )
    parser.add_argument("--mass", type=float, required=True, metavar="KG", help="mass, kg (> 0)")
    parser.add_argument(
        "--radius", type=float, required=True, metavar="M", help="sphere radius, m (> 0)"
    )
    parser.add_argument(
        "--speed",
        type=float,
        metavar="M/S",
        help="impact speed, m/s, for a file that gives the incidence as theta_deg",
    )
    parser.add_argument(
        "--g",
        type=float,
        default=None,
        metavar="M/S2",
        help="gravity, m/s^2, of a video track's flights and contacts (default 9.81 for a "
        "track, 0 for rebounds)",
    )
    _add_sphere_arguments(parser, "fit with the engine's to export to it")
    add_free_argument(parser, "tangential parameters to fit (default: the stiffness and mu)")
    add_output_arguments(parser)
    parser.set_defaults(handler=run_fit_oblique)


def _add_sphere_arguments(parser, contact_point_use: str, prefix: str = ""):
    """`--inertia` and `--contact-point`, the sphere's moment of inertia and where its
    tangential force acts (`prefix`: what the help says first, e.g. "with --tangential: ")."""
    parser.add_argument(
        "--inertia",
        type=float,
        default=0.4,
        metavar="K",
        help=f"{prefix}moment of inertia over m R^2 (default 0.4, a solid sphere)",
    )
    parser.add_argument(
        "--contact-point",
        choices=("surface", "midpoint", "plane"),
        default="surface",
        help=f"{prefix}where the tangential force acts: lever arm R (surface, LAMMPS; the "
        "default), R - x/2 (midpoint: LIGGGHTS, MuJoCo, Drake), R - x (plane: Yade's wall); "
        f"{contact_point_use}",
    )


def add_oblique_impact_arguments(parser):
    """`simulate`'s oblique impact: `--tangential`, `--tparam`, `--radius`, `--angle`,
    `--omega`, `--inertia`, `--contact-point` (`run_oblique_impact`)."""
    add_tangential_arguments(
        parser,
        required=False,
        help="an oblique impact of a sphere (with --radius and --angle): its tangential law",
        tparam_help="with --tangential: the tangential law's parameters in SI units, e.g. "
        "--tparam G_star=1.35e10 mu=0.092 (mindlin also takes G=... nu=...)",
    )
    parser.add_argument(
        "--radius",
        type=float,
        metavar="M",
        help="with --tangential: the sphere's radius, m (> 0)",
    )
    parser.add_argument(
        "--angle",
        type=float,
        nargs="+",
        metavar="DEG",
        help="with --tangential: the incidence from the normal, degrees in [0, 90) (--v0 is "
        "the speed: v_n = v0 cos, v_t = v0 sin); several for a sweep of e_t(angle)",
    )
    parser.add_argument(
        "--omega",
        type=float,
        default=0.0,
        metavar="RAD/S",
        help="with --tangential: the spin before impact, rad/s (default 0; omega = v_t / R "
        "rolls without slip)",
    )
    parser.add_argument(
        "--max-segments",
        type=int,
        default=16,
        metavar="N",
        help="with --tangential: the most stick and slip phases one impact may have (default "
        "16); an impact that needs more ends out_of_steps and says so",
    )
    _add_sphere_arguments(parser, "as the engine you export to", "with --tangential: ")


def check_oblique_arguments(args) -> None:
    """`--radius`, `--angle` and the rest of an oblique impact, or a one-line `CLIError`:
    asked without `--tangential`, missing, or out of range (before any work)."""
    from .._engines.materials import warn_sphere_density

    oblique = {"--radius": args.radius, "--angle": args.angle}
    if args.tangential is None:
        given = [flag for flag, value in oblique.items() if value is not None]
        given += ["--tparam"] if args.tparam else []
        given += ["--omega"] if args.omega != 0.0 else []
        given += ["--max-segments"] if args.max_segments != 16 else []
        if given:
            raise CLIError(f"{given[0]} is for an oblique impact: add --tangential NAME")
        return
    for flag, value in oblique.items():
        if value is None:
            raise CLIError(f"an oblique impact (--tangential) needs {flag}")
    if not (math.isfinite(args.radius) and args.radius > 0):
        raise CLIError(f"--radius must be a finite number > 0 (m), got {args.radius:g}")
    for angle in args.angle:
        if not (math.isfinite(angle) and 0 <= angle < 90):
            raise CLIError(
                f"--angle {angle:g}: the incidence is in degrees from the normal, in [0, 90)"
            )
    if len(args.v0) > 1:
        raise CLIError("an oblique impact takes one --v0 (the speed); sweep --angle instead")
    if not math.isfinite(args.omega):
        raise CLIError(f"--omega must be a finite number (rad/s), got {args.omega:g}")
    _warn_unlikely_spin(args.omega, args.radius, args.v0[0])
    if not (math.isfinite(args.inertia) and args.inertia > 0):
        raise CLIError(f"--inertia must be a finite number > 0 (I / (m R^2)), got {args.inertia:g}")
    if args.max_segments < 1:
        raise CLIError(f"--max-segments must be at least 1, got {args.max_segments}")
    warn_sphere_density(args.mass, args.radius)


# a spin whose surface speed is this many times the impact speed is likely a unit slip
LIKELY_SPIN_RATIO = 100.0


def _warn_unlikely_spin(omega: float, R: float, v0: float) -> None:
    """A warning where the surface speed `R omega` (m/s) of the spin is more than
    `LIKELY_SPIN_RATIO` times the impact speed: a unit is likely wrong (rad/s, not rpm)."""
    import warnings

    if math.isfinite(v0) and v0 > 0 and abs(omega) * R > LIKELY_SPIN_RATIO * v0:
        warnings.warn(
            f"--omega {omega:g} rad/s turns the sphere's surface at R omega = "
            f"{abs(omega) * R:.3g} m/s, {abs(omega) * R / v0:.3g} times the impact speed: "
            "check the units (--omega in rad/s, --radius in m)",
            stacklevel=2,
        )


def run_oblique_impact(args, law, head: list[str]) -> int:
    """`simulate --tangential`: one oblique impact per `--angle`, printed as text (a line
    per field for one angle, a table for several) or JSON; `head`: the normal law's lines."""
    from .._oblique import oblique_impact
    from .._oblique.report import MEASURED, oblique_runs_text

    tangential = tangential_from_args(args)
    v0 = args.v0[0]
    runs, results = [], []
    for angle in args.angle:
        theta = math.radians(angle)
        result = oblique_impact(
            law,
            tangential,
            m=args.mass,
            R=args.radius,
            v_n=v0 * math.cos(theta),
            v_t=v0 * math.sin(theta),
            omega=args.omega,
            inertia=args.inertia,
            g=args.gravity,
            separation=args.separation,
            contact_point=args.contact_point,
            max_segments=args.max_segments,
            throw=False,
        )
        data = {"angle_deg": angle, "v0": v0, **result.to_dict()}
        for name in ("angle_out", "angle_out_contact"):
            value = data[name]
            data[f"{name}_deg"] = None if value is None else math.degrees(value)
        runs.append(data)
        results.append(result)
    if args.plot is not None:
        series = {k: [math.nan if d[k] is None else d[k] for d in runs] for k in MEASURED}
        plot_oblique(args.plot, [d["angle_deg"] for d in runs], series)
    conditions = [
        f"sphere     m = {args.mass:g} kg, R = {args.radius:g} m, I = {args.inertia:g} m R^2, "
        f"contact point {args.contact_point}",
        f"impact     v0 = {v0:g} m/s, omega = {args.omega:g} rad/s, g = {args.gravity:g} m/s^2, "
        f"separation by {args.separation}",
    ]
    lines = [*head, f"tangential {tangential!r}", *conditions, ""]
    lines += oblique_runs_text(runs, results)
    if args.plot is not None:
        lines.append(f"plot written to {args.plot}")
    failed = [d for d in runs if Status[d["status"]].is_failure]
    if failed:
        angles = ", ".join(format(d["angle_deg"], "g") for d in failed)
        switches = max(d["num_switches"] for d in failed)
        what = (
            f"raise --max-segments ({args.max_segments})"
            if switches + 1 >= args.max_segments
            else "each phase ran out of solver steps: check the units and the laws' parameters"
        )
        lines.append(
            f"the solve ended {failed[0]['status']} at --angle {angles} (after {switches} "
            f"stick-slip switches): {what}"
        )
    emit(args, runs[0] if len(runs) == 1 else runs, "\n".join(lines))
    return 1 if failed else 0


def run_fit_oblique(args):
    import numpy as np

    from .._engines.materials import warn_sphere_density
    from .._oblique import fit_oblique
    from .._oblique.report import COLUMNS, MEASURED, fit_oblique_text, normal_check, read_rebounds

    check_plot_path(args.plot, inputs=(args.file,))
    warn_sphere_density(args.mass, args.radius)
    if args.speed is not None and not args.speed > 0:
        raise CLIError(f"--speed must be > 0 (m/s), got {args.speed:g}")
    g = args.g
    if g is not None and not (math.isfinite(g) and g >= 0):
        raise CLIError(f"--g must be a finite number >= 0 (m/s^2), got {g:g}")
    normal = {}
    if args.source is not None:
        if args.param:
            raise CLIError("--param conflicts with --from: the fit gives the parameters")
        law, normal = normal_law_from_fit(args.source, args.law, args.mass)
    elif args.law is None:
        raise CLIError("give the normal law: --law NAME (with --param) or --from FIT.json")
    data = read_rebounds(args.file, args.speed, 9.81 if g is None else g)
    track = "sigma_e_t" in data
    g = (9.81 if track else 0.0) if g is None else g
    if args.source is None:
        law = law_from_args(args)
    tangential = tangential_from_args(args)
    free = free_names(args.free)
    if free is None:
        from .._oblique.fit import default_free

        free = default_free(tangential)
    rows = {k: np.asarray(data.get(k, []), dtype=float) for k in (*COLUMNS, "theta")}
    measured = {k: rows[k] if np.any(np.isfinite(rows[k])) else None for k in MEASURED}
    sigmas = {k: np.asarray(data[k]) for k in ("sigma_e_t", "sigma_omega") if k in data}
    label = f"fitting {args.tangential} to {rows['v_n'].size} rebounds"
    with metered(heartbeat_meter(), 1, label) as bar:  # a first fit compiles for 40-75 s
        fit = fit_oblique(
            law,
            tangential,
            m=args.mass,
            R=args.radius,
            v_n=rows["v_n"],
            v_t=rows["v_t"],
            omega=rows["omega"],
            e_t=measured["e_t"],
            omega_out=measured["omega_out"],
            free=free,
            inertia=args.inertia,
            g=g,
            contact_point=args.contact_point,
            **sigmas,
            **({"separation": normal["separation"]} if normal else {}),
        )
        bar.update(1, "done")
    if args.plot is not None:
        plot_oblique(args.plot, rows["theta"], {k: getattr(fit, k) for k in MEASURED}, rows)
    check = normal_check(law, args.mass, float(np.max(rows["v_n"])))
    record = {**fit.to_dict(), "check": check, **({"normal": normal} if normal else {})}
    emit(args, record, lambda: fit_oblique_text(fit, rows, check, normal))
    return 0


def normal_law_from_fit(path: Path, name: str | None, mass: float):
    """`(law, record)`: the normal law of the fit in the JSON file `path` that `jaximpact
    calibrate --json` writes (`common.read_fit`: one law, or `--law all`'s ranking: its
    best, or the law `name` names), and what the output says of it (`law`, `params`,
    `separation`, `from`). Its mass must be `mass` (kg); each missing or mismatched field
    is a one-line `CLIError`, a fit that did not converge a warning."""
    import warnings

    _, record, fit = read_fit(path, name)
    if fit.m is not None and not math.isclose(float(fit.m), mass, rel_tol=1e-12):
        raise CLIError(
            f"--mass {mass:g} but {path} was fitted for m = {float(fit.m)!r} kg: the normal "
            "law's e and T depend on the mass; give the sphere's mass the law was fitted for"
        )
    separation = record.get("separation", "force")
    if separation not in ("force", "penetration"):
        raise CLIError(f"--from {path}: separation {separation!r} is not 'force' or 'penetration'")
    if fit.converged is not None and not fit.converged:
        warnings.warn(f"the fit in {path} did not converge", stacklevel=2)
    params = {k: float(v) for k, v in fit.params.items()}
    return fit.law, {
        "law": fit.law.name,
        "params": params,
        "separation": separation,
        "from": str(path),
    }
