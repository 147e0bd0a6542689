"""One shape's curves as data: `Curves`, and the constants of their tables."""

import dataclasses

import numpy as np

from . import chebyshev
from .shapes import CurveKey

# the tabulated outputs, in this order: e, T/t*, x_max/x*, t_max/t*, F_max/(c x*^n)
OUTPUTS = ("e", "tau", "x_max", "t_max", "F_max")
BETA_MIN = 1e-18  # below it every output is its elastic limit plus the first-order slope
BETA_MAX = 1e4
DEGREE = 20


@dataclasses.dataclass(frozen=True, eq=False)
class Curves:
    """A shape's curves: `ln` of the `OUTPUTS` as piecewise Chebyshev series in `ln beta`.

    `breaks` (K + 1,), `coefficients` (K, DEGREE + 1, 5); `beta_max`: the end of the
    table; `capture`: `None`, or the `beta` above which the body never leaves (then the
    table ends below it and the curves do not serve this key); `tail` (K, 5): each piece's
    largest last coefficient per output, an estimate of its error (above the build
    tolerance only where the reference itself is noisy: `T` at heavy damping under the
    force criterion, where the force stays near zero while the body creeps out)."""

    key: CurveKey
    breaks: np.ndarray
    coefficients: np.ndarray
    beta_max: float
    capture: float | None
    tail: np.ndarray

    def log_values(self, beta) -> np.ndarray:
        """`ln` of the outputs at `beta` (numpy, inside the table): `(len(beta), 5)`."""
        return chebyshev.evaluate_numpy(self.breaks, self.coefficients, np.log(beta))
