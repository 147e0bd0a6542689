"""Which one-group impacts the curves describe: a shape `(n, p)` and a separation criterion.

Without gravity and without a dry force, the law `F = c x^n + b x^p v` gives an impact
that depends on one number, `beta = b x*^(p+1)/(m v0) = b v0 x*^(p-n)/c`, in the units
`x* = (m v0^2/c)^(1/(n+1))` and `t* = x*/v0`. `CurveKey` names one such family of
impacts; where `p = n` the force vanishes only at `x = 0`, so both criteria are the same
curve (`separation="either"`).
"""

import dataclasses

SEPARATIONS = ("force", "penetration", "either")


@dataclasses.dataclass(frozen=True)
class CurveKey:
    """`n`, `p`: exponents of `F = c x^n + b x^p v` (`0 <= p <= n`); `separation`."""

    n: float
    p: float
    separation: str

    def __post_init__(self):
        if not (self.n > 0 and 0 <= self.p <= self.n):
            raise ValueError(
                f"the curves need exponents 0 <= p <= n and n > 0, got n={self.n}, p={self.p}"
            )
        if self.separation not in SEPARATIONS:
            raise ValueError(f"separation must be one of {SEPARATIONS}, got {self.separation!r}")

    @property
    def gap(self):
        """`PowerDynamics.gap`: `"x"` where the force vanishes at `x = 0` only, else `n - p`."""
        return "x" if self.n == self.p else float(self.n - self.p)

    @property
    def name(self) -> str:
        return f"n={self.n:g},p={self.p:g},{self.separation}"


def curve_key(n, p, separation: str) -> CurveKey:
    """The key of the shape `(n, p)` under `separation` (`"force"` or `"penetration"`).

    `p = n` and `(n, p) = (1, 1)`-type laws (`F = x^p (c x^(n-p) + b v)` with `n = p`) end
    contact at `x = 0` under both criteria, so they share one curve."""
    n, p = float(n), float(p)
    return CurveKey(n, p, "either" if n == p else separation)
