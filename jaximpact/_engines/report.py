"""`jaximpact export` and `jaximpact engine-e`: their help read from the registry, their
checks of input (one-line ValueErrors) and their text, rendered from the records alone."""

import math

from .._format import format_number
from .registry import ENGINES, engine as _engine


def listed(words, last: str = "and") -> str:
    """`"a, b and c"`."""
    words = list(words)
    return words[0] if len(words) == 1 else f"{', '.join(words[:-1])} {last} {words[-1]}"


def labels(where=lambda engine: True, last: str = "and") -> str:
    """The engines' labels where `where(engine)`."""
    return listed([e.LABEL for e in ENGINES.values() if where(e)], last)


def takes(key: str):
    """Whether an engine's parameters have the key `key`."""
    return lambda engine: any(k.name == key for k in engine.KEYS)


def per_kg(engine) -> bool:
    """Whether `engine`'s contact is per unit mass (its parameters from e and T alone)."""
    return engine.MASS_DEPENDS is None


def export_description() -> str:
    """What `jaximpact export` does, for its `--help`."""
    return (
        "Turn a law (--law, --param), a fit (--from FILE, the JSON of 'jaximpact calibrate "
        f"--json') or target --e and --T into the contact parameters of {labels(last='or')}, "
        "in the engine's own names and units, with a snippet to paste, a recommended time "
        "step (the coarsest at which the engine's stepping realises e within 0.5 % wherever "
        "the first touch falls and T within 0.5 %, printed as T/n too), and the e and T the "
        "engine realises (its time stepping included). Scenes: "
        f"{labels(lambda e: not e.TWO_SPHERES)}, a body of --mass on a plane; the others, two "
        "spheres each of --mass and --radius colliding head-on at relative speed --v0 "
        "(--wall: one sphere on a fixed flat wall). docs/engines.md has the formulas and "
        "measured tables.\n\n"
        "--mass has no default: every engine's parameters depend on it "
        f"({labels(per_kg)} from --e and --T alone excepted: its contact is per unit mass), "
        "and so do a law's e and T. An export the engine cannot realise at --timestep (a "
        "parameter not finite, e outside [0, 1], fewer than 5 steps per contact, or e or T "
        "more than 5 % off the target) is refused with the step that would work; --no-strict "
        "exports it anyway, with a warning."
    )


def engine_e_description() -> str:
    """What `jaximpact engine-e` does, then each engine's keys and stepping."""
    each = []
    for engine in ENGINES.values():
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


def export_text(x, *, given_step: bool, source: str | None = None, warnings=None) -> str:
    """The text of the export `x` (`source`: where its law came from; `given_step`: the
    step is the caller's; `warnings`: default `x.warnings`)."""
    from ._stepping import describe_step

    if not x.timestep:
        step = "timestep 0 (its continuous plant)"
    else:  # the coarsest step that realises the target within 0.5 %, as T/n too
        which = "given" if given_step else "recommended"
        step = f"{which} timestep {describe_step(x.timestep, x.target_T)}"
    mass = "per unit mass" if x.m is None else f"m = {format_number(x.m)} kg"
    spread = (
        x.e_range and f" (e {x.e_range[0]:.5g} to {x.e_range[1]:.5g} over where contact starts)"
    )
    lines = [
        f"{x.engine}: {x.scene}",
        *([f"from     {source}"] if source is not None else []),
        f"asked    e = {x.target_e:.6g}, T = {x.target_T:.6g} s at v0 = {x.v0:g} m/s, {mass}",
        step,
        f"realised e = {x.e:.6g}, T = {x.T:.6g} s at that step{spread or ''}",
    ]
    if x.e_band is not None:
        lines.append(
            f"band     e {x.e_band[0]:.5g} to {x.e_band[1]:.5g}, T {x.T_band[0]:.5g} to "
            f"{x.T_band[1]:.5g} s (5-95 % over {x.band_draws} posterior draws, that step)"
        )
    lines += ["parameters:", *(f"  {k} = {v}" for k, v in x.parameters.items()), "snippet:"]
    lines += [f"  {line}" for line in x.snippet.splitlines()]
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
        spin = "each spin (rad/s)" if "two equal spheres" in x.scene else "spin after (rad/s)"
        lines.append(
            f"  angle (deg)   e_t       {spin:<18}   e normal" + ("   e_t law" if law else "")
        )
        rows = zip(x.angles, x.e_t_engine, x.omega_engine, x.e_n_engine, strict=True)
        for k, (angle, e_t, omega, e_n) in enumerate(rows):
            lines.append(
                f"  {angle:11g}   {e_t:.5f}   {omega:<18.4g}   {e_n:.5f}"
                + (f"    {x.e_t_target[k]:.5f}" if law else "")
            )
    lines += [f"warning: {w}" for w in (x.warnings if warnings is None else warnings)]
    return "\n".join(lines)


def check_scene(engine: str, *, mass, radius, from_law: bool, wall: bool) -> None:
    """A one-line ValueError where an export to `engine` lacks `--mass` or `--radius`."""
    chosen = _engine(engine)
    missing = []
    if mass is None and (from_law or chosen.MASS_DEPENDS is not None):
        missing.append("--mass (kg)")
    if radius is None and chosen.TWO_SPHERES:
        missing.append("--radius (m)")
    what = " and ".join(missing)
    if "--mass (kg)" in missing:
        from .compose import missing_mass

        raise ValueError(missing_mass(engine, from_law, f"give {what}"))
    if missing:
        raise ValueError(f"{engine} needs {what} of the {'sphere' if wall else 'two spheres'}")


def reworded(run, option: str = "--no-strict"):
    """`(x, words)`: the export `run()`, its refusal raised as a one-line ValueError in the
    words of `option`, and its `UnrealisedWarning` warned again in them (`words`: the text in
    `x.warnings` -> the text shown); other warnings as they came."""
    import warnings

    from .refusal import UnrealisedExport, UnrealisedWarning

    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", UnrealisedWarning)
            x = run()
    except UnrealisedExport as refusal:
        raise ValueError(refusal.message(option)) from None
    words = {}
    for shown in caught:
        message = shown.message
        if isinstance(message, UnrealisedWarning) and message.refusal is not None:
            words[str(message)] = said = message.refusal.message(option, exported=True)
            warnings.warn(said, UnrealisedWarning, stacklevel=2)
        else:
            warnings.warn_explicit(
                message, shown.category, shown.filename, shown.lineno, source=shown.source
            )
    return x, words


def _number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def fit_source(fit, record: dict, path: str, *, mass=None, v0=None):
    """`(law, m, v0, notes, posterior)` of the fit in `record` (`calibrate --json`'s, read
    from `path`): its law (at the posterior medians, with `posterior` that record, where it
    has one), mass (kg; `mass` must agree) and speed (m/s; `v0` picks one of several).
    One-line ValueErrors; `notes`: warnings for the output."""
    where = f"--from {path}"
    m = mass if fit.m is None else float(fit.m)
    if m is None:
        raise ValueError(f"{where}: no mass ('m'); give --mass (kg), the one it was fitted for")
    if mass is not None and not math.isclose(mass, m, rel_tol=1e-12):
        raise ValueError(
            f"--mass {mass:g} but {path} was fitted for m = {m:g} kg: the law's e and T "
            "depend on the mass; leave --mass out"
        )
    speeds, notes = sorted(set(fit.v0.tolist())), []
    span = f"{speeds[0]:g} to {speeds[-1]:g}" if speeds else ""
    if v0 is not None:
        if speeds and not (speeds[0] <= v0 <= speeds[-1]):
            notes.append(
                f"v0 = {v0:g} m/s is outside the speeds of the fit ({span} m/s): the law is "
                "extrapolated"
            )
    elif len(speeds) == 1:
        v0 = speeds[0]
    elif not speeds:
        raise ValueError(f"{where}: no impact speed ('rows'[].v0 or 'v0'); give --v0 (m/s)")
    else:
        raise ValueError(
            f"{where}: the fit has {len(speeds)} speeds ({span} m/s); give --v0, the speed "
            "the export is to be exact at"
        )
    separation = record.get("separation", "force")
    if separation != "force":
        raise ValueError(
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
            raise ValueError(f"{where}: its 'posterior' has no 'median' (NAME -> number)")
        law = law.replace(**{k: float(median[k]) for k in fit.params if k in median})
    return law, m, float(v0), notes, posterior


def posterior_band(
    x, posterior: dict, path: str, *, user_law: bool, band_draws, progress, **options
):
    """`(x, origin, notes)`: the export `x` with the engine's band over the draws of
    `posterior` (`Posterior.to_dict`'s record, in the file `path`), each exported with
    `options`, and the words for its origin; or `x` and a note why there is no band."""
    from .._posterior.result import Posterior
    from .export import with_band

    origin = " at the posterior medians"
    if "samples" not in posterior or "z" not in posterior:
        why = (
            "no engine band: the posterior in the file holds no draws (write it with "
            "'jaximpact calibrate --posterior --json')"
        )
        return x, origin, [why]
    if user_law:
        return x, origin, ["no engine band for a user's law (FILE.py:NAME) read from JSON"]
    try:
        post = Posterior.from_dict(posterior)
    except (KeyError, TypeError, ValueError) as error:
        raise ValueError(
            f"--from {path}: its posterior is not one that 'jaximpact calibrate --posterior "
            f"--json' writes ({error})"
        ) from None
    x = with_band(x, post, band_draws=band_draws, progress=progress, **options)
    thinned = posterior.get("thinned", {})
    of = f", of {thinned['of']}" if isinstance(thinned, dict) and "of" in thinned else ""
    return x, f"{origin} (band over {x.band_draws} of its draws{of})", []


def check_parameters(engine: str, params) -> None:
    """A one-line ValueError unless `params` (JSON) has every needed key of `engine`'s `KEYS`,
    no other, and numbers (`solref` two, `limit_damping` true or false)."""
    if not isinstance(params, dict):
        raise ValueError("--params must be a JSON object, e.g. '{\"solref\": [0.02, 1]}'")
    keys = _engine(engine).KEYS
    missing = [k.name for k in keys if k.needed and k.name not in params]
    if missing:
        raise ValueError(f"--params for {engine} needs {', '.join(missing)}")
    known = [k.name for k in keys]
    unknown = [k for k in params if k not in known]
    if unknown:
        raise ValueError(
            f"--params for {engine} has no key {', '.join(map(repr, unknown))}; "
            f"it takes {', '.join(known)}"
        )
    for key, value in params.items():
        if key == "limit_damping":
            if not isinstance(value, bool):
                raise ValueError(f"limit_damping must be true or false, got {value!r}")
        elif key == "solref":
            if not (isinstance(value, list) and len(value) == 2 and all(map(_number, value))):
                raise ValueError("solref must be two numbers, [timeconst, dampratio]")
        elif not _number(value):
            raise ValueError(f"{key} must be a number, got {value!r}")


def response_record(engine: str, params: dict, *, m, speeds, radius=None) -> dict:
    """`jaximpact engine-e --json`'s record: what `params` realise in `engine` for mass `m`
    (kg; None: per unit mass, where the engine allows) at `speeds` (m/s)."""
    from .response import engine_response, stepped_response

    chosen = _engine(engine)
    if m is None and chosen.MASS_DEPENDS is not None:
        each = ", of each sphere" if chosen.TWO_SPHERES else ""
        raise ValueError(
            f"{engine} needs --mass (kg{each}): the e and T its parameters give depend on it"
        )
    m = 1.0 if m is None else m  # MuJoCo: per unit mass, e and T do not depend on it

    law, separation, e, T = engine_response(engine, params, m=m, speeds=speeds, radius=radius)
    stepped = stepped_response(engine, params, m=m, speeds=speeds, radius=radius)
    return {
        "engine": engine,
        "law": {"name": law.name, "parameters": {k: float(v) for k, v in law.parameters.items()}},
        "separation": separation,
        "speeds": list(speeds),
        "e": list(e),
        "T": list(T),
        "stepped": None
        if stepped is None
        else dict(zip(("timestep", "e", "T", "e_min", "e_max"), stepped, strict=True)),
    }


def response_text(data: dict) -> str:
    """The text of a `response_record`."""
    e, T, stepped = data["e"], data["T"], data["stepped"]
    lines = [f"{data['engine']}: law {data['law']['name']} ({data['separation']} criterion)"]
    if stepped is None:
        lines.append("speed (m/s)   e   T (s)   (continuous law)")
        lines += [
            f"  {format_number(v):>9}   {ei:.5g}   {Ti:.5g}"
            for v, ei, Ti in zip(data["speeds"], e, T, strict=True)
        ]
        return "\n".join(lines)
    e_s, T_s, e_lo, e_hi = (stepped[k] for k in ("e", "T", "e_min", "e_max"))
    lines.append(
        f"speed (m/s)   e   T (s)   (continuous law) | e   T (s)   e range   "
        f"(stepped at {format_number(stepped['timestep'])} s)"
    )
    lines += [
        f"  {format_number(v):>9}   {e[i]:.5g}   {T[i]:.5g} | {e_s[i]:.5g}   {T_s[i]:.5g}   "
        f"{e_lo[i]:.5g}-{e_hi[i]:.5g}"
        for i, v in enumerate(data["speeds"])
    ]
    return "\n".join(lines)
