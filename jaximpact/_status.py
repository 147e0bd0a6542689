"""How an impact ended."""

import enum


class Status(enum.IntEnum):
    """How an impact ended; `ImpactResult.status` holds these as small integers.

    - `separated`: the body left the surface (by the chosen separation criterion).
    - `stuck`: a dry force `P` held the body at rest inside the surface (e = 0).
    - `captured`: the body never left, e.g. over-damped Kelvin-Voigt under the penetration
      criterion, or a body resting on the surface under gravity (e = 0; T is the time at
      which the integration gave up, see `impact`).
    - `out_of_steps`: the solver used `max_steps` before the contact ended: every result
      field is NaN (raise `max_steps` or loosen `rtol`).
    - `invalid`: a row of a batch whose inputs were refused (not finite, or out of range:
      a mass, speed or stiffness <= 0, a negative damping), or whose results float64
      cannot hold (its scales under- or overflow, e.g. v0 = 1e-300 m/s); it has no result
      (NaN) while the other rows have theirs (`impact_batch`).
    - `failed`: the solver failed otherwise (a step size below diffrax's minimum, or a
      force that is not a number along the solve): every result field is NaN.

    A failure (`out_of_steps`, `failed`) is never presented as a number: an eager `impact`
    raises a one-line error (pass `throw=False` to get the NaN result with its status),
    and under `jit` or `vmap` the member's result fields are NaN with its status.
    """

    separated = 0
    stuck = 1
    captured = 2
    out_of_steps = 3
    invalid = 4
    failed = 5

    @property
    def is_failure(self) -> bool:
        """The solve failed (no result), as opposed to a physical ending."""
        return self in (Status.out_of_steps, Status.failed)
