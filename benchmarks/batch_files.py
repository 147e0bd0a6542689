"""`batch_file` (a CSV of bodies streamed in chunks) against `impact_batch` on the same rows in
memory: rows per second, the share of reading and writing, and peak memory per file size.

    python benchmarks/batch_files.py     # writes benchmarks/batch_files.md

Each size runs in a fresh process (peak resident memory from `resource`), twice: the first
call compiles, the second is timed. Curves path (law 14 without gravity, chunks of 100,000)
from 1e4 to 1e7 rows, and the integrated path (gravity on) at 1e5 rows. Then one process
against two (`jaximpact batch --coordinator ... --num-processes 2`, `--mesh global` and
`--mesh local`, on this machine), wall
clock of the whole command (start-up and compiling included, as a user sees it).
"""

import json
import os
import platform
import resource
import socket
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
CASES = (  # (path, rows, g)
    ("curves", 10_000, 0.0),
    ("curves", 100_000, 0.0),
    ("curves", 1_000_000, 0.0),
    ("curves", 10_000_000, 0.0),
    ("integrated", 100_000, 9.81),
)
PROCESS_CASES = (("curves", 1_000_000, 0.0), ("integrated", 100_000, 9.81))


def child(mode: str, n: int, folder: str, g: float = 0.0):
    """One measurement in this fresh process: `make` writes the file, `file` times
    `batch_file`, `memory` times `impact_batch` on the same rows; prints JSON."""
    import jax

    jax.config.update("jax_enable_x64", True)
    import numpy as np

    import jaximpact as ji

    source = os.path.join(folder, f"bodies-{n}.csv")
    if mode == "make":
        rng = np.random.default_rng(0)
        columns = [
            rng.uniform(1e6, 3e6, n),
            rng.uniform(100.0, 2000.0, n),
            rng.uniform(0.5, 2.0, n),
            rng.uniform(0.5, 5.0, n),
        ]
        with open(source, "w") as handle:
            handle.write("c,b1,m,v0\n")
            for row in zip(*columns, strict=True):
                handle.write(",".join(repr(float(x)) for x in row) + "\n")
        print(json.dumps(dict(size_mib=os.path.getsize(source) / 2**20)))
        return
    if mode == "file":
        out = os.path.join(folder, f"impacts-{n}.csv")
        ji.batch_file(source, out, "hertz_rate", g=g, progress=False)  # compiles
        start = time.perf_counter()
        ji.batch_file(source, out, "hertz_rate", g=g, progress=False)
    else:
        table = np.loadtxt(source, delimiter=",", skiprows=1)
        params = {"c": table[:, 0], "b1": table[:, 1]}
        kwargs = dict(m=table[:, 2], v0=table[:, 3], g=g, progress=False)
        ji.impact_batch("hertz_rate", params, **kwargs)
        start = time.perf_counter()
        ji.impact_batch("hertz_rate", params, **kwargs)
    seconds = time.perf_counter() - start
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024  # MiB on Linux
    print(json.dumps(dict(seconds=seconds, peak_mib=peak)))


def _run(mode, n, folder, g=0.0):
    done = subprocess.run(
        [sys.executable, __file__, "--child", mode, str(n), folder, repr(g)],
        capture_output=True,
        text=True,
        check=True,
    )
    return json.loads(done.stdout.strip().splitlines()[-1])


def _processes(n, folder, g, count, mesh="global"):
    """Wall clock (s) of `jaximpact batch` on `count` processes (`--mesh mesh`), and the
    output's bytes."""
    source = os.path.join(folder, f"bodies-{n}.csv")
    out = os.path.join(folder, f"impacts-{n}-{count}p.csv")
    command = ["jaximpact", "batch", source, "--law", "hertz_rate", "--out", out, "--g", repr(g)]
    if count > 1:
        with socket.socket() as probe:
            probe.bind(("localhost", 0))
            port = probe.getsockname()[1]
        command += [
            "--coordinator",
            f"localhost:{port}",
            "--num-processes",
            str(count),
            "--mesh",
            mesh,
        ]
    env = {**os.environ, "JAXIMPACT_PROGRESS": "0"}
    start = time.perf_counter()
    procs = [
        subprocess.Popen(
            command + (["--process-id", str(k)] if count > 1 else []),
            env=env,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
        )
        for k in range(count)
    ]
    for p in procs:
        _, err = p.communicate()
        if p.returncode:
            raise RuntimeError(err.decode()[-2000:])
    seconds = time.perf_counter() - start
    with open(out, "rb") as handle:
        data = handle.read()
    os.remove(out)
    return seconds, data


def main():
    import tempfile

    rows, process_rows = [], []
    with tempfile.TemporaryDirectory() as folder:
        for path, n, g in CASES:
            made, file, memory = (_run(mode, n, folder, g) for mode in ("make", "file", "memory"))
            rows.append(
                dict(
                    path=path,
                    n=n,
                    size_mib=made["size_mib"],
                    file_s=file["seconds"],
                    memory_s=memory["seconds"],
                    peak_mib=file["peak_mib"],
                    memory_peak_mib=memory["peak_mib"],
                )
            )
            print(rows[-1], flush=True)
        for path, n, g in PROCESS_CASES:
            one, one_bytes = _processes(n, folder, g, 1)
            two, two_bytes = _processes(n, folder, g, 2, "global")
            local, local_bytes = _processes(n, folder, g, 2, "local")
            process_rows.append(
                dict(
                    path=path,
                    n=n,
                    one=one,
                    two=two,
                    local=local,
                    same=one_bytes == two_bytes == local_bytes,
                )
            )
            print(process_rows[-1], flush=True)
    load = os.getloadavg()[0]
    lines = [
        "# Many bodies from a file: `batch_file` against `impact_batch` in memory",
        "",
        f"{platform.processor() or platform.machine()}, {os.cpu_count()} cores, no "
        f"accelerator, load {load:.1f} at the end; `python benchmarks/batch_files.py`. Law 14 "
        "(c, b1, m, v0 per row), chunks of 100,000 rows, second call timed; `curves`: no "
        "gravity (the universal curves), `integrated`: g = 9.81 m/s^2 (diffrax).",
        "",
        "| path | rows | input file (MiB) | batch_file (s) | rows/s | impact_batch in memory "
        "(s) | reading and writing (share) | batch_file peak memory (MiB) | in memory peak "
        "(MiB) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        share = 1 - r["memory_s"] / r["file_s"]
        lines.append(
            f"| {r['path']} | {r['n']:,} | {r['size_mib']:.1f} | {r['file_s']:.2f} | "
            f"{r['n'] / r['file_s']:,.0f} | {r['memory_s']:.3f} | {share:.0%} | "
            f"{r['peak_mib']:.0f} | {r['memory_peak_mib']:.0f} |"
        )
    lines += [
        "",
        "Each column is its own process: peak memory is that process's resident maximum "
        "(the JAX runtime included). `batch_file` holds one chunk at a time; the in-memory "
        "call holds every row (and `np.loadtxt`'s copy of the file).",
        "",
        "## One process against two (`jaximpact batch`, this machine)",
        "",
        "| path | rows | 1 process (s) | 2 processes, `--mesh global` (s) | speed-up | "
        "2 processes, `--mesh local` (s) | speed-up | same file, bit for bit (all three) |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for r in process_rows:
        lines.append(
            f"| {r['path']} | {r['n']:,} | {r['one']:.1f} | {r['two']:.1f} | "
            f"{r['one'] / r['two']:.2f} | {r['local']:.1f} | {r['one'] / r['local']:.2f} | "
            f"{'yes' if r['same'] else 'NO'} |"
        )
    lines += [
        "",
        "Wall clock of the whole command, start-up and compiling included. `global`: each "
        "round of chunks (one per process) is one jitted program over a mesh of both "
        "processes' devices (on the CPU, XLA's collectives go through gloo); `local`: each "
        "process runs its chunks on its own device and never waits for the other. Both "
        "processes share this machine's 2 cores: the gain comes from each process parsing "
        "and writing its own chunks (single-threaded Python and numpy work) while the other "
        "computes; on separate machines each process brings its own cores.",
    ]
    with open(os.path.join(HERE, "batch_files.md"), "w") as handle:
        handle.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    if len(sys.argv) > 1 and sys.argv[1] == "--child":
        child(sys.argv[2], int(sys.argv[3]), sys.argv[4], float(sys.argv[5]))
    else:
        main()
