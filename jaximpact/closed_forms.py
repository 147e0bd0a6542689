"""Exact solutions, public: `jaximpact.closed_forms.kelvin_voigt(c, b, m, v0)` and friends."""

from ._laws.closed_forms import (
    hunt_crossley_restitution as hunt_crossley_restitution,
    kelvin_voigt as kelvin_voigt,
    maxwell as maxwell,
    power_spring as power_spring,
)
