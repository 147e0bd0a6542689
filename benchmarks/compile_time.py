"""Compile time: the first call of `impact` and of `jax.grad` of it, per law, in a fresh
process, without and with JAX's persistent compilation cache; and the command line's cold
start.

For every law of `jaximpact.LAW_NAMES` (paper parameters, m = 1 kg, v0 = 2.5 m/s) a new
Python process measures: the import of jax and jaximpact, the first `impact(law, m, v0)`
(defaults; tracing + compilation + run) and a second one, the first
`jax.grad(lambda p: impact(law(p)).e)` and a second one. This is done twice per law with
one cache directory: `cold` (empty cache: compile and write) and `warm` (a new process
reading what `cold` wrote). `jaximpact simulate` is timed the same way. Each process is
run `--repeat` times (fresh cache for every cold run); medians are reported.

Run: `python benchmarks/compile_time.py` (writes compile_time.json / compile_time.md);
`--laws`, `--repeat`.
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
JSON_PATH = os.path.join(HERE, "compile_time.json")
MD_PATH = os.path.join(HERE, "compile_time.md")

PAPER = {
    "kelvin_voigt": dict(c=2e6, b=400.0),
    "kelvin_voigt_modified": dict(c=2e6, b1=4e5),
    "bingham": dict(c=2e6, b=200.0, P=400.0),
    "bingham_modified": dict(c=2e6, b1=200.0, P=400.0),
    "bingham_compression": dict(c=2e6, P=800.0),
    "maxwell": dict(c=2e6, b=2000.0),
    "hertz_viscous": dict(c=2e6, b=40.0),
    "hertz_modified": dict(c=2e6, b=2e4),
    "hertz_rate": dict(c=2e6, b1=800.0),
    "hunt_crossley": dict(c=2e6, a=0.1),
}
NOMINAL = dict(c=2e6, e_nominal=0.8)

CHILD = r"""
import json, os, sys, time
t0 = time.perf_counter()
c0 = time.process_time()
os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")
import jax
jax.config.update("jax_enable_x64", True)
cache = sys.argv[3]
if cache:
    jax.config.update("jax_compilation_cache_dir", cache)
    jax.config.update("jax_persistent_cache_min_compile_time_secs", 0.0)
    jax.config.update("jax_persistent_cache_min_entry_size_bytes", 0)
import jaximpact as ji
t_import = time.perf_counter() - t0
cpu_import = time.process_time() - c0
name, params = sys.argv[1], json.loads(sys.argv[2])
law = ji.law(name, **params)

CPU = {}

def clock(fn, label):
    start, cpu = time.perf_counter(), time.process_time()
    jax.block_until_ready(fn())
    CPU[label] = time.process_time() - cpu
    return time.perf_counter() - start

out = dict(import_s=t_import)
out["impact_first_s"] = clock(lambda: ji.impact(law, m=1.0, v0=2.5).e, "impact_first")
out["impact_second_s"] = clock(lambda: ji.impact(law, m=1.0, v0=2.5).e, "impact_second")
out["path"] = ji.impact(law, m=1.0, v0=2.5).path
grad = jax.grad(lambda p: ji.impact(ji.law(name, **p), m=1.0, v0=2.5).e)
p0 = {k: float(v) for k, v in params.items()}
out["grad_first_s"] = clock(lambda: grad(p0), "grad_first")
out["grad_second_s"] = clock(lambda: grad(p0), "grad_second")
out["total_s"] = time.perf_counter() - t0
out["cpu_import_s"] = cpu_import
out.update({f"cpu_{k}_s": v for k, v in CPU.items()})
print("RESULT " + json.dumps(out))
"""


def child(name, params, cache):
    env = dict(os.environ, TF_CPP_MIN_LOG_LEVEL="3")
    proc = subprocess.run(
        [sys.executable, "-c", CHILD, name, json.dumps(params), cache or ""],
        capture_output=True,
        text=True,
        env=env,
        check=True,
    )
    line = [x for x in proc.stdout.splitlines() if x.startswith("RESULT ")][-1]
    return json.loads(line[len("RESULT ") :])


def cli(cache):
    env = dict(os.environ, TF_CPP_MIN_LOG_LEVEL="3", JAXIMPACT_CACHE_DIR=cache)
    cmd = [
        "jaximpact",
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
        "--json",
    ]
    start = time.perf_counter()
    subprocess.run(cmd, capture_output=True, env=env, check=True)
    return time.perf_counter() - start


def median_of(rows, key):
    values = [r[key] for r in rows]
    return statistics.median(values)


def run(args):
    from _common import load_average, machine

    import jaximpact as ji

    results = dict(machine=machine(), loads=[load_average()], rows=[], cli=[])
    if args.resume and os.path.exists(JSON_PATH):
        with open(JSON_PATH) as f:
            results = json.load(f)
        results["loads"].append(load_average())
    laws = args.laws or list(ji.LAW_NAMES)
    done = {r["law"] for r in results["rows"]}
    for name in laws:
        if name in done:
            continue
        params = PAPER.get(name, NOMINAL)
        cold, warm = [], []
        for _ in range(args.repeat):
            cache = tempfile.mkdtemp(prefix="jaximpact-cc-")
            try:
                cold.append(child(name, params, cache))
                warm.append(child(name, params, cache))
            finally:
                shutil.rmtree(cache, ignore_errors=True)
        row = dict(law=name, path=cold[0]["path"], load=load_average())
        for label, runs in (("cold", cold), ("warm", warm)):
            for key in (
                "import_s",
                "impact_first_s",
                "impact_second_s",
                "grad_first_s",
                "grad_second_s",
                "total_s",
                "cpu_import_s",
                "cpu_impact_first_s",
                "cpu_grad_first_s",
            ):
                row[f"{label}_{key}"] = median_of(runs, key)
        results["rows"].append(row)
        print(json.dumps(row), flush=True)
        with open(JSON_PATH, "w") as f:
            json.dump(results, f, indent=1)
    for _ in range(0 if results["cli"] else args.repeat):
        cache = tempfile.mkdtemp(prefix="jaximpact-cli-")
        try:
            results["cli"].append(dict(cold_s=cli(cache), warm_s=cli(cache), warm2_s=cli(cache)))
        finally:
            shutil.rmtree(cache, ignore_errors=True)
    results["loads"].append(load_average())
    with open(JSON_PATH, "w") as f:
        json.dump(results, f, indent=1)
    return results


def report(results):
    from _common import machine_markdown, table

    rows = results["rows"]

    def s(x):
        return f"{x:.1f}" if x >= 1 else f"{x:.2f}"

    lines = [
        "# Compile time",
        "",
        "Generated by `python benchmarks/compile_time.py` (data in `compile_time.json`). Each "
        "law in a fresh Python process (float64), seconds, median of the repeats: `import` = "
        "`import jax, jaximpact`; `impact 1st` = first `impact(law, m=1, v0=2.5)` with the "
        "defaults (trace + compile + run), `2nd` = the next call; `grad 1st` = first "
        "`jax.grad` of e with respect to the law's parameters. `cold`: JAX's persistent "
        "compilation cache on, empty; `warm`: a new process with the cache the cold run "
        "wrote. Wall-clock seconds on a loaded machine (see the load average) run well "
        "above the CPU seconds of the process, which are given too (all threads).",
        "",
        machine_markdown(results["machine"], results["loads"]),
        "",
        table(
            [
                "law",
                "path",
                "import",
                "impact 1st cold",
                "impact 1st warm",
                "impact 2nd",
                "grad 1st cold",
                "grad 1st warm",
                "grad 2nd",
                "process total cold / warm",
                "CPU s: impact 1st cold / warm",
                "CPU s: grad 1st cold / warm",
            ],
            [
                [
                    r["law"],
                    r["path"],
                    s(r["cold_import_s"]),
                    s(r["cold_impact_first_s"]),
                    s(r["warm_impact_first_s"]),
                    f"{r['warm_impact_second_s'] * 1e3:.2f} ms",
                    s(r["cold_grad_first_s"]),
                    s(r["warm_grad_first_s"]),
                    f"{r['warm_grad_second_s'] * 1e3:.1f} ms",
                    f"{s(r['cold_total_s'])} / {s(r['warm_total_s'])}",
                    f"{s(r['cold_cpu_impact_first_s'])} / {s(r['warm_cpu_impact_first_s'])}",
                    f"{s(r['cold_cpu_grad_first_s'])} / {s(r['warm_cpu_grad_first_s'])}",
                ]
                for r in rows
            ],
        ),
        "",
    ]
    if rows:
        cold = statistics.median(r["cold_impact_first_s"] for r in rows)
        warm = statistics.median(r["warm_impact_first_s"] for r in rows)
        gcold = statistics.median(r["cold_grad_first_s"] for r in rows)
        gwarm = statistics.median(r["warm_grad_first_s"] for r in rows)
        lines += [
            f"Median over laws: first `impact` {cold:.1f} s cold, {warm:.1f} s warm "
            f"({cold / warm:.1f}x); first `jax.grad` {gcold:.1f} s cold, {gwarm:.1f} s warm "
            f"({gcold / gwarm:.1f}x). A warm first call still pays for tracing (Python), "
            "which the cache does not store.",
            "",
        ]
    if results.get("cli"):
        c = results["cli"]
        lines += [
            "`jaximpact simulate --law hertz_rate --param c=2e6 b1=800 --v0 2.5 --mass 1 --json` (whole "
            "process, its own cache in `JAXIMPACT_CACHE_DIR`): "
            f"cold {statistics.median(x['cold_s'] for x in c):.1f} s, warm "
            f"{statistics.median(x['warm_s'] for x in c):.1f} s, warm again "
            f"{statistics.median(x['warm2_s'] for x in c):.1f} s.",
            "",
        ]
    with open(MD_PATH, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--laws", nargs="*")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--report", action="store_true")
    parser.add_argument("--resume", action="store_true")
    args = parser.parse_args()
    if args.report:
        with open(JSON_PATH) as f:
            results = json.load(f)
    else:
        results = run(args)
    report(results)


if __name__ == "__main__":
    main()
