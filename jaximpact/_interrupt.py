"""Ctrl-C (SIGINT) and SIGTERM on the command line: the command stops at once, exits with
status 130 (SIGINT) or 143 (SIGTERM), and says in one line what it kept.

`handle_interrupts()` (the `jaximpact` entry point wraps every command in it) installs a
handler that records the signal and raises `Interrupted` (a `KeyboardInterrupt`) in the main
thread. That is not always enough: the main thread may be inside a long XLA computation
(Python runs no handler until it returns), and an exception raised while JAX runs a Python
callback may be caught there and reported as something else, or printed and ignored (Python
prints an exception raised in a garbage-collection callback, such as JAX's, as "Exception
ignored in ..." and goes on). So

- an `Interrupted` that Python could not raise (`sys.unraisablehook`) is not printed: the
  signal is recorded and raised again at the next safe point;

- the long loops call `check_interrupt()` at their safe points (between chunks, between
  fits), which raises again if a signal was recorded, whatever became of the first raise;
- a watchdog thread wakes on the signal itself (`signal.set_wakeup_fd`, written by the C
  level handler even while Python is blocked) and, if the process is still running
  `GRACE` seconds later (or at a second signal), prints the line and ends the process with
  `os._exit`; files are written to temporary names and renamed into place
  (`_files.atomic_output`), so no final name ever holds a partial file.

`set_note(text)` says what a stop now would keep (`batch`: the finished chunks and
`--resume`); the line printed is `interrupted by SIGINT; <note>`.
"""

import contextlib
import os
import signal
import sys
import threading

GRACE = 2.0  # s a stopping command has to reach its own clean exit before the watchdog's
_SIGNALS = (signal.SIGINT, signal.SIGTERM)
_state = {"signal": None, "note": None, "active": False, "reported": False}
_lock = threading.Lock()


class Interrupted(KeyboardInterrupt):
    """A command stopped by a signal; `status` is the exit status (128 + signal number)."""

    def __init__(self, signum: int):
        self.signum = signum
        self.status = 128 + signum
        super().__init__(interrupt_message(signum))


def interrupt_message(signum: int) -> str:
    """`interrupted by SIGINT; <what was kept>`."""
    note = _state["note"]
    return f"interrupted by {signal.Signals(signum).name}" + (f"; {note}" if note else "")


def set_note(text: str | None):
    """What a stop now would keep (one sentence), printed after `interrupted by ...`."""
    _state["note"] = text


def received() -> int | None:
    """The signal recorded since `handle_interrupts` began (None: none)."""
    return _state["signal"]


def check_interrupt():
    """Raise `Interrupted` if a signal was recorded (a safe point of a long loop); nothing
    outside `handle_interrupts` (a library call from a script keeps Python's own Ctrl-C)."""
    if _state["active"] and _state["signal"] is not None:
        raise Interrupted(_state["signal"])


def mark_reported():
    """The command line has printed the line: the watchdog only bounds the exit."""
    _state["reported"] = True


def _handler(signum, frame):
    with _lock:
        _state["signal"] = _state["signal"] or signum
    raise Interrupted(_state["signal"])


def _quiet_unraisable(previous):
    """An unraisable-exception hook that drops `Interrupted` (recorded; raised again at the
    next safe point or ended by the watchdog) and passes anything else to `previous`."""

    def hook(unraisable):
        if isinstance(unraisable.exc_value, Interrupted):
            return
        previous(unraisable)

    return hook


def _watch(read_fd: int, stop: threading.Event):
    """The watchdog: on the first signal, give the main thread `GRACE` seconds (a second
    signal: none) to stop by itself, then print the line (unless printed) and `os._exit`."""
    first = None
    while not stop.is_set():
        try:
            data = os.read(read_fd, 64)
        except OSError:
            return
        if stop.is_set() or not data:
            return
        signums = [b for b in data if b in _SIGNALS]
        if not signums:
            continue
        if first is None:
            first = signums[0]
            with _lock:
                _state["signal"] = _state["signal"] or first
            if len(signums) == 1:
                _wait_for_more(read_fd, stop)
        if stop.is_set():
            return
        signum = _state["signal"] or first
        if not _state["reported"]:
            line = f"jaximpact: error: {interrupt_message(signum)}\n"
            with contextlib.suppress(OSError):
                os.write(2, line.encode())
        os._exit(128 + signum)


def _wait_for_more(read_fd: int, stop: threading.Event):
    """Return after `GRACE` seconds, or at once when a second signal arrives."""
    import select

    deadline = GRACE
    with contextlib.suppress(OSError, ValueError):
        ready, _, _ = select.select([read_fd], [], [], deadline)
        if ready:
            os.read(read_fd, 64)


def stop_at_once():
    """Until `handle_interrupts` takes over: SIGINT and SIGTERM end the process at once
    with one line and status 128 + signal (for the start of the command line, which has
    written nothing yet)."""

    def handler(signum, frame):
        with contextlib.suppress(OSError):
            os.write(2, f"jaximpact: error: {interrupt_message(signum)}\n".encode())
        os._exit(128 + signum)

    if threading.current_thread() is threading.main_thread():
        for s in _SIGNALS:
            signal.signal(s, handler)


@contextlib.contextmanager
def handle_interrupts():
    """Within the block, SIGINT and SIGTERM raise `Interrupted` (exit status 128 + signal)
    and a watchdog ends the process if it does not stop within `GRACE` seconds. Only in
    the main thread; elsewhere the block runs unchanged."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    read_fd, write_fd = os.pipe()
    os.set_blocking(write_fd, False)
    stop = threading.Event()
    previous = {s: signal.getsignal(s) for s in _SIGNALS}
    previous_fd = signal.set_wakeup_fd(write_fd, warn_on_full_buffer=False)
    previous_hook = sys.unraisablehook
    sys.unraisablehook = _quiet_unraisable(previous_hook)
    _state.update(signal=None, note=None, active=True, reported=False)
    watchdog = threading.Thread(target=_watch, args=(read_fd, stop), daemon=True)
    watchdog.start()
    try:  # the handlers that raise last: a signal from here on is the block's to handle
        for s in _SIGNALS:
            signal.signal(s, _handler)
        yield
    finally:
        if _state["signal"] is None:  # a stop under way keeps its watchdog to the end
            stop.set()
            for s, handler in previous.items():
                signal.signal(s, handler)
            signal.set_wakeup_fd(previous_fd)
            sys.unraisablehook = previous_hook
            os.close(write_fd)  # wakes the watchdog, which returns
            watchdog.join(1.0)
            os.close(read_fd)
        _state["active"] = False
