"""Progress of long work, as a small meter interface (the pattern of diffrax's progress
meters): the work calls `start(total, label)`, `update(n, note)` as it goes and `close()`.

A long function takes `progress=`: `False` for none (`NoMeter`), `True` for the default
meter (`default_meter`), or any `AbstractMeter`; `metered(progress, total, label)` opens it
as a context manager. The default meter is tqdm's bar where tqdm is installed and stderr is
a terminal, else a `TextMeter` on stderr (a bar redrawn in place on a terminal, a plain line
now and then in a log, a pipe, CI); none when `JAXIMPACT_PROGRESS` is `off` (or `0`, `no`,
`false`), which silences every default meter, the command line's included.
"""

import abc
import contextlib
import importlib.util
import os
import sys
import threading
import time

PROGRESS_ENV = "JAXIMPACT_PROGRESS"


def progress_enabled() -> bool:
    """Whether default meters report: yes unless `JAXIMPACT_PROGRESS` is `off` (or `0`,
    `no`, `false`)."""
    value = os.environ.get(PROGRESS_ENV, "auto").strip().lower()
    return value not in ("off", "0", "no", "false")


def is_terminal(stream) -> bool:
    """Whether `stream` is a terminal (False for anything that cannot say)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


class AbstractMeter(abc.ABC):
    """How far long work has got: `start(total, label)`, then `update(n, note)` after each
    step, then `close()`. `total` may be raised while the work runs (work whose size is
    learnt as it goes). A meter can be started again after `close()`."""

    total: int = 0

    @abc.abstractmethod
    def start(self, total: int, label: str) -> None:
        """Begin `total` steps of the work called `label`."""

    @abc.abstractmethod
    def update(self, n: int = 1, note: str = "") -> None:
        """`n` more steps done; `note` says where the work is (`"1,000 rows"`)."""

    @abc.abstractmethod
    def close(self) -> None:
        """The work is over (also when it failed)."""


class NoMeter(AbstractMeter):
    """Reports nothing (`progress=False`)."""

    def start(self, total, label):
        self.total = total

    def update(self, n=1, note=""):
        pass

    def close(self):
        pass


class TextMeter(AbstractMeter):
    """Progress on `stream` (default stderr) without any library: on a terminal a bar
    redrawn in place; elsewhere one line at most every `interval` seconds (the first after
    `delay` seconds) and a last one at the end, so that quick work stays silent.

    `heartbeat` (s): also redraw that often from a background thread while the work runs,
    so that a step that takes long (a first compilation) still shows the clock moving; then
    nothing is drawn before `delay` seconds, on a terminal too."""

    def __init__(self, stream=None, interval: float = 5.0, delay: float = 2.0, heartbeat=None):
        self.stream, self.interval, self.delay, self.heartbeat = stream, interval, delay, heartbeat

    def start(self, total, label):
        self.total, self.label, self.done, self.note = total, label, 0, ""
        self._out = sys.stderr if self.stream is None else self.stream
        self._terminal = is_terminal(self._out)
        self._start = time.perf_counter()
        self._last_line, self._last_done = None, -1  # the last line written (not a terminal)
        self._shown = self.heartbeat is None  # with a heartbeat: nothing before `delay`
        self._lock, self._stop, self._thread = threading.Lock(), threading.Event(), None
        if self.heartbeat is None:
            self._draw()
        else:
            self._thread = threading.Thread(target=self._beat, daemon=True)
            self._thread.start()

    def _beat(self):
        if self._stop.wait(self.delay):
            return
        while True:
            with self._lock:
                self._shown = True
                self._draw()
            if self._stop.wait(self.heartbeat):
                return

    def update(self, n=1, note=""):
        with self._lock:
            self.done, self.note = self.done + n, note
            if self._thread is None:
                self._draw()

    def _text(self) -> str:
        width = 24
        filled = int(width * self.done / max(self.total, 1))
        elapsed = time.perf_counter() - self._start
        bar = "#" * filled + "-" * (width - filled)
        return f"{self.label} [{bar}] {self.done}/{self.total} {elapsed:5.1f}s {self.note:<24}"

    def _draw(self, final=False):
        if not self._shown:
            return
        if self._terminal:
            self._out.write("\r" + self._text())
            self._out.flush()
            return
        now = time.perf_counter()
        if final:
            due = self._last_done != self.done or self._last_line is None
        elif self._last_line is None:
            due = now - self._start >= self.delay
        else:
            due = now - self._last_line >= self.interval
        if due:
            self._out.write(self._text().rstrip() + "\n")
            self._out.flush()
            self._last_line, self._last_done = now, self.done

    def close(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        if self._shown:
            if self._terminal:
                if self._thread is not None:  # the last update may be between beats
                    self._draw()
                self._out.write("\n")
            else:
                self._draw(final=True)
            self._out.flush()


class TqdmMeter(AbstractMeter):
    """tqdm's bar (`pip install tqdm`); `options` go to `tqdm.auto.tqdm` (default: on
    stderr, kept at the end)."""

    def __init__(self, heartbeat: float | None = 1.0, **options):
        self.options, self.heartbeat = options, heartbeat
        self._bar, self._stop, self._thread = None, threading.Event(), None

    @property
    def total(self):
        return 0 if self._bar is None else self._bar.total

    @total.setter
    def total(self, value):
        if self._bar is not None and value != self._bar.total:
            self._bar.total = value
            self._bar.refresh()

    def start(self, total, label):
        from tqdm.auto import tqdm

        self._bar = tqdm(total=total, desc=label, **{"file": sys.stderr, **self.options})
        self._stop.clear()
        if self.heartbeat is not None:  # the clock moves while one step takes long
            self._thread = threading.Thread(target=self._beat, daemon=True)
            self._thread.start()

    def _beat(self):
        while not self._stop.wait(self.heartbeat):
            self._bar.refresh()

    def update(self, n=1, note=""):
        if note:
            self._bar.set_postfix_str(note, refresh=False)
        self._bar.update(n)

    def close(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
            self._thread = None
        self._bar.close()


def default_meter() -> AbstractMeter:
    """What `progress=True` reports with: none when `JAXIMPACT_PROGRESS` is off; tqdm's bar
    where tqdm is installed and stderr is a terminal; else a `TextMeter` on stderr. Both
    keep their clock moving while one step takes long (a first compilation, a table built
    on first use): a bar at 0/1 with a frozen clock read as a hang."""
    if not progress_enabled():
        return NoMeter()
    if is_terminal(sys.stderr) and importlib.util.find_spec("tqdm") is not None:
        return TqdmMeter()
    return TextMeter(heartbeat=1.0)


def as_meter(progress) -> AbstractMeter:
    """`progress=` as a meter: `True` the default meter, `False` (or None) none, a meter
    itself."""
    if isinstance(progress, AbstractMeter):
        return progress
    if progress is None or progress is False:
        return NoMeter()
    if progress is True:
        return default_meter()
    raise TypeError(f"progress must be True, False or an AbstractMeter, got {progress!r}")


@contextlib.contextmanager
def metered(progress, total: int, label: str):
    """`with metered(progress, total, label) as meter: ... meter.update(1, note)`: the meter
    of `progress=` started, and closed at the end of the block."""
    meter = as_meter(progress)
    meter.start(total, label)
    try:
        yield meter
    finally:
        meter.close()
