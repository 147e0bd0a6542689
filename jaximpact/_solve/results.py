"""What one impact gives: `ImpactResult`."""

import equinox as eqx
from jaxtyping import Array

from .._status import Status


class ImpactResult(eqx.Module):
    """What one impact gives (SI units).

    - `e`: coefficient of restitution `-v_out / v0` (0 unless `status == separated`).
    - `T`: contact duration (s), from first touch to separation; for `stuck` the time at
      which the body came to rest; for `captured` the time the solve gave up (the horizon
      `tau_max t*`, or the instant its speed and net force fell below `rest_tol`; in closed
      form for over-damped Kelvin-Voigt under `"penetration"` and for over-damped Maxwell,
      `mu = sqrt(m c)/b >= 2` without gravity, which never reaches maximum compression).
      Its derivatives are those of that instant (finite); `e` of a captured member is 0
      with derivative 0.
    - `x_max` (m), `t_max` (s): maximum penetration and when it is reached.
    - `F_max` (N): largest contact force (at first touch, at the first force peak in
      compression, or at maximum compression, whichever is largest).
    - `dissipated` (J): kinetic energy taken by the contact, `m v0^2 (1 - e^2)/2` plus the
      work of gravity over the final penetration.
    - `v_out` (m/s): velocity at separation (negative: leaving).
    - `status`: a `jaximpact.Status` as an integer array; `num_steps`: solver steps.
    - `x_max`, `t_max`, `F_max` are `None` under `impact(..., peaks=False)`, which skips the
      events that find them (a law split at maximum compression still gives `x_max`).
    - `path`: `"similarity"` (read off the universal curves), `"closed_form"` or
      `"integrated"`.
    - `ts`, `x`, `v`, `F`: time histories, only when `impact(..., ts=...)` asked for them.
    """

    e: Array
    T: Array
    dissipated: Array
    v_out: Array
    status: Array
    num_steps: Array
    path: str = eqx.field(static=True)
    x_max: Array | None = None
    F_max: Array | None = None
    t_max: Array | None = None
    ts: Array | None = None
    x: Array | None = None
    v: Array | None = None
    F: Array | None = None

    @property
    def separated(self) -> Array:
        return self.status == Status.separated

    @property
    def status_name(self) -> str:
        """The status as a word (for a single impact, not a batch)."""
        return Status(int(self.status)).name
