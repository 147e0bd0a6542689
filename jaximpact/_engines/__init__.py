"""Exports of a law to the contact parameters of MuJoCo, Drake, LAMMPS, LIGGGHTS, Chrono and
Yade with the e and T they realise (docs/engines.md); the engines are declared through
`base.py` and registered in `registry.ENGINES` (docs/layout.md, "Adding an engine")."""

from .base import (
    AbstractEngine as AbstractEngine,
    AbstractNormalModel as AbstractNormalModel,
    AbstractTangentialModel as AbstractTangentialModel,
    Design as Design,
    Key as Key,
    Scene as Scene,
    Stepping as Stepping,
)
from .export import ENGINES as ENGINES, Export as Export, export as export
from .materials import (
    effective_mass as effective_mass,
    effective_radius as effective_radius,
    hertz_stiffness as hertz_stiffness,
)
from .response import engine_response as engine_response, stepped_response as stepped_response
