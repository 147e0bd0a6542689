"""`ENGINES`, the one registry of the engines that `export`, `engine_response`,
`stepped_response` and the command line read, and `engine(name)`, the lookup that refuses
an unknown name in one line."""

from .._choices import unknown_name
from . import chrono, yade
from .base import AbstractEngine
from .drake.engine import Drake
from .lammps.engine import Lammps
from .liggghts.engine import Liggghts
from .mujoco.engine import Mujoco

# The registry, in the order messages list the engines: one final `AbstractEngine` each.
# A new engine is its module and one line here (docs/layout.md, "Adding an engine").
ENGINES: dict[str, AbstractEngine] = {
    engine.NAME: engine
    for engine in (Mujoco(), Lammps(), Drake(), Liggghts(), chrono.Chrono(), yade.Yade())
}


def engine(name: str) -> AbstractEngine:
    """The engine `name` of `ENGINES`, or a one-line ValueError naming the engines."""
    if name not in ENGINES:
        raise ValueError(unknown_name("engine", name, list(ENGINES)))
    return ENGINES[name]
