"""Drake: point contact in a MultibodyPlant (`normal.py`) and its friction."""

from ..base import TANGENTIAL_LAWS, AbstractEngine
from .friction import StribeckFriction
from .normal import PointContact


class Drake(AbstractEngine):
    """Drake's point contact for a body on a half space."""

    NAME = "drake"
    LABEL = "Drake"
    SCENES = {
        "wall": "a body of mass m on a fixed half space (both geometries with the exported "
        "properties), no gravity, approaching along the normal at v0; continuous plant "
        "(time_step = 0), or discrete with the Lagged, Similar or TAMSI approximation when a "
        "timestep is given"
    }
    TWO_SPHERES = False
    CONTINUOUS_PLANT = True
    NORMAL = {"point_contact": PointContact()}
    # friction only (its mu), whatever the tangential law
    TANGENTIAL = dict.fromkeys(TANGENTIAL_LAWS, StribeckFriction())

    def snippet(self, parameters) -> str:
        per = parameters["per_geometry"]
        friction, tolerance = "", ""
        if "friction" in parameters:
            mu_s, mu_d = parameters["friction"]
            friction = f"friction=CoulombFriction({mu_s!r}, {mu_d!r}), "
            tolerance = f"plant.set_stiction_tolerance({parameters['stiction_tolerance']!r})\n"
        return (
            "from pydrake.geometry import AddContactMaterial, ProximityProperties\n"
            + ("from pydrake.multibody.plant import CoulombFriction\n" if friction else "")
            + "props = ProximityProperties()\n"
            f"AddContactMaterial(dissipation={per['hunt_crossley_dissipation']!r}, "
            f"point_stiffness={per['point_contact_stiffness']!r}, {friction}properties=props)\n"
            "# give these props to BOTH geometries in contact (they combine in series)\n"
            f"plant = MultibodyPlant(time_step={parameters['time_step']!r})"
            + (
                "  # continuous: the promise holds\n"
                if not parameters["time_step"]
                else "\nplant.set_discrete_contact_approximation("
                "DiscreteContactApproximation.kLagged)  # not kSap\n"
            )
            + "plant.set_contact_model(ContactModel.kPoint)"
            + (f"\n{tolerance}" if tolerance else "")
        )
