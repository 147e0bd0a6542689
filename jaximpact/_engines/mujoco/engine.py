"""MuJoCo: a body on a plane through its soft contact (`normal.py`) and friction."""

from ..base import TANGENTIAL_LAWS, AbstractEngine
from .friction import PyramidalFriction
from .normal import Solref


class Mujoco(AbstractEngine):
    """MuJoCo's soft contact for a body on a plane, at its Euler step."""

    NAME = "mujoco"
    LABEL = "MuJoCo"
    SCENES = {
        "wall": "a free body of mass m on a fixed plane (MuJoCo scales the contact per unit "
        "mass: the promise holds for any mass), no gravity, approaching along the normal at v0"
    }
    TWO_SPHERES = False
    CONTINUOUS_PLANT = False
    NORMAL = {"kelvin_voigt": Solref()}
    # friction only (its mu), whatever the tangential law: the table's names are the laws'
    TANGENTIAL = dict.fromkeys(TANGENTIAL_LAWS, PyramidalFriction())

    def snippet(self, parameters) -> str:
        solref = " ".join(f"{v:.10g}" for v in parameters["solref"])
        solimp = " ".join(f"{v:g}" for v in parameters["solimp"])
        option, geom, note = "", "", ""
        if "friction" in parameters:
            friction = " ".join(f"{v:.10g}" for v in parameters["friction"])
            option = ' cone="pyramidal" impratio="1"'
            geom = f' friction="{friction}" condim="{parameters["condim"]}"'
            note = "; it takes the larger friction of the two"
        return (
            f'<option timestep="{parameters["timestep"]:.6g}" integrator="Euler"{option}/>\n'
            "<default>\n"
            f'  <geom solref="{solref}" solimp="{solimp}"{geom}/>\n'
            "</default>\n"
            "<!-- MuJoCo mixes the solref/solimp of the two geoms in contact: give both these\n"
            f"     values (the default class above does), or use a <pair>{note} -->"
        )
