"""Maxwell's law (eqs. 10-11), a spring `c` in series with a dashpot `b`: the first law
whose force is a contact state (`dF/dt = c (v - F/b)`), not a function of `(x, v)`. Its row
of the law table (`MAXWELL`) stands beside the class that it builds."""

from typing import ClassVar

from jaxtyping import Array

from .base import AbstractLaw, LawSpec
from .closed_forms import maxwell_closed_form
from .dynamics import maxwell_dynamics
from .parameters import checked_parameters


class MaxwellLaw(AbstractLaw):
    """Maxwell's law, built by `jaximpact.law("maxwell", c=..., b=...)`: its force is a
    state of the contact, integrated with the motion (`MaxwellDynamics`), so it has no
    `force(x, v)`; read the force's history from `impact(..., ts=...).F`.

    **Example**: `jaximpact.law("maxwell", c=2e6, b=2000.0)`.
    """

    params: dict[str, Array]
    has_state: ClassVar[bool] = True

    @property
    def name(self) -> str:
        return MAXWELL.name

    @property
    def spec(self) -> LawSpec:
        return MAXWELL

    def replace(self, **params):
        self._refuse_unknown(params)
        return MaxwellLaw(checked_parameters(MAXWELL, {**self.params, **params}))

    def dynamics(self, *, m, v0, g):
        return maxwell_dynamics(self.params["c"], self.params["b"], m=m, v0=v0, g=g)

    def force(self, x, v, **_):
        """Not defined: the Maxwell force is a state of the contact."""
        raise ValueError(
            "the Maxwell force is a state, not a function of (x, v): "
            "read it from impact(..., ts=...).F"
        )


MAXWELL = LawSpec(
    name="maxwell",
    damping="b",
    map_range=(3000.0, 20000.0),
    restitution_table=True,  # Fig. 7: 4 b^2 > m c
    equation="10-11",
    formula="spring c in series with dashpot b: dF/dt = c (v - F/b)",
    parameters=("c", "b"),
    units={"c": "N/m", "b": "N s/m"},
    reference="Polukoshko et al. 2007, eqs. 10-11",
    state=MaxwellLaw,
    positive=("c", "b"),
    # eqs. 10-11 are linear with a constant forcing m g: exact for any damping and g >= 0
    closed_form=maxwell_closed_form,
    closed_form_gravity=True,
)
