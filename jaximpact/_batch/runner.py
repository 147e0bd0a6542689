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
process id from the cluster's scheduler or as arguments). Either each process gives its
own rows, the same number in every process, to `run_batch(fn, rows, devices="global")`,
which runs one SPMD program over a mesh of all processes' devices (`batch_file`'s
`mesh="global"`), or each process runs its own share of the rows on its own devices (its
default):

```python
jax.distributed.initialize()  # before any other JAX call
rows = np.array_split(np.arange(n), jax.process_count())[jax.process_index()]
share = jax.tree.map(lambda a: a[rows], inputs)
out = run_batch(fn, share)  # devices=None: this process's jax.local_devices()
write_table(f"part-{jax.process_index()}.csv", {"row": rows, **out})
```

The members of a batch are independent, so no device ever needs another one's data: in the
second form the processes do not communicate after start-up, and the parts concatenate to
the whole table.
"""

import collections
import concurrent.futures
import functools
import math

import jax
import numpy as np
from jax.sharding import Mesh, NamedSharding, PartitionSpec, SingleDeviceSharding

from .._progress import AbstractMeter, metered

_AXIS = "batch"


GLOBAL = "global"  # `devices=GLOBAL`: one mesh over the devices of every process


def _resolve_devices(devices) -> tuple:
    local = jax.local_devices()
    if devices is None or (isinstance(devices, str) and devices == GLOBAL):
        return tuple(local)  # under GLOBAL: this process's blocks; the mesh is jax.devices()
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
    `n / n_devices`, at least 2 (so that small batches compile for a few shapes only and
    run at most twice the rows they need)."""
    per_device = math.ceil(max(n, 1) / n_devices)
    if per_device >= chunk_size:
        return chunk_size
    # at least 2 rows: XLA compiles a vmap over one row otherwise (measured: an integrated
    # impact's e then differs in the last bits from the same row in any larger block)
    return min(max(1 << (per_device - 1).bit_length(), 2), chunk_size)


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
    progress: bool | AbstractMeter = True,
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
      or a sequence of devices. `"global"`: one SPMD program over a mesh of the devices of
      every process of a `jax.distributed` job (`jax.devices()`), each process giving its
      own rows (one block per local device) and getting back their results; every process
      must then call `run_batch` with the same `fn`, `chunk_size` and number of rows `n`
      (the program's collectives pair the calls), and `exact` does not apply.
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
    - `progress`: a meter of the chunks: `True` the default one (on stderr), `False` none,
      or an `AbstractMeter`.

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
    spans_processes = isinstance(devices, str) and devices == GLOBAL
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

    mesh_devices = tuple(jax.devices()) if spans_processes else devices
    sharding = _sharding(mesh_devices)
    if exact and not spans_processes:
        struct = unflatten([jax.ShapeDtypeStruct((block,) + a.shape[1:], a.dtype) for a in leaves])
        executables = _executables(fn, batched, devices, struct)
    else:
        spmd = _spmd(fn, batched, mesh_devices)

    def launch(r):
        """Place round r (one block per device) with the mesh sharding, start it, and return
        the results of its blocks that hold rows."""
        first = r * len(devices)
        live = min(len(devices), blocks - first)
        rows = [block_rows(b) for b in range(first, first + len(devices))]
        local = unflatten([np.concatenate(p) for p in zip(*rows, strict=True)])
        if spans_processes:  # this process's blocks, placed on its devices of the mesh
            chunk = jax.tree.map(
                lambda a: jax.make_array_from_process_local_data(
                    sharding, a, (block * jax.device_count(),) + a.shape[1:]
                ),
                local,
            )
            return _local_blocks(spmd(chunk), live)
        chunk = jax.device_put(local, sharding)
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

    with metered(progress, rounds, description) as bar:
        pending = None
        for r in range(rounds):
            results = launch(r)  # dispatched asynchronously
            if pending is not None:  # copy the previous round back while this one runs
                collect(*pending)
                bar.update(1, f"{min(r * len(devices) * block, n):,}/{n:,} rows")
            pending = (r, results)
        collect(*pending)
        bar.update(1, f"{n:,}/{n:,} rows")

    out_def, out_leaves = outputs[0], outputs[1:]
    if order is not None:
        inverse = np.empty_like(order)
        inverse[order] = np.arange(n)
        out_leaves = [leaf[inverse] for leaf in out_leaves]
    return jax.tree_util.tree_unflatten(out_def, out_leaves)


def _local_blocks(result, count: int) -> list:
    """The first `count` blocks of a result over a mesh of several processes that this
    process holds (one per local device), in row order: its own rows' results."""
    leaves, treedef = jax.tree.flatten(result)
    shards = [
        [s.data for s in sorted(leaf.addressable_shards, key=lambda s: s.index[0].start or 0)]
        for leaf in leaves
    ]
    return [jax.tree.unflatten(treedef, [leaf[k] for leaf in shards]) for k in range(count)]


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
