"""The processes sharing one batch, on JAX's multi-process runtime (`jax.distributed`).

`ProcessGroup.current()` is this process's place (`index`, `count`): (0, 1) unless
`jax.distributed.initialize` was called (by hand, or from SLURM's or Open MPI's environment).
Chunk `k` of a table belongs to process `k % count`, so every process reads the whole file but
parses and computes only its own chunks, and the chunks (hence the output, bit for bit) are
the same whatever the number of processes. `gather` shares a small JSON value between all
processes and is a barrier as well. Both go through the coordination service that
`jax.distributed` starts (its key-value store): no device computation, nothing printed.
"""

import itertools
import json

import numpy as np

_WAIT_MS = 7 * 24 * 3600 * 1000  # a process may wait for the others' chunks that long
_CALLS = itertools.count()  # the same sequence in every process: unique keys per call


_FAILED, _OK = "jaximpact: a process failed", "jaximpact: a process finished"


class PeerFailed(RuntimeError):
    """Another process of the batch failed (it said so at a `gather` of this one)."""

    def __init__(self):
        super().__init__("another process of the batch failed; run again with --resume")


class ProcessGroup:
    """`index` of this process among `count`; one process: no communication at all.
    `peer_failed`: another process said it failed (then this one must not wait for it)."""

    def __init__(self, index: int = 0, count: int = 1, calls=None):
        self.index, self.count = index, count
        self.peer_failed = False
        self._calls = _CALLS if calls is None else calls  # numbers the exchanges

    @classmethod
    def current(cls) -> "ProcessGroup":
        """This process's place in the running `jax.distributed` job (or alone)."""
        import jax

        return cls(jax.process_index(), jax.process_count())

    def owns(self, chunk: int) -> bool:
        """Whether chunk `chunk` is this process's to compute (round robin)."""
        return chunk % self.count == self.index

    def gather(self, value) -> list:
        """`value` (anything `json` writes) of every process, in process order; returns when
        every process has given its own. Raises `PeerFailed` where another process has
        reported a failure (`report`) instead of giving its value."""
        values = self._exchange(value)
        if any(v == _FAILED for k, v in enumerate(values) if k != self.index):
            self.peer_failed = True
            raise PeerFailed()
        return values

    def report(self, failed: bool) -> bool:
        """Say whether this process failed, and learn whether any did: the last exchange of
        a batch. A process still at an earlier `gather` takes the report for its value and
        raises `PeerFailed`, so that nobody waits for a process that has stopped."""
        values = self._exchange(_FAILED if failed else _OK)
        return failed or any(v != _OK for v in values)

    def _exchange(self, value) -> list:
        if self.count == 1:
            return [value]
        key = f"jaximpact/batch/{next(self._calls)}"
        client = _client()
        if client is None:
            return _gather_on_devices(value, self.count)
        client.key_value_set(f"{key}/{self.index}", json.dumps(value))
        return [
            json.loads(client.blocking_key_value_get(f"{key}/{k}", _WAIT_MS))
            for k in range(self.count)
        ]


def _client():
    """The coordination service's client of `jax.distributed` (None if not reachable)."""
    try:
        from jax._src.distributed import global_state
    except ImportError:
        return None
    client = getattr(global_state, "client", None)
    needed = ("key_value_set", "blocking_key_value_get")
    return client if all(hasattr(client, n) for n in needed) else None


def _gather_on_devices(value, count: int) -> list:
    """`gather` through a collective over all processes' devices (JAX's public API)."""
    from jax.experimental import multihost_utils

    data = np.frombuffer(json.dumps(value).encode(), np.uint8)
    sizes = np.asarray(multihost_utils.process_allgather(np.array([data.size], np.int64)))
    padded = np.zeros(int(sizes.max()), np.uint8)
    padded[: data.size] = data
    every = np.asarray(multihost_utils.process_allgather(padded)).reshape(count, -1)
    return [
        json.loads(bytes(row[:n]).decode()) for row, n in zip(every, sizes.ravel(), strict=True)
    ]
