"""`Progress`: a bar redrawn in place on a terminal, plain lines elsewhere (logs, pipes, CI)."""

import io

from jaximpact._progress import Progress, progress_enabled


class Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_terminal_gets_a_bar_redrawn_in_place():
    stream = Terminal()
    with Progress(3, "fitting", stream=stream) as bar:
        for label in ("a", "b", "c"):
            bar.update(label)
    text = stream.getvalue()
    assert text.count("\r") == 4 and text.endswith("\n") and "3/3" in text


def test_a_pipe_gets_lines_not_carriage_returns():
    stream = io.StringIO()  # not a terminal
    with Progress(40, "fitting", stream=stream, delay=0.0, interval=0.0) as bar:
        for k in range(40):
            bar.update(f"law {k}")
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue()
    assert len(lines) == 41 and lines[-1].startswith("fitting [") and "40/40" in lines[-1]


def test_a_pipe_gets_at_most_a_line_per_interval_and_always_the_last():
    stream = io.StringIO()
    with Progress(1000, "rows", stream=stream, delay=3600.0) as bar:
        for _ in range(1000):
            bar.update("x")
    (line,) = stream.getvalue().splitlines()  # quick work: the final line only
    assert "1000/1000" in line


def test_disabled_is_silent_and_the_environment_switch(monkeypatch):
    stream = io.StringIO()
    with Progress(2, "x", enabled=False, stream=stream) as bar:
        bar.update()
    assert stream.getvalue() == ""
    for value, expected in (("off", False), ("0", False), ("auto", True), ("1", True)):
        monkeypatch.setenv("JAXIMPACT_PROGRESS", value)
        assert progress_enabled() is expected
