"""The engine interface: `AbstractEngine`, what every engine an export can target declares and
provides; `Design`, what an engine's design gives for a target e and T; `Stepping`, its time
stepping replicated; `Key`, one input of its parameters.

Each engine is one final class in its own module (`mujoco.py`, `drake.py`, ...), registered
once in `export.ENGINES`, which `jaximpact.export`, `engine_response`, `stepped_response` and
the command line read: nothing else names an engine (docs/layout.md, "Adding an engine").
Units are SI throughout; an engine's own parameters keep its own names.
"""

import abc
import dataclasses
from collections.abc import Callable, Mapping
from typing import ClassVar, NamedTuple

import numpy as np


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


@dataclasses.dataclass(frozen=True)
class Stepping:
    """An engine's time stepping, replicated in numpy: its `timestep` (s), and `run(v)`, the
    arrays `(e, T)` (T in s) over start phases (where the first touch falls inside a step)
    of one contact at impact speed `v` (m/s)."""

    timestep: float
    run: Callable[[float], tuple[np.ndarray, np.ndarray]]


# the facts every engine declares (class attributes), checked when its class is made
FACTS = (
    "NAME",
    "LABEL",
    "SCENES",
    "TWO_SPHERES",
    "MASS_DEPENDS",
    "KEYS",
    "LAW",
    "STEPPING",
    "CONTINUOUS_PLANT",
)


class AbstractEngine(abc.ABC):
    """A simulation engine that `export` can target. Abstract: an engine is a final class
    derived from this one alone, declaring every fact below and implementing every abstract
    method.

    **Facts** (class attributes):

    - `NAME`: the name `export(..., engine)` and `jaximpact export ENGINE` take;
      `LABEL`: the engine's name as its documentation spells it.
    - `SCENES`: the collision an export is for, by geometry (`export(geometry=)`), the
      first being the default: `"spheres"`, two equal spheres head-on at relative speed v0;
      `"wall"`, one body on a fixed flat wall (or plane) at v0.
    - `TWO_SPHERES`: the default scene is two equal spheres: the radius is needed (m),
      a contact duration T is needed, and the contact's effective mass is m/2.
    - `MASS_DEPENDS`: what the mass changes in its parameters, or None where they do not
      depend on it (MuJoCo's solref is per unit mass).
    - `KEYS`: its parameters as `engine_response` takes them (`Key`: name, unit, needed).
    - `LAW`: the jaximpact law (its contact law family) the engine integrates.
    - `STEPPING`: how it steps, in words (what `stepper` replicates, or that it does not).
    - `CONTINUOUS_PLANT`: a time step of 0 runs a continuous, error-controlled plant.
    - `NEAREST` (optional, default None: its `LAW` law): how the engine's nearest law to
      one it lacks (a plastic or adhesive law) is named in an export's warning.

    - `TANGENTIAL` (optional, default none): the tangential laws (`tangential_law` names)
      the engine takes exactly, with `with_tangential`.
    - `CONTACT_POINT` (optional, default on the undeformed surface): where its tangential
      force acts, by scene, as the share `f` of the overlap off each sphere's lever arm
      `R - f x` (`oblique_impact(contact_point=)`; 0.5: halfway through the overlap).
    - `FRICTION` (optional, default None): where the engine has no tangential law of
      jaximpact's but friction alone, what it makes of a tangential law (its nearest), in
      words; `with_tangential` then takes any tangential law's `mu`.
    - `REFUSES_LIMIT_DAMPING` (optional, default None): the engine's model that refuses
      `export(limit_damping=True)` (LAMMPS's cohesive `jkr` and `dmt`), refused before any
      work (`check_limit_damping`).

    **Optional methods**: `native(law)`, the engine (its own model) that exports `law`
    where the engine has that law itself (LAMMPS's `jkr`), else None;
    `with_tangential(parameters, tangential)`, the design's parameters with the tangential
    law set (for the laws of `TANGENTIAL`, or its friction for a `FRICTION` engine);
    `check_tangential(tangential, radius=, timestep=)`, its refusal before any work;
    `tangential_options(design, tangential, options)`, the design options its tangential
    law needs; `realised_tangential(parameters, tangential)`, the tangential law it realises;
    and `tangential_changes(parameters, tangential)`, how it differs, in words;
    `oblique(parameters, *, m, radius, v_n, v_t)`, the oblique impacts the engine realises
    where it is replicated (else None: an export promises its continuous laws').
    """

    NAME: ClassVar[str]
    LABEL: ClassVar[str]
    SCENES: ClassVar[Mapping[str, str]]
    TWO_SPHERES: ClassVar[bool]
    MASS_DEPENDS: ClassVar[str | None]
    KEYS: ClassVar[tuple[Key, ...]]
    LAW: ClassVar[str]
    STEPPING: ClassVar[str]
    CONTINUOUS_PLANT: ClassVar[bool]
    NEAREST: ClassVar[str | None] = None
    TANGENTIAL: ClassVar[tuple[str, ...]] = ()
    FRICTION: ClassVar[str | None] = None
    CONTACT_POINT: ClassVar[Mapping[str, float]] = {"wall": 0.0, "spheres": 0.0}
    REFUSES_LIMIT_DAMPING: ClassVar[str | None] = None

    def check_limit_damping(self, limit_damping: bool) -> None:
        """A one-line ValueError where `limit_damping` is asked of a model that refuses it
        (`REFUSES_LIMIT_DAMPING`), before any work."""
        if limit_damping and self.REFUSES_LIMIT_DAMPING is not None:
            raise ValueError(
                f"{self.LABEL} refuses limit_damping with its {self.REFUSES_LIMIT_DAMPING} "
                "model (a cohesive normal model): drop limit_damping"
            )

    def check_tangential(self, tangential, *, radius, timestep) -> None:
        """A one-line ValueError where the engine cannot take `tangential` (before any
        work); `radius` (m) and `timestep` (s or None) are the export's."""
        self.with_tangential({}, tangential)

    def tangential_options(self, design: "Design", tangential, options: dict) -> dict:
        """The design `options` (`poisson`, ...) with which the engine's tangential law,
        tied to its normal contact, realises `tangential`, given a first `design`; an
        export designs again with them where they differ. Default: `options`."""
        return options

    def tangential_changes(self, parameters: dict, tangential) -> list[str]:
        """What the engine changes with `parameters` exported for `tangential`: where the
        law it realises differs from `tangential`, and what of the normal design it set
        anew, in words (an empty list where nothing)."""
        return []

    def realised_tangential(self, parameters: dict, tangential):
        """The tangential law (a jaximpact one) the engine realises with `parameters`
        exported for `tangential`: `tangential` itself unless the engine ties its tangential
        spring or damper to other parameters (LIGGGHTS)."""
        return tangential

    def oblique(self, parameters: dict, *, m: float, radius: float, v_n, v_t):
        """`(e, e_t, omega)` per first-touch phase (rad/s for the spin) that the engine's
        own time stepping realises with `parameters` for a sphere of mass `m` (kg) and
        radius `radius` (m)
        meeting its plane at `v_n`, `v_t` (m/s, arrays of one shape, no spin before), or
        None where it is not replicated."""
        return None

    def with_tangential(self, parameters: dict, tangential) -> dict:
        """`parameters` with the tangential law `tangential` (a law of `TANGENTIAL`); a
        one-line ValueError for a law the engine does not take."""
        raise ValueError(
            f"{self.LABEL} has no tangential export yet (the normal law is exported alone); "
            "export tangential laws to lammps, liggghts, yade, mujoco or drake"
        )

    def native(self, law) -> "AbstractEngine | None":
        """The engine's own model for `law` (a law of the table it has beyond its `LAW`
        family), or None: it exports the family's law."""
        return None

    def __init_subclass__(cls, **kwargs):
        super().__init_subclass__(**kwargs)
        if cls.__bases__ != (AbstractEngine,):
            raise TypeError(
                f"{cls.__name__}: an engine is a final class derived from AbstractEngine alone"
            )
        missing = [fact for fact in FACTS if not hasattr(cls, fact)]
        if missing:
            raise TypeError(f"engine {cls.__name__} does not declare {', '.join(missing)}")

    @abc.abstractmethod
    def design(
        self,
        e: float,
        T: float | None,
        *,
        m: float,
        v0: float,
        timestep: float | None = None,
        radius: float | None = None,
        poisson: float = 0.3,
        limit_damping: bool = False,
        geometry: str | None = None,
    ) -> Design:
        """The parameters that realise restitution `e` and duration `T` (s; None where the
        engine has a default) for mass `m` (kg; each sphere's) at impact speed `v0` (m/s),
        at the engine's step `timestep` (s; None: a recommended one), with the spheres'
        `radius` (m) and `poisson` ratio where the engine takes them, `limit_damping` (keep
        the force non-attractive, where that is an option) and `geometry` (a key of
        `SCENES`; None: the default). A one-line ValueError where it cannot."""

    @abc.abstractmethod
    def law_parameters(self, parameters: dict, m: float) -> dict:
        """The parameters (SI) of the engine's law `LAW` that its `parameters` give a body of
        mass `m` (kg)."""

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

    @abc.abstractmethod
    def snippet(self, parameters: dict) -> str:
        """Text to paste into the engine's model or script, from its design's
        `parameters`."""

    def law(self, parameters: dict, m: float):
        """The continuous law the engine realises with `parameters` for a body of mass `m`
        (kg), as a jaximpact law `LAW`."""
        from .._laws import law as make_law

        return make_law(self.LAW, **self.law_parameters(parameters, m))

    def geometry(self, geometry: str | None) -> str:
        """The scene `geometry` asks of the engine (a key of `SCENES`; None: the default, the
        first), or a one-line ValueError."""
        if geometry is None:
            return next(iter(self.SCENES))
        if geometry not in self.SCENES:
            kinds = " or ".join(map(repr, self.SCENES))
            raise ValueError(f"{self.NAME} exports geometry {kinds}, not {geometry!r}")
        return geometry

    def effective_mass(self, m: float, geometry: str | None = None) -> float:
        """The mass (kg) the contact moves: `m/2` for two equal spheres of mass `m` (a
        two-sphere engine's scene unless `geometry` is `"wall"`), else `m` (a body on a wall
        or plane)."""
        return m / 2.0 if self.TWO_SPHERES and geometry != "wall" else m

    def __repr__(self) -> str:
        return f"{type(self).__name__}()"
