"""`export`: from a law, a fit or target e and T to an engine's own contact parameters, with
the e and T that the engine will realise; `ENGINES`, the one registry of the engines that
`export`, `engine_response`, `stepped_response` and the command line read."""

import dataclasses
import warnings as _warnings

import numpy as np

from .._checks import check_scale
from .._choices import unknown_name
from . import _stepping, chrono, drake, lammps, liggghts, mujoco, yade
from .base import AbstractEngine, Design
from .materials import (
    check_poisson,
    check_positive,
    check_restitution,
    hertz_constant,
    modulus_warnings,
)

# The registry, in the order messages list the engines: one final `AbstractEngine` each.
# A new engine is its module and one line here (docs/layout.md, "Adding an engine").
ENGINES: dict[str, AbstractEngine] = {
    engine.NAME: engine
    for engine in (
        mujoco.Mujoco(),
        lammps.Lammps(),
        drake.Drake(),
        liggghts.Liggghts(),
        chrono.Chrono(),
        yade.Yade(),
    )
}
_SPEED_FACTORS = (0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0)


class UnrealisedExport(ValueError):
    """An export its engine cannot realise at the given step (`_stepping.unrealised`): the
    `engine`, its time `step` (s), the `reason`, and `working` (s), a step that realises the
    target (0.0: Drake's continuous plant; None where none was found); `continuous`: the
    engine also has a continuous plant (time step 0); `T` (s): the target duration, by
    which the steps are also told as T/n."""

    def __init__(self, engine: str, step, reason: str, working, *, continuous: bool = False,
                 T=None):  # fmt: skip
        self.engine, self.step, self.reason, self.working = engine, step, reason, working
        self.continuous, self.T = continuous, T
        super().__init__(self.message("strict=False"))

    def message(self, option: str, *, exported: bool = False) -> str:
        """The one line: the refusal, ending with how to export it anyway (`option`:
        `"strict=False"` in Python, `"--no-strict"` on the command line), or with
        `exported` the warning of an export made anyway with that option."""
        if self.working is None:
            fix = f"no time step down to T/{_stepping.MAX_STEPS} realises it"
        elif self.working == 0.0:
            fix = "use time_step = 0 (its continuous plant)"
        else:
            fix = f"use a time step of {self.working:.3g} s or less"
            if self.T:
                fix += f" ({_stepping.per_contact(self.working, self.T)})"
            if self.continuous:
                fix += " (or time_step = 0, its continuous plant)"
        if exported:
            tail = f"; exported anyway ({option})"
        else:
            tail = f", or pass {option} to export it anyway"
        return (
            f"{self.engine} cannot realise the target at time step "
            f"{_stepping.describe_step(self.step, self.T)}: {self.reason}; {fix}{tail}"
        )


class UnrealisedWarning(UserWarning):
    """`export(..., strict=False)` of an export its engine cannot realise, built from the
    `refusal` it would have raised (an `UnrealisedExport`, kept as `.refusal`: its `message`
    in other words, as the command line's) or from a text (`.refusal` None)."""

    def __init__(self, refusal):
        self.refusal = refusal if isinstance(refusal, UnrealisedExport) else None
        text = refusal if self.refusal is None else refusal.message("strict=False", exported=True)
        super().__init__(text)


def missing_mass(engine: str, from_law: bool, how: str) -> str:
    """The one-line reason an export to `engine` needs the mass (`how`: how to give it)."""
    chosen = _engine(engine)
    each = " of each sphere" if chosen.TWO_SPHERES else ""
    why = [chosen.MASS_DEPENDS] if chosen.MASS_DEPENDS else []
    if from_law:
        why.append("the law's e and T at v0 depend on it")
    per_kg = " and ".join(e.LABEL for e in ENGINES.values() if e.MASS_DEPENDS is None)
    return (
        f"{engine} needs the mass{each}: {how}; {' and '.join(why)} ({per_kg} from target e "
        "and T alone needs none)"
    )


@dataclasses.dataclass(frozen=True)
class Export:
    """An engine's contact parameters and what the engine realises with them.

    - `engine`, `scene`: the engine and the collision the promise is for.
    - `parameters`: the engine's own names and units (MuJoCo `solref`, `solimp`, `timestep`;
      Drake `point_contact_stiffness` N/m, `hunt_crossley_dissipation` s/m, `time_step` s;
      LAMMPS `pair_style`, `pair_coeff`, `timestep`, the strings its input takes, SI units).
    - `snippet`: text to paste into the engine's model or script.
    - `e`, `T` (s): what the engine realises at `v0` with `timestep` (its time stepping
      included: the mean over where the first touch falls inside a step); `e_range`,
      `T_range`: their extremes over those start phases (None for Drake's continuous plant).
    - `timestep` (s): the given step, or the recommended one: the coarsest at which the
      engine's replicated stepping realises e within 0.5 % of the target wherever the first
      touch falls and T (the mean over those start phases) within 0.5 %
      (`_stepping.recommended_step`; T/100 for Chrono, whose stepper is not replicated; at
      most T/400 with a tangential law); `steps_per_contact`.
    - `target_e`, `target_T`: what was asked (the law's e and T at `v0`, or the targets).
      With `v0=[...]` (a law the engine lacks): `v0` is the speeds' geometric middle,
      `target_e` the middle of the law's e over them, `speeds` those given.
    - `law` (SI units), `law_m` (kg), `separation`: the engine's contact as a jaximpact law,
      for every engine the law whose impact at the export's effective mass `law_m` is the
      engine's contact without its time stepping: `impact(x.law, m=x.law_m, v0=x.v0,
      separation=x.separation)`. `law_m` is the mass the contact moves: `m/2` for two equal
      spheres of mass `m` (the default scene of LAMMPS, LIGGGHTS, Yade and Chrono; `law`'s
      forces are then half those of a law that moves `m` alike), `m` for a body on a plane
      or wall (MuJoCo, Drake, `geometry="wall"`; 1 kg for MuJoCo from targets alone, its
      contact per unit mass). That impact gives `target_e` and `target_T` (to 1e-6)
      where the design inverts the engine's continuous law (LAMMPS's hertz/material and
      dmt, LIGGGHTS, Yade, Chrono, Drake's continuous plant), `e` and `T` then being the
      same within the stepping's error (the 0.5 % above at the recommended step). MuJoCo
      and Drake's discrete plant set their law off the target by their stepping's own bias,
      so that the stepping lands on it: the law's e and T are then what the replica gives
      as the step vanishes. LAMMPS's jkr models break the neck at the least force, which no
      jkr law does: `law` is the jkr law whose neck takes LAMMPS's energy per impact (its
      e is LAMMPS's continuous e at every speed, its contact longer, by 0.3 % at e = 0.95 to
      7 % at e = 0.2), and with `damping viscoelastic` the `jkr_viscoelastic` law alike (its
      e and T within 0.3 % of the target, LAMMPS's continuous impact, for the rubber-like
      spheres of tests/engines). For a law the engine lacks (`thornton`), `law` is the
      nearest law it has.
    - `speeds` (m/s), `e_engine`, `T_engine`, `e_target`, `T_target`: e(v) and T(v) that the
      engine realises (its time stepping included where it is replicated, as `e` is; else
      its continuous law) and of the given law (None when targets were given) over a range
      of speeds.
    - `warnings`: where the engine will not do what was asked, or only with care; among them
      where, with a radius, the contact's Hertz constant implies a Young's modulus no
      material has (outside 1e5 to 1e12 Pa, by `c = 4/3 E* sqrt(R*)`), or a tangential
      law's shear modulus lies more than a factor 100 from its `E / (2 (1 + nu))`
      (`materials.modulus_warnings`).
    - With a tangential law (`export(tangential=...)`): `tangential`, the engine's (as
      `law`: the given one, its forces halved for two spheres of mass `m` as the normal
      law's are, so that the pair moves as the law moves `m`), and at `v0` from
      `angles` (degrees from the normal) the tangential restitution `e_t_engine`, the
      spin after `omega_engine` (rad/s; of each sphere for two spheres, which turn alike,
      the sense that rolls a sphere on the wall along its tangential velocity) and the
      normal restitution `e_n_engine` that the
      engine realises, no spin before: MuJoCo's Euler step replicated (the mean over
      first-touch phases; equal to MuJoCo to round-off, tests/engines), Drake's continuous
      plant integrated (scipy's Radau at rtol 1e-10; equal to Drake to 1e-8), else the engine's
      continuous laws (LAMMPS: the real LAMMPS on a wall within 0.002 at the recommended
      step, two spheres within 0.01, whose line of centres turns during contact: a
      warning estimates by how much where it matters); and
      `e_t_target`, the given laws' at mass `m` (the pair's effective radius and inertia
      for two spheres; None from targets).
    """

    engine: str
    scene: str
    parameters: dict
    snippet: str
    e: float
    T: float
    timestep: float | None
    warnings: tuple[str, ...]
    target_e: float
    target_T: float
    m: float
    v0: float
    e_range: tuple | None = None
    T_range: tuple | None = None
    steps_per_contact: float | None = None
    law: object = None
    law_m: float | None = None
    separation: str = "force"
    speeds: tuple = ()
    e_engine: tuple = ()
    T_engine: tuple = ()
    e_target: tuple | None = None
    T_target: tuple | None = None
    tangential: object = None
    angles: tuple = ()
    e_t_engine: tuple = ()
    omega_engine: tuple = ()
    e_n_engine: tuple = ()
    e_t_target: tuple | None = None

    def to_dict(self) -> dict:
        laws = ("law", "tangential")
        out = {
            f.name: getattr(self, f.name) for f in dataclasses.fields(self) if f.name not in laws
        }
        for name in laws:
            law = getattr(self, name)
            parameters = {} if law is None else {k: float(v) for k, v in law.parameters.items()}
            out[name] = None if law is None else {"name": law.name, "parameters": parameters}
        return out


def _law_of(law_or_fit):
    from .._laws import AbstractLaw

    if isinstance(law_or_fit, AbstractLaw):
        return law_or_fit
    inner = getattr(law_or_fit, "law", None)
    if isinstance(inner, AbstractLaw):
        return inner
    raise ValueError(
        "export needs a law (jaximpact.law(...)), a fit (calibrate's result) or None with "
        f"e= and T=; got {type(law_or_fit).__name__}"
    )


def _curve(law, m, speeds, separation):
    from .._solve.impact import impact

    es, Ts = [], []
    for v in speeds:
        r = impact(law, m=m, v0=float(v), separation=separation)
        es.append(float(r.e))
        Ts.append(float(r.T))
    return tuple(es), tuple(Ts)


def export(
    law_or_fit,
    engine: str,
    *,
    m=None,
    v0,
    timestep=None,
    radius=None,
    poisson=None,
    e=None,
    T=None,
    limit_damping: bool = False,
    geometry: str | None = None,
    curves: bool = True,
    strict: bool = True,
    tangential=None,
) -> Export:
    """Parameters for `engine` (`"mujoco"`, `"drake"`, `"lammps"`, `"liggghts"`, `"chrono"`,
    `"yade"`)
    that realise the e and T of `law_or_fit` (a law or `calibrate`'s fit) for mass `m` (kg)
    at impact speed `v0` (m/s), or the targets `e` and `T` (s) when `law_or_fit` is None.

    The scene: MuJoCo and Drake, a body of mass `m` on a fixed plane; LAMMPS, LIGGGHTS, Chrono
    and Yade, two spheres each of mass `m` and radius `radius` (m, required) colliding head-on
    at relative speed `v0` (Chrono by its source's formula, not run here)
    (`poisson`: their Poisson's ratio, default 0.3; `limit_damping`: keep the force
    non-attractive). `geometry="wall"`: instead one sphere of mass `m` and radius `radius`
    hitting a fixed flat wall at speed `v0` (LAMMPS `fix wall/gran`, LIGGGHTS a primitive
    wall, Yade a fixed wall body, Chrono a fixed box; the drop test); `"spheres"` (the
    default for those engines) is the pair. MuJoCo and Drake have only their body on a plane
    (`"wall"` is accepted for them and changes nothing). `timestep` (s): the engine's step
    if already chosen (the export then corrects for it where it can and warns where it
    cannot); default, the recommended step (`Export.timestep`: the coarsest at which the
    engine's stepping realises the target within 0.5 %).
    The returned `Export` states what the engine realises, computed through a replica of its
    time stepping (MuJoCo, LAMMPS) checked against the engines in tests/engines.

    `m` has no default: every engine's parameters depend on it (LAMMPS, LIGGGHTS, Chrono:
    the Young's modulus; Yade: the density; Drake: the stiffness), and so do a law's e and T
    at `v0`. MuJoCo from targets alone (`law_or_fit` None) needs none: solref scales the
    contact per unit mass (the `Export`'s `m` is then None, its `law` per kg).

    Laws with a contact state: a `jkr` law goes to LAMMPS's own `jkr` normal model
    (`lammps_jkr`: its cohesion set so that LAMMPS takes the law's energy per impact, so
    its e(v) is the law's at every speed, and its E for T at `v0`; a warning says how its
    neck differs from JKR's). A `thornton` law (any engine), or a `jkr` law to an engine
    without JKR, goes to the engine's nearest law, with a first warning line that says so
    and how far that law's e(v) departs from the law's (worst |de|); `v0` may then be a
    list of speeds (m/s): e is set to the middle of the law's e over them (a speed-free
    e's best worst case), T to the law's at their geometric middle, and the report covers
    those speeds.

    `tangential`: a tangential law (`tangential_law(...)`) exported with the normal one,
    to an engine that has it exactly (`AbstractEngine.TANGENTIAL`: LAMMPS's
    `linear_history`, `mindlin`, `mindlin/force`), or as its friction `mu` alone to an
    engine with friction and no tangential spring (`AbstractEngine.FRICTION`: MuJoCo's
    pyramidal cone; Drake's Stribeck-regularised Coulomb friction, continuous plant only;
    `radius` needed; a warning says how far its e_t falls and how its normal e moves);
    the `Export` then also holds the oblique impacts the engine realises at `v0` from
    `OBLIQUE_ANGLES` (degrees from the normal): `e_t_engine`, `omega_engine` (rad/s),
    `e_n_engine`, and the law's `e_t_target`. Another engine: a one-line ValueError.

    An export the engine cannot realise at `timestep` is refused: an `UnrealisedExport`
    (a `ValueError`) that names the step that would work (`.working`, told as T/n too), or
    with `strict=False` an `UnrealisedWarning` (also in `Export.warnings`) and the export
    anyway. It cannot realise it when a
    parameter is not finite, when what it realises is no impact (e or T not finite, e
    outside [0, 1], T <= 0), when fewer than 5 steps resolve the contact (T over the step),
    or when its e or T (the mean over where first touch falls inside a step) misses the
    target by more than 5 % (`_stepping.unrealised`).

    **Example**: `export(law("hertz_rate", c=2e6, b1=800.0), "mujoco", m=1.0, v0=2.5).parameters`.
    """
    chosen = _engine(engine)
    geometry = chosen.geometry(geometry)
    m_given = m is not None
    chosen, lacked = _native(chosen, None if law_or_fit is None else _law_of(law_or_fit))
    chosen.check_limit_damping(limit_damping)  # refused before the law's e and T
    v0, speeds = _speeds(v0, lacked, chosen)
    m, v0, timestep, poisson = _inputs(chosen, law_or_fit, m, v0, timestep, poisson)
    # what is refused without the law's impact comes first (a law's e and T compile)
    if chosen.TWO_SPHERES:
        if radius is None:
            what = "sphere's" if geometry == "wall" else "spheres'"
            raise ValueError(f"{engine} needs the {what} radius: pass radius= (m)")
        radius = check_positive("radius", radius, "m")
    if tangential is not None:  # refused before any work by an engine without it
        if radius is None:  # a two-sphere engine asked for it above
            raise ValueError(
                f"{engine} with a tangential law needs the sphere's radius (its friction's "
                "lever arm and inertia): pass radius= (m)"
            )
        chosen.check_tangential(tangential, radius=radius, timestep=timestep)
    source, target_e, target_T = _targets(law_or_fit, e=e, T=T, m=m, v0=v0, speeds=speeds)
    if target_T is not None:
        _check_scales(m, v0, target_T)
    if chosen.TWO_SPHERES and target_T is None:
        raise ValueError(f"{engine} needs a contact duration: pass T= (s) or a law")
    options = dict(m=m, v0=v0, radius=radius, poisson=0.3 if poisson is None else poisson,
                   limit_damping=limit_damping, geometry=geometry)  # fmt: skip
    out = chosen.design(target_e, target_T, timestep=timestep, **options)
    if tangential is not None:  # an engine whose tangential law ties to its normal options
        tied = chosen.tangential_options(out, tangential, options)
        if tied != options:
            options = tied
            out = chosen.design(target_e, target_T, timestep=timestep, **options)
    if tangential is not None and timestep is None and out.timestep:
        # the tangential promise (the continuous laws where the oblique stepping is not
        # replicated) was measured against the engines at TANGENTIAL_STEPS per contact
        fine = _stepping.nice_down(out.T / TANGENTIAL_STEPS)
        if out.timestep > fine:
            out = chosen.design(target_e, target_T, timestep=fine, **options)
    if out.target_T is not None:  # MuJoCo without T: its default timeconst's
        target_T = out.target_T
    warnings = list(out.warnings)
    reason = _unrealised(out, target_e, target_T)
    if reason is not None:
        step = _working_step(chosen, target_e, target_T, options)
        refusal = UnrealisedExport(
            engine, out.timestep, reason, step, continuous=chosen.CONTINUOUS_PLANT, T=target_T
        )
        if strict:
            raise refusal
        anyway = UnrealisedWarning(refusal)
        warnings.insert(0, str(anyway))
        _warnings.warn(anyway, stacklevel=2)
    # the law each side realises; a two-sphere engine's promise is for the pair (effective
    # mass m/2), or for the sphere on a wall (its own mass): `law_m`
    engine_law = chosen.law(out.parameters, m)
    law_m = chosen.effective_mass(m, geometry)
    response = {}
    if curves or lacked:  # the nearest law's report needs its e(v)
        stepping = None if out.stepping is None else chosen.stepper(out.stepping, m=m,
                                                                    radius=radius)  # fmt: skip
        response, note = _responses(engine_law, law_m, out, stepping, source, m=m, v0=v0,
                                    speeds=speeds)  # fmt: skip
        if lacked and (note or speeds is not None):
            warnings.insert(0, _nearest(chosen, source, response, target_e,
                                        fitted=speeds is not None, v0=v0))  # fmt: skip
        else:
            warnings += [note] if note else []
    parameters, oblique, exported = out.parameters, {}, None
    if tangential is not None:
        # the normal export moves the scene's mass (m/2 for two spheres) as the law moves
        # m, its forces scaled by that ratio: the tangential law's forces alike
        exported = tangential.forces_scaled(law_m / m)
        parameters = chosen.with_tangential(parameters, exported)
        oblique = _oblique_promise(chosen, parameters, engine_law, out.separation, exported,
                                   source, tangential, m=m, v0=v0, radius=radius,
                                   geometry=geometry)  # fmt: skip
        warnings += chosen.tangential_changes(parameters, exported)
        if chosen.FRICTION is not None:
            warnings.append(_friction_note(chosen, tangential, oblique))
        elif source is not None and (departure := _departure(oblique))[0] > E_T_WARN:
            warnings.append(departure[1] + _contact_point_note(chosen, geometry))
        if _two_spheres(chosen, geometry):
            warnings += _turning_note(out.T, v0=v0, radius=radius)
    if radius is not None:  # a stiffness or shear modulus no material has
        c = hertz_constant(engine_law, v0)
        if c is None and source is not None and (c := hertz_constant(source, v0)) is not None:
            c *= law_m / m  # the engine's law is not Hertz's (MuJoCo, Drake): the given law's
        warnings += modulus_warnings(c, exported, radius=radius, poisson=options["poisson"],
                                     two_spheres=_two_spheres(chosen, geometry))  # fmt: skip
    return Export(
        engine=engine,
        scene=chosen.SCENES[geometry],
        parameters=parameters,
        snippet=chosen.snippet(parameters),
        e=out.e,
        T=out.T,
        timestep=out.timestep,
        warnings=tuple(warnings),
        target_e=target_e,
        target_T=target_T,
        m=m if m_given else None,
        v0=v0,
        e_range=out.e_range,
        T_range=out.T_range,
        steps_per_contact=out.steps_per_contact,
        law=engine_law,
        law_m=law_m,
        separation=out.separation,
        **response,
        **oblique,
    )


# the steps per contact an export with a tangential law takes at most when no step is given:
# its promise was measured against the real engines at this resolution (docs/oblique.md)
TANGENTIAL_STEPS = 400
# the incidences (degrees from the normal) an export with a tangential law reports
OBLIQUE_ANGLES = (5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 75.0)
# how far the engine's e_t may fall from the law's before an export warns
E_T_WARN = 0.005
# how far two spheres' turning line of centres may mix their velocities before it warns
TURN_WARN = 0.01


def _oblique_promise(chosen, parameters, engine_law, separation, tangential, source,
                     given, *, m, v0, radius, geometry):  # fmt: skip
    """The oblique impacts at speed `v0` (m/s) from `OBLIQUE_ANGLES` (no spin before) that
    the engine realises with `parameters`: its own stepping where it is replicated
    (`chosen.oblique`, the mean over first-touch phases), else its continuous laws (its
    normal law `engine_law`, the exported `tangential` law) through `oblique_impact`; and
    the tangential restitution of the given law `source` with the given tangential law
    `given` (None from targets). A sphere of mass `m` (kg) and radius `radius` (m) on the
    wall, or the pair's effective sphere (`two_spheres`) for two spheres; the given laws
    move it at mass `m` (the normal export's convention: the law's e and T at `m`, realised
    by the pair at `m/2` with its forces halved, the tangential ones too)."""
    import numpy as np

    from .._oblique import incidence, oblique_impact, two_spheres

    if _two_spheres(chosen, geometry):
        scene = two_spheres(m, radius, m, radius)
    else:
        scene = dict(m=m, R=radius, inertia=0.4)
    v_n, v_t = (np.asarray(v, float) for v in incidence(v0, np.deg2rad(OBLIQUE_ANGLES)))

    def continuous(normal_law, tangential_law, contact_point=0.0, ends=separation, body=None):
        # a soft spring sticks and slips many times (throw=False: a solve that still
        # fails is NaN in the promise, not an error of the export)
        body = scene if body is None else body
        rows = [oblique_impact(normal_law, tangential_law, **body, v_n=float(a), v_t=float(b),
                               separation=ends, contact_point=contact_point,
                               max_segments=64, throw=False)
                for a, b in zip(v_n, v_t, strict=True)]  # fmt: skip
        return tuple(
            np.array([[float(getattr(r, k)) for r in rows] for k in ("e", "e_t", "omega_out")])
        )

    stepped = chosen.oblique(parameters, m=m, radius=radius, v_n=v_n, v_t=v_t)
    if stepped is None:
        realised = chosen.realised_tangential(parameters, tangential)
        e_n, e_t, omega = continuous(engine_law, realised, _engine_share(chosen, geometry))
    else:
        e_n, e_t, omega = (np.asarray(a).mean(axis=-1) for a in stepped)
    if _two_spheres(chosen, geometry):
        # each sphere's spin: both turn alike, R* W* = R (w1 + w2) for the pair's slip
        omega = omega * scene["R"] / (2.0 * radius)
    # the law's own: under the force criterion, as its e and T (`_targets`), at mass m
    target = None
    if source is not None:
        at_m = dict(scene, m=m)
        target = tuple(map(float, continuous(source, given, ends="force", body=at_m)[1]))
    return dict(tangential=tangential, angles=OBLIQUE_ANGLES, e_t_engine=tuple(map(float, e_t)),
                omega_engine=tuple(map(float, omega)), e_n_engine=tuple(map(float, e_n)),
                e_t_target=target)  # fmt: skip


def _friction_note(chosen, tangential, oblique) -> str:
    """The warning of an export to an engine with friction alone (`FRICTION`): what it
    takes, how far its e_t falls from the law's over the angles, how its normal e moves."""
    import numpy as np

    angles, e_n = np.asarray(oblique["angles"]), np.asarray(oblique["e_n_engine"])
    note = (
        f"{chosen.FRICTION} (mu = {float(tangential.params['mu']):.4g} of "
        f"{tangential.name}); over {angles.min():g}-{angles.max():g} degrees its normal e "
        f"runs {e_n.min():.4g} to {e_n.max():.4g}"
    )
    if oblique["e_t_target"] is not None:
        note += ", and " + _departure(oblique)[1]
    return note


def _turning_note(T: float, *, v0: float, radius: float) -> list[str]:
    """Two spheres passing each other turn their line of centres by about `v_t T / (2 R)`
    (rad) during a contact of duration `T` (s), which a promise computed for one body
    against a fixed normal leaves out; their normal and tangential velocities then mix by
    about `tan(theta)` times that angle. A warning where that reaches 0.01 at the largest
    angle. Measured at 75 degrees: Yade's soft pair (turn 0.075 rad, estimate 0.28) fell
    0.23 in e and 0.036 in e_t; LAMMPS's Kharaz pair (turn 0.0096 rad, estimate 0.036)
    0.0043 in e_t, 0.0077 at 45 degrees."""
    import numpy as np

    theta = np.deg2rad(max(OBLIQUE_ANGLES))
    turn = v0 * np.sin(theta) * T / (2.0 * radius)
    mixing = float(np.tan(theta) * turn)
    if mixing < TURN_WARN:
        return []
    return [
        f"two spheres turn their line of centres by about {turn:.2g} rad during contact "
        f"at {max(OBLIQUE_ANGLES):g} degrees (v_t T / 2R), which the promise holds fixed: "
        f"the engine's e may fall up to about {mixing:.2g} below it there, its e_t and spin "
        "by less (and all less at smaller angles); a wall (geometry='wall') or a shorter "
        "contact keeps it small"
    ]


def _two_spheres(chosen, geometry) -> bool:
    """Whether the export's scene is two equal spheres (a two-sphere engine, no wall)."""
    return chosen.effective_mass(1.0, geometry) != 1.0


def _engine_share(chosen, geometry) -> float:
    """`oblique_impact`'s `contact_point` for the engine's scene: each sphere's share of
    the overlap off its lever arm (`CONTACT_POINT`), halved for two equal spheres through
    their effective radius."""
    share = chosen.CONTACT_POINT[geometry]
    return share / 2.0 if _two_spheres(chosen, geometry) else share


def _contact_point_note(chosen, geometry) -> str:
    """Where the engine applies the tangential force, when not on the undeformed surface."""
    share = chosen.CONTACT_POINT[geometry]
    if not share:
        return ""
    return (
        f"; {chosen.LABEL} applies the tangential force at the lever arm R - {share:g} x "
        f"(x the overlap), the law at R: oblique_impact(contact_point="
        f"{_engine_share(chosen, geometry):g}) is the engine's"
    )


def _departure(oblique) -> tuple[float, str]:
    """How far the engine's e_t falls from the law's over the angles: the largest
    |e_t engine - e_t law|, and that in words."""
    import numpy as np

    gap = np.abs(np.asarray(oblique["e_t_engine"]) - np.asarray(oblique["e_t_target"]))
    k = int(np.nanargmax(gap))
    angle = oblique["angles"][k]
    return float(gap[k]), (
        f"its e_t departs from the law's by up to {gap[k]:.3g} (at {angle:g} degrees)"
    )


def _inputs(chosen: AbstractEngine, law_or_fit, m, v0, timestep, poisson):
    """`(m, v0, timestep, poisson)` checked (kg, m/s, s or None, Poisson's ratio or None),
    `m` 1.0 where the engine `chosen` does not need it (its parameters per unit mass, from
    targets); one-line ValueErrors."""
    if m is None:
        if law_or_fit is not None or chosen.MASS_DEPENDS is not None:
            raise ValueError(missing_mass(chosen.NAME, law_or_fit is not None, "pass m= (kg)"))
        m = 1.0  # MuJoCo from targets: per unit mass (the export does not depend on it)
    m = check_scale("m", check_positive("m", m, "kg"), "kg")
    v0 = check_scale("v0", check_positive("v0", v0, "m/s"), "m/s")
    if timestep is not None:
        timestep = check_positive("timestep", timestep, "s")
    if poisson is not None:
        poisson = check_poisson("poisson", poisson)
    return m, v0, timestep, poisson


def _targets(law_or_fit, *, e, T, m: float, v0: float, speeds=None):
    """`(source, target_e, target_T)`: the law of `law_or_fit` (None with targets) and the e
    and T (s; None where not given) an export aims at: the targets `e` and `T`, checked, or
    the law's e and T for mass `m` (kg) at `v0` (m/s); with `speeds` (m/s, a law the engine
    lacks), the middle of the law's e over them (the constant e nearest to it in the worst
    case) and its T at `v0`. A one-line ValueError where neither or both are given, or the
    law does not separate."""
    if law_or_fit is None:
        if e is None:
            raise ValueError("export needs a law or fit, or the target e= (and T=)")
        return None, check_restitution(e), None if T is None else check_positive("T", T, "s")
    if e is not None or T is not None:
        raise ValueError("give either a law (or fit) or the targets e= and T=, not both")
    source = _law_of(law_or_fit)
    from .._solve.impact import impact

    if speeds is not None:
        es, _ = _curve(source, m, speeds, "force")
        if not max(es) > 0:
            raise ValueError("the law does not separate at any of these speeds: no engine target")
        return source, 0.5 * (max(es) + min(es)), float(impact(source, m=m, v0=v0).T)
    result = impact(source, m=m, v0=v0)
    if int(result.status) != 0:
        below = ""
        # an adhesive law with a closed-form sticking speed (jkr; dmt's has none)
        if hasattr(source, "sticking_speed"):
            below = f", below its sticking speed {float(source.sticking_speed(m)):.4g} m/s"
        raise ValueError(
            f"the law does not separate at this m and v0 (e = 0{below}): no engine target"
        )
    return source, float(result.e), float(result.T)


def _responses(engine_law, m_engine: float, out: Design, stepping, source, *, m, v0,
               speeds=None):  # fmt: skip
    """`(fields, note)`: the `Export` fields `speeds` (m/s, `v0` times `_SPEED_FACTORS`, or
    the `speeds` given),
    `e_engine`, `T_engine` (what the engine realises: its `stepping`'s mean over first-touch
    phases where it is replicated, else its continuous law `engine_law` on mass `m_engine`,
    kg) and `e_target`, `T_target` (the `source` law's on mass `m`; None from targets), and a
    warning where the two e(v) part by more than 0.02 (else None)."""
    speeds = tuple(v0 * f for f in _SPEED_FACTORS) if speeds is None else tuple(speeds)
    if stepping is None:  # the continuous plant, or a stepper not replicated (Chrono)
        e_engine, T_engine = _curve(engine_law, m_engine, speeds, out.separation)
    else:  # what the engine's stepping realises: the mean over first-touch phases
        runs = [stepping.run(v) for v in speeds]
        e_engine = tuple(float(np.mean(es)) for es, _ in runs)
        T_engine = tuple(float(np.mean(Ts)) for _, Ts in runs)
    fields = dict(speeds=speeds, e_engine=e_engine, T_engine=T_engine)
    if source is None:
        return fields, None
    e_target, T_target = _curve(source, m, speeds, "force")
    fields.update(e_target=e_target, T_target=T_target)
    spread = max(abs(a - b) for a, b in zip(e_engine, e_target, strict=True))
    if spread <= 0.02:
        return fields, None
    return fields, (
        f"the engine's e(v) departs from the law's by up to {spread:.3f} between "
        f"{speeds[0]:.3g} and {speeds[-1]:.3g} m/s: the export is exact at v0 only"
    )


def _native(chosen: AbstractEngine, source):
    """`(engine, lacked)`: the engine that exports the law `source` (None: targets), its own
    model for it where it has one (an engine's `native(law)`: LAMMPS's `jkr` for a `jkr`
    law), and whether it lacks the law, a plastic or adhesive one (`LawSpec.kind`:
    Thornton's, JKR's), so that the export goes to its nearest law (`_nearest` says so
    where their e(v) part)."""
    if source is None:
        return chosen, False
    own = chosen.native(source)
    if own is not None:
        return own, False
    kind = "viscoelastic" if source.spec is None else source.spec.kind
    return chosen, kind != "viscoelastic" and chosen.LAW != source.name


def _speeds(v0, lacked, chosen: AbstractEngine):
    """`(v0, speeds)`: a speed (m/s) as given, with None; or from a sequence of speeds (for
    a law the engine lacks), their geometric middle and the speeds, sorted. One-line
    ValueErrors."""
    if isinstance(v0, str) or np.ndim(v0) == 0:
        return v0, None
    if not lacked:
        raise ValueError(
            f"v0 must be one speed (m/s) for this law and {chosen.LABEL}; a list of speeds "
            "is for a law with a contact state the engine lacks (thornton; jkr but for "
            "LAMMPS), whose nearest engine law is then set over them"
        )
    speeds = sorted(check_positive("v0", v, "m/s") for v in np.ravel(v0))
    if len(speeds) < 2 or speeds[0] == speeds[-1]:
        raise ValueError("give two or more different speeds in v0=[...] (m/s), or one speed")
    return float(np.sqrt(speeds[0] * speeds[-1])), tuple(speeds)


def _nearest(chosen: AbstractEngine, source, fields: dict, target_e: float, *, fitted: bool,
             v0: float) -> str:  # fmt: skip
    """The one line for a law with a contact state (`source`) that engine `chosen` does not
    have: the nearest law it has (its `NEAREST`, else its `LAW`), how it was set (`fitted`:
    the middle of the law's e over the speeds given, else e and T at `v0`), and the worst
    |e_engine - e_law| over `fields`' speeds."""
    speeds, mine, law = fields["speeds"], fields["e_engine"], fields["e_target"]
    gaps = [abs(a - b) for a, b in zip(mine, law, strict=True)]
    worst = int(np.argmax(gaps))
    nearest = chosen.NEAREST or f"its {chosen.LAW} law"
    lacked = f"{source.name} law ({source.spec.equation}; e(v) from a contact state)"
    how = (
        f"set to e = {target_e:.3g} (the middle of the law's {min(law):.3g} to "
        f"{max(law):.3g}) and the law's T at {v0:.3g} m/s"
        if fitted
        else f"set to the law's e and T at v0 = {v0:.3g} m/s"
    )
    tail = "" if fitted else "; pass v0=[...] (m/s) to fit e over the speeds you need"
    return (
        f"{chosen.LABEL} has no {lacked}; the nearest is {nearest}, {how}: from "
        f"{speeds[0]:.3g} to {speeds[-1]:.3g} m/s its e departs from the law's by up to "
        f"{gaps[worst]:.3g} (|de| at {speeds[worst]:.3g} m/s){tail}"
    )


def _unrealised(out: Design, target_e: float, target_T) -> str | None:
    """Why the design `out` of an engine does not realise `target_e`, `target_T` (s)."""
    h = out.timestep
    steps = target_T / h if (h and target_T is not None) else None
    return _stepping.unrealised(
        out.e, out.T, target_e=target_e, target_T=target_T, steps_per_contact=steps,
        parameters=out.parameters,
    )  # fmt: skip


def _working_step(chosen: AbstractEngine, target_e: float, target_T, options: dict):
    """A time step (s) at which engine `chosen` realises the target: its recommended step
    (the design without a step), or where that is a continuous plant (0.0), the first of
    T/50, T/100, ... T/51200 whose discrete plant does; None where none does. `options`:
    the design's other arguments."""
    try:
        out = chosen.design(target_e, target_T, timestep=None, **options)
    except ValueError:
        return None
    if out.target_T is not None:
        target_T = out.target_T
    if out.timestep and _unrealised(out, target_e, target_T) is None:
        return float(out.timestep)
    if out.timestep == 0.0 and target_T is not None:  # a continuous plant: 0 or a step
        steps = 50
        while steps <= 51200:
            h = _stepping.nice_down(target_T / steps)
            try:
                out = chosen.design(target_e, target_T, timestep=h, **options)
            except ValueError:
                return 0.0
            near = abs(out.e / target_e - 1) <= 0.005 and abs(out.T / target_T - 1) <= 0.005
            if near and _unrealised(out, target_e, target_T) is None:
                return h
            steps *= 2
        return 0.0
    return None


def _check_scales(m: float, v0: float, T: float) -> None:
    """A one-line ValueError where float64 cannot hold the contact's scales: its stiffness
    `m / T^2`, the square of a step `(T / 1e5)^2`, its depth `v0 T` and force `m v0 / T`."""
    with np.errstate(all="ignore"):
        m_, v_, T_ = np.float64(m), np.float64(v0), np.float64(T)
        scales = (m_ / T_**2, (T_ / 1e5) ** 2, v_ * T_, m_ * v_ / T_)
    tiny = np.finfo(np.float64).tiny
    if not all(np.isfinite(s) and s > tiny for s in scales):
        raise ValueError(
            f"T = {T:g} s, m = {m:g} kg and v0 = {v0:g} m/s give a stiffness, step or force "
            "that float64 cannot hold; are they in s, kg and m/s?"
        )


def engine_response(engine: str, parameters: dict, *, m, speeds, radius=None):
    """The inverse: e(v) and T(v) (continuous law of the engine) that given engine parameters
    produce, for a body of mass `m` (kg; two-sphere engines: each sphere) at each speed of
    `speeds` (m/s). Parameters: the names of the engine's `KEYS` (MuJoCo `solref`,
    `timestep` for refsafe; LAMMPS, LIGGGHTS, Chrono `E` (Pa), `coeff_restitution`,
    `poisson`, `limit_damping`; Yade `tc` (s), `en`; Drake `point_contact_stiffness` (N/m),
    `hunt_crossley_dissipation` (s/m)); `"geometry": "wall"` (LAMMPS, LIGGGHTS, Chrono,
    Yade): one sphere on a wall of its material. The step is not part of this answer:
    `stepped_response` gives what the stepping realises. Returns `(law, separation, e, T)`."""
    chosen = _engine(engine)
    m = check_positive("m", m, "kg")
    speeds = [check_positive("speed", v, "m/s") for v in np.atleast_1d(speeds)]
    law, separation = chosen.response(parameters, m=m, radius=radius)
    m_engine = chosen.effective_mass(m, parameters.get("geometry"))
    e, T = _curve(law, m_engine, speeds, separation)
    return law, separation, e, T


def stepped_response(engine: str, parameters: dict, *, m, speeds, radius=None):
    """What the engine's own time stepping realises with `parameters` at each speed (m/s):
    `(timestep, e, T, e_min, e_max)`, e and T the mean over where the first touch falls
    inside a step and `e_min`, `e_max` their extremes. Modelled (replicas checked against
    the engines): MuJoCo at its `timestep` (default 0.002 s), LAMMPS and LIGGGHTS with a
    `timestep` (velocity Verlet), Yade with a `timestep` (leapfrog, and its NewtonIntegrator
    `damping`, default 0 here), Drake with `time_step > 0` (its implicit discrete step, the
    Lagged, Similar and TAMSI approximations). `None` where the step does not apply or is
    not known: a two-sphere engine without a `timestep`, Drake's continuous plant
    (error-controlled integration: no step error), and Chrono (its stepper not modelled);
    each engine's `STEPPING` says which."""
    chosen = _engine(engine)
    m = check_positive("m", m, "kg")
    speeds = [check_positive("speed", v, "m/s") for v in np.atleast_1d(speeds)]
    stepping = chosen.stepper(parameters, m=m, radius=radius)
    if stepping is None:
        return None
    runs = [stepping.run(v) for v in speeds]
    return (
        stepping.timestep,
        [float(np.mean(es)) for es, _ in runs],
        [float(np.mean(Ts)) for _, Ts in runs],
        [float(np.min(es)) for es, _ in runs],
        [float(np.max(es)) for es, _ in runs],
    )


def _engine(name: str) -> AbstractEngine:
    """The engine `name` of `ENGINES`, or a one-line ValueError naming the engines."""
    if name not in ENGINES:
        raise ValueError(unknown_name("engine", name, list(ENGINES)))
    return ENGINES[name]
