"""The engine interface, after LAMMPS's `granular_model.cpp`: an export composes a normal
model and a tangential model of one engine. `AbstractNormalModel` (LAMMPS's
`GranSubModNormal`) designs the engine's parameters for a target e and T; an
`AbstractTangentialModel` (`GranSubModTangential`) adds a tangential law to them;
`AbstractEngine` declares its scene and its tables of both, `NORMAL` and `TANGENTIAL` (law
name -> model), as LAMMPS's `GranSubModStyle` lines register its sub-models. `Design` is what
a normal model's design gives, `Stepping` its time stepping replicated, `Key` one input of
its parameters, `Scene` the collision an export is for.

Each engine is one final class (`mujoco/engine.py`, `yade.py`, ...), registered once in
`registry.ENGINES`, which `jaximpact.export`, `engine_response`, `stepped_response` and the
command line read: nothing else names an engine (docs/layout.md, "Adding an engine").
Units are SI throughout; an engine's own parameters keep its own names.
"""

import abc
import dataclasses
from collections.abc import Callable, Mapping
from typing import ClassVar, NamedTuple

import numpy as np

from .._oblique.tangential import TANGENTIAL_LAW_NAMES
from .materials import check_positive


class Key(NamedTuple):
    """One input of an engine's parameters as `engine_response` and `jaximpact engine-e` take
    them: the engine's `name` for it, its `unit` (SI, or the form of the value), and whether
    it is `needed` (else optional)."""

    name: str
    unit: str
    needed: bool = True


@dataclasses.dataclass(frozen=True)
class Design:
    """What an engine's `design` gives for a target e and T: its parameters and what the
    engine realises with them (its time stepping included where it is replicated).

    - `parameters`: the engine's own names and units (what `Export.parameters` shows).
    - `e`, `T` (s): the restitution and contact duration it realises; with a replicated
      stepping, the mean over where the first touch falls inside a step.
    - `timestep` (s): the step of the design (given or recommended); 0.0 for Drake's
      continuous plant.
    - `separation`: how the engine ends contact, `"force"` or `"penetration"` (the
      criterion its continuous law is to be read with, `jaximpact.impact(separation=)`).
    - `warnings`: where the engine will not do what was asked, or only with care.
    - `e_range`, `T_range`: the extremes of e and T (s) over the start phases; None where no
      stepping is replicated.
    - `steps_per_contact`: T over the step; None for a continuous plant.
    - `target_T` (s): the T the design aimed at where none was asked (MuJoCo: its default
      timeconst's); None when it is the T asked.
    - `stepping`: the parameters the engine's `stepper` takes to replay this design's time
      stepping (the mean e(v) of `export`'s curves); None where it is not replicated.
    - `clause`: where the engine writes its models as clauses of one command (LAMMPS's
      `pair_coeff`), the normal model's (`hertz/material ... damping coeff_restitution`),
      which a tangential clause follows; else None.
    """

    parameters: dict
    e: float
    T: float
    timestep: float
    separation: str
    warnings: tuple[str, ...] = ()
    e_range: tuple[float, float] | None = None
    T_range: tuple[float, float] | None = None
    steps_per_contact: float | None = None
    target_T: float | None = None
    stepping: dict | None = None
    clause: str | None = None

    @classmethod
    def stepped(cls, parameters, es, Ts, h, warnings, separation, stepping, **more) -> "Design":
        """The design whose replicated `stepping` at the step `h` (s) realises `es`, `Ts`
        (s) per start phase: their means `e`, `T`, their ranges, the steps per contact."""
        return cls(
            parameters=parameters,
            e=float(es.mean()),
            T=float(Ts.mean()),
            timestep=h,
            separation=separation,
            warnings=tuple(warnings),
            e_range=(float(es.min()), float(es.max())),
            T_range=(float(Ts.min()), float(Ts.max())),
            steps_per_contact=float(Ts.mean() / h),
            stepping=stepping,
            **more,
        )


@dataclasses.dataclass(frozen=True)
class Stepping:
    """An engine's time stepping, replicated in numpy: its `timestep` (s), and `run(v)`, the
    arrays `(e, T)` (T in s) over start phases (where the first touch falls inside a step)
    of one contact at impact speed `v` (m/s)."""

    timestep: float
    run: Callable[[float], tuple[np.ndarray, np.ndarray]]


@dataclasses.dataclass(frozen=True)
class Scene:
    """The collision an export is designed for: each body's mass `m` (kg), the impact speed
    `v0` (m/s), the spheres' `radius` (m; None where the engine takes none), the `geometry`
    (a key of the engine's `SCENES`: `"spheres"`, two equal spheres; `"wall"`, one body on a
    fixed wall or plane), and the `law` exported (None from targets; LAMMPS's `dmt` and
    damped `jkr` models map its parameters)."""

    m: float
    v0: float
    radius: float | None
    geometry: str
    law: object = None

    @property
    def wall(self) -> bool:
        return self.geometry == "wall"


def _check_declared(cls, base) -> None:
    """A final class derived from `base` alone, declaring every fact (`base`'s annotated
    class attributes)."""
    if cls.__bases__ != (base,):
        raise TypeError(f"{cls.__name__}: a final class derived from {base.__name__} alone")
    missing = [fact for fact in base.__annotations__ if not hasattr(cls, fact)]
    if missing:
        raise TypeError(f"{cls.__name__} does not declare {', '.join(missing)}")


class AbstractNormalModel(abc.ABC):
    """One normal model of an engine (LAMMPS's `GranSubModNormal`): a final class derived
    from this one alone, declaring every fact and implementing every abstract method.

    **Facts** (class attributes):

    - `NAME`: the engine's own name for the model (LAMMPS's `jkr`); the value of an
      export's `parameters["normal"]` where the engine has several models alike.
    - `LAW`: the jaximpact law (its contact law family) the model integrates.
    - `KEYS`: its parameters as `engine_response` takes them (`Key`: name, unit, needed).
    - `STEPPING`: how the engine steps it, in words (what `stepper` replicates, or not).
    - `MASS_DEPENDS`: what the mass changes in its parameters, or None where they do not
      depend on it (MuJoCo's solref is per unit mass).
    - `ALLOWS_LIMIT_DAMPING`: whether it takes `export(limit_damping=True)` (LAMMPS's
      cohesive models do not: refused before any work, as `GranularModel::init()` does).
    - `NEAREST`: how it is named where it is the engine's nearest law to one the engine
      lacks (a plastic or adhesive law), in an export's first warning.
    - `SCENES`: the engine's scenes (`AbstractEngine.SCENES`) in the model's own words, or
      None: the engine's.
    """

    NAME: ClassVar[str]
    LAW: ClassVar[str]
    KEYS: ClassVar[tuple[Key, ...]]
    STEPPING: ClassVar[str]
    MASS_DEPENDS: ClassVar[str | None]
    ALLOWS_LIMIT_DAMPING: ClassVar[bool]
    NEAREST: ClassVar[str]
    SCENES: ClassVar[Mapping[str, str] | None]

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        _check_declared(cls, AbstractNormalModel)

    @abc.abstractmethod
    def design(
        self,
        e: float,
        T: float | None,
        scene: Scene,
        *,
        timestep: float | None = None,
        poisson: float = 0.3,
        limit_damping: bool = False,
    ) -> Design:
        """The parameters that realise restitution `e` and duration `T` (s; None where the
        engine has a default) in `scene`, at the engine's step `timestep` (s; None: a
        recommended one), with the spheres' `poisson` ratio where the engine takes it and
        `limit_damping` (keep the force non-attractive, where that is an option). A one-line
        ValueError where it cannot."""

    @abc.abstractmethod
    def law_parameters(self, parameters: dict, m: float) -> dict:
        """The parameters (SI) of its law `LAW` that `parameters` give a body of mass `m`
        (kg)."""

    @abc.abstractmethod
    def response(self, parameters: dict, *, m: float, radius: float | None = None):
        """`(law, separation)`: the continuous law the engine's `parameters` (names of
        `KEYS`, each value checked: a one-line ValueError) give a body of mass `m` (kg;
        each sphere's) of radius `radius` (m, where the engine takes it), and its end of
        contact (`"force"` or `"penetration"`)."""

    @abc.abstractmethod
    def stepper(self, parameters: dict, *, m: float, radius: float | None = None):
        """The `Stepping` that the engine's own time stepping realises with `parameters`, or
        None where it does not apply (no step given, a continuous plant) or is not
        replicated."""

    def law(self, parameters: dict, m: float):
        """The continuous law the model realises with `parameters` for a body of mass `m`
        (kg), as a jaximpact law `LAW`."""
        from .._laws import law as make_law

        return make_law(self.LAW, **self.law_parameters(parameters, m))

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class AbstractTangentialModel(abc.ABC):
    """One tangential model of an engine (LAMMPS's `GranSubModTangential`), the row of its
    `TANGENTIAL` table for one or more tangential laws: a final class derived from this one
    alone, declaring every fact and implementing every abstract method (each states all of
    them: no default is overridden).

    **Facts**: `MODEL`, the model in words (the opening of the refusal of a tangential law
    the table lacks); `FRICTION`, where the engine has no tangential spring but friction
    alone, what it makes of a tangential law (its `mu`), in words, else None;
    `CONTACT_POINT`, where its tangential force acts, by scene, as the share `f` of the
    overlap off each sphere's lever arm `R - f x` (`oblique_impact(contact_point=)`; 0.5:
    halfway through the overlap)."""

    MODEL: ClassVar[str]
    FRICTION: ClassVar[str | None]
    CONTACT_POINT: ClassVar[Mapping[str, float]]

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        _check_declared(cls, AbstractTangentialModel)

    @abc.abstractmethod
    def check(self, tangential, *, timestep) -> None:
        """A one-line ValueError where the model cannot take `tangential` (a law of its
        rows) at `timestep` (s or None), before any work."""

    @abc.abstractmethod
    def poisson(self, design: Design, tangential) -> float | None:
        """The Poisson's ratio at which the normal model is to be designed again so that the
        model realises `tangential` (LIGGGHTS ties its G* to E and nu), given a first
        `design`; None where the model is not tied to it."""

    @abc.abstractmethod
    def parameters(self, design: Design, tangential) -> dict:
        """The `design`'s parameters with `tangential` set (its clause, friction, ...)."""

    @abc.abstractmethod
    def realised(self, parameters: dict, tangential):
        """The tangential law (a jaximpact one) the engine realises with `parameters`
        exported for `tangential`."""

    @abc.abstractmethod
    def notes(self, parameters: dict, tangential) -> list[str]:
        """What the engine changes with `parameters` exported for `tangential`, in words (an
        empty list where nothing)."""

    @abc.abstractmethod
    def oblique(self, parameters: dict, *, m: float, radius: float, v_n, v_t):
        """`(e, e_t, omega)` per first-touch phase (rad/s for the spin) that the engine's
        own time stepping realises with `parameters` for a sphere of mass `m` (kg) and
        radius `radius` (m) meeting its plane at `v_n`, `v_t` (m/s, arrays of one shape, no
        spin before), or None where it is not replicated (the promise is then the
        continuous laws')."""

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class AbstractEngine(abc.ABC):
    """A simulation engine that `export` can target: a final class derived from this one
    alone, declaring every fact below and implementing `snippet`.

    **Facts** (class attributes):

    - `NAME`: the name `export(..., engine)` and `jaximpact export ENGINE` take;
      `LABEL`: the engine's name as its documentation spells it.
    - `SCENES`: the collision an export is for, by geometry (`export(geometry=)`), the
      first being the default: `"spheres"`, two equal spheres head-on at relative speed v0;
      `"wall"`, one body on a fixed flat wall (or plane) at v0.
    - `TWO_SPHERES`: the default scene is two equal spheres: the radius is needed (m),
      a contact duration T is needed, and the contact's effective mass is m/2.
    - `CONTINUOUS_PLANT`: a time step of 0 runs a continuous, error-controlled plant.
    - `NORMAL`: its normal models by the law each exports (law name -> model); the first
      row is the engine's default design, and its nearest law to a law it lacks.
    - `TANGENTIAL`: its tangential models by tangential law (`tangential_law` names); an
      empty table: the engine exports the normal law alone.

    `KEYS`, `MASS_DEPENDS` and `STEPPING` are the first normal model's (what the command
    line shows of the engine); `FRICTION`, its tangential table's (None: exact or none).
    """

    NAME: ClassVar[str]
    LABEL: ClassVar[str]
    SCENES: ClassVar[Mapping[str, str]]
    TWO_SPHERES: ClassVar[bool]
    CONTINUOUS_PLANT: ClassVar[bool]
    NORMAL: ClassVar[Mapping[str, AbstractNormalModel]]
    TANGENTIAL: ClassVar[Mapping[str, AbstractTangentialModel]]

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        _check_declared(cls, AbstractEngine)

    @abc.abstractmethod
    def snippet(self, parameters: dict) -> str:
        """Text to paste into the engine's model or script, from an export's `parameters`
        (its normal design's, with the tangential model's where one was exported)."""

    @property
    def KEYS(self) -> tuple[Key, ...]:  # noqa: N802
        return next(iter(self.NORMAL.values())).KEYS

    @property
    def MASS_DEPENDS(self) -> str | None:  # noqa: N802
        return next(iter(self.NORMAL.values())).MASS_DEPENDS

    @property
    def STEPPING(self) -> str:  # noqa: N802
        return next(iter(self.NORMAL.values())).STEPPING

    @property
    def FRICTION(self) -> str | None:  # noqa: N802
        return next((model.FRICTION for model in self.TANGENTIAL.values()), None)

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


# the tangential laws (`tangential_law` names, read from their table), all with a Coulomb
# mu: the rows of an engine whose one tangential model is its friction alone (MuJoCo's,
# Drake's)
TANGENTIAL_LAWS = TANGENTIAL_LAW_NAMES
# the facts every final class declares (its base's annotated class attributes)
FACTS, NORMAL_FACTS, TANGENTIAL_FACTS = (
    tuple(base.__annotations__)
    for base in (AbstractEngine, AbstractNormalModel, AbstractTangentialModel)
)


def scene_geometry(engine: AbstractEngine, geometry: str | None) -> str:
    """The scene `geometry` asks of `engine` (a key of `SCENES`; None: the default, the
    first), or a one-line ValueError."""
    if geometry is None:
        return next(iter(engine.SCENES))
    if geometry not in engine.SCENES:
        kinds = " or ".join(map(repr, engine.SCENES))
        raise ValueError(f"{engine.NAME} exports geometry {kinds}, not {geometry!r}")
    return geometry


def sphere_radius(engine: str, radius, geometry: str | None) -> float:
    """The spheres' `radius` (m) checked, or the one-line ValueError of `engine` (its name)
    without one (on a wall, `geometry` "wall", the sphere's)."""
    if radius is None:
        what = "sphere's" if geometry == "wall" else "spheres'"
        raise ValueError(f"{engine} needs the {what} radius: pass radius= (m)")
    return check_positive("radius", radius, "m")


def contact_mass(engine: AbstractEngine, m: float, geometry: str | None = None) -> float:
    """The mass (kg) the contact moves: `m/2` for two equal spheres of mass `m` (a
    two-sphere engine's scene unless `geometry` is `"wall"`), else `m` (a body on a wall
    or plane)."""
    return m / 2.0 if engine.TWO_SPHERES and geometry != "wall" else m
