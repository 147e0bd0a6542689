"""Nondimensional restitution tables, the start of a calibration.

For a law whose restitution depends on one dimensionless damping group `d` (the power-law
family `F = c x^n + b x^p v`: `d = b x*^(p+1)/(m v0)`; Maxwell: `d = b/sqrt(m c)`), an impact at
unit scales (`c = m = v0 = 1`, so `x* = t* = 1`) gives `e(d)` and `tau(d) = T/t*` once and for
all. The tables are computed by this module's `main()`
(`python -m jaximpact._fit.restitution_tables`)
and shipped in `_restitution_tables.npz`, so a first calibration does not pay their compile;
`tests/test_calibrate.py` checks them against fresh impacts.
"""

import functools
from pathlib import Path

import jax
import jax.numpy as jnp
import numpy as np

from .._laws import LAWS, table_law
from .._solve.impact import impact
from .._status import Status

# the laws whose rows ask for a table (`LawSpec.restitution_table`)
TABLE_LAWS = tuple(name for name, spec in LAWS.items() if spec.restitution_table)
GROUPS = np.logspace(-4, 2.5, 209)
_FILE = Path(__file__).with_name("_restitution_tables.npz")


def compute_table(name: str, separation: str, n: float = 1.5):
    """`(groups, e, tau)` from impacts at unit scales, separated members only."""
    spec = LAWS[name]

    def one(group):
        params = {"c": 1.0, **({"n": n} if "n" in spec.parameters else {})}
        # the damping that makes the family's b (or Maxwell's b / sqrt(m c)) equal the group
        per_unit = (
            1.0
            if spec.state is not None
            else spec.coefficients({**params, spec.damping: 1.0}, 1.0)[2]
        )
        params[spec.damping] = group / per_unit
        law = table_law(name, {k: jnp.asarray(v, float) for k, v in params.items()})
        result = impact(law, m=1.0, v0=1.0, separation=separation, peaks=False, rtol=1e-10)
        return result.e, result.T, result.status

    e, tau, status = jax.jit(jax.vmap(one))(jnp.asarray(GROUPS))
    ok = np.asarray(status) == Status.separated
    return GROUPS[ok], np.asarray(e)[ok], np.asarray(tau)[ok]


@functools.cache
def _shipped():
    if not _FILE.exists():
        return {}
    with np.load(_FILE) as data:
        return {key: data[key] for key in data.files}


@functools.cache
def restitution_table(name: str, separation: str, n: float = 1.5):
    """`(groups, e, tau)` for a law, from the shipped file when it has it (n = 1.5)."""
    key = f"{name}/{separation}"
    shipped = _shipped()
    if n == 1.5 and f"{key}/groups" in shipped:
        return shipped[f"{key}/groups"], shipped[f"{key}/e"], shipped[f"{key}/tau"]
    return compute_table(name, separation, n)


def main():
    jax.config.update("jax_enable_x64", True)
    arrays = {}
    for name in TABLE_LAWS:
        for separation in ("force", "penetration"):
            groups, e, tau = compute_table(name, separation)
            key = f"{name}/{separation}"
            arrays.update({f"{key}/groups": groups, f"{key}/e": e, f"{key}/tau": tau})
            print(f"{key}: {len(groups)} points, e from {e.min():.4f} to {e.max():.6f}")
    np.savez(_FILE, **arrays)
    print(f"written {_FILE}")


if __name__ == "__main__":
    main()
