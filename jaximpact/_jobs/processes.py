"""The processes sharing one file job, on JAX's multi-process runtime (`jax.distributed`).

`ProcessGroup.current()` is this process's place (`index`, `count`): (0, 1) unless
`jax.distributed.initialize` was called (by hand, or from SLURM's or Open MPI's environment).
Chunk `k` of a table belongs to process `k % count`, so every process reads the whole file but
parses and computes only its own chunks, and the chunks (hence the output, bit for bit) are
the same whatever the number of processes. `gather` shares a small JSON value between all
processes and is a barrier as well; it goes through JAX's public multi-host API
(`jax.experimental.multihost_utils.process_allgather`, a collective over every process's
devices). One process exchanges nothing.

A collective waits for every process (on CPUs at most 30 minutes, XLA's timeout), so a
process that may wait long for the others (one that finished its chunks first) waits on the
file system they share instead (`wait_for_all`), and exchanges once they all have arrived.
"""

import json
import time
from pathlib import Path

import numpy as np

_FAILED, _OK = "jaximpact: a process failed", "jaximpact: a process finished"
_POLL_S = 0.2  # how often a process waiting for the others looks at the shared directory


class PeerFailed(RuntimeError):
    """Another process of the job failed (it said so at a `gather` of this one)."""

    def __init__(self):
        super().__init__("another process of the batch failed; run again with --resume")


class ProcessGroup:
    """`index` of this process among `count`; one process: no communication at all.
    `peer_failed`: another process said it failed (then this one must not wait for it).
    `allgather(value, count)`: every process's JSON value, in process order (default:
    `process_allgather`; a test gives its own)."""

    def __init__(self, index: int = 0, count: int = 1, allgather=None):
        self.index, self.count = index, count
        self.peer_failed = False
        self._allgather = _allgather if allgather is None else allgather

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
        a job. A process still at an earlier `gather` takes the report for its value and
        raises `PeerFailed`, so that nobody waits for a process that has stopped."""
        values = self._exchange(_FAILED if failed else _OK)
        return failed or any(v != _OK for v in values)

    def wait_for_all(self, directory: Path):
        """Say in `directory` (seen by every process) that this process has arrived, and
        return when every process has: a wait of any length with no collective pending.
        `clear(directory)` first, before a `gather` that all processes pass."""
        if self.count == 1:
            return
        _arrival(directory, self.index).touch()
        while not all(_arrival(directory, k).exists() for k in range(self.count)):
            time.sleep(_POLL_S)

    @staticmethod
    def clear(directory: Path):
        """Remove the arrivals an earlier (interrupted) job left in `directory`."""
        for path in Path(directory).glob("arrived-*"):
            path.unlink(missing_ok=True)

    def _exchange(self, value) -> list:
        if self.count == 1:
            return [value]
        return self._allgather(value, self.count)


def _arrival(directory: Path, index: int) -> Path:
    return Path(directory) / f"arrived-{index:06d}"


def _allgather(value, count: int) -> list:
    """Every process's `value` through a collective over all processes' devices (JAX's
    public multi-host API): the sizes first, then the JSON texts padded to one length (a
    power of two, so that few shapes are compiled)."""
    from jax.experimental import multihost_utils

    data = np.frombuffer(json.dumps(value).encode(), np.uint8)
    sizes = np.asarray(multihost_utils.process_allgather(np.array([data.size], np.int32)))
    padded = np.zeros(max(64, 1 << (int(sizes.max()) - 1).bit_length()), np.uint8)
    padded[: data.size] = data
    every = np.asarray(multihost_utils.process_allgather(padded)).reshape(count, -1)
    return [
        json.loads(bytes(row[:n]).decode()) for row, n in zip(every, sizes.ravel(), strict=True)
    ]
