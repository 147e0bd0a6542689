"""`export`: from a law, a fit or target e and T to an engine's own contact parameters, with
the e and T that the engine will realise (the engines: `registry.ENGINES`). An export is
the composition of the engine's sub-models, as LAMMPS's `GranularModel::calculate_forces`:
find the normal model for the law, design it, add the tangential model, make the promise
(`promise.py`)."""

import dataclasses
import sys

from . import compose
from .refusal import UnrealisedExport as UnrealisedExport, UnrealisedWarning as UnrealisedWarning
from .registry import ENGINES as ENGINES, engine as _engine

BAND_FIELDS = ("e_band", "T_band", "band_draws")


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
    - From a posterior (`export(post, ...)`): `e`, `T` and the rest are the export of the
      law at the posterior medians (`post.median_law`); `e_band`, `T_band` (s) the 5 and
      95 % quantiles of what the engine realises over `band_draws` posterior draws, each
      draw's law exported as that law would be at the same step (`timestep`): its
      design, stepping, criterion and clamps. None for a law, a fit or targets.
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
    e_band: tuple | None = None
    T_band: tuple | None = None
    band_draws: int | None = None

    def to_dict(self) -> dict:
        """Every field, the laws as `{"name", "parameters"}`; the band's fields
        (`e_band`, `T_band`, `band_draws`) only for an export of a posterior."""
        laws = ("law", "tangential")
        band = () if self.e_band is not None else BAND_FIELDS
        out = {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if f.name not in laws and f.name not in band
        }
        for name in laws:
            law = getattr(self, name)
            parameters = {} if law is None else {k: float(v) for k, v in law.parameters.items()}
            out[name] = None if law is None else {"name": law.name, "parameters": parameters}
        return out


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
    band_draws: int = 200,
    progress=True,
) -> Export:
    """Parameters for `engine` (`"mujoco"`, `"drake"`, `"lammps"`, `"liggghts"`, `"chrono"`,
    `"yade"`)
    that realise the e and T of `law_or_fit` (a law, `calibrate`'s fit or a `Posterior`)
    for mass `m` (kg) at impact speed `v0` (m/s), or the targets `e` and `T` (s) when
    `law_or_fit` is None.

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
    (`lammps/jkr.py`: its cohesion set so that LAMMPS takes the law's energy per impact, so
    its e(v) is the law's at every speed, and its E for T at `v0`; a warning says how its
    neck differs from JKR's). A `thornton` law (any engine), or a `jkr` law to an engine
    without JKR, goes to the engine's nearest law, with a first warning line that says so
    and how far that law's e(v) departs from the law's (worst |de|); `v0` may then be a
    list of speeds (m/s): e is set to the middle of the law's e over them (a speed-free
    e's best worst case), T to the law's at their geometric middle, and the report covers
    those speeds.

    `tangential`: a tangential law (`tangential_law(...)`) exported with the normal one,
    to an engine that has it exactly (a row of `AbstractEngine.TANGENTIAL`: LAMMPS's
    `linear_history`, `mindlin`, `mindlin/force`), or as its friction `mu` alone to an
    engine with friction and no tangential spring (a tangential model's `FRICTION`: MuJoCo's
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

    A posterior (`posterior(fit, ...)`, a `Posterior`) is exported at its medians
    (`post.median_law`), and the `Export` also holds the engine's band, `e_band` and
    `T_band`: the 5-95 % band of what the engine realises over `band_draws` (200) evenly
    thinned draws, each draw's law exported with the same arguments at the median export's
    step (strict or not, a draw the engine cannot realise counts with what it realises;
    a draw whose law does not separate is left out, with a warning). One export per draw:
    about 10 ms each for LAMMPS, 0.3-0.8 s for MuJoCo, whose design inverts its stepping;
    `progress`: the meter of those draws (True: on stderr; False: none; an
    `AbstractMeter`).

    **Example**: `export(law("hertz_rate", c=2e6, b1=800.0), "mujoco", m=1.0, v0=2.5).parameters`.
    """
    scene = dict(m=m, v0=v0, timestep=timestep, radius=radius, poisson=poisson)
    design = dict(limit_damping=limit_damping, geometry=geometry, tangential=tangential)
    if _is_posterior(law_or_fit):
        options = dict(curves=curves, strict=strict, **scene, **design)
        return _posterior_export(law_or_fit, engine, band_draws, progress, e, T, options)
    chosen = _engine(engine)
    # the normal model, and what is refused without the law's impact (a law's e and T
    # compile), then the law's e and T (or the targets)
    asked = compose.request(
        chosen, law_or_fit, e=e, T=T, engines=ENGINES, missing_mass=missing_mass, **scene, **design
    )
    out = compose.design(asked, tangential)  # the normal model designed (and its tie)
    warnings = [*compose.refusal(asked, out, strict=strict), *out.warnings]
    engine_law = asked.normal.law(out.parameters, asked.m)
    response, first, last = compose.report(asked, out, engine_law, curves=curves)
    warnings = first + warnings + last  # the nearest law's line first
    parameters, oblique, lines = compose.tangential(asked, out, engine_law, tangential)
    warnings += lines + compose.modulus(asked, engine_law, oblique.get("tangential"))
    return Export(
        engine=engine,
        scene=(asked.normal.SCENES or chosen.SCENES)[asked.scene.geometry],
        parameters=parameters,
        snippet=chosen.snippet(parameters),
        warnings=tuple(warnings),
        target_e=asked.target_e,
        target_T=compose.aimed_T(asked, out),
        m=None if m is None else asked.m,
        v0=asked.scene.v0,
        law=engine_law,
        law_m=asked.law_m,
        **{
            f: getattr(out, f)
            for f in ("e", "T", "timestep", "e_range", "T_range", "steps_per_contact", "separation")
        },
        **response,
        **oblique,
    )


def _is_posterior(value) -> bool:
    """Whether `value` is a `Posterior` (its module is loaded only where one was made: an
    export of a law does not import the sampler's layer)."""
    module = sys.modules.get("jaximpact._posterior.result")
    return module is not None and isinstance(value, module.Posterior)


def _posterior_export(post, engine: str, band_draws, progress, e, T, options) -> Export:
    """The export of `post`'s median law with `export`'s `options`, and the engine's band
    over its draws (`band_draws`, `progress`: `export`'s); the targets `e`, `T` refused."""
    if e is not None or T is not None:
        raise ValueError("give either a posterior or the targets e= and T=, not both")
    median = export(post.median_law, engine, **options)
    return with_band(median, post, band_draws=band_draws, progress=progress, **options)


def with_band(x: Export, post, *, band_draws: int = 200, progress=True, **options) -> Export:
    """`x` (an export of a law, the median of `post`) with the engine's band over the draws
    of `post`: each draw's law exported to `x.engine` with `options` (`export`'s, but
    `e`, `T`, `curves`, `strict`) at `x`'s step, not strict (what the engine realises,
    refused or not). A draw whose law does not separate is left out, with a warning line."""
    from .._posterior.engine_band import engine_band

    step = x.timestep or None  # Drake's continuous plant: 0, its default
    each = {**options, "timestep": step, "curves": False, "strict": False}

    def realise(law):
        one = export(law, x.engine, **each)
        return one.e, one.T

    band = engine_band(post, realise, draws=band_draws, progress=progress)
    lines = list(x.warnings)
    if band["failed"]:
        lines.append(
            f"{band['failed']} of {band['failed'] + band['draws']} posterior draws left out of "
            "the band: their laws do not separate at this m and v0, or the engine refused them"
        )
    return dataclasses.replace(
        x,
        e_band=band["e_band"],
        T_band=band["T_band"],
        band_draws=band["draws"],
        warnings=tuple(lines),
    )
