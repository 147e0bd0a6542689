"""The command line's first seconds and its last write (issue 34, items 3 and 12): Ctrl-C at any
moment of the start, while Python imports numpy and JAX, ends it with one line and status
130, never a traceback; a closed stdout is an error, not a silent success."""

import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

SIMULATE = [
    "simulate",
    "--law",
    "hertz_rate",
    "--param",
    "c=2e6",
    "b1=800",
    "--v0",
    "2.5",
    "--mass",
    "1",
]


def _script() -> str:
    script = Path(sys.executable).with_name("jaximpact")
    script = str(script) if script.exists() else shutil.which("jaximpact")
    if script is None:
        pytest.skip("the jaximpact console script is not installed (pip install -e .)")
    return script


def _interrupted(command, after: float, tmp_path) -> subprocess.CompletedProcess:
    """`command` sent SIGINT `after` seconds after its start (its compilation cache empty,
    a figure to draw: seconds of work behind the imports)."""
    env = {
        **os.environ,
        "JAXIMPACT_CACHE_DIR": str(tmp_path / "cache"),
        "JAXIMPACT_PROGRESS": "off",
    }
    argv = [*command, *SIMULATE, "--plot", str(tmp_path / "impact.png")]
    child = subprocess.Popen(
        argv, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    time.sleep(after)
    assert child.poll() is None, "the command ended before the signal: make it longer"
    child.send_signal(signal.SIGINT)
    out, err = child.communicate(timeout=30)
    return subprocess.CompletedProcess(argv, child.returncode, out, err)


@pytest.mark.parametrize("after", [0.3, 1.0, pytest.param(2.0, marks=pytest.mark.slow)])
def test_ctrl_c_while_the_console_script_starts_is_one_line(tmp_path, after):
    done = _interrupted([_script()], after, tmp_path)
    assert done.returncode == 130, done.stderr
    assert "Traceback" not in done.stderr and "KeyboardInterrupt" not in done.stderr
    lines = done.stderr.splitlines()
    assert 1 <= len(lines) <= 2 and lines[-1].startswith("jaximpact: error: interrupted by SIGINT")
    assert not (tmp_path / "impact.png").exists()


def test_ctrl_c_while_python_m_starts_is_one_line(tmp_path):
    done = _interrupted([sys.executable, "-m", "jaximpact._cli"], 0.3, tmp_path)
    assert done.returncode == 130, done.stderr
    assert "Traceback" not in done.stderr
    assert done.stderr.splitlines()[-1:] == ["jaximpact: error: interrupted by SIGINT"]


# the console script's own lines, with SIGINT sent to itself as `module` starts to load
TRIP = """
import os, signal, sys

class Trip:
    def find_spec(self, name, path=None, target=None):
        if name == MODULE:
            sys.meta_path.remove(self)
            os.kill(os.getpid(), signal.SIGINT)

sys.meta_path.insert(0, Trip())
sys.argv = ["jaximpact", *ARGV]
from jaximpact._cli import main
sys.exit(main())
"""


@pytest.mark.parametrize("module", ["numpy", "jax"])
def test_ctrl_c_while_a_module_loads_is_one_line(tmp_path, module):
    """The same at a chosen moment, not a time: as numpy (the command modules' first heavy
    import) or JAX (`configure_jax`) starts to load."""
    code = f"MODULE = {module!r}\nARGV = {[*SIMULATE, '--plot', str(tmp_path / 'i.png')]!r}\n"
    env = {**os.environ, "JAXIMPACT_CACHE_DIR": str(tmp_path / "cache")}
    done = subprocess.run(
        [sys.executable, "-c", code + TRIP], capture_output=True, text=True, timeout=120, env=env
    )
    assert done.returncode == 130, done.stderr
    assert done.stdout == "" and "Traceback" not in done.stderr
    assert done.stderr.splitlines() == ["jaximpact: error: interrupted by SIGINT"]


@pytest.mark.parametrize("how", ["console script", "python -m"])
def test_a_closed_stdout_is_an_error(how):
    command = [_script()] if how == "console script" else [sys.executable, "-m", "jaximpact._cli"]
    closed = ["sh", "-c", 'exec "$@" >&-', "sh"]  # stdout closed, not /dev/null
    done = subprocess.run(
        [*closed, *command, *SIMULATE], stderr=subprocess.PIPE, text=True, timeout=120
    )
    assert done.returncode == 2
    assert done.stderr.splitlines() == [
        "jaximpact: error: cannot write the output: stdout is closed"
    ]
