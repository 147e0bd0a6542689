"""The engines people run (MuJoCo, Drake, LAMMPS, LIGGGHTS, Chrono, Yade): material inputs,
and exports of a law to an engine's own contact parameters with the e and T the engine
realises (docs/engines.md). `base.AbstractEngine` is what an engine declares, its tables
of normal and tangential models (`base.AbstractNormalModel`, `base.AbstractTangentialModel`)
included; `registry.ENGINES` is the one registry of them (docs/layout.md, "Adding an engine")."""

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
