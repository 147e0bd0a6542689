"""Helpers shared by the benchmark scripts: timing, machine description, markdown tables.

Timing follows brax's rule: compile time is reported apart from run time, and every clock
stops after `jax.block_until_ready`. The machine is small and shared, so each timing is the
median over several rounds (each round long enough to swamp the clock's resolution), and
every report carries the load average and the CPU seen while it ran.
"""

import os
import platform
import subprocess
import time

# the timing helpers live in the package, shared with `jaximpact bench`
from jaximpact._bench import block, first_call, load_average, time_call  # noqa: F401

# the oblique fits' data, as code for a child process (after `import jax`, `math`, numpy as
# `np` and jaximpact as `ji`): 8 Hertz-Mindlin rebounds of an alumina sphere on aluminium
# at 3.9 m/s, synthetic, with noise 0.01 in e_t (G* 1.35e10 Pa, mu 0.092)
OBLIQUE_REBOUNDS = """M, R = 2.618e-4, 2.5e-3
E = 1 / ((1 - 0.23**2) / 3.8e11 + (1 - 0.25**2) / 7.0e10)
law = ji.law("hunt_crossley", c=4.0 / 3.0 * E * math.sqrt(R), a=0.0)
truth = ji.tangential_law("mindlin", G_star=1.35e10, mu=0.092)
v_n, v_t = ji.incidence(3.9, np.deg2rad([5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0, 60.0]))
made = jax.vmap(lambda a, b: ji.oblique_impact(law, truth, m=M, R=R, v_n=a, v_t=b))(v_n, v_t)
e_t = np.asarray(made.e_t) + np.random.default_rng(1).normal(0.0, 0.01, 8)
"""


def machine() -> dict:
    """Versions, CPU and load, for the header of a report."""
    import diffrax
    import jax
    import scipy

    try:
        lscpu = subprocess.run(["lscpu"], capture_output=True, text=True, check=False).stdout
        lscpu = "\n".join(lscpu.splitlines()[:15])
    except OSError:
        lscpu = platform.processor()
    try:
        root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
        commit = subprocess.run(
            ["git", "-C", root, "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            check=False,
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", root, "status", "--short", "jaximpact"],
            capture_output=True,
            text=True,
            check=False,
        ).stdout.strip()
    except OSError:
        commit, dirty = "?", ""
    return dict(
        python=platform.python_version(),
        jax=jax.__version__,
        diffrax=diffrax.__version__,
        scipy=scipy.__version__,
        backend=jax.default_backend(),
        lscpu=lscpu,
        commit=commit + (" (jaximpact/ modified in the working tree)" if dirty else ""),
        date=time.strftime("%Y-%m-%d %H:%M:%S %Z"),
    )


def machine_markdown(info: dict, loads: list[str]) -> str:
    lines = [
        f"- Run {info['date']}, commit {info['commit']}; python {info['python']}, "
        f"jax {info['jax']} ({info['backend']}), diffrax {info['diffrax']}, "
        f"scipy {info['scipy']}.",
        "- Load average (1, 5, 15 min) seen during the run: " + "; ".join(loads) + ".",
        "- `lscpu | head -15`:",
        "",
        "```",
        info["lscpu"],
        "```",
    ]
    return "\n".join(lines)


def fmt(value, digits=2) -> str:
    """A number for a table: `-` for None, scientific for small or large values."""
    if value is None:
        return "-"
    if isinstance(value, str):
        return value
    if value != value:  # NaN
        return "NaN"
    if value == 0:
        return "0"
    if abs(value) < 1e-2 or abs(value) >= 1e5:
        return f"{value:.{digits - 1}e}"
    return f"{value:.{digits + 1}g}"


def us(seconds) -> str:
    """Seconds as microseconds for a table."""
    return "-" if seconds is None else f"{seconds * 1e6:.{3}g}"


def table(header: list[str], rows: list[list]) -> str:
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(lines)


# the five laws the speed benchmarks compare, at the seed paper's parameters (SI units;
# m = 1 kg, v0 = 2.5 m/s)
PAPER_CASES = {
    "kelvin_voigt": dict(c=2e6, b=400.0),
    "maxwell": dict(c=2e6, b=2000.0),
    "hertz_viscous": dict(c=2e6, b=40.0),
    "hertz_rate": dict(c=2e6, b1=800.0),
    "hunt_crossley": dict(c=2e6, a=0.1),
}


def write_report(path: str, text: str) -> None:
    """Write a benchmark's markdown report and print it."""
    with open(path, "w") as handle:
        handle.write(text)
    print(text)


def fresh_process(code: str, *args: str) -> dict:
    """The JSON that `python -c code *args` prints last, run in a fresh process with an empty
    persistent cache of its own (a first call's time); its stderr tail on failure."""
    import json
    import sys
    import tempfile

    with tempfile.TemporaryDirectory(prefix="jaximpact-fresh-") as cache:
        done = subprocess.run(
            [sys.executable, "-c", code, *args],
            capture_output=True,
            text=True,
            check=False,
            env=dict(os.environ, JAXIMPACT_CACHE_DIR=cache, TF_CPP_MIN_LOG_LEVEL="3"),
        )
    if done.returncode != 0:
        raise RuntimeError(done.stderr[-2000:])
    return json.loads(done.stdout.strip().splitlines()[-1])
