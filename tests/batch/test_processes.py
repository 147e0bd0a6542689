"""The processes' exchanges (`ProcessGroup`): two groups in threads of this process, through a
stand-in for the coordination service's key-value store (the real one is exercised by the
two-process tests in test_files.py)."""

import itertools
import threading

import pytest

from jaximpact._batch import processes
from jaximpact._batch.processes import PeerFailed, ProcessGroup


class _Store:
    """`key_value_set` and `blocking_key_value_get` as jax.distributed's client has them."""

    def __init__(self):
        self.values, self.changed = {}, threading.Condition()

    def key_value_set(self, key, value):
        with self.changed:
            self.values[key] = value
            self.changed.notify_all()

    def blocking_key_value_get(self, key, timeout_ms):
        with self.changed:
            if not self.changed.wait_for(lambda: key in self.values, timeout_ms / 1000):
                raise TimeoutError(key)
            return self.values[key]


@pytest.fixture
def pair(monkeypatch):
    store = _Store()
    monkeypatch.setattr(processes, "_client", lambda: store)
    monkeypatch.setattr(processes, "_WAIT_MS", 20_000)
    return [ProcessGroup(k, 2, calls=itertools.count()) for k in range(2)]


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
