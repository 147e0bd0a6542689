"""Progress meters: `TextMeter` draws a bar redrawn in place on a terminal and plain lines
elsewhere (logs, pipes, CI); `progress=` takes True, False or a meter; tqdm's meter where
tqdm is installed."""

import io
import time

import numpy as np
import pytest

import jaximpact as ji
from jaximpact._progress import (
    AbstractMeter,
    NoMeter,
    TextMeter,
    TqdmMeter,
    as_meter,
    default_meter,
    metered,
    progress_enabled,
)


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_terminal_gets_a_bar_redrawn_in_place():
    stream = Terminal()
    with metered(TextMeter(stream=stream), 3, "fitting") as bar:
        for label in ("a", "b", "c"):
            bar.update(1, label)
    text = stream.getvalue()
    assert text.count("\r") == 4 and text.endswith("\n") and "3/3" in text


def test_a_pipe_gets_lines_not_carriage_returns():
    stream = io.StringIO()  # not a terminal
    with metered(TextMeter(stream=stream, delay=0.0, interval=0.0), 40, "fitting") as bar:
        for k in range(40):
            bar.update(1, f"law {k}")
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue()
    assert len(lines) == 41 and lines[-1].startswith("fitting [") and "40/40" in lines[-1]


def test_a_pipe_gets_at_most_a_line_per_interval_and_always_the_last():
    stream = io.StringIO()
    with metered(TextMeter(stream=stream, delay=3600.0), 1000, "rows") as bar:
        for _ in range(1000):
            bar.update(1, "x")
    (line,) = stream.getvalue().splitlines()  # quick work: the final line only
    assert "1000/1000" in line


def test_a_meter_can_be_started_again_and_its_total_raised():
    stream = io.StringIO()
    meter = TextMeter(stream=stream, delay=3600.0)
    for label in ("checking", "batch"):
        with metered(meter, 1, label) as bar:
            bar.total += 1
            bar.update(2)
    assert [line.split(" [")[0] for line in stream.getvalue().splitlines()] == ["checking", "batch"]
    assert all("2/2" in line for line in stream.getvalue().splitlines())


def test_progress_argument_and_the_environment_switch(monkeypatch):
    assert isinstance(as_meter(False), NoMeter) and isinstance(as_meter(None), NoMeter)
    meter = NoMeter()
    assert as_meter(meter) is meter
    with pytest.raises(TypeError, match="AbstractMeter"):
        as_meter("yes")
    for value, expected in (("off", False), ("0", False), ("auto", True), ("1", True)):
        monkeypatch.setenv("JAXIMPACT_PROGRESS", value)
        assert progress_enabled() is expected
        assert isinstance(as_meter(True), NoMeter) is not expected
    monkeypatch.setattr("sys.stderr", io.StringIO())  # not a terminal: the text meter
    assert isinstance(default_meter(), TextMeter)


def test_a_users_meter_sees_every_chunk_of_a_batch():
    class Count(AbstractMeter):
        def start(self, total, label):
            self.total, self.label, self.done = total, label, 0

        def update(self, n=1, note=""):
            self.done += n

        def close(self):
            self.closed = True

    meter = Count()
    ji.run_batch(lambda row: row["x"] * 2, {"x": np.arange(3.0)}, chunk_size=1, progress=meter)
    assert (meter.label, meter.done, meter.closed) == ("batch", meter.total, True)


def test_tqdm_meter():
    pytest.importorskip("tqdm")
    stream = io.StringIO()
    with metered(TqdmMeter(file=stream), 3, "fitting") as bar:
        bar.total += 1
        for label in ("a", "b", "c", "d"):
            bar.update(1, label)
    assert "fitting" in stream.getvalue() and "4/4" in stream.getvalue()


def test_the_default_meter_keeps_its_clock_moving_through_a_long_step(monkeypatch):
    """A step that takes long (a first compilation, curves built on first use) once left
    `0/1` and a frozen clock for minutes: the default meter redraws while it runs."""
    stream = io.StringIO()
    monkeypatch.delenv("JAXIMPACT_PROGRESS", raising=False)
    monkeypatch.setattr("sys.stderr", stream)  # not a terminal: the text meter
    meter = default_meter()
    assert meter.heartbeat is not None
    meter.delay, meter.interval, meter.heartbeat = 0.05, 0.1, 0.05
    with metered(meter, 1, "building curves") as bar:
        time.sleep(0.45)
        bar.update(1)
    lines = stream.getvalue().splitlines()
    waiting = [line for line in lines if " 0/1 " in line]
    assert len(waiting) >= 2, lines
    clocks = [float(line.split(" 0/1 ")[1].split("s")[0]) for line in waiting]
    assert clocks == sorted(clocks) and clocks[-1] > clocks[0]
    assert "1/1" in lines[-1]
