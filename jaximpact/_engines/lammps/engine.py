"""LAMMPS's `pair_style granular` (two equal spheres, or a sphere on `fix wall/gran`) at `fix
nve/sphere`'s velocity Verlet: its models as `GranSubModStyle` lines register them."""

from ..base import AbstractEngine
from . import script
from .dmt import DMT
from .hertz import HertzMaterial
from .jkr import JKR
from .jkr_viscoelastic import JKRViscoelastic
from .tangential import TANGENTIAL


class Lammps(AbstractEngine):
    """LAMMPS's `pair_style granular`."""

    NAME = "lammps"
    LABEL = "LAMMPS"
    SCENES = {
        "spheres": "two equal spheres, each of mass m and radius `radius`, colliding head-on at "
        "relative speed v0 (no gravity, no friction effect on a head-on impact)",
        "wall": "a sphere of mass m and radius `radius` hitting a fixed flat wall (fix "
        "wall/gran, the sphere's own material) head-on at speed v0 (no gravity, no friction "
        "effect)",
    }
    TWO_SPHERES = True
    CONTINUOUS_PLANT = False
    NORMAL = {
        "tsuji": HertzMaterial(),
        "jkr": JKR(),
        "dmt": DMT(),
        "jkr_viscoelastic": JKRViscoelastic(),
    }
    TANGENTIAL = TANGENTIAL

    def snippet(self, parameters) -> str:
        return script.snippet(parameters)  # every normal model's scene alike
