"""Answer times of the README's commands: each one run as a user runs it, a fresh process
of the console script, first with an empty persistent compilation cache (`cold`) and then
with the cache that run filled (`warm`); wall seconds and the CPU seconds of the process
(user + system, all its threads: on 2 cores the wall can be under the CPU). What a user
waits for before the first answer, and what the cache saves (issue 35, item 4).

The data are SYNTHETIC, made here by the library itself before any timing (8 oblique
rebounds of a 5 mm alumina sphere by Hertz-Mindlin; the ping-pong drops of
examples/data/drops.csv, themselves synthetic).

Run: python benchmarks/answer_times.py [--repeat 1] [--only NAME ...]
(writes benchmarks/answer_times.md).
"""

import argparse
import math
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
sys.path.insert(0, HERE)
from _common import load_average, machine, machine_markdown, table, write_report  # noqa: E402

# Kharaz's sphere (examples/oblique_rebounds.py)
M, R, SPEED = 2.618e-4, 2.5e-3, 3.9
E_STAR = 1 / ((1 - 0.23**2) / 3.8e11 + (1 - 0.25**2) / 7.0e10)
C_HERTZ = 4.0 / 3.0 * E_STAR * math.sqrt(R)


def rebounds_csv(path):
    """8 rebounds (theta_deg, e_t) of the sphere by Hertz-Mindlin (G* 1.35e10 Pa, mu 0.092):
    synthetic, exact (no noise)."""
    import jax

    jax.config.update("jax_enable_x64", True)
    import numpy as np

    import jaximpact as ji

    law = ji.law("hunt_crossley", c=C_HERTZ, a=0.0)
    truth = ji.tangential_law("mindlin", G_star=1.35e10, mu=0.092)
    degrees = np.array([5.0, 10.0, 15.0, 20.0, 30.0, 40.0, 50.0, 60.0])
    v_n, v_t = ji.incidence(SPEED, np.deg2rad(degrees))
    rows = [
        ji.oblique_impact(law, truth, m=M, R=R, v_n=float(a), v_t=float(b)).e_t
        for a, b in zip(v_n, v_t, strict=True)
    ]
    with open(path, "w") as f:
        f.write("theta_deg,e_t\n")
        for d, e_t in zip(degrees, rows, strict=True):
            f.write(f"{d:g},{float(e_t):.12g}\n")


def commands(work):
    """(name, argv) of the README's commands, the issue's table in its order."""
    drops = os.path.join(ROOT, "examples", "data", "drops.csv")
    rebounds = os.path.join(work, "rebounds.csv")
    return [
        (
            "simulate",
            [
                "simulate",
                "--law",
                "hertz_rate",
                "--param",
                "c=2e6",
                "b1=800",
                "--mass",
                "1",
                "--v0",
                "2.5",
            ],
        ),
        (
            "calibrate (e, T at one speed)",
            [
                "calibrate",
                "--law",
                "hertz_rate",
                "--mass",
                "1",
                "--v0",
                "2.5",
                "--e",
                "0.85",
                "--T",
                "7.8e-3",
            ],
        ),
        (
            "export lammps --wall",
            [
                "export",
                "lammps",
                "--law",
                "hertz_rate",
                "--param",
                "c=2e6",
                "b1=800",
                "--mass",
                "0.05",
                "--v0",
                "1",
                "--radius",
                "0.01",
                "--wall",
            ],
        ),
        (
            "the same with --tangential mindlin",
            [
                "export",
                "lammps",
                "--law",
                "hertz_rate",
                "--param",
                "c=2e6",
                "b1=800",
                "--mass",
                "0.05",
                "--v0",
                "1",
                "--radius",
                "0.01",
                "--wall",
                "--tangential",
                "mindlin",
                "--tparam",
                "G_star=1e9",
                "mu=0.3",
            ],
        ),
        (
            "fit-oblique, 8 rebounds",
            [
                "fit-oblique",
                rebounds,
                "--speed",
                str(SPEED),
                "--mass",
                str(M),
                "--radius",
                str(R),
                "--law",
                "hunt_crossley",
                "--param",
                f"c={C_HERTZ:.6g}",
                "a=0",
                "--tangential",
                "mindlin",
                "--tparam",
                "G_star=1e10",
                "mu=0.1",
            ],
        ),
        (
            "calibrate --law all, e at 6 speeds",
            ["calibrate", "--law", "all", "--mass", "0.0027", "--data", drops],
        ),
        ("paper (the seed paper recomputed)", ["paper", "--out", os.path.join(work, "paper")]),
    ]


def run(argv, cache_home):
    """Wall and CPU seconds of one console-script process, its cache under `cache_home`."""
    script = os.path.join(os.path.dirname(sys.executable), "jaximpact")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    done = subprocess.run(
        [script, *argv],
        capture_output=True,
        text=True,
        check=False,
        env=dict(os.environ, XDG_CACHE_HOME=cache_home, JAXIMPACT_PROGRESS="off"),
    )
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        raise RuntimeError(f"jaximpact {' '.join(argv)}: {done.stderr[-1500:]}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--repeat", type=int, default=1)
    parser.add_argument("--only", nargs="+", default=None, help="names to run (substrings)")
    args = parser.parse_args()
    work = tempfile.mkdtemp(prefix="jaximpact-answers-")
    loads, rows = [load_average()], []
    try:
        rebounds_csv(os.path.join(work, "rebounds.csv"))
        for name, argv in commands(work):
            if args.only and not any(key in name for key in args.only):
                continue
            cold, warm = [], []
            for _ in range(args.repeat):
                home = tempfile.mkdtemp(prefix="jaximpact-cache-")
                try:
                    cold.append(run(argv, home))
                    warm.append(run(argv, home))
                finally:
                    shutil.rmtree(home, ignore_errors=True)

            def median(runs, k):
                return statistics.median(r[k] for r in runs)

            rows.append(
                [
                    f"`jaximpact {argv[0]}`: {name}",
                    f"{median(cold, 0):.1f}",
                    f"{median(cold, 1):.1f}",
                    f"{median(warm, 0):.1f}",
                    f"{median(warm, 1):.1f}",
                ]
            )
            print(" | ".join(rows[-1]), flush=True)
            loads.append(load_average())
    finally:
        shutil.rmtree(work, ignore_errors=True)
    text = "\n".join(
        [
            "# Answer times of the README's commands",
            "",
            "Generated by `python benchmarks/answer_times.py`. Each command is a fresh process of "
            "the console script: `cold` with an empty persistent compilation cache, `warm` with "
            "the cache the cold run filled. Wall and CPU seconds (user + system of the process "
            "and its threads), median of the repeats. The data are synthetic (made by the "
            "library: 8 Hertz-Mindlin rebounds; `examples/data/drops.csv`).",
            "",
            machine_markdown(machine(), loads),
            "",
            table(["command", "cold wall s", "cold CPU s", "warm wall s", "warm CPU s"], rows),
            "",
        ]
    )
    write_report(os.path.join(HERE, "answer_times.md"), text)


if __name__ == "__main__":
    main()
