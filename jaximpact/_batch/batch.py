"""Large batches: in chunks of bounded size, sharded over the local devices, ordered by cost.

A vmapped event-terminated solve runs until its *slowest* member has finished: under
`jax.vmap`, diffrax's `while_loop` continues while any member is still going, and the members
that are done are carried along (their results frozen with a `select`). The cost of one chunk
is therefore `chunk size x the largest step count in it`, whatever the others need. `run_batch`
takes an optional `cost` key and runs the members in its order, so that each chunk holds
members of similar cost, then returns the results in the caller's order; `impact_batch` derives
the key from the dimensionless groups that fix an impact's step count (the damping group
`beta`, the dry-force and gravity groups; shared/notes, sections 0 and 4.4).
benchmarks/batch.md has the measurements.

Multi-host use follows JAX's multi-process model: start one process per host, call
`jax.distributed.initialize()` first in each (coordinator address, number of processes and
process id from the cluster's scheduler or as arguments), and let each process run its own
share of the rows on its own devices:

```python
jax.distributed.initialize()  # before any other JAX call
rows = np.array_split(np.arange(n), jax.process_count())[jax.process_index()]
share = jax.tree.map(lambda a: a[rows], inputs)
out = run_batch(fn, share)  # devices=None: this process's jax.local_devices()
write_table(f"part-{jax.process_index()}.csv", {"row": rows, **out})
```

The members of a batch are independent, so no device ever needs another one's data: the
processes do not communicate after start-up, and the parts concatenate to the whole table.
"""

import collections
import concurrent.futures
import csv
import functools
import json
import math
import os

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec, SingleDeviceSharding

from .._checks import check_nonnegative, check_positive
from .._laws import LAW_NAMES, LAWS, CustomLaw, Law, custom_law, law as make_law
from .._laws.closed_forms import closed_form_for
from .._progress import Progress
from .._solve.impact import CURVES_RTOL, impact, similarity_reason

_AXIS = "batch"


def _resolve_devices(devices) -> tuple:
    local = jax.local_devices()
    if devices is None:
        return tuple(local)
    if isinstance(devices, int):
        if not 1 <= devices <= len(local):
            raise ValueError(f"devices={devices}: this process has {len(local)} local devices")
        return tuple(local[:devices])
    devices = tuple(devices)
    if not devices:
        raise ValueError("devices must name at least one device")
    return devices


def block_length(n: int, chunk_size: int, n_devices: int) -> int:
    """Rows per device per compiled call for a batch of `n` rows: `chunk_size`, or for a
    batch smaller than `n_devices * chunk_size` the next power of two above
    `n / n_devices` (so that small batches compile for a few shapes only and run at most
    twice the rows they need)."""
    per_device = math.ceil(max(n, 1) / n_devices)
    if per_device >= chunk_size:
        return chunk_size
    return min(1 << (per_device - 1).bit_length(), chunk_size)


@functools.lru_cache(maxsize=64)
def _vectorised(fn, batched: bool):
    """One jitted, vmapped `fn` per Python function, so that every call with the same
    function (and block shape) reuses one trace and its compilations."""
    return jax.jit(fn if batched else jax.vmap(fn))


@functools.lru_cache(maxsize=16)
def _sharding(devices: tuple) -> NamedSharding:
    """Rows split over a 1-D mesh of `devices`, one contiguous block per device."""
    mesh = Mesh(np.asarray(devices, dtype=object), (_AXIS,))
    return NamedSharding(mesh, PartitionSpec(_AXIS))


@functools.lru_cache(maxsize=64)
def _spmd(fn, batched: bool, devices: tuple):
    sharding = _sharding(devices)
    body = fn if batched else jax.vmap(fn)
    return jax.jit(body, in_shardings=sharding, out_shardings=sharding)


_EXECUTABLES: collections.OrderedDict = collections.OrderedDict()  # least recently used first
_MAX_EXECUTABLES = 256


def _executables(fn, batched, devices, block_struct):
    """The vmapped `fn` compiled for each device for one block shape (compiled in threads:
    XLA compiles outside the Python lock). The same program runs on every device, so
    results do not depend on which device or how many ran them."""
    jitted = _vectorised(fn, batched)
    leaves, treedef = jax.tree.flatten(block_struct)
    shapes = (treedef, tuple((s.shape, str(s.dtype)) for s in leaves))
    missing = [d for d in devices if (jitted, d, shapes) not in _EXECUTABLES]

    def compile_for(device):
        placed = jax.tree.map(
            lambda s: jax.ShapeDtypeStruct(s.shape, s.dtype, sharding=SingleDeviceSharding(device)),
            block_struct,
        )
        return device, jitted.lower(placed).compile()

    if len(missing) == 1:
        compiled = [compile_for(missing[0])]
    elif missing:
        with concurrent.futures.ThreadPoolExecutor(len(missing)) as pool:
            compiled = list(pool.map(compile_for, missing))
    else:
        compiled = []
    for device, executable in compiled:
        _EXECUTABLES[(jitted, device, shapes)] = executable
    found = []
    for device in devices:
        _EXECUTABLES.move_to_end((jitted, device, shapes))
        found.append(_EXECUTABLES[(jitted, device, shapes)])
    while len(_EXECUTABLES) > _MAX_EXECUTABLES:
        _EXECUTABLES.popitem(last=False)
    return found


def _ordering(cost, n):
    """A permutation running rows in order of `cost` (1-D, or a sequence of 1-D keys,
    the first the primary one); `None` keeps the given order."""
    if cost is None:
        return None
    if isinstance(cost, (list, tuple)):
        keys = [np.asarray(k, dtype=float).reshape(-1) for k in cost]
    else:
        keys = [np.asarray(cost, dtype=float).reshape(-1)]
    for key in keys:
        if key.shape != (n,):
            raise ValueError(f"cost must hold one value per row ({n}), got shape {key.shape}")
    return np.lexsort(keys[::-1])


def run_batch(
    fn,
    inputs,
    *,
    chunk_size: int = 1024,
    progress: bool = True,
    devices=None,
    cost=None,
    exact: bool = True,
    batched: bool = False,
    description: str = "batch",
):
    """Run `fn` over every row of `inputs` in chunks, sharded over the local devices, and
    return numpy arrays.

    - `fn(row) -> outputs`: a pure JAX function of one row (a pytree of scalars, or of arrays
      with the trailing shapes of `inputs`), vmapped over the rows; with `batched=True`, `fn`
      takes and returns whole blocks of rows (it is already vectorised).
    - `inputs`: a pytree (e.g. a dict) of arrays whose leading axes all have the same length
      `n`: one row per member.
    - `chunk_size`: rows per device per compiled call (a *block*). A chunk is one block per
      device, placed with a `NamedSharding` over a 1-D `Mesh` of the devices (axis
      `"batch"`). Memory is bounded by about two chunks of inputs and outputs plus the
      solver's state for one chunk. The last block is padded by repeating its last row, so
      every block has one shape and compiles once; a batch smaller than one chunk runs in
      blocks of the next power of two above `n / devices`.
    - `devices`: `None` for all of `jax.local_devices()`, an integer for the first that many,
      or a sequence of devices.
    - `exact`: `True` (default): every device runs the same one-device program on its blocks,
      so the results are bitwise those of `devices=1` (whenever the block length is the same:
      always for `n >= devices * chunk_size`), and each device stops as soon as its own
      members are done; it compiles once per device (in parallel threads). `False`: one SPMD
      program over the mesh (`jax.jit` with `in_shardings`): a single compilation, but the
      devices advance in lockstep (the loop condition is all-reduced at every step) and XLA
      partitions the program differently, so a few results may differ from the one-device
      run in the last bits (measured: 1 member of 4096 at 1e-14; benchmarks/batch.md).
    - `cost`: expected cost per row (1-D, or a sequence of 1-D keys sorted lexicographically,
      first key primary). Rows run in that order, so that each block holds rows of similar
      cost (a vmapped event-terminated solve runs until its slowest member is done), and the
      outputs come back in the order of `inputs`. `None`: run in the given order.
    - `progress`: draw a progress bar over the chunks (on stderr).

    Returns the pytree of outputs as numpy arrays with leading axis `n`.
    Several hosts: see the module docstring (`jax.distributed.initialize`, one share of the
    rows per process).

    **Example**:
    ```python
    f = lambda row: jnp.sin(row["x"]) * row["y"]
    out = run_batch(f, {"x": np.linspace(0, 1, 10**6), "y": np.ones(10**6)}, chunk_size=65536)
    ```
    """
    leaves, treedef = jax.tree_util.tree_flatten(inputs)
    if not leaves:
        raise ValueError("inputs must hold at least one array")
    leaves = [np.asarray(leaf) for leaf in leaves]
    if any(leaf.ndim == 0 for leaf in leaves):
        raise ValueError("every input must be an array with one row per member (not a scalar)")
    n = leaves[0].shape[0]
    if any(leaf.shape[0] != n for leaf in leaves):
        shapes = [leaf.shape for leaf in leaves]
        raise ValueError(f"every input needs the same number of rows; got shapes {shapes}")
    if not isinstance(chunk_size, int) or chunk_size < 1:
        raise ValueError(f"chunk_size must be a positive integer, got {chunk_size!r}")
    devices = _resolve_devices(devices)
    order = _ordering(cost, n)
    if order is not None:
        leaves = [leaf[order] for leaf in leaves]

    block = block_length(n, chunk_size, len(devices))
    blocks = max(math.ceil(n / block), 1)
    rounds = math.ceil(blocks / len(devices))
    unflatten = functools.partial(jax.tree_util.tree_unflatten, treedef)

    def block_rows(b):  # block b padded to `block` rows (an empty block repeats the last row)
        start = min(b * block, max(n - 1, 0))
        return [_pad(leaf[start : (b + 1) * block], block) for leaf in leaves]

    if n == 0:
        struct = jax.eval_shape(
            _vectorised(fn, batched),
            unflatten([jax.ShapeDtypeStruct((1,) + a.shape[1:], a.dtype) for a in leaves]),
        )
        return jax.tree.map(lambda s: np.empty((0,) + s.shape[1:], s.dtype), struct)

    sharding = _sharding(devices)
    if exact:
        struct = unflatten([jax.ShapeDtypeStruct((block,) + a.shape[1:], a.dtype) for a in leaves])
        executables = _executables(fn, batched, devices, struct)
    else:
        spmd = _spmd(fn, batched, devices)

    def launch(r):
        """Place round r (one block per device) with the mesh sharding, start it, and return
        the results of its blocks that hold rows."""
        first = r * len(devices)
        live = min(len(devices), blocks - first)
        rows = [block_rows(b) for b in range(first, first + len(devices))]
        chunk = jax.device_put(
            unflatten([np.concatenate(p) for p in zip(*rows, strict=True)]), sharding
        )
        if exact:  # the same one-device program on each device's shard
            shards = [_shard(chunk, k, block) for k in range(live)]
            return [executables[k](shards[k]) for k in range(live)]
        result = spmd(chunk)
        return [
            jax.tree.map(lambda a, k=k: a[k * block : (k + 1) * block], result) for k in range(live)
        ]

    outputs = []

    def collect(r, results):
        for k, result in enumerate(results):
            start = (r * len(devices) + k) * block
            stop = min(start + block, n)
            host = [np.asarray(leaf) for leaf in jax.tree.leaves(result)]
            if not outputs:
                outputs.append(jax.tree.structure(result))
                outputs.extend(np.empty((n,) + a.shape[1:], a.dtype) for a in host)
            for target, values in zip(outputs[1:], host, strict=True):
                target[start:stop] = values[: stop - start]

    with Progress(rounds, description, enabled=progress) as bar:
        pending = None
        for r in range(rounds):
            results = launch(r)  # dispatched asynchronously
            if pending is not None:  # copy the previous round back while this one runs
                collect(*pending)
                bar.update(f"{min(r * len(devices) * block, n):,}/{n:,} rows")
            pending = (r, results)
        collect(*pending)
        bar.update(f"{n:,}/{n:,} rows")

    out_def, out_leaves = outputs[0], outputs[1:]
    if order is not None:
        inverse = np.empty_like(order)
        inverse[order] = np.arange(n)
        out_leaves = [leaf[inverse] for leaf in out_leaves]
    return jax.tree_util.tree_unflatten(out_def, out_leaves)


def _shard(chunk, k: int, block: int):
    """The single-device arrays holding rows `[k block, (k+1) block)` of a placed chunk."""

    def local(array):
        for shard in array.addressable_shards:
            if (shard.index[0].start or 0) == k * block:
                return shard.data
        raise RuntimeError(f"no local shard starts at row {k * block}")

    return jax.tree.map(local, chunk)


def _pad(rows: np.ndarray, length: int) -> np.ndarray:
    """`rows` padded to `length` by repeating its last row (a valid input, never NaN)."""
    missing = length - rows.shape[0]
    if missing == 0:
        return rows
    return np.concatenate([rows, np.repeat(rows[-1:], missing, axis=0)])


# ----------------------------------------------------------------------------- tables


def write_table(path, columns: dict) -> str:
    """Write equal-length 1-D columns to `path` as CSV (`.csv`) or JSON (`.json`), without
    pandas; returns the path.

    CSV: a header row of the column names, then one row per member, floats written with
    `repr` (round-trips exactly). JSON: `{"columns": [...], "rows": n, "data": {name:
    [values]}}`, NaN and infinities written as `null`.

    **Example**: `write_table("impacts.csv", impact_batch("hertz_rate", ...))`.
    """
    path = os.fspath(path)
    names = list(columns)
    if not names:
        raise ValueError("write_table needs at least one column")
    arrays = [np.asarray(columns[name]) for name in names]
    for name, array in zip(names, arrays, strict=True):
        if array.ndim != 1:
            raise ValueError(f"column {name!r} must be 1-D, got shape {array.shape}")
    lengths = {array.shape[0] for array in arrays}
    if len(lengths) != 1:
        raise ValueError(
            "columns must have equal lengths, got "
            + ", ".join(f"{n}: {a.shape[0]}" for n, a in zip(names, arrays, strict=True))
        )
    rows = lengths.pop()
    values = [array.tolist() for array in arrays]
    suffix = os.path.splitext(path)[1].lower()
    if suffix == ".csv":
        with open(path, "w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(names)
            writer.writerows(zip(*values, strict=True))
    elif suffix == ".json":
        data = {
            name: [_json_value(v) for v in column]
            for name, column in zip(names, values, strict=True)
        }
        with open(path, "w") as handle:
            json.dump({"columns": names, "rows": rows, "data": data}, handle)
    else:
        raise ValueError(f"write_table writes .csv or .json files, got {path!r}")
    return path


def _json_value(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


# ----------------------------------------------------------------------------- impacts

IMPACT_FIELDS = ("e", "T", "x_max", "F_max", "status")
_ALL_FIELDS = (
    "e",
    "T",
    "x_max",
    "t_max",
    "F_max",
    "dissipated",
    "v_out",
    "status",
    "num_steps",
)
_GROUPS = ("beta", "mu", "dry_in", "dry_out", "gamma")  # dimensionless groups, by importance


def _law_skeleton(law):
    """A hashable description of a law's structure (everything but its parameter values)."""
    if isinstance(law, str):
        return ("law", law)
    if isinstance(law, Law):
        return ("law", law.name)
    if isinstance(law, CustomLaw):
        return ("custom", law.fn, law.name)
    raise TypeError(
        f"impact_batch takes a law name or a law from jaximpact.law / custom_law, "
        f"got {type(law).__name__}"
    )


def _build_law(skeleton, params):
    """The law of `skeleton` with `params` (arrays, possibly traced), without re-checking
    them (impact_batch has checked the whole batch at once). A table law's skeleton may
    carry fixed shape parameters as numbers (`_fix_shape`), which the row then lacks."""
    if skeleton[0] == "law":
        fixed = dict(skeleton[2]) if len(skeleton) > 2 else {}
        params = {**{k: jnp.asarray(v, dtype=float) for k, v in fixed.items()}, **params}
        return Law(skeleton[1], {k: params[k] for k in LAWS[skeleton[1]].parameters})
    return CustomLaw(skeleton[1], params, skeleton[2])


@functools.lru_cache(maxsize=64)
def _impact_member(skeleton, fields: tuple, options: tuple):
    """One row -> the requested `ImpactResult` fields; cached per law structure and options,
    so every batch of the same kind reuses one compiled program per block shape. A row
    without `g` passes `g=0.0` as a number (so that `impact` may take a closed form)."""
    keywords = dict(options)

    def member(row):
        law = _build_law(skeleton, row["params"])
        result = impact(law, m=row["m"], v0=row["v0"], g=row.get("g", 0.0), **keywords)
        return {name: getattr(result, name) for name in fields if getattr(result, name) is not None}

    return member


@functools.lru_cache(maxsize=64)
def _dynamics_fn(skeleton):
    def dynamics(params, m, v0, g):
        return _build_law(skeleton, params).dynamics(m=m, v0=v0, g=g)

    return jax.jit(jax.vmap(dynamics))


def _cost_key(skeleton, params, m, v0, g):
    """Sort keys that predict an impact's step count: its dimensionless groups (the damping
    group `beta` or Maxwell's `mu` first, then the dry-force and gravity groups), each on a
    log scale binned to 1/20 of a decade so that the later keys order rows of similar
    damping. `None` for a user's own law (its groups are unknown)."""
    if skeleton[0] != "law":
        return None
    groups = _dynamics_fn(skeleton)(params, m, v0, g)
    keys = []
    for name in _GROUPS:
        value = getattr(groups, name, None)
        if value is None:
            continue
        value = np.abs(np.asarray(value, dtype=float))
        if np.ptp(value) == 0:
            continue
        keys.append(np.round(20.0 * np.log10(value + 1e-300)))
    return keys or None


def _fix_shape(skeleton, params):
    """Move a table law's shape parameters (Hunt-Crossley's `n`, the power law's `n` and
    `p`) into the skeleton as numbers when they are the same on every row, so that the
    rows can be read off the universal curves (which need the shape as numbers)."""
    if skeleton[0] != "law" or not LAWS[skeleton[1]].shape_parameters:
        return skeleton, params
    shape = LAWS[skeleton[1]].shape_parameters
    if not all(np.ptp(params[k]) == 0 for k in shape):
        return skeleton, params
    fixed = tuple((k, float(params[k][0])) for k in shape)
    return (*skeleton, fixed), {k: v for k, v in params.items() if k not in shape}


def batch_path(
    law, separation, *, method="auto", rtol=1e-11, g_is_zero=True, **impact_options
) -> str:
    """The path every row of a batch of `law`'s impacts takes: `"closed_form"`,
    `"similarity"` (the universal curves) or `"integrated"` (the same choice as `impact`'s
    `method="auto"`, made once for the batch)."""
    if g_is_zero and method != "integrate" and closed_form_for(law, separation) is not None:
        return "closed_form"
    if (
        g_is_zero
        and method in ("auto", "similarity")
        and rtol >= CURVES_RTOL
        and "solver" not in impact_options
        and similarity_reason(law, separation) is None
    ):
        return "similarity"
    return "integrated"


def prepare_rows(law, params, *, m, v0, g=0.0):
    """Check a batch of impacts once, eagerly, and lay it out as rows.

    Returns `(skeleton, params, kinematics)`: the law's hashable structure, its parameters
    and `{"m", "v0", "g"}` as 1-D float arrays of one common length (numbers and arrays
    broadcast). Raises a one-line `ValueError` naming the first bad value.
    """
    skeleton = _law_skeleton(law)
    base = {} if isinstance(law, str) else dict(law.parameters)
    given = {**base, **(params or {})}
    if skeleton[0] == "law":
        name = skeleton[1]
        if name not in LAWS:
            raise ValueError(f"unknown law {name!r}; choose one of: {', '.join(LAW_NAMES)}")
        given = {**LAWS[name].defaults, **given}
    arrays = {k: np.asarray(v, dtype=float) for k, v in given.items()}
    if {"m", "v0", "g"} & set(arrays):
        raise ValueError("a law parameter may not be called m, v0 or g")
    arrays.update(m=np.asarray(m, dtype=float), v0=np.asarray(v0, dtype=float))
    arrays["g"] = np.asarray(g, dtype=float)
    for key, value in arrays.items():
        if value.ndim > 1:
            raise ValueError(f"{key} must be a number or a 1-D array, got shape {value.shape}")
    try:
        arrays = dict(zip(arrays, np.broadcast_arrays(*arrays.values()), strict=True))
    except ValueError:
        shapes = {k: v.shape for k, v in arrays.items()}
        raise ValueError(f"the inputs do not broadcast to one batch: {shapes}") from None
    arrays = {k: np.atleast_1d(np.ascontiguousarray(v)) for k, v in arrays.items()}
    kinematics = {k: arrays.pop(k) for k in ("m", "v0", "g")}
    if skeleton[0] == "law":
        make_law(skeleton[1], **arrays)
    else:
        custom_law(skeleton[1], **arrays)
    for key, what, unit, positive in (
        ("m", "mass m", "kg", True),
        ("v0", "impact speed v0", "m/s", True),
        ("g", "gravity g", "m/s^2", False),
    ):
        (check_positive if positive else check_nonnegative)(what, kinematics[key], unit)
    return skeleton, arrays, kinematics


def impact_batch(
    law,
    params: dict | None = None,
    *,
    m,
    v0,
    g=0.0,
    separation: str = "force",
    method: str = "auto",
    rtol: float = 1e-11,
    peaks: bool = True,
    fields: tuple = IMPACT_FIELDS,
    order: str = "cost",
    chunk_size: int | None = None,
    progress: bool = True,
    devices=None,
    exact: bool = True,
    **impact_options,
) -> dict[str, np.ndarray]:
    """Impacts of many bodies at once: `impact` over a batch, in chunks, on all local devices.

    - `law`: a law name of `LAW_NAMES` (then `params` must hold all its parameters), or a
      law from `jaximpact.law` / `custom_law` whose parameters `params` may replace.
    - `params`: parameter name -> number or 1-D array (SI units, as in `jaximpact.law`).
    - `m` (kg), `v0` (m/s), `g` (m/s^2, along the inward normal): numbers or 1-D arrays.
      Every array is broadcast against the others: `n` rows.
    - `separation`, `method`, `rtol`, `peaks` and `impact_options` (`solver`, `atol`,
      `max_steps`, `tau_max`, `rest_tol`): as in `jaximpact.impact`.
    - `fields`: which `ImpactResult` fields to return (default `e, T, x_max, F_max, status`);
      with `peaks=False` the peak fields are left out.
    - `order`: `"cost"` (default) runs the rows sorted by their dimensionless groups (which
      fix the step count; see `run_batch`) and returns them in the given order; `"given"`
      runs them as given.
    - `chunk_size`: rows per device per compiled call (default 1024 for integrated impacts,
      65536 for closed forms and the universal curves, which cost little per row);
      `progress`, `devices`, `exact`: as
      in `run_batch`.

    Returns a dict of numpy arrays of length `n` (`status` as integers of `Status`).
    Inputs are checked once for the whole batch (a `ValueError` names the first bad value).

    **Example**:
    ```python
    out = impact_batch("hertz_rate", {"c": 2e6, "b1": np.linspace(100, 2000, 10_000)},
                       m=1.0, v0=2.5)
    out["e"], out["T"]
    ```
    """
    if order not in ("cost", "given"):
        raise ValueError(f"order must be 'cost' or 'given', got {order!r}")
    unknown = sorted(set(fields) - set(_ALL_FIELDS))
    if unknown:
        raise ValueError(f"unknown fields {unknown}; choose from {_ALL_FIELDS}")
    skeleton, law_params, kinematics = prepare_rows(law, params, m=m, v0=v0, g=g)
    skeleton, law_params = _fix_shape(skeleton, law_params)
    zero_gravity = bool(np.all(kinematics["g"] == 0.0))
    rows = {"params": law_params, "m": kinematics["m"], "v0": kinematics["v0"]}
    if not zero_gravity:
        rows["g"] = kinematics["g"]
    options = dict(separation=separation, method=method, rtol=rtol, peaks=peaks, **impact_options)
    try:
        member = _impact_member(skeleton, tuple(fields), tuple(sorted(options.items())))
    except TypeError:  # an option that cannot be hashed (an array): compiled for this call
        member = _impact_member.__wrapped__(skeleton, tuple(fields), tuple(options.items()))
    cost = None
    first = _build_law(skeleton, {k: v[:1] for k, v in law_params.items()})
    path = batch_path(
        first, separation, method=method, rtol=rtol, g_is_zero=zero_gravity, **impact_options
    )
    closed = path != "integrated"
    if order == "cost" and not closed:
        cost = _cost_key(skeleton, law_params, **kinematics)
    label = skeleton[1] if skeleton[0] == "law" else "custom law"
    out = run_batch(
        member,
        rows,
        chunk_size=(65536 if closed else 1024) if chunk_size is None else chunk_size,
        progress=progress,
        devices=devices,
        cost=cost,
        exact=exact,
        description=f"impacts ({label})",
    )
    return {name: out[name] for name in fields if name in out}
