"""What a contact is: the force laws, their table of per-law facts, their dynamics and exact
solutions. The bottom layer: imports nothing of jaximpact but the leaf helpers."""

from .base import (
    AbstractLaw as AbstractLaw,
    LawSpec as LawSpec,
    damping_parameter as damping_parameter,
    exponents as exponents,
    shape_of as shape_of,
    stiffness_parameter as stiffness_parameter,
)
from .custom import CustomLaw as CustomLaw, custom_law as custom_law
from .maxwell import MaxwellLaw as MaxwellLaw
from .named_law import Law as Law, law as law, table_law as table_law
from .table import LAW_NAMES as LAW_NAMES, LAWS as LAWS, SHIPPED_SHAPES as SHIPPED_SHAPES
