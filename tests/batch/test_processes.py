"""The processes' exchanges (`ProcessGroup`): two groups in threads of this process, through a
stand-in for the collective that `jax.experimental.multihost_utils.process_allgather` makes
over every process's devices (the real one is exercised by the two-process tests in
test_files.py), and the wait on a shared directory."""

import threading

import pytest

from jaximpact._jobs import processes
from jaximpact._jobs.processes import PeerFailed, ProcessGroup


class _Collective:
    """An all-gather between threads: the k-th call of each member pairs with the k-th call
    of the others, as the calls of a collective do."""

    def __init__(self, count):
        self.count, self.values, self.changed = count, {}, threading.Condition()
        self.calls = [0] * count

    def member(self, index):
        def allgather(value, count):
            assert count == self.count
            with self.changed:
                call = self.calls[index]
                self.calls[index] += 1
                self.values[call, index] = value
                self.changed.notify_all()
                every = [(call, k) for k in range(count)]
                if not self.changed.wait_for(lambda: all(k in self.values for k in every), 20):
                    raise TimeoutError(call)
                return [self.values[k] for k in every]

        return allgather


@pytest.fixture
def pair():
    collective = _Collective(2)
    return [ProcessGroup(k, 2, allgather=collective.member(k)) for k in range(2)]


def _both(first, second):
    """Run `first()` and `second()` at once; their results (or the exceptions they raised)."""
    out = [None, None]

    def run(k, fn):
        try:
            out[k] = fn()
        except Exception as error:  # noqa: BLE001 - returned for the test to check
            out[k] = error

    threads = [threading.Thread(target=run, args=(k, fn)) for k, fn in enumerate((first, second))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=30)
        assert not thread.is_alive(), "an exchange never returned"
    return out


def test_gather_gives_every_value_in_process_order(pair):
    a, b = pair
    assert _both(lambda: a.gather({"x": 1}), lambda: b.gather(None)) == [[{"x": 1}, None]] * 2
    assert _both(lambda: a.report(False), lambda: b.report(False)) == [False, False]


def test_a_failure_reported_reaches_a_process_still_at_its_gather(pair):
    """Process 1 fails and reports while process 0 is at a gather of its loop: process 0
    raises PeerFailed (and does not wait to report), process 1 learns nothing is wrong with
    it but returns True, and neither waits for the other."""
    a, b = pair
    got = _both(lambda: a.gather("round 3"), lambda: b.report(True))
    assert isinstance(got[0], PeerFailed) and "run again with --resume" in str(got[0])
    assert a.peer_failed and got[1] is True


def test_a_process_that_finished_learns_of_a_failure_at_its_report(pair):
    a, b = pair
    assert _both(lambda: a.report(False), lambda: b.report(True)) == [True, True]


def test_one_process_exchanges_nothing():
    alone = ProcessGroup()
    assert alone.gather(5) == [5] and alone.report(False) is False and alone.report(True)


def test_a_process_waits_on_the_shared_directory_for_the_others(pair, tmp_path, monkeypatch):
    """The first process to finish waits on the disk (no collective pending) until the
    other arrives; arrivals of an earlier run are cleared first."""
    monkeypatch.setattr(processes, "_POLL_S", 0.01)
    a, b = pair
    (tmp_path / "arrived-000001").touch()  # left by an interrupted run
    ProcessGroup.clear(tmp_path)
    waiting = threading.Thread(target=a.wait_for_all, args=(tmp_path,))
    waiting.start()
    waiting.join(timeout=0.3)
    assert waiting.is_alive()  # process 1 has not arrived
    b.wait_for_all(tmp_path)
    waiting.join(timeout=10)
    assert not waiting.is_alive()


def test_the_exchange_goes_through_public_jax_only():
    """No private JAX module under the file jobs or the batches (issue 25)."""
    from pathlib import Path

    import jaximpact

    root = Path(jaximpact.__file__).parent
    found = [
        str(path.relative_to(root))
        for unit in ("_batch", "_jobs")
        for path in (root / unit).rglob("*.py")
        if "jax._src" in path.read_text()
    ]
    assert not found
