"""The steps of an export, as LAMMPS's `GranularModel::calculate_forces` composes its
sub-models: the request checked and the engine's normal model found (`request`), the
normal model designed (`design`), refused or warned where the engine cannot realise it
(`refusal`), its e(v) reported (`report`), the tangential model added and its promise made
(`tangential`, `promise.py`), and the materials checked (`modulus`). `export.export` is
their composition."""

import dataclasses
import warnings as _warnings

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


@dataclasses.dataclass(frozen=True)
class Request:
    """An export's request, checked: the engine `chosen`, its `normal` model for the law
    (`lacked`: the engine lacks the law, its nearest exported), its tangential model `slot`
    (None without a tangential law), the `scene` (SI), the `speeds` given (m/s, a law the
    engine lacks) or None, the `timestep` (s or None), the targets `target_e`, `target_T`
    (s), the law `source` (None from targets) and the design's `options` (`poisson`,
    `limit_damping`)."""

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
    def source(self):
        return self.scene.law

    @property
    def law_m(self) -> float:
        """The mass (kg) the contact moves (`base.contact_mass`)."""
        return contact_mass(self.chosen, self.scene.m, self.scene.geometry)


def request(
    chosen: AbstractEngine,
    law_or_fit,
    *,
    m,
    v0,
    timestep,
    radius,
    poisson,
    e,
    T,
    limit_damping,
    geometry,
    tangential,
    engines,
    missing_mass,
) -> Request:
    """The `Request` of `export`'s arguments to engine `chosen`, each refused in one line in
    `export`'s order: what needs no law's impact first (a law's e and T compile)."""
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
    slot = None if tangential is None else _slot(chosen, tangential, timestep, engines)
    source, target_e, target_T = targets(law_or_fit, e=e, T=T, m=m, v0=v0, speeds=speeds)
    if target_T is not None:
        check_scales(m, v0, target_T)
    if chosen.TWO_SPHERES and target_T is None:
        raise ValueError(f"{chosen.NAME} needs a contact duration: pass T= (s) or a law")
    options = dict(poisson=0.3 if poisson is None else poisson, limit_damping=limit_damping)
    return Request(
        chosen,
        normal,
        lacked,
        slot,
        Scene(m, v0, radius, geometry, source),
        speeds,
        timestep,
        target_e,
        target_T,
        options,
    )


def design(asked: Request, tangential) -> Design:
    """The normal model's design for the request; designed again where its tangential model
    ties it to a Poisson's ratio (LIGGGHTS), and where no step was given, at the steps per
    contact its tangential promise was measured at (`TANGENTIAL_STEPS`) at most."""
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
    """The T (s) the export aims at: the one asked, or the design's (MuJoCo without T: its
    default timeconst's)."""
    return asked.target_T if out.target_T is None else out.target_T


def refusal(asked: Request, out: Design, *, strict: bool) -> list[str]:
    """The refusal (`UnrealisedExport`) of a design its engine cannot realise at its step,
    or with `strict=False` its warning (also returned, as a line); else no line."""
    target_T = aimed_T(asked, out)
    reason = unrealised(out, asked.target_e, target_T)
    if reason is None:
        return []
    step = working_step(asked.normal, asked.target_e, target_T, asked.scene, asked.options)
    refused = UnrealisedExport(
        asked.chosen.NAME,
        out.timestep,
        reason,
        step,
        continuous=asked.chosen.CONTINUOUS_PLANT,
        T=target_T,
    )
    if strict:
        raise refused
    anyway = UnrealisedWarning(refused)
    _warnings.warn(anyway, stacklevel=3)
    return [str(anyway)]


def report(asked: Request, out: Design, engine_law, *, curves: bool):
    """`(fields, first, last)`: the `Export`'s curves (with `curves`, or where the law is
    one the engine lacks, whose line needs them), and the lines of warning they give: the
    nearest law's (`first`) or where the engine's e(v) departs from the law's (`last`)."""
    if not (curves or asked.lacked):
        return {}, [], []
    scene, normal = asked.scene, asked.normal
    stepping = (
        None
        if out.stepping is None
        else normal.stepper(out.stepping, m=scene.m, radius=scene.radius)
    )
    fields, note = responses(
        engine_law,
        asked.law_m,
        out,
        stepping,
        scene.law,
        m=scene.m,
        v0=scene.v0,
        speeds=asked.speeds,
    )
    if asked.lacked and (note or asked.speeds is not None):
        return (
            fields,
            [
                nearest(
                    asked.chosen,
                    normal,
                    scene.law,
                    fields,
                    asked.target_e,
                    fitted=asked.speeds is not None,
                    v0=scene.v0,
                )
            ],
            [],
        )
    return fields, [], [note] if note else []


def tangential(asked: Request, out: Design, engine_law, given):
    """`(parameters, fields, lines)`: the design's parameters with the tangential model's
    (the `given` tangential law's forces scaled as the normal law's: the scene moves
    `law_m` where the law moves `m`), the `Export`'s oblique fields and the lines of
    warning of its promise (`promise.tangential_promise`); without a tangential law, the
    design's parameters alone."""
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
    """Where, with a radius, the contact's stiffness or the `exported` tangential law's shear
    modulus is no material's (`materials.modulus_warnings`)."""
    scene = asked.scene
    if scene.radius is None:
        return []
    law_m = asked.law_m
    c = hertz_constant(engine_law, scene.v0)
    if c is None and scene.law is not None:  # the engine's law is not Hertz's: the given law's
        c = hertz_constant(scene.law, scene.v0)
        c = None if c is None else c * law_m / scene.m
    return modulus_warnings(
        c,
        exported,
        radius=scene.radius,
        poisson=asked.options["poisson"],
        two_spheres=law_m != scene.m,
    )


def _radius(chosen: AbstractEngine, radius, geometry: str, tangential):
    """The spheres' radius (m) checked, or None where the engine takes none; a one-line
    ValueError where a two-sphere engine, or a tangential law, needs it."""
    if chosen.TWO_SPHERES:
        radius = sphere_radius(chosen.NAME, radius, geometry)
    if tangential is not None and radius is None:  # a two-sphere engine asked for it above
        raise ValueError(
            f"{chosen.NAME} with a tangential law needs the sphere's radius (its friction's "
            "lever arm and inertia): pass radius= (m)"
        )
    return radius


def _slot(chosen: AbstractEngine, tangential, timestep, engines):
    """The row of `chosen.TANGENTIAL` for `tangential`, checked at `timestep` (s or None),
    or a one-line ValueError: an engine without tangential models names those with, an
    engine without this law says what its model is."""
    slot = chosen.TANGENTIAL.get(tangential.name)
    if slot is None and not chosen.TANGENTIAL:
        exact = [n for n, e in engines.items() if e.TANGENTIAL and e.FRICTION is None]
        friction = [n for n, e in engines.items() if e.FRICTION is not None]
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
