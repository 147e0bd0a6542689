"""LIGGGHTS: `pair_style gran model hertz` (`normal.py`) and its `tangential history`."""

from ..base import AbstractEngine
from ..lammps.engine import Lammps
from .normal import Hertz
from .tangential import TangentialHistory


class Liggghts(AbstractEngine):
    """LIGGGHTS's granular pair style with the material as `fix property/global`."""

    NAME = "liggghts"
    LABEL = "LIGGGHTS"
    SCENES = {
        "spheres": Lammps.SCENES["spheres"],
        "wall": "a sphere of mass m and radius `radius` hitting a fixed flat primitive wall "
        "(fix wall/gran, of the sphere's own material: atom type 1) head-on at speed v0 (no "
        "gravity, no friction effect)",
    }
    TWO_SPHERES = True
    CONTINUOUS_PLANT = False
    NORMAL = {"tsuji": Hertz()}
    TANGENTIAL = {"mindlin": TangentialHistory()}

    def snippet(self, parameters) -> str:
        return "\n".join(
            [
                "units si",
                "atom_style granular",
                "communicate single vel yes",
                *([parameters["particle_range"]] if parameters.get("particle_range") else []),
                parameters["youngsModulus"],
                parameters["poissonsRatio"],
                parameters["coefficientRestitution"],
                parameters["coefficientFriction"],
                parameters["pair_style"],
                parameters["pair_coeff"],
                *([parameters["fix_wall"]] if parameters.get("fix_wall") else []),
                "fix integr all nve/sphere",
                parameters["timestep"],
            ]
        )
