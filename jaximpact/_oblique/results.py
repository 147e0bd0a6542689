"""What one oblique impact gives: `ObliqueResult`."""

import math

import equinox as eqx
import numpy as np
from jaxtyping import Array

from .._checks import is_traced
from .._format import format_fields, format_number, format_value, jsonable
from .._solve.results import status_names, status_text
from .._status import Status

# the fields as `summary()` shows them: name, unit ("" a pure number, None a count)
_SHOWN = (
    ("e", ""),
    ("e_t", ""),
    ("e_t_contact", ""),
    ("v_n_out", "m/s"),
    ("v_t_out", "m/s"),
    ("omega_out", "rad/s"),
    ("u_out", "m/s"),
    ("angle_out", "rad"),
    ("angle_out_contact", "rad"),
    ("T", "s"),
    ("impulse_n", "N s"),
    ("impulse_t", "N s"),
    ("dissipated", "J"),
    ("num_switches", None),
    ("num_steps", None),
)
_NOT_RESULTS = ("status", "num_steps", "num_switches")


def _shown(value, unit: str | None) -> str:
    """A field as `summary()` shows it: an angle in radians with its degrees beside it
    (`408.7 mrad (23.42 deg)`), the rest by `format_value`."""
    text = format_value(value, unit)
    if unit != "rad" or is_traced(value) or np.ndim(value) != 0 or not np.isfinite(value):
        return text
    return f"{text} ({format_number(math.degrees(float(value)), 4)} deg)"


class ObliqueResult(eqx.Module):
    """What one oblique impact gives (SI units; angles in radians, measured from the
    normal, positive towards the incident tangential motion).

    - `e`: normal restitution `v_n_out / v_n` (0 unless `status == separated`);
      `v_n_out` (m/s): the normal speed of leaving (> 0).
    - `e_t`: `v_t_out / v_t`, the centre's tangential restitution (DESIGN.md; Kharaz et
      al.'s and Chung & Ooi's Test 4 `e_t`); NaN for `v_t = 0`, where it has no meaning.
    - `e_t_contact`: `u_out / u`, the contact point's (Maw et al.'s rebound/incidence
      ratio; Chung & Ooi's `beta` is `-e_t_contact`); NaN for `u = 0`.
    - `v_t_out` (m/s), `omega_out` (rad/s): the centre's tangential velocity and the spin
      after the impact; `u_out = v_t_out - R omega_out` (m/s) the contact point's slip.
    - `angle_in`, `angle_out`: the centre's incidence and rebound angles,
      `arctan(v_t / v_n)`, `arctan(v_t_out / v_n_out)`; `angle_in_contact`,
      `angle_out_contact`: the contact point's, `arctan(u / v_n)`, `arctan(u_out / v_n_out)`
      (Chung & Ooi's Test 4 rebound angle; Maw et al.'s `psi_2` is proportional to its
      tangent times `e`).
    - `T` (s): contact duration; `impulse_n`, `impulse_t` (N s): the momentum the contact
      gave, `m (v_n_out + v_n)` and `m (v_t_out - v_t)`; `dissipated` (J): the kinetic
      energy (translation and spin) the contact took, plus the work of gravity over the
      final penetration.
    - `status`: a `jaximpact.Status` as an integer array (`separated`, `stuck`,
      `captured`, `out_of_steps`: also where the contact switched between sticking and
      sliding more than `max_segments - 1` times, `failed`); a failed solve has NaN in
      every result field. `num_switches`: how many times the contact changed between
      sticking and sliding; `num_steps`: solver steps.
    - `path`: the path that served (DESIGN.md, "Off the curves"): `"integrated"` (the
      event-terminated diffrax solve, `oblique_impact`'s), or for a batch of
      `oblique_impact_batch` a tuple with one name per row, `"grid"` where the
      phase-angle grid served it (`_oblique/grid.py`).
    """

    e: Array
    e_t: Array
    e_t_contact: Array
    v_n_out: Array
    v_t_out: Array
    omega_out: Array
    u_out: Array
    angle_in: Array
    angle_out: Array
    angle_in_contact: Array
    angle_out_contact: Array
    T: Array
    impulse_n: Array
    impulse_t: Array
    dissipated: Array
    status: Array
    num_switches: Array
    num_steps: Array
    path: str | tuple[str, ...] = eqx.field(static=True, default="integrated")

    @property
    def separated(self) -> Array:
        return self.status == Status.separated

    @property
    def status_name(self) -> str:
        """The status as a word (for a single impact, not a batch)."""
        return Status(int(self.status)).name

    def _status_text(self) -> str:
        return status_text(self.status)

    def summary(self) -> str:
        """The impact as text, every number with its unit; a batch by the range of each
        field and the count of each status; inside `jit` the shapes."""
        rows = [(name, _shown(getattr(self, name), unit)) for name, unit in _SHOWN]
        rows.append(("status", self._status_text()))
        return format_fields("ObliqueResult (SI units, angles in rad)", rows)

    def to_dict(self) -> dict:
        """The fields as plain numbers and lists (SI units, radians), NaN as None,
        `status` as its name (a list of names for a batch)."""
        out = {name: jsonable(getattr(self, name)) for name, _ in _SHOWN}
        for name in ("angle_in", "angle_in_contact"):
            out[name] = jsonable(getattr(self, name))
        out["status"] = status_names(self.status)
        return out

    def __repr__(self) -> str:
        return self.summary()
