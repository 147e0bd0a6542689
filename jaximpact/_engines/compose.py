"""The steps of an export, as LAMMPS's `GranularModel::calculate_forces` composes its
sub-models: the request checked (`request`), the normal model designed (`design`) and
refused where unrealised (`refusal`), its e(v) (`report`), the tangential model and its
promise (`tangential`), the materials checked (`modulus`)."""

import dataclasses
import warnings as _warnings
from typing import NamedTuple

from . import _stepping
from .base import (
    AbstractEngine,
    AbstractNormalModel,
    Design,
    Scene,
    contact_mass,
    scene_geometry,
    sphere_radius,
)
from .materials import hertz_constant, modulus_warnings
from .promise import TANGENTIAL_STEPS, tangential_promise
from .refusal import UnrealisedExport, UnrealisedWarning, unrealised, working_step
from .registry import ENGINES
from .targets import (
    check_scales,
    given_speeds,
    inputs,
    law_of,
    nearest,
    normal_model,
    responses,
    targets,
)


def missing_mass(engine: str, from_law: bool, how: str) -> str:
    """The one-line reason an export to `engine` needs the mass (`how`: how to give it)."""
    chosen = ENGINES[engine]
    each = " of each sphere" if chosen.TWO_SPHERES else ""
    why = [chosen.MASS_DEPENDS] if chosen.MASS_DEPENDS else []
    if from_law:
        why.append("the law's e and T at v0 depend on it")
    per_kg = " and ".join(e.LABEL for e in ENGINES.values() if e.MASS_DEPENDS is None)
    return (
        f"{engine} needs the mass{each}: {how}; {' and '.join(why)} ({per_kg} from target e "
        "and T alone needs none)"
    )


class Given(NamedTuple):
    """`export`'s arguments of the scene and the design, as given (SI units, None: unset)."""

    m: object
    v0: object
    timestep: object
    radius: object
    poisson: object
    limit_damping: bool
    geometry: str | None
    tangential: object


@dataclasses.dataclass(frozen=True)
class Request:
    """An export's request, checked: the engine `chosen`, its `normal` model for the law
    (`lacked`: the engine lacks the law), the tangential model `slot` (or None), the `scene`,
    the `speeds` given for a law the engine lacks (or None), the `timestep` (s or None), the
    targets and the design's `options` (`poisson`, `limit_damping`)."""

    chosen: AbstractEngine
    normal: AbstractNormalModel
    lacked: bool
    slot: object
    scene: Scene
    speeds: tuple | None
    timestep: float | None
    target_e: float
    target_T: float | None
    options: dict

    @property
    def m(self) -> float:
        return self.scene.m

    @property
    def law_m(self) -> float:
        """The mass (kg) the contact moves (`base.contact_mass`)."""
        return contact_mass(self.chosen, self.scene.m, self.scene.geometry)


def request(chosen: AbstractEngine, law_or_fit, e, T, given: Given) -> Request:
    """The `Request` of `export`'s arguments, each refused in one line in `export`'s order:
    what needs no law's impact first (a law's e and T compile)."""
    m, v0, timestep, radius, poisson, limit_damping, geometry, tangential = given
    geometry = scene_geometry(chosen, geometry)
    normal, lacked = normal_model(chosen, None if law_or_fit is None else law_of(law_or_fit))
    if limit_damping and not normal.ALLOWS_LIMIT_DAMPING:  # as GranularModel::init()
        raise ValueError(
            f"{chosen.LABEL} refuses limit_damping with its {normal.NAME} model "
            "(a cohesive normal model): drop limit_damping"
        )
    v0, speeds = given_speeds(v0, lacked, chosen)
    if m is None and (law_or_fit is not None or chosen.MASS_DEPENDS is not None):
        raise ValueError(missing_mass(chosen.NAME, law_or_fit is not None, "pass m= (kg)"))
    # MuJoCo from targets: per unit mass (the export does not depend on it)
    m, v0, timestep, poisson = inputs(1.0 if m is None else m, v0, timestep, poisson)
    radius = _radius(chosen, radius, geometry, tangential)
    slot = None if tangential is None else _slot(chosen, tangential, timestep)
    source, target_e, target_T = targets(law_or_fit, e=e, T=T, m=m, v0=v0, speeds=speeds)
    if target_T is not None:
        check_scales(m, v0, target_T)
    if chosen.TWO_SPHERES and target_T is None:
        raise ValueError(f"{chosen.NAME} needs a contact duration: pass T= (s) or a law")
    options = dict(poisson=0.3 if poisson is None else poisson, limit_damping=limit_damping)
    scene = Scene(m, v0, radius, geometry, source)
    return Request(
        chosen, normal, lacked, slot, scene, speeds, timestep, target_e, target_T, options
    )


def design(asked: Request, tangential) -> Design:
    """The normal model's design; again at the Poisson's ratio its tangential model ties it
    to (LIGGGHTS), and without a given step at `TANGENTIAL_STEPS` per contact at most (where
    the tangential promise was measured)."""
    normal, slot, options = asked.normal, asked.slot, asked.options

    def make(timestep):
        return normal.design(
            asked.target_e, asked.target_T, asked.scene, timestep=timestep, **options
        )

    out = make(asked.timestep)
    if slot is None:
        return out
    tied = slot.poisson(out, tangential)
    if tied is not None and tied != options["poisson"]:
        options["poisson"] = tied
        out = make(asked.timestep)
    if asked.timestep is None and out.timestep:
        fine = _stepping.nice_down(out.T / TANGENTIAL_STEPS)
        if out.timestep > fine:
            out = make(fine)
    return out


def aimed_T(asked: Request, out: Design):
    """The T (s) aimed at: the one asked, or the design's (MuJoCo's default timeconst's)."""
    return asked.target_T if out.target_T is None else out.target_T


def refusal(asked: Request, out: Design, *, strict: bool) -> list[str]:
    """Raises `UnrealisedExport` where the engine cannot realise the design at its step, or
    with `strict=False` warns and returns the warning's line; else no line."""
    target_T = aimed_T(asked, out)
    reason = unrealised(out, asked.target_e, target_T)
    if reason is None:
        return []
    step = working_step(asked.normal, asked.target_e, target_T, asked.scene, asked.options)
    chosen = asked.chosen
    refused = UnrealisedExport(
        chosen.NAME, out.timestep, reason, step, continuous=chosen.CONTINUOUS_PLANT, T=target_T
    )
    if strict:
        raise refused
    anyway = UnrealisedWarning(refused)
    _warnings.warn(anyway, stacklevel=3)
    return [str(anyway)]


def report(asked: Request, out: Design, engine_law, *, curves: bool):
    """`(fields, first, last)`: the `Export`'s curves (with `curves`, or for a law the engine
    lacks) and their warning lines: the nearest law's (`first`), or where the engine's e(v)
    departs from the law's (`last`)."""
    if not (curves or asked.lacked):
        return {}, [], []
    scene, normal, fitted = asked.scene, asked.normal, asked.speeds is not None
    m, radius = scene.m, scene.radius
    stepping = None if out.stepping is None else normal.stepper(out.stepping, m=m, radius=radius)
    fields, note = responses(engine_law, asked.law_m, out, stepping, scene, asked.speeds)
    if asked.lacked and (note or fitted):
        line = nearest(asked.chosen, normal, scene, fields, asked.target_e, fitted=fitted)
        return fields, [line], []
    return fields, [], [note] if note else []


def tangential(asked: Request, out: Design, engine_law, given):
    """`(parameters, fields, lines)`: the design's parameters with the tangential model's
    (the `given` law's forces scaled as the normal law's, by `law_m / m`), the `Export`'s
    oblique fields and its promise's warnings; without a tangential law, the design's."""
    if asked.slot is None:
        return out.parameters, {}, []
    scene = asked.scene
    exported = given.forces_scaled(asked.law_m / scene.m)
    parameters = asked.slot.parameters(out, exported)
    fields, lines = tangential_promise(
        asked.chosen, asked.slot, out, parameters, engine_law, exported, given, scene
    )
    return parameters, fields, lines


def modulus(asked: Request, engine_law, exported) -> list[str]:
    """`materials.modulus_warnings` of the contact's Hertz constant and the `exported`
    tangential law, with a radius."""
    scene = asked.scene
    if scene.radius is None:
        return []
    law_m = asked.law_m
    c = hertz_constant(engine_law, scene.v0)
    if c is None and scene.law is not None:  # the engine's law is not Hertz's: the given law's
        c = hertz_constant(scene.law, scene.v0)
        c = None if c is None else c * law_m / scene.m
    poisson, two_spheres = asked.options["poisson"], law_m != scene.m
    return modulus_warnings(
        c, exported, radius=scene.radius, poisson=poisson, two_spheres=two_spheres
    )


def _radius(chosen: AbstractEngine, radius, geometry: str, tangential):
    """The spheres' radius (m) checked, or None where none is needed (a one-line ValueError
    where a two-sphere engine, or a tangential law, needs it)."""
    if chosen.TWO_SPHERES:
        radius = sphere_radius(chosen.NAME, radius, geometry)
    if tangential is not None and radius is None:  # a two-sphere engine asked for it above
        raise ValueError(
            f"{chosen.NAME} with a tangential law needs the sphere's radius (its friction's "
            "lever arm and inertia): pass radius= (m)"
        )
    return radius


def _slot(chosen: AbstractEngine, tangential, timestep):
    """The row of `chosen.TANGENTIAL` for `tangential`, checked at `timestep`, or a one-line
    ValueError naming the engines with tangential models, or what the engine's model is."""
    slot = chosen.TANGENTIAL.get(tangential.name)
    if slot is None and not chosen.TANGENTIAL:
        exact = [n for n, e in ENGINES.items() if e.TANGENTIAL and e.FRICTION is None]
        friction = [n for n, e in ENGINES.items() if e.FRICTION is not None]
        names = [*exact, *friction]
        raise ValueError(
            f"{chosen.LABEL} has no tangential export yet (the normal law is exported alone); "
            f"export tangential laws to {', '.join(names[:-1])} or {names[-1]}"
        )
    if slot is None:
        model = next(iter(chosen.TANGENTIAL.values())).MODEL
        raise ValueError(
            f"{model}, not {tangential.name!r}: export a {' or '.join(chosen.TANGENTIAL)} law"
        )
    slot.check(tangential, timestep=timestep)
    return slot
