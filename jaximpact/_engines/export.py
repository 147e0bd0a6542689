"""`export`: a law, a fit or target e and T to an engine's contact parameters, with the e and
T the engine realises: the composition of its sub-models (`compose.py`), as LAMMPS's
`GranularModel::calculate_forces`."""

import dataclasses
import sys

from . import compose
from .refusal import UnrealisedExport as UnrealisedExport, UnrealisedWarning as UnrealisedWarning
from .registry import ENGINES as ENGINES, engine as _engine

BAND_FIELDS = ("e_band", "T_band", "band_draws")


@dataclasses.dataclass(frozen=True)
class Export:
    """An engine's contact parameters and what the engine realises with them.

    - `engine`, `scene`; `parameters` (the engine's own names and units) and `snippet`, text
      to paste into its model or script.
    - `e`, `T` (s): what the engine realises at `v0` with `timestep`, its stepping included
      (the mean over where the first touch falls inside a step); `e_range`, `T_range`: their
      extremes over those phases (None for a continuous plant); `steps_per_contact`.
    - `timestep` (s): the given step or the recommended one, the coarsest at which the
      replicated stepping realises e within 0.5 % at every start phase and T within 0.5 %
      (T/100 for Chrono, not replicated; at most T/400 with a tangential law).
    - `target_e`, `target_T`: what was asked (the law's e and T at `v0`, or the targets); with
      `v0=[...]` (a law the engine lacks) `v0` is the speeds' geometric middle, `target_e` the
      middle of the law's e over them, `speeds` those given.
    - `law`, `law_m` (kg), `separation`: the engine's contact as a jaximpact law, so that
      `impact(x.law, m=x.law_m, v0=x.v0, separation=x.separation)` is the engine without its
      stepping; `law_m` is the mass the contact moves, m/2 for two equal spheres of mass `m`
      (LAMMPS, LIGGGHTS, Yade, Chrono; `law`'s forces then half a law's that moves `m`), `m`
      on a plane or wall (MuJoCo, Drake, `geometry="wall"`; 1 kg for MuJoCo from targets).
      That impact gives `target_e`, `target_T` (to 1e-6) where the design inverts the
      continuous law (LAMMPS's hertz/material and dmt, LIGGGHTS, Yade, Chrono, Drake's
      continuous plant); MuJoCo and Drake's discrete plant set it off by their stepping's
      bias, so that the stepping lands on the target. LAMMPS's jkr models break the neck at
      the least force, as no jkr law does: `law` is the jkr (or `jkr_viscoelastic`) law whose
      neck takes LAMMPS's energy per impact (e LAMMPS's continuous e at every speed; its
      contact 0.3 % at e = 0.95 to 7 % at e = 0.2 longer). For a law the engine lacks
      (`thornton`), `law` is the nearest it has.
    - `speeds` (m/s), `e_engine`, `T_engine`, `e_target`, `T_target`: e(v) and T(v) of the
      engine (as `e`) and of the given law (None from targets).
    - `warnings`: where the engine will not do what was asked, or only with care, including
      a Hertz constant whose Young's modulus no material has (outside 1e5 to 1e12 Pa, `c =
      4/3 E* sqrt(R*)`) or a shear modulus more than a factor 100 from `E / (2 (1 + nu))`.
    - With a tangential law: `tangential` (the given one, its forces scaled as `law`'s), and
      at `v0` from `angles` (degrees from the normal, no spin before) the engine's
      tangential restitution `e_t_engine`, spin after `omega_engine` (rad/s; each sphere's
      for two spheres, positive rolling along the tangential velocity) and normal `e_n_engine`:
      MuJoCo's Euler step replicated (equal to MuJoCo to round-off), Drake's continuous plant
      integrated (Radau, rtol 1e-10; equal to Drake to 1e-8), else the continuous laws
      (LAMMPS within 0.002 on a wall, 0.01 for two spheres, whose line of centres turns: a
      warning says where it matters); `e_t_target`, the given laws' at mass `m`.
    - From a posterior: the export at the posterior medians, and `e_band`, `T_band` (s), the
      5-95 % band of what the engine realises over `band_draws` draws at the same step
      (None otherwise).
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
    `"yade"`) that realise the e and T of `law_or_fit` (a law, `calibrate`'s fit or a
    `Posterior`) for mass `m` (kg) at impact speed `v0` (m/s), or the targets `e` and `T` (s)
    when `law_or_fit` is None.

    Scenes: MuJoCo and Drake, a body on a fixed plane; LAMMPS, LIGGGHTS, Chrono and Yade, two
    spheres each of mass `m` and radius `radius` (m, required) head-on at relative speed `v0`,
    or with `geometry="wall"` one sphere on a fixed flat wall (the drop test). `poisson`
    (default 0.3); `limit_damping`: keep the force non-attractive. `timestep` (s): the
    engine's step if chosen (corrected for where possible, else warned about); default, the
    recommended step (`Export.timestep`).

    `m` has no default: every engine's parameters depend on it, and so do a law's e and T;
    MuJoCo from targets alone needs none (solref is per unit mass; `Export.m` is then None).

    A `jkr` law goes to LAMMPS's `jkr` model (its cohesion set so that LAMMPS takes the law's
    energy per impact, its E for T at `v0`). A `thornton` law, or a `jkr` law to an engine
    without JKR, goes to the engine's nearest law, with a first warning saying how far its
    e(v) departs (worst |de|); `v0` may then be a list of speeds (m/s): e is set to the middle
    of the law's e over them, T to the law's at their geometric middle.

    `tangential`: a tangential law exported with the normal one, exactly (a row of the
    engine's `TANGENTIAL`: LAMMPS, LIGGGHTS, Yade) or as its friction `mu` alone (MuJoCo's
    pyramidal cone; Drake's Stribeck friction, continuous plant only; `radius` needed); the
    `Export` then holds the oblique impacts the engine realises at `v0` from
    `OBLIQUE_ANGLES`. Another engine: a one-line ValueError.

    An export the engine cannot realise at `timestep` (a parameter not finite, e or T no
    impact's, fewer than 5 steps per contact, or e or T more than 5 % off the target) raises
    `UnrealisedExport` (a `ValueError` naming a step that works, `.working`), or with
    `strict=False` warns `UnrealisedWarning` (also in `Export.warnings`) and exports anyway.

    A `Posterior` is exported at its medians, with the engine's 5-95 % band over
    `band_draws` (200) thinned draws, each exported alike at the median's step (a draw whose
    law does not separate is left out, with a warning): about 10 ms each for LAMMPS, 0.3-0.8
    s for MuJoCo. `progress`: their meter (True: stderr; False: none; an `AbstractMeter`).

    **Example**: `export(law("hertz_rate", c=2e6, b1=800.0), "mujoco", m=1.0, v0=2.5).parameters`.
    """
    given = compose.Given(m, v0, timestep, radius, poisson, limit_damping, geometry, tangential)
    if _is_posterior(law_or_fit):
        options = dict(curves=curves, strict=strict, **given._asdict())
        return _posterior_export(law_or_fit, engine, band_draws, progress, e, T, options)
    chosen = _engine(engine)
    # the normal model, and what is refused without the law's impact (a law's e and T
    # compile), then the law's e and T (or the targets)
    asked = compose.request(chosen, law_or_fit, e, T, given)
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
