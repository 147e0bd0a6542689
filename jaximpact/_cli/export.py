"""`jaximpact export` (a law or target e, T -> an engine's contact parameters and what the
engine realises) and `jaximpact engine-e` (engine parameters -> e(v), T(v)). The engines, their
names and what the help says of each come from the one registry, `_engines.registry.ENGINES`;
the text and the checks of their input from `_engines.report`."""

import json

from .common import (
    CLIError,
    add_law_arguments,
    add_output_arguments,
    add_tangential_arguments,
    command_parser,
    emit,
    heartbeat_meter,
    parse_params,
    read_fit,
    tangential_from_args,
)


def add_export(subparsers):
    from .._engines.report import ENGINES, export_description, labels, listed, per_kg, takes

    parser = command_parser(
        subparsers,
        "export",
        help=f"an engine's contact parameters ({labels()}) for a law, a fit or target e, T",
        description=export_description(),
        example="jaximpact export mujoco --e 0.75 --T 0.01 --v0 1\n"
        "jaximpact export lammps --law hertz_rate --param c=2e6 b1=800 "
        "--mass 1 --v0 2.5 --radius 0.02 --json\n"
        "jaximpact calibrate --law hertz_rate --mass 0.05 --v0 2.5 --e 0.85 --T 7.8e-3 "
        "--json > fit.json\n"
        "jaximpact export mujoco --from fit.json",
    )
    parser.add_argument(
        "engine_name",
        nargs="?",
        metavar="ENGINE",
        help=f"{listed(ENGINES, 'or')} (or --engine NAME)",
    )
    parser.add_argument("--engine", metavar="NAME", help="the engine, as ENGINE")
    parser.add_argument(
        "--from",
        dest="source",
        metavar="FILE",
        help="a fit to export: the JSON that 'jaximpact calibrate --json' (or 'simulate "
        "--json') writes, '-' for stdin; its law, parameters, mass and speed are used. From "
        "'calibrate --posterior --json': the law at the posterior medians, and the band "
        "(5-95 %%) of what the engine realises over the draws the file holds",
    )
    parser.add_argument(
        "--band-draws",
        type=int,
        default=200,
        metavar="N",
        help="with --from a posterior: the engine's band over N of its draws (default 200; "
        "one export each: about 10 ms for LAMMPS, 0.5 s for MuJoCo)",
    )
    add_law_arguments(parser, required=False)
    parser.add_argument("--e", type=float, help="target restitution in (0, 1] (without --law)")
    parser.add_argument("--T", type=float, metavar="S", help="target contact duration, s")
    _add_mass(
        parser, f"required, except for {labels(per_kg)} from --e/--T, and with --from (the fit's)"
    )
    parser.add_argument(
        "--v0",
        type=float,
        metavar="M/S",
        help="impact speed, m/s (with --from: the fit's, if it has one speed)",
    )
    parser.add_argument("--timestep", type=float, metavar="S", help="the engine's step, s")
    _add_radius(parser)
    parser.add_argument(
        "--poisson", type=float, help=f"Poisson's ratio ({labels(takes('poisson'))}; default 0.3)"
    )
    parser.add_argument(
        "--limit-damping",
        action="store_true",
        help=f"{labels(takes('limit_damping'))}: keep the force non-attractive",
    )
    parser.add_argument(
        "--wall",
        action="store_true",
        help=f"{labels(lambda e: e.TWO_SPHERES and 'wall' in e.SCENES)}: one sphere of "
        "--mass and --radius hitting a fixed flat wall at --v0 (the drop test), instead of "
        "two spheres",
    )
    add_tangential_arguments(
        parser,
        required=False,
        help=f"{labels(lambda e: bool(e.TANGENTIAL or e.FRICTION))}: also export the "
        "tangential law NAME with --tparam (MuJoCo and Drake take its mu alone), and print "
        "the e_t, spin and normal e the engine realises from 5 to 75 degrees, beside the "
        "law's e_t",
        tparam_help="the tangential law's parameters, SI units, e.g. --tparam "
        "G_star=1.35e10 mu=0.092",
    )
    parser.add_argument(
        "--no-strict",
        dest="strict",
        action="store_false",
        help="export what the engine cannot realise at --timestep anyway, with a warning",
    )
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_export)


def _add_mass(parser, when: str):
    """`--mass`, its help ending in `when`."""
    parser.add_argument(
        "--mass",
        type=float,
        metavar="KG",
        help=f"mass, kg (two-sphere engines: of each sphere); {when}",
    )


def _add_radius(parser):
    from .._engines.report import labels

    parser.add_argument(
        "--radius",
        type=float,
        metavar="M",
        help=f"sphere radius, m ({labels(lambda e: e.TWO_SPHERES)})",
    )


def _engine_name(args) -> str:
    """ENGINE or --engine (one of them, the same if both), checked by the registry."""
    from .._engines.registry import ENGINES, engine

    names = {n for n in (args.engine_name, args.engine) if n is not None}
    if not names:
        raise CLIError(f"name the engine: jaximpact export ENGINE, one of {', '.join(ENGINES)}")
    if len(names) > 1:
        raise CLIError(f"ENGINE {args.engine_name!r} and --engine {args.engine!r} disagree")
    return engine(names.pop()).NAME


def _run_export(args):
    from .._engines import export
    from .._engines.materials import warn_sphere_density
    from .._engines.report import check_scene, export_text, fit_source, posterior_band, reworded
    from .._jobs.file_law import is_file_law, make_law

    engine = _engine_name(args)
    notes = []
    if args.source is not None:
        if args.e is not None or args.T is not None:
            raise CLIError("give either --from or --e/--T, not both")
        if args.param:
            raise CLIError("--param conflicts with --from: the fit gives the parameters")
        _, record, fit = read_fit(args.source, args.law)
        source, args.mass, args.v0, notes, posterior = fit_source(
            fit, record, args.source, mass=args.mass, v0=args.v0
        )
        name = source.name
        if args.band_draws < 1:
            raise CLIError(f"--band-draws must be at least 1, got {args.band_draws}")
    else:
        if args.law is None and args.e is None:
            raise CLIError("give --law (with --param), --from FILE or the target --e (and --T)")
        if args.law is not None and (args.e is not None or args.T is not None):
            raise CLIError("give either --law or --e/--T, not both")
        if args.law is None and args.param:
            raise CLIError("--param needs --law")
        if args.v0 is None:
            raise CLIError("--v0 is required: the impact speed, m/s")
        name, params, posterior, source = args.law, parse_params(args.param), None, None
    check_scene(
        engine, mass=args.mass, radius=args.radius, from_law=name is not None, wall=args.wall
    )
    warn_sphere_density(args.mass, args.radius)
    if source is None and name is not None:
        source = make_law(name, params)
    options = dict(  # export's, and each posterior draw's
        m=args.mass,
        v0=args.v0,
        radius=args.radius,
        poisson=args.poisson,
        limit_damping=args.limit_damping,
        geometry="wall" if args.wall else None,
        tangential=tangential_from_args(args),
    )
    # with --no-strict, the refusal comes as a warning (one line on stderr)
    x, words = reworded(
        lambda: export(
            source,
            engine,
            timestep=args.timestep,
            e=args.e,
            T=args.T,
            strict=args.strict,
            **options,
        )
    )
    origin = ""
    if posterior is not None:  # the engine's band over the posterior's draws
        x, origin, why = posterior_band(
            x,
            posterior,
            args.source,
            user_law=is_file_law(name),
            band_draws=args.band_draws,
            progress=heartbeat_meter(),
            **options,
        )
        notes += why
    data = x.to_dict()
    data["warnings"] = [*notes, *(words.get(w, w) for w in data["warnings"])]
    if args.source is not None:
        data["from"] = str(args.source)
    source_line = None if args.source is None else f"{args.source}: law {name}{origin}"
    emit(
        args,
        data,
        lambda: export_text(
            x, given_step=args.timestep is not None, source=source_line, warnings=data["warnings"]
        ),
    )


def add_engine_e(subparsers):
    from .._engines.report import ENGINES, engine_e_description, labels, listed, per_kg

    parser = command_parser(
        subparsers,
        "engine-e",
        help="the e(v) and T(v) that given engine contact parameters produce",
        description=engine_e_description(),
        example="jaximpact engine-e --engine mujoco --params '{\"solref\": [0.02, 1]}' "
        "--mass 0.05 --speed 0.5 1 2",
    )
    parser.add_argument("--engine", required=True, metavar="NAME", help=listed(ENGINES, "or"))
    parser.add_argument("--params", required=True, metavar="JSON", help="engine parameters")
    _add_mass(parser, f"required except for {labels(per_kg)}, whose parameters are per unit mass")
    parser.add_argument("--speed", type=float, nargs="+", required=True, metavar="M/S")
    _add_radius(parser)
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_engine_e)


def _run_engine_e(args):
    from .._engines.registry import engine
    from .._engines.report import check_parameters, response_record, response_text

    engine(args.engine)  # an unknown one refused before its parameters are read
    try:
        params = json.loads(args.params)
    except json.JSONDecodeError as error:
        raise CLIError(f"--params is not JSON: {error.msg}") from None
    check_parameters(args.engine, params)
    data = response_record(args.engine, params, m=args.mass, speeds=args.speed, radius=args.radius)
    emit(args, data, response_text(data))
