"""`jaximpact export` (a law or target e, T -> an engine's contact parameters and what the
engine realises) and `jaximpact engine-e` (engine parameters -> e(v), T(v))."""

import json

from .._format import format_number
from .common import (
    CLIError,
    add_output_arguments,
    command_parser,
    emit,
    parse_params,
)

_ENGINES = ("mujoco", "lammps", "drake", "liggghts", "chrono", "yade")


def add_export(subparsers):
    parser = command_parser(
        subparsers,
        "export",
        help="an engine's contact parameters (MuJoCo, Drake, LAMMPS, LIGGGHTS, Chrono, Yade) "
        "for a law or target e, T",
        description="Turn a law (--law, --param) or target --e and --T into the contact "
        "parameters of MuJoCo, Drake, LAMMPS, LIGGGHTS, Chrono or Yade, in the engine's own "
        "names and units, with a "
        "snippet to paste, a recommended time step, and the e and T the engine realises "
        "(its time stepping included). Scenes: MuJoCo and Drake, a body of --mass on a "
        "plane; the others, two spheres each of --mass and --radius colliding head-on at "
        "relative speed --v0. docs/engines.md has the formulas and measured tables.",
        example="jaximpact export --engine mujoco --e 0.75 --T 0.01 --mass 0.05 --v0 1\n"
        "jaximpact export --engine lammps --law hertz_rate --param c=2e6 b1=800 "
        "--mass 1 --v0 2.5 --radius 0.02 --json",
    )
    parser.add_argument(
        "--engine",
        required=True,
        metavar="NAME",
        help="mujoco, lammps, drake, liggghts, chrono or yade",
    )
    parser.add_argument("--law", metavar="NAME", help="a law of 'jaximpact laws'")
    parser.add_argument("--param", action="extend", nargs="+", default=[], metavar="NAME=VALUE")
    parser.add_argument("--e", type=float, help="target restitution in (0, 1] (without --law)")
    parser.add_argument("--T", type=float, metavar="S", help="target contact duration, s")
    parser.add_argument("--mass", type=float, default=1.0, metavar="KG", help="mass, kg")
    parser.add_argument("--v0", type=float, required=True, metavar="M/S", help="impact speed")
    parser.add_argument("--timestep", type=float, metavar="S", help="the engine's step, s")
    parser.add_argument("--radius", type=float, metavar="M", help="sphere radius, m (LAMMPS)")
    parser.add_argument("--poisson", type=float, help="Poisson's ratio (LAMMPS; default 0.3)")
    parser.add_argument(
        "--limit-damping", action="store_true", help="LAMMPS: keep the force non-attractive"
    )
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_export)


def _run_export(args):
    from .._engines import export

    if args.engine not in _ENGINES:
        raise CLIError(f"unknown engine {args.engine!r}; choose one of: {', '.join(_ENGINES)}")
    if args.law is None and args.e is None:
        raise CLIError("give --law (with --param) or the target --e (and --T)")
    if args.law is not None and (args.e is not None or args.T is not None):
        raise CLIError("give either --law or --e/--T, not both")
    if args.law is None and args.param:
        raise CLIError("--param needs --law")
    from .._engines.export import ENGINES

    if args.radius is None and ENGINES[args.engine].TWO_SPHERES:
        raise CLIError(f"{args.engine} needs --radius (m) of the two spheres")
    source = None
    if args.law is not None:
        from .._laws import law

        source = law(args.law, **parse_params(args.param))
    x = export(
        source,
        args.engine,
        m=args.mass,
        v0=args.v0,
        timestep=args.timestep,
        radius=args.radius,
        poisson=args.poisson,
        e=args.e,
        T=args.T,
        limit_damping=args.limit_damping,
    )

    def text():
        lines = [
            f"{x.engine}: {x.scene}",
            f"asked    e = {x.target_e:.6g}, T = {x.target_T:.6g} s at v0 = {x.v0:g} m/s",
            f"realised e = {x.e:.6g}, T = {x.T:.6g} s with time step {x.timestep:.6g} s"
            + (
                f" (e {x.e_range[0]:.5g} to {x.e_range[1]:.5g} over where contact starts)"
                if x.e_range
                else ""
            ),
            "parameters:",
            *(f"  {k} = {v}" for k, v in x.parameters.items()),
            "snippet:",
            *(f"  {line}" for line in x.snippet.splitlines()),
        ]
        if x.speeds:
            with_law = x.e_target is not None  # an export from targets has no law to compare
            lines.append("speed (m/s)   e engine" + ("   e law" if with_law else ""))
            for i, v in enumerate(x.speeds):
                law_e = f"   {x.e_target[i]:.5g}" if with_law else ""
                lines.append(f"  {format_number(v):>9}   {x.e_engine[i]:.5g}{law_e}")
        lines += [f"warning: {w}" for w in x.warnings]
        return "\n".join(lines)

    emit(args, x.to_dict(), text)


def add_engine_e(subparsers):
    parser = command_parser(
        subparsers,
        "engine-e",
        help="the e(v) and T(v) that given engine contact parameters produce",
        description="The inverse of export: given an engine's contact parameters as JSON "
        '(MuJoCo {"solref": [timeconst, dampratio], "timestep": s} (default step 0.002 s, '
        'for its refsafe rule); LAMMPS {"E": Pa, '
        '"coeff_restitution": e, "poisson": nu, "limit_damping": false} for '
        "hertz/material with damping coeff_restitution, and the same keys for LIGGGHTS "
        "(limit_damping: its limitForce) and Chrono (its Young's modulus, restitution and "
        "Poisson ratio; its force is always kept non-attractive); Drake "
        '{"point_contact_stiffness": N/m, "hunt_crossley_dissipation": s/m}), the e and T '
        "of the continuous law the engine integrates, at each --speed, and beside them what "
        "the engine's time stepping realises (MuJoCo at its timestep; LAMMPS when "
        '"timestep" is given; the mean over where first touch falls inside a step, with the '
        'range of e); Yade {"tc": s, "en": e} (ViscElMat; "timestep" and '
        'NewtonIntegrator "damping" for its stepping); Drake with "time_step" > 0: its '
        "discrete plant (Lagged, Similar, TAMSI).",
        example="jaximpact engine-e --engine mujoco --params '{\"solref\": [0.02, 1]}' "
        "--mass 0.05 --speed 0.5 1 2",
    )
    parser.add_argument(
        "--engine",
        required=True,
        metavar="NAME",
        help="mujoco, lammps, drake, liggghts, chrono or yade",
    )
    parser.add_argument("--params", required=True, metavar="JSON", help="engine parameters")
    parser.add_argument("--mass", type=float, default=1.0, metavar="KG", help="mass, kg")
    parser.add_argument("--speed", type=float, nargs="+", required=True, metavar="M/S")
    parser.add_argument("--radius", type=float, metavar="M", help="sphere radius, m (LAMMPS)")
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_engine_e)


def _check_engine_params(engine, params):
    """Every needed key there, every key one that `engine` reads (its module's `KEYS`), every
    value a number (`solref` two numbers, `limit_damping` true or false)."""
    from .._engines.export import ENGINES

    needed, optional = ENGINES[engine].KEYS
    missing = [k for k in needed if k not in params]
    if missing:
        raise CLIError(f"--params for {engine} needs {', '.join(missing)}")
    known = (*needed, *optional)
    unknown = [k for k in params if k not in known]
    if unknown:
        raise CLIError(
            f"--params for {engine} has no key {', '.join(map(repr, unknown))}; "
            f"it takes {', '.join(known)}"
        )
    for key, value in params.items():
        if key == "limit_damping":
            if not isinstance(value, bool):
                raise CLIError(f"limit_damping must be true or false, got {value!r}")
        elif key == "solref":
            if not (isinstance(value, list) and len(value) == 2 and all(map(_number, value))):
                raise CLIError("solref must be two numbers, [timeconst, dampratio]")
        elif not _number(value):
            raise CLIError(f"{key} must be a number, got {value!r}")


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _run_engine_e(args):
    from .._engines import engine_response, stepped_response

    if args.engine not in _ENGINES:
        raise CLIError(f"unknown engine {args.engine!r}; choose one of: {', '.join(_ENGINES)}")
    try:
        params = json.loads(args.params)
    except json.JSONDecodeError as error:
        raise CLIError(f"--params is not JSON: {error.msg}") from None
    if not isinstance(params, dict):
        raise CLIError("--params must be a JSON object, e.g. '{\"solref\": [0.02, 1]}'")
    _check_engine_params(args.engine, params)
    law, separation, e, T = engine_response(
        args.engine, params, m=args.mass, speeds=args.speed, radius=args.radius
    )
    stepped = stepped_response(
        args.engine, params, m=args.mass, speeds=args.speed, radius=args.radius
    )
    data = {
        "engine": args.engine,
        "law": {"name": law.name, "parameters": {k: float(v) for k, v in law.parameters.items()}},
        "separation": separation,
        "speeds": list(args.speed),
        "e": list(e),
        "T": list(T),
        "stepped": None
        if stepped is None
        else dict(zip(("timestep", "e", "T", "e_min", "e_max"), stepped, strict=True)),
    }
    lines = [f"{args.engine}: law {law.name} ({separation} criterion)"]
    if stepped is None:
        lines.append("speed (m/s)   e   T (s)   (continuous law)")
        lines += [
            f"  {format_number(v):>9}   {ei:.5g}   {Ti:.5g}"
            for v, ei, Ti in zip(args.speed, e, T, strict=True)
        ]
    else:
        h, e_s, T_s, e_lo, e_hi = stepped
        lines.append(
            f"speed (m/s)   e   T (s)   (continuous law) | e   T (s)   e range   "
            f"(stepped at {format_number(h)} s)"
        )
        lines += [
            f"  {format_number(v):>9}   {e[i]:.5g}   {T[i]:.5g} | {e_s[i]:.5g}   {T_s[i]:.5g}   "
            f"{e_lo[i]:.5g}-{e_hi[i]:.5g}"
            for i, v in enumerate(args.speed)
        ]
    emit(args, data, "\n".join(lines))
