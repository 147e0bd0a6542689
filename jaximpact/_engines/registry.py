"""`ENGINES`, the one registry of the engines, and `engine(name)`."""

from .._choices import unknown_name
from . import chrono, yade
from .base import AbstractEngine
from .drake.engine import Drake
from .lammps.engine import Lammps
from .liggghts.engine import Liggghts
from .mujoco.engine import Mujoco

# in the order messages list them; a new engine is its module and one line here
ENGINES: dict[str, AbstractEngine] = {
    engine.NAME: engine
    for engine in (Mujoco(), Lammps(), Drake(), Liggghts(), chrono.Chrono(), yade.Yade())
}


def engine(name: str) -> AbstractEngine:
    """The engine `name` of `ENGINES`, or a one-line ValueError naming the engines."""
    if name not in ENGINES:
        raise ValueError(unknown_name("engine", name, list(ENGINES)))
    return ENGINES[name]
