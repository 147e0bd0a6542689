"""Progress of long work on stderr: a bar on a terminal, plain lines elsewhere (a log, a pipe,
CI), so that a run of minutes is never silent.

`JAXIMPACT_PROGRESS` chooses what `progress_enabled()` answers for the command line:
`auto` (default: on), `off` (or `0`: none); a `Progress` that is enabled draws a bar when its
stream is a terminal and writes a line at most every `interval` seconds (and at the end)
when it is not.
"""

import os
import sys
import threading
import time

PROGRESS_ENV = "JAXIMPACT_PROGRESS"


def progress_enabled() -> bool:
    """Whether the command line reports progress: yes unless `JAXIMPACT_PROGRESS` is `off`
    (or `0`, `no`, `false`)."""
    value = os.environ.get(PROGRESS_ENV, "auto").strip().lower()
    return value not in ("off", "0", "no", "false")


def is_terminal(stream) -> bool:
    """Whether `stream` is a terminal (False for anything that cannot say)."""
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):
        return False


class Progress:
    """`with Progress(total, "fitting") as bar: ... bar.update(label)`; silent unless
    `enabled`. On a terminal a bar redrawn in place; otherwise one line per `interval`
    seconds at most (the first after `delay` seconds) and a last one at the end.

    `heartbeat` (s): also redraw that often from a background thread while the work runs,
    so that a step that takes long (a first compile) still shows the clock moving; then
    nothing is drawn before `delay` seconds, so quick work stays silent."""

    def __init__(
        self,
        total: int,
        what: str,
        enabled: bool = True,
        stream=None,
        interval: float = 5.0,
        delay: float = 2.0,
        heartbeat: float | None = None,
    ):
        self.total, self.what, self.done = total, what, 0
        self.stream = sys.stderr if stream is None else stream
        self.enabled = enabled
        self.interval, self.delay, self.heartbeat = interval, delay, heartbeat
        self.terminal = is_terminal(self.stream)
        self.start = time.perf_counter()
        self._last_line = None  # when the last line was written (lines mode)
        self._last_done = -1
        self._label = ""
        self._lock, self._stop = threading.Lock(), threading.Event()
        self._thread = None
        self._shown = heartbeat is None  # with a heartbeat: nothing before `delay`

    def __enter__(self):
        if self.enabled and self.heartbeat is not None:
            self._thread = threading.Thread(target=self._beat, daemon=True)
            self._thread.start()
        else:
            self._draw("")
        return self

    def _beat(self):
        if self._stop.wait(self.delay):
            return
        with self._lock:
            self._shown = True
        while True:
            with self._lock:
                self._draw(self._label)
            if self._stop.wait(self.heartbeat):
                return

    def update(self, label: str = ""):
        with self._lock:
            self.done += 1
            self._label = label
            if self._thread is None:
                self._draw(label)

    def _text(self, label):
        width = 24
        filled = int(width * self.done / max(self.total, 1))
        elapsed = time.perf_counter() - self.start
        bar = "#" * filled + "-" * (width - filled)
        return f"{self.what} [{bar}] {self.done}/{self.total} {elapsed:5.1f}s {label:<24}"

    def _draw(self, label, final=False):
        if not (self.enabled and self._shown):
            return
        self._label = label
        if self.terminal:
            self.stream.write("\r" + self._text(label))
            self.stream.flush()
            return
        now = time.perf_counter()
        if final:
            due = self._last_done != self.done or self._last_line is None
        elif self._last_line is None:
            due = now - self.start >= self.delay
        else:
            due = now - self._last_line >= self.interval
        if due:
            self.stream.write(self._text(label).rstrip() + "\n")
            self.stream.flush()
            self._last_line, self._last_done = now, self.done

    def __exit__(self, *exc):
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
        if self.enabled and self._shown:
            if self.terminal:
                if self._thread is not None:  # the last update may be between beats
                    self._draw(self._label)
                self.stream.write("\n")
            else:
                self._draw(self._label, final=True)
            self.stream.flush()
        return False
