"""A batch of oblique impacts at batch speed: `oblique_impact_batch`, every row on the
phase-angle grid first (`grid.py`, one batched pass with no event search), then the rows
the grid did not serve in a second batched pass of `oblique_impact`'s event-terminated
solve (gathered on the host, in chunks of `CHUNK` rows, the last one padded with copies
of its first row: one compiled shape serves every count; measured, a chunk of 2 rows of
`linear_history` runs in 5 ms where one of 16 takes 11 ms, but each new shape compiles
for 12 s)."""

import dataclasses

import diffrax as dfx
import equinox as eqx
import jax
import jax.numpy as jnp
import numpy as np

from .._checks import MemberChecks
from .._solve.precision import resolvable_tolerances
from .grid import grid_applies, solve_oblique_grid
from .impact import (
    ObliqueInputs,
    ObliqueOptions,
    checked_inputs,
    checked_settings,
    lever_share,
    solve_oblique,
)
from .results import ObliqueResult

METHODS = ("auto", "integrate")
# rows per call of the second pass, the last chunk padded to it: one compiled shape
CHUNK = 16


@eqx.filter_jit
def _on_grid(law, tangential, m, R, v_n, v_t, omega, inertia, options):
    def one(*row):
        return solve_oblique_grid(law, tangential, *row, options)

    return jax.vmap(one)(m, R, v_n, v_t, omega, inertia)


@eqx.filter_jit
def _integrated(law, tangential, rows: ObliqueInputs, options):
    """`solve_oblique` over `rows` (an `ObliqueInputs` of 1-D arrays, SI units)."""

    def one(row):
        return solve_oblique(law, tangential, row, options)

    return jax.vmap(one)(rows)


def batch_options(*, separation: str, contact_point, rtol: float) -> ObliqueOptions:
    """The options of both of `oblique_impact_batch`'s passes: `oblique_impact`'s
    defaults (forward solve, no landing) at `rtol`."""
    rtol, atol, rest_tol = resolvable_tolerances(rtol, rtol, 1e-7)
    return ObliqueOptions(
        separation=separation,
        solver=dfx.Tsit5(),
        adjoint=dfx.RecursiveCheckpointAdjoint(),
        rtol=float(rtol),
        atol=float(atol),
        max_steps=4096,
        max_segments=16,
        tau_max=1e4,
        rest_tol=float(rest_tol),
        lever_share=lever_share(contact_point),
    )


def oblique_impact_batch(
    law,
    tangential,
    *,
    m,
    R,
    v_n,
    v_t,
    omega=0.0,
    inertia=0.4,
    g=0.0,
    separation: str = "force",
    contact_point="surface",
    rtol: float | None = None,
    method: str = "auto",
) -> ObliqueResult:
    """Many oblique impacts at once: `oblique_impact` over rows (SI units; numbers and 1-D
    arrays broadcast to one length), each row's result as `oblique_impact` gives it to its
    tolerance, in an `ObliqueResult` of arrays whose `path` names, row by row, the path that
    served it: `"grid"` (the normal contact and the tangential stick and slip stepped
    together on the phase-angle grid, the transitions placed on it: `_oblique/grid.py`)
    or `"integrated"` (the rows the grid cannot serve: heavy damping, a force that pulls,
    modes that take turns, transitions closer than a grid step or a pair of them inside
    one, a state-dependent law, a rescaled history, gravity; and every row with
    `method="integrate"`). Concrete inputs only (not inside
    `jit` or `vmap`: it gathers the rows for its second pass on the host); for
    derivatives use `jax.vmap` of `oblique_impact`.

    **Example**: `oblique_impact_batch(jaximpact.law("hunt_crossley", c=2.6e10, a=0.0),
    tangential_law("mindlin", G=1.5e11, nu=0.23, mu=0.092), m=2.6e-4, R=2.5e-3,
    v_n=3.9 * np.cos(angles), v_t=3.9 * np.sin(angles)).e_t`.
    """
    rtol = checked_settings(law, tangential, separation, rtol)
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    inputs = checked_inputs(MemberChecks(), m, R, v_n, v_t, omega, inertia, g)
    names = ("m", "R", "v_n", "v_t", "omega", "inertia", "g")
    arrays = {k: np.asarray(v, dtype=float) for k, v in zip(names, inputs, strict=True)}
    if any(a.ndim > 1 for a in arrays.values()):
        raise ValueError("oblique_impact_batch takes numbers and 1-D arrays")
    arrays = dict(zip(arrays, np.broadcast_arrays(*arrays.values()), strict=True))
    arrays = {k: np.atleast_1d(v).astype(float) for k, v in arrays.items()}
    n = arrays["v_n"].shape[0]
    options = batch_options(separation=separation, contact_point=contact_point, rtol=rtol)
    served = np.zeros(n, dtype=bool)
    fields = None
    if method == "auto" and grid_applies(law, tangential, options):
        result, on_grid = _on_grid(
            law,
            tangential,
            *(jnp.asarray(arrays[k]) for k in names[:-1]),
            options,  # no g
        )
        served = np.asarray(on_grid) & (arrays["g"] == 0.0)
        fields = {f.name: np.array(getattr(result, f.name)) for f in _array_fields()}
    left = np.flatnonzero(~served)
    if left.size:
        part = [arrays[k] for k in names]
        rest = _second_pass(law, tangential, part, left, options)
        if fields is None:
            fields = rest
        else:
            for name, values in rest.items():
                fields[name] = fields[name].astype(np.result_type(fields[name], values))
                fields[name][left] = values
    path = tuple("grid" if s else "integrated" for s in served)
    return ObliqueResult(**{k: jnp.asarray(v) for k, v in fields.items()}, path=path)


def _second_pass(law, tangential, arrays, left, options) -> dict:
    """`solve_oblique` over the rows `left` of `arrays`, `CHUNK` rows a call: the
    result's fields as numpy arrays."""
    parts = []
    for start in range(0, left.size, CHUNK):
        rows = left[start : start + CHUNK]
        pick = np.concatenate([rows, np.full(CHUNK - rows.size, rows[0])])
        rows_in = ObliqueInputs(*(jnp.asarray(a[pick]) for a in arrays))
        rest = _integrated(law, tangential, rows_in, options)
        parts.append(
            {f.name: np.asarray(getattr(rest, f.name))[: rows.size] for f in _array_fields()}
        )
    return {name: np.concatenate([p[name] for p in parts]) for name in parts[0]}


def _array_fields():
    return [f for f in dataclasses.fields(ObliqueResult) if f.name != "path"]
