"""The engine interface, after LAMMPS's `granular_model.cpp`: an export composes one normal
model (`GranSubModNormal`: designs the engine's parameters for a target e and T) and one
tangential model (`GranSubModTangential`) of an engine; `AbstractEngine` declares its scenes
and its tables of both, law name -> model, as `GranSubModStyle` lines register them. Each
engine is one final class, registered once in `registry.ENGINES`. SI units throughout."""

import abc
import dataclasses
from collections.abc import Callable, Mapping
from typing import ClassVar, NamedTuple

import numpy as np

from .._oblique.tangential import TANGENTIAL_LAW_NAMES
from .materials import check_positive


class Key(NamedTuple):
    """One input of an engine's parameters (`engine_response`, `jaximpact engine-e`): its
    name, unit (or form) and whether it is needed."""

    name: str
    unit: str
    needed: bool = True


@dataclasses.dataclass(frozen=True)
class Design:
    """A normal model's design for a target e and T: its `parameters` (the engine's names and
    units) and what the engine realises with them, its stepping included where replicated.
    `timestep` 0.0: Drake's continuous plant; `separation`: `"force"` or `"penetration"`;
    `e_range`, `T_range`: extremes over start phases (None: no stepping replicated);
    `target_T`: the T aimed at where none was asked (MuJoCo's default timeconst's);
    `stepping`: what the model's `stepper` takes to replay it; `clause`: LAMMPS's normal
    `pair_coeff` clause, which a tangential clause follows."""

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
        """The design whose stepping at step `h` (s) realises `es`, `Ts` per start phase."""
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
    """An engine's stepping replicated: its `timestep` (s) and `run(v)`, `(e, T)` per start
    phase at impact speed `v` (m/s)."""

    timestep: float
    run: Callable[[float], tuple[np.ndarray, np.ndarray]]


@dataclasses.dataclass(frozen=True)
class Scene:
    """The collision exported: mass `m` (kg, each body), `v0` (m/s), `radius` (m or None),
    `geometry` (`"spheres"`: two equal spheres; `"wall"`: one body on a fixed wall or plane)
    and the `law` exported (None from targets)."""

    m: float
    v0: float
    radius: float | None
    geometry: str
    law: object = None

    @property
    def wall(self) -> bool:
        return self.geometry == "wall"


def _check_declared(cls, base) -> None:
    """A final class derived from `base` alone, declaring `base`'s annotated facts."""
    if cls.__bases__ != (base,):
        raise TypeError(f"{cls.__name__}: a final class derived from {base.__name__} alone")
    missing = [fact for fact in base.__annotations__ if not hasattr(cls, fact)]
    if missing:
        raise TypeError(f"{cls.__name__} does not declare {', '.join(missing)}")


class _Final:
    """The abstract bases: each subclass is final and declares every fact."""

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        base = next(b for b in cls.__mro__ if _Final in b.__bases__)
        if base is not cls:
            _check_declared(cls, base)

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"


class AbstractNormalModel(_Final, abc.ABC):
    """One normal model of an engine (LAMMPS's `GranSubModNormal`). Facts: `NAME`, the
    engine's name for it; `LAW`, the jaximpact law it integrates; `KEYS`, its parameters;
    `STEPPING`, how the engine steps it, in words; `MASS_DEPENDS`, what the mass changes (None:
    per unit mass); `ALLOWS_LIMIT_DAMPING` (LAMMPS's cohesive models refuse it, as
    `GranularModel::init()`); `NEAREST`, its name as the nearest law to one the engine lacks;
    `SCENES`, the engine's scenes in its own words, or None."""

    NAME: ClassVar[str]
    LAW: ClassVar[str]
    KEYS: ClassVar[tuple[Key, ...]]
    STEPPING: ClassVar[str]
    MASS_DEPENDS: ClassVar[str | None]
    ALLOWS_LIMIT_DAMPING: ClassVar[bool]
    NEAREST: ClassVar[str]
    SCENES: ClassVar[Mapping[str, str] | None]

    @abc.abstractmethod
    def design(self, e, T, scene: Scene, *, timestep=None, poisson=0.3, limit_damping=False):
        """The parameters that realise `e` and `T` (s; None: the engine's default) in
        `scene` at `timestep` (s; None: recommended); a one-line ValueError where not."""

    @abc.abstractmethod
    def law_parameters(self, parameters: dict, m: float) -> dict:
        """The parameters (SI) of `LAW` that `parameters` give a body of mass `m` (kg)."""

    @abc.abstractmethod
    def response(self, parameters: dict, *, m: float, radius: float | None = None):
        """`(law, separation)` of the engine's `parameters` (checked) for mass `m` (kg, each
        sphere's) and `radius` (m)."""

    @abc.abstractmethod
    def stepper(self, parameters: dict, *, m: float, radius: float | None = None):
        """The `Stepping` of `parameters`, or None where none applies or is replicated."""

    def law(self, parameters: dict, m: float):
        """The jaximpact law `LAW` that `parameters` realise for mass `m` (kg)."""
        from .._laws import law as make_law

        return make_law(self.LAW, **self.law_parameters(parameters, m))


class AbstractTangentialModel(_Final, abc.ABC):
    """One tangential model of an engine (LAMMPS's `GranSubModTangential`), a row of its
    `TANGENTIAL` table; every method stated (no default). Facts: `MODEL`, in words (how a law
    the table lacks is refused); `FRICTION`, for an engine with friction alone, what it makes
    of a law's `mu`, else None; `CONTACT_POINT`, by scene, the share `f` of the overlap off
    each sphere's lever arm `R - f x` (`oblique_impact(contact_point=)`)."""

    MODEL: ClassVar[str]
    FRICTION: ClassVar[str | None]
    CONTACT_POINT: ClassVar[Mapping[str, float]]

    @abc.abstractmethod
    def check(self, tangential, *, timestep) -> None:
        """A one-line ValueError where the model cannot take `tangential` at `timestep`."""

    @abc.abstractmethod
    def poisson(self, design: Design, tangential) -> float | None:
        """The Poisson's ratio to design the normal model at again (LIGGGHTS ties G* to E
        and nu), or None."""

    @abc.abstractmethod
    def parameters(self, design: Design, tangential) -> dict:
        """The `design`'s parameters with `tangential` set."""

    @abc.abstractmethod
    def realised(self, parameters: dict, tangential):
        """The tangential law the engine realises with `parameters`."""

    @abc.abstractmethod
    def notes(self, parameters: dict, tangential) -> list[str]:
        """What the engine changes of `tangential`, in words."""

    @abc.abstractmethod
    def oblique(self, parameters: dict, *, m: float, radius: float, v_n, v_t):
        """`(e, e_t, omega)` per first-touch phase of the engine's stepping for a sphere (`m`
        kg, `radius` m) meeting its plane at `v_n`, `v_t` (m/s), or None where not
        replicated."""


class AbstractEngine(_Final, abc.ABC):
    """An engine `export` targets. Facts: `NAME` (for `export` and the command line),
    `LABEL` (as its documentation spells it), `SCENES` (geometry -> words, the first the
    default), `TWO_SPHERES` (its default scene is two equal spheres: a radius and T needed,
    effective mass m/2), `CONTINUOUS_PLANT` (a step of 0 runs a continuous plant), `NORMAL`
    (law name -> normal model, the first the default and the nearest to a law it lacks) and
    `TANGENTIAL` (tangential law name -> model; empty: none). `KEYS`, `MASS_DEPENDS` and
    `STEPPING` are its first normal model's, `FRICTION` its tangential table's."""

    NAME: ClassVar[str]
    LABEL: ClassVar[str]
    SCENES: ClassVar[Mapping[str, str]]
    TWO_SPHERES: ClassVar[bool]
    CONTINUOUS_PLANT: ClassVar[bool]
    NORMAL: ClassVar[Mapping[str, AbstractNormalModel]]
    TANGENTIAL: ClassVar[Mapping[str, AbstractTangentialModel]]

    @abc.abstractmethod
    def snippet(self, parameters: dict) -> str:
        """Text to paste into the engine's model or script, from an export's `parameters`."""

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


# the tangential laws, all with a Coulomb mu: the rows of a friction-only engine's table
TANGENTIAL_LAWS = TANGENTIAL_LAW_NAMES
# the facts every final class declares
FACTS, NORMAL_FACTS, TANGENTIAL_FACTS = (
    tuple(base.__annotations__)
    for base in (AbstractEngine, AbstractNormalModel, AbstractTangentialModel)
)


def scene_geometry(engine: AbstractEngine, geometry: str | None) -> str:
    """The key of `engine.SCENES` that `geometry` asks (None: the first)."""
    if geometry is None:
        return next(iter(engine.SCENES))
    if geometry not in engine.SCENES:
        kinds = " or ".join(map(repr, engine.SCENES))
        raise ValueError(f"{engine.NAME} exports geometry {kinds}, not {geometry!r}")
    return geometry


def sphere_radius(engine: str, radius, geometry: str | None) -> float:
    """The spheres' `radius` (m) checked, or `engine`'s one-line ValueError without one."""
    if radius is None:
        what = "sphere's" if geometry == "wall" else "spheres'"
        raise ValueError(f"{engine} needs the {what} radius: pass radius= (m)")
    return check_positive("radius", radius, "m")


def contact_mass(engine: AbstractEngine, m: float, geometry: str | None = None) -> float:
    """The mass (kg) the contact moves: m/2 for two equal spheres, else m."""
    return m / 2.0 if engine.TWO_SPHERES and geometry != "wall" else m
