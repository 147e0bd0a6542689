"""The first call of each entry point: `impact`, `jax.grad` of it, `calibrate`, `bounce` and
`fit_bounces`, each in a fresh Python process (law 14 at the seed paper's parameters,
float64), without JAX's persistent compilation cache (`cold`) and with one that a previous
process filled (`warm`); the second call beside it. What a user waits for before the first
answer, and how much of it the cache saves.

Run: python benchmarks/first_calls.py [--repeat 2] (writes benchmarks/first_calls.md).
"""

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from _common import load_average, machine, machine_markdown, table, write_report  # noqa: E402

CHILD = r"""
import json, os, sys, time
os.environ["TF_CPP_MIN_LOG_LEVEL"] = "3"
start = time.perf_counter()
import jax
jax.config.update("jax_enable_x64", True)
if sys.argv[2]:
    jax.config.update("jax_compilation_cache_dir", sys.argv[2])
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
import jaximpact as ji
out = {"import": time.perf_counter() - start}
law = ji.law("hertz_rate", c=2e6, b1=800.0)
times = [0.0, 0.02, 0.05, 0.3, 0.38]
calls = {
    "impact": lambda: ji.impact(law, m=1.0, v0=2.5).e,
    "grad": lambda: jax.grad(lambda c: ji.impact(law.replace(c=c), m=1.0, v0=2.5).e)(2e6),
    "calibrate": lambda: ji.calibrate(law, m=1.0, v0=2.5, e=0.85, T=7.8e-3).params["c"],
    "bounce": lambda: ji.bounce(law, m=1.0, h0=0.6, t_end=1.0).e,
    "fit_bounces": lambda: ji.fit_bounces(law, m=1.0, impact_times=ji.bounce(
        ji.law("hertz_rate", c=2e6, b1=900.0), m=1.0, h0=0.6, t_end=5.0).impact_times[:8]).e,
}
name = sys.argv[1]
for key in ("first", "second"):
    t0 = time.perf_counter()
    jax.block_until_ready(calls[name]())
    out[key] = time.perf_counter() - t0
print(json.dumps(out))
"""
ENTRIES = ("impact", "grad", "calibrate", "bounce", "fit_bounces")
# the same calls as the command line runs them: equinox's run-time checks as NaN rather than
# host callbacks (jaximpact/__init__.py), so that JAX may cache the fits' programs
CLI_MODE = " (EQX_ON_ERROR=nan)"
CHOICES = ENTRIES + tuple(name + CLI_MODE for name in ("calibrate", "fit_bounces"))
CLI_ROW = "jaximpact calibrate (command line, wall s incl. import)"
CLI_ARGS = ["calibrate", "--law", "hertz_rate", "--mass", "1", "--v0", "2.5", "--e", "0.85"]


def child(name, cache):
    env = dict(os.environ)
    if name.endswith(CLI_MODE):
        name, env["EQX_ON_ERROR"] = name[: -len(CLI_MODE)], "nan"
    done = subprocess.run(
        [sys.executable, "-c", CHILD, name, cache],
        capture_output=True,
        text=True,
        check=False,
        env=env,
    )
    if done.returncode != 0:
        raise RuntimeError(done.stderr[-2000:])
    return json.loads(done.stdout.strip().splitlines()[-1])


def cli_wall(cache_home):
    """Wall time of the console script, its persistent cache under `cache_home`."""
    script = os.path.join(os.path.dirname(sys.executable), "jaximpact")
    start = time.perf_counter()
    subprocess.run(
        [script, *CLI_ARGS, "--T", "7.8e-3"],
        capture_output=True,
        check=True,
        env=dict(os.environ, XDG_CACHE_HOME=cache_home),
    )
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=2)
    parser.add_argument("--entries", nargs="+", default=list(CHOICES), choices=CHOICES)
    parser.add_argument("--no-cli", action="store_true", help="skip the console script's row")
    args = parser.parse_args()
    loads, rows = [load_average()], []
    for name in args.entries:
        runs = {"cold": [], "warm": []}
        for _ in range(args.repeat):
            cache = tempfile.mkdtemp(prefix="jaximpact-first-")
            try:
                runs["cold"].append(child(name, ""))
                child(name, cache)  # fills the cache
                runs["warm"].append(child(name, cache))
            finally:
                shutil.rmtree(cache, ignore_errors=True)

        def median(kind, key, runs=runs):
            return statistics.median(r[key] for r in runs[kind])

        rows.append(
            [
                name,
                f"{median('cold', 'import'):.1f}",
                f"{median('cold', 'first'):.1f}",
                f"{median('warm', 'first'):.1f}",
                f"{median('cold', 'second') * 1e3:.1f}",
            ]
        )
        print(" | ".join(rows[-1]), flush=True)
        loads.append(load_average())
    if not args.no_cli:
        cold, warm = [], []
        for _ in range(args.repeat):
            home = tempfile.mkdtemp(prefix="jaximpact-cli-")
            try:
                cold.append(cli_wall(home))
                warm.append(cli_wall(home))
            finally:
                shutil.rmtree(home, ignore_errors=True)
        rows.append(
            [CLI_ROW, "-", f"{statistics.median(cold):.1f}", f"{statistics.median(warm):.1f}", "-"]
        )
        print(" | ".join(rows[-1]), flush=True)
        loads.append(load_average())
    text = "\n".join(
        [
            "# First calls: what a user waits for",
            "",
            "Generated by `python benchmarks/first_calls.py`. Law 14 (c = 2e6, b1 = 800), "
            "m = 1 kg, v0 = 2.5 m/s, float64, defaults; each entry point in a fresh process, "
            f"median of {args.repeat}. `cold`: no persistent cache; `warm`: a cache filled by "
            "a previous process. `fit_bounces`: eight impact times of a simulated drop. "
            f"`{CLI_MODE.strip()}`: as the command line runs them (equinox's run-time checks "
            "give NaN instead of calling back to Python, and JAX caches only programs without "
            "host callbacks: the fits' checks come from lineax, in the implicit derivative of "
            "diffrax's event times). Tracing (about 5 s for `calibrate`) is never cached.",
            "",
            machine_markdown(machine(), loads),
            "",
            table(
                [
                    "entry point",
                    "import s",
                    "first call s, cold",
                    "first call s, warm",
                    "second call ms",
                ],
                rows,
            ),
            "",
        ]
    )
    write_report(os.path.join(HERE, "first_calls.md"), text)


if __name__ == "__main__":
    main()
