"""`jaximpact export` (a law or target e, T -> an engine's contact parameters and what the
engine realises) and `jaximpact engine-e` (engine parameters -> e(v), T(v)). The engines, their
names and what the help says of each come from the one registry, `_engines.registry.ENGINES`."""

import json

from .._format import format_number
from .common import (
    CLIError,
    add_law_arguments,
    add_output_arguments,
    add_tangential_arguments,
    command_parser,
    emit,
    heartbeat_meter,
    is_file_law,
    make_law,
    parse_params,
    read_fit,
    tangential_from_args,
    warn_sphere_density,
)


def _engines() -> dict:
    """The registry of engines, name -> `AbstractEngine` (light to import: the engines'
    numerics load on use)."""
    from .._engines.export import ENGINES

    return ENGINES


def _listed(words, last: str = "and") -> str:
    """`"a, b and c"`."""
    words = list(words)
    return words[0] if len(words) == 1 else f"{', '.join(words[:-1])} {last} {words[-1]}"


def _labels(where=lambda engine: True, last: str = "and") -> str:
    """The engines' labels (as their documentation spells them) where `where(engine)`."""
    return _listed([e.LABEL for e in _engines().values() if where(e)], last)


def _names(last: str = "or") -> str:
    """The engines' names as `--engine` takes them."""
    return _listed(_engines(), last)


def _export_description() -> str:
    plane = _labels(lambda e: not e.TWO_SPHERES)
    per_kg = _labels(lambda e: e.MASS_DEPENDS is None)
    return (
        "Turn a law (--law, --param), a fit (--from FILE, the JSON of 'jaximpact calibrate "
        f"--json') or target --e and --T into the contact parameters of {_labels(last='or')}, "
        "in the engine's own names and units, with a snippet to paste, a recommended time "
        "step (the coarsest at which the engine's stepping realises e within 0.5 % wherever "
        "the first touch falls and T within 0.5 %, printed as T/n too), and the e and T the "
        "engine realises (its time stepping included). Scenes: "
        f"{plane}, a body of --mass on a plane; the others, two spheres each of --mass and "
        "--radius colliding head-on at relative speed --v0 (--wall: one sphere on a fixed "
        "flat wall). docs/engines.md has the formulas and measured tables.\n\n"
        "--mass has no default: every engine's parameters depend on it "
        f"({per_kg} from --e and --T alone excepted: its contact is per unit mass), and so "
        "do a law's e and T. An export the engine cannot realise at --timestep (a parameter "
        "not finite, e outside [0, 1], fewer than 5 steps per contact, or e or T more than "
        "5 % off the target) is refused with the step that would work; --no-strict exports "
        "it anyway, with a warning."
    )


def _takes(key: str):
    """Whether an engine's parameters have the key `key`."""
    return lambda engine: any(k.name == key for k in engine.KEYS)


def add_export(subparsers):
    parser = command_parser(
        subparsers,
        "export",
        help=f"an engine's contact parameters ({_labels()}) for a law, a fit or target e, T",
        description=_export_description(),
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
        help=f"{_names()} (or --engine NAME)",
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
    parser.add_argument(
        "--mass",
        type=float,
        metavar="KG",
        help="mass, kg (two-sphere engines: of each sphere); required, except for "
        f"{_labels(lambda e: e.MASS_DEPENDS is None)} from --e/--T, and with --from (the "
        "fit's)",
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
        "--poisson",
        type=float,
        help=f"Poisson's ratio ({_labels(_takes('poisson'))}; default 0.3)",
    )
    parser.add_argument(
        "--limit-damping",
        action="store_true",
        help=f"{_labels(_takes('limit_damping'))}: keep the force non-attractive",
    )
    parser.add_argument(
        "--wall",
        action="store_true",
        help=f"{_labels(lambda e: e.TWO_SPHERES and 'wall' in e.SCENES)}: one sphere of "
        "--mass and --radius hitting a fixed flat wall at --v0 (the drop test), instead of "
        "two spheres",
    )
    add_tangential_arguments(
        parser,
        required=False,
        help=f"{_labels(lambda e: bool(e.TANGENTIAL or e.FRICTION))}: also export the "
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


def _add_radius(parser):
    parser.add_argument(
        "--radius",
        type=float,
        metavar="M",
        help=f"sphere radius, m ({_labels(lambda e: e.TWO_SPHERES)})",
    )


def _engine_name(args) -> str:
    """ENGINE or --engine (one of them, the same if both), checked."""
    names = {n for n in (args.engine_name, args.engine) if n is not None}
    if not names:
        raise CLIError(f"name the engine: jaximpact export ENGINE, one of {', '.join(_engines())}")
    if len(names) > 1:
        raise CLIError(f"ENGINE {args.engine_name!r} and --engine {args.engine!r} disagree")
    (name,) = names
    _check_engine(name)
    return name


def _check_engine(name: str) -> None:
    """The library's refusal of an unknown engine (`registry.engine`), as a `CLIError`."""
    from .._engines.registry import engine

    try:
        engine(name)
    except ValueError as error:
        raise CLIError(str(error)) from None


def _run_export(args):
    import warnings

    from .._engines import export
    from .._engines._stepping import describe_step
    from .._engines.export import UnrealisedExport, UnrealisedWarning, missing_mass

    engine = _engine_name(args)
    notes = []
    if args.source is not None:
        if args.e is not None or args.T is not None:
            raise CLIError("give either --from or --e/--T, not both")
        if args.param:
            raise CLIError("--param conflicts with --from: the fit gives the parameters")
        source, args.mass, args.v0, notes, posterior = _from_fit(args.source, args)
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
    chosen = _engines()[engine]
    missing = []
    if args.mass is None and (name is not None or chosen.MASS_DEPENDS is not None):
        missing.append("--mass (kg)")
    if args.radius is None and chosen.TWO_SPHERES:
        missing.append("--radius (m)")
    if missing:
        what = " and ".join(missing)
        if "--mass (kg)" in missing:
            raise CLIError(missing_mass(engine, name is not None, f"give {what}"))
        raise CLIError(f"{engine} needs {what} of the {'sphere' if args.wall else 'two spheres'}")
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
    try:  # with --no-strict, the refusal comes as a warning (one line on stderr)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UnrealisedWarning)
            x = export(
                source,
                engine,
                timestep=args.timestep,
                e=args.e,
                T=args.T,
                strict=args.strict,
                **options,
            )
        origin = ""
        if posterior is not None:  # the engine's band over the posterior's draws
            x, origin, why = _band(x, posterior, name, args, options)
            notes += why
    except UnrealisedExport as refusal:
        raise CLIError(refusal.message("--no-strict")) from None
    data = x.to_dict()
    for caught_warning in caught:  # in the command line's words, then shown as they came
        message = caught_warning.message
        if isinstance(message, UnrealisedWarning) and message.refusal is not None:
            said = message.refusal.message("--no-strict", exported=True)
            data["warnings"] = [said if w == str(message) else w for w in data["warnings"]]
            warnings.warn(said, UnrealisedWarning, stacklevel=1)
        else:
            warnings.warn_explicit(
                message,
                caught_warning.category,
                caught_warning.filename,
                caught_warning.lineno,
                source=caught_warning.source,
            )
    data["warnings"] = [*notes, *data["warnings"]]
    if args.source is not None:
        data["from"] = str(args.source)

    if not x.timestep:
        step = "timestep 0 (its continuous plant)"
    else:  # the coarsest step that realises the target within 0.5 %, as T/n too
        which = "recommended" if args.timestep is None else "given"
        step = f"{which} timestep {describe_step(x.timestep, x.target_T)}"

    def text():
        mass = "per unit mass" if x.m is None else f"m = {format_number(x.m)} kg"
        lines = [
            f"{x.engine}: {x.scene}",
            *([f"from     {args.source}: law {name}{origin}"] if args.source is not None else []),
            f"asked    e = {x.target_e:.6g}, T = {x.target_T:.6g} s at v0 = {x.v0:g} m/s, {mass}",
            step,
            f"realised e = {x.e:.6g}, T = {x.T:.6g} s at that step"
            + (
                f" (e {x.e_range[0]:.5g} to {x.e_range[1]:.5g} over where contact starts)"
                if x.e_range
                else ""
            ),
            *(
                [
                    f"band     e {x.e_band[0]:.5g} to {x.e_band[1]:.5g}, T {x.T_band[0]:.5g} to "
                    f"{x.T_band[1]:.5g} s (5-95 % over {x.band_draws} posterior draws, that step)"
                ]
                if x.e_band is not None
                else []
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
        if x.tangential is not None:
            lines.append(
                f"tangential {x.tangential.name}: what the engine realises at v0 (no spin before)"
            )
            law = x.e_t_target is not None
            # two spheres: relative e_t and e, each sphere's spin (they turn alike)
            pair = "two equal spheres" in x.scene
            spin = "each spin (rad/s)" if pair else "spin after (rad/s)"
            lines.append(
                f"  angle (deg)   e_t       {spin:<18}   e normal" + ("   e_t law" if law else "")
            )
            rows = zip(x.angles, x.e_t_engine, x.omega_engine, x.e_n_engine, strict=True)
            for k, (angle, e_t, omega, e_n) in enumerate(rows):
                lines.append(
                    f"  {angle:11g}   {e_t:.5f}   {omega:<18.4g}   {e_n:.5f}"
                    + (f"    {x.e_t_target[k]:.5f}" if law else "")
                )
        lines += [f"warning: {w}" for w in data["warnings"]]
        return "\n".join(lines)

    emit(args, data, text)


def _band(x, posterior: dict, name: str, args, options: dict):
    """`(x, origin, notes)`: the export `x` with the engine's band over the draws of
    `posterior` (a `Posterior.to_dict` record, as `calibrate --posterior --json` writes
    it), each exported with `options` (`export`'s), and the words for its origin, or `x`
    alone with a note saying why there is no band (no draws in the file, a user's law)."""
    from .._engines.export import with_band
    from .._posterior import Posterior

    origin = " at the posterior medians"
    if "samples" not in posterior or "z" not in posterior:
        return (
            x,
            origin,
            [
                "no engine band: the posterior in the file holds no draws (write "
                "it with 'jaximpact calibrate --posterior --json')"
            ],
        )
    if is_file_law(name):
        return x, origin, ["no engine band for a user's law (FILE.py:NAME) read from JSON"]
    try:
        post = Posterior.from_dict(posterior)
    except (KeyError, TypeError, ValueError) as error:
        raise CLIError(
            f"--from {args.source}: its posterior is not one that 'jaximpact "
            f"calibrate --posterior --json' writes ({error})"
        ) from None
    x = with_band(x, post, band_draws=args.band_draws, progress=heartbeat_meter(), **options)
    thinned = posterior.get("thinned", {})
    of = f", of {thinned['of']}" if isinstance(thinned, dict) and "of" in thinned else ""
    return x, f"{origin} (band over {x.band_draws} of its draws{of})", []


def _from_fit(path: str, args):
    """`(law, m, v0, notes, posterior)` of the fit in the JSON file `path` ('-': stdin) that
    `jaximpact calibrate --json` (or `simulate --json`) writes (`common.read_fit`): its law,
    its mass (kg) and its speed (m/s). With `calibrate --posterior --json`'s `posterior`,
    the law is at the posterior medians of its free parameters and `posterior` is that
    record (else None). `--mass` and `--law`, where given, must agree with the file; `--v0`
    picks the speed (required where the fit has several). Each missing or mismatched field
    is a one-line `CLIError`; `notes` are warnings for the output."""
    import math

    where = f"--from {path}"
    _, record, fit = read_fit(path, args.law)
    m = args.mass if fit.m is None else float(fit.m)
    if m is None:
        raise CLIError(f"{where}: no mass ('m'); give --mass (kg), the one it was fitted for")
    if args.mass is not None and not math.isclose(args.mass, m, rel_tol=1e-12):
        raise CLIError(
            f"--mass {args.mass:g} but {path} was fitted for m = {m:g} kg: the law's e and T "
            "depend on the mass; leave --mass out"
        )
    speeds, notes = sorted(set(fit.v0.tolist())), []
    span = f"{speeds[0]:g} to {speeds[-1]:g}" if speeds else ""
    if args.v0 is not None:
        v0 = args.v0
        if speeds and not (speeds[0] <= v0 <= speeds[-1]):
            notes.append(
                f"v0 = {v0:g} m/s is outside the speeds of the fit ({span} m/s): the law is "
                "extrapolated"
            )
    elif len(speeds) == 1:
        v0 = speeds[0]
    elif not speeds:
        raise CLIError(f"{where}: no impact speed ('rows'[].v0 or 'v0'); give --v0 (m/s)")
    else:
        raise CLIError(
            f"{where}: the fit has {len(speeds)} speeds ({span} m/s); give --v0, the speed "
            "the export is to be exact at"
        )
    separation = record.get("separation", "force")
    if separation != "force":
        raise CLIError(
            f"{where}: fitted with separation {separation!r}; the engines' contacts end when "
            "the force does (separation 'force'): refit with --separation force, or export "
            "the measured --e and --T"
        )
    if fit.g:
        notes.append(
            f"the fit had gravity g = {fit.g:g} m/s^2 during contact; the export's targets are "
            "the law's e and T without it"
        )
    if fit.converged is not None and not fit.converged:
        notes.append(f"the fit in {path} did not converge")
    law, posterior = fit.law, record.get("posterior")
    if posterior is not None:
        median = posterior.get("median") if isinstance(posterior, dict) else None
        if not isinstance(median, dict) or not all(map(_number, median.values())):
            raise CLIError(f"{where}: its 'posterior' has no 'median' (NAME -> number)")
        params = {k: float(v) for k, v in fit.params.items()}
        law = make_law(law.name, {**params, **{k: float(median[k]) for k in params if k in median}})
    return law, m, float(v0), notes, posterior


def add_engine_e(subparsers):
    parser = command_parser(
        subparsers,
        "engine-e",
        help="the e(v) and T(v) that given engine contact parameters produce",
        description=_engine_e_description(),
        example="jaximpact engine-e --engine mujoco --params '{\"solref\": [0.02, 1]}' "
        "--mass 0.05 --speed 0.5 1 2",
    )
    parser.add_argument(
        "--engine",
        required=True,
        metavar="NAME",
        help=_names(),
    )
    parser.add_argument("--params", required=True, metavar="JSON", help="engine parameters")
    parser.add_argument(
        "--mass",
        type=float,
        metavar="KG",
        help="mass, kg (two-sphere engines: of each sphere); required except for "
        f"{_labels(lambda e: e.MASS_DEPENDS is None)}, whose parameters are per unit mass",
    )
    parser.add_argument("--speed", type=float, nargs="+", required=True, metavar="M/S")
    _add_radius(parser)
    add_output_arguments(parser, plot=False)
    parser.set_defaults(handler=_run_engine_e)


def _engine_e_description() -> str:
    """What engine-e does, then one paragraph per engine: its keys and how it steps."""
    each = []
    for engine in _engines().values():
        needed, optional = (
            ", ".join(f'"{k.name}" ({k.unit})' for k in engine.KEYS if k.needed is flag)
            for flag in (True, False)
        )
        each.append(
            f"{engine.LABEL} (--engine {engine.NAME}): {needed}"
            + (f"; optional {optional}" if optional else "")
            + f". Stepping: {engine.STEPPING}."
        )
    return (
        "The inverse of export: given an engine's contact parameters as JSON (--params), the "
        "e and T of the continuous law the engine integrates, at each --speed, and beside "
        "them what the engine's time stepping realises where it is replicated (the mean "
        "over where first touch falls inside a step, with the range of e). The parameters, "
        "and the stepping, of each engine:\n\n" + "\n\n".join(each)
    )


def _check_engine_params(engine, params):
    """Every needed key there, every key one that `engine` reads (its `KEYS`), every value a
    number (`solref` two numbers, `limit_damping` true or false)."""
    keys = _engines()[engine].KEYS
    missing = [k.name for k in keys if k.needed and k.name not in params]
    if missing:
        raise CLIError(f"--params for {engine} needs {', '.join(missing)}")
    known = [k.name for k in keys]
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

    _check_engine(args.engine)
    try:
        params = json.loads(args.params)
    except json.JSONDecodeError as error:
        raise CLIError(f"--params is not JSON: {error.msg}") from None
    if not isinstance(params, dict):
        raise CLIError("--params must be a JSON object, e.g. '{\"solref\": [0.02, 1]}'")
    _check_engine_params(args.engine, params)
    chosen = _engines()[args.engine]
    if args.mass is None:
        if chosen.MASS_DEPENDS is not None:
            each = ", of each sphere" if chosen.TWO_SPHERES else ""
            raise CLIError(
                f"{args.engine} needs --mass (kg{each}): the e and T its parameters give "
                "depend on it"
            )
        args.mass = 1.0  # MuJoCo: per unit mass, e and T do not depend on it
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
