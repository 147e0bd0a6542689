"""A minimal progress bar on stderr, for work that takes more than a moment."""

import sys
import time


class Progress:
    """`with Progress(total, "fitting") as bar: ... bar.update(label)`; silent if not
    `enabled` or when stderr is not a terminal and `force` is not set."""

    def __init__(self, total: int, what: str, enabled: bool = True, stream=None):
        self.total, self.what, self.done = total, what, 0
        self.stream = sys.stderr if stream is None else stream
        self.enabled = enabled
        self.start = time.perf_counter()

    def __enter__(self):
        self._draw("")
        return self

    def update(self, label: str = ""):
        self.done += 1
        self._draw(label)

    def _draw(self, label):
        if not self.enabled:
            return
        width = 24
        filled = int(width * self.done / max(self.total, 1))
        elapsed = time.perf_counter() - self.start
        bar = "#" * filled + "-" * (width - filled)
        self.stream.write(
            f"\r{self.what} [{bar}] {self.done}/{self.total} {elapsed:5.1f}s {label:<24}"
        )
        self.stream.flush()

    def __exit__(self, *exc):
        if self.enabled:
            self.stream.write("\n")
            self.stream.flush()
        return False
