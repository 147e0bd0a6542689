"""One run per output (issue 34, item 4): a run writing `OUT` holds `OUT.lock`; a second run on
the same output, however its path is spelled, is refused in one line naming the first run's
process; the lock ends with its run however the run ends, and one left by a dead process is
taken over."""

import os
import signal
import subprocess
import sys
import textwrap

import pytest
from helpers import assert_one_line_error, run_cli

import jaximpact as ji
from jaximpact._files import lock_name, output_lock

BODIES = "c,b1,m,v0\n2e6,800,1,2.5\n2e6,900,1,2.0\n2e6,1000,1,1.5\n"


def _refusal(pid: int, out) -> str:
    return f"another run (pid {pid}) is writing {out}; wait for it or choose another output file"


def _holder(out) -> subprocess.Popen:
    """Another process that takes the lock of `out` and holds it until killed."""
    code = textwrap.dedent(
        f"""
        import time
        from jaximpact._files import output_lock
        with output_lock({str(out)!r}):
            print("held", flush=True)
            time.sleep(60)
        """
    )
    child = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    assert child.stdout.readline() == "held\n"
    return child


def test_a_second_writer_of_one_output_is_refused_however_spelled(tmp_path, monkeypatch):
    (tmp_path / "in.csv").write_text(BODIES)
    (tmp_path / "sub").mkdir()
    (tmp_path / "link.csv").symlink_to(tmp_path / "out.csv")
    monkeypatch.chdir(tmp_path)
    with output_lock(tmp_path / "out.csv"):
        for out in ["out.csv", "sub/../out.csv", str(tmp_path / "out.csv"), "link.csv"]:
            with pytest.raises(ValueError) as error:
                ji.batch_file("in.csv", out, "hertz_rate", progress=False)
            assert str(error.value) == _refusal(os.getpid(), out)
        assert not (tmp_path / "out.csv").exists() and not (tmp_path / "out.csv.parts").exists()
    assert not lock_name(tmp_path / "out.csv").exists()  # released with the block
    ji.batch_file("in.csv", "out.csv", "hertz_rate", progress=False)
    assert (tmp_path / "out.csv").exists() and not lock_name("out.csv").exists()


def test_the_command_line_names_the_other_run_and_a_dead_one_s_lock_is_taken_over(capsys, tmp_path):
    source, out = tmp_path / "in.csv", tmp_path / "same.csv"
    source.write_text(BODIES)
    argv = ["batch", str(source), "--law", "hertz_rate", "--out", str(out)]
    child = _holder(out)
    try:
        assert_one_line_error(*run_cli(capsys, argv), contains=_refusal(child.pid, out))
    finally:
        child.send_signal(signal.SIGKILL)  # dies holding it: the lock file stays, unlocked
        child.wait()
    assert lock_name(out).read_text().split()[0] == str(child.pid)
    status, text, err = run_cli(capsys, argv)
    assert status == 0 and "3 impacts written" in text, err
    assert not lock_name(out).exists()


def test_the_lock_ends_with_a_run_that_fails(tmp_path):
    (tmp_path / "in.csv").write_text(BODIES.replace("2.0", "-2.0"))
    out = tmp_path / "out.csv"
    with pytest.raises(ValueError, match="line 3, column v0"):
        ji.batch_file(tmp_path / "in.csv", out, "hertz_rate", progress=False)
    assert not lock_name(out).exists()
    with output_lock(out):  # free again
        pass


def test_the_lock_file_is_an_output_that_must_not_be_an_input(tmp_path):
    source = tmp_path / "out.csv.lock"
    source.write_text(BODIES)
    with pytest.raises(ValueError, match="is the input"):
        ji.batch_file(source, tmp_path / "out.csv", "hertz_rate", progress=False)
