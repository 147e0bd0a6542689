"""Batches of impacts: throughput against batch size, scipy per impact, memory, cost ordering,
and the sharded run on 4 forced host devices. Prints the tables and writes benchmarks/batch.md.

Run: python benchmarks/batch.py [--quick] [--out benchmarks/batch.md]
(`--quick`: batch sizes up to 10 000 and smaller side experiments, for a smoke test.)

Every timing is the best of `--repeat` runs after a first call that compiles (reported apart,
as brax does), with `block_until_ready` implied by the copy back to numpy. The machine is a
shared 2-core VM: read the load average printed with the tables.
"""

import argparse
import functools
import json
import os
import platform
import subprocess
import sys
import time

os.environ.setdefault("TF_CPP_MIN_LOG_LEVEL", "3")

import jax  # noqa: E402

jax.config.update("jax_enable_x64", True)

import numpy as np  # noqa: E402

import jaximpact as ji  # noqa: E402
from jaximpact._batch import cost_key, impact_batch  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "tests"))
from reference import reference_impact  # noqa: E402

SIZES = (1, 10, 100, 1000, 10_000, 100_000)


def population(name, n, seed=0):
    """Parameters spread around the seed paper's sets (m = 1 kg, v0 from 1 to 5 m/s)."""
    rng = np.random.default_rng(seed)
    lu = lambda a, b: np.exp(rng.uniform(np.log(a), np.log(b), n))  # noqa: E731
    params = {
        "kelvin_voigt": lambda: dict(c=lu(2e6, 2e7), b=rng.uniform(200, 1000, n)),
        "hertz_rate": lambda: dict(c=lu(1e6, 1e7), b1=rng.uniform(200, 2000, n)),
        "maxwell": lambda: dict(c=lu(2e6, 2e7), b=rng.uniform(3000, 20000, n)),
        "bingham": lambda: dict(
            c=lu(2e6, 2e7), b=rng.uniform(100, 600, n), P=rng.uniform(100, 800, n)
        ),
        "hunt_crossley": lambda: dict(c=lu(1e6, 1e7), a=rng.uniform(0.02, 0.3, n)),
    }[name]()
    return params, np.ones(n), rng.uniform(1.0, 5.0, n)


def wide_population(name, n, seed=1):
    """Parameters over decades (a Monte Carlo over materials): step counts vary widely."""
    rng = np.random.default_rng(seed)
    lu = lambda a, b: np.exp(rng.uniform(np.log(a), np.log(b), n))  # noqa: E731
    damping = {"hertz_rate": ("b1", 1, 1e4), "maxwell": ("b", 1e3, 1e5), "bingham": ("b", 1, 1e4)}
    key, lo, hi = damping[name]
    params = {"c": lu(1e5, 1e8), key: lu(lo, hi)}
    if name == "bingham":
        params["P"] = lu(1, 1e3)
    return params, lu(0.1, 10), lu(0.1, 10)


CASES = [  # (label, law, method)
    ("kelvin_voigt (closed form)", "kelvin_voigt", "auto"),
    ("kelvin_voigt (integrated)", "kelvin_voigt", "integrate"),
    ("hertz_rate", "hertz_rate", "auto"),
    ("maxwell", "maxwell", "auto"),
    ("bingham", "bingham", "auto"),
    ("hunt_crossley", "hunt_crossley", "auto"),
]


def timed(fn, repeat):
    start = time.perf_counter()
    out = fn()
    first = time.perf_counter() - start
    runs = []
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        runs.append(time.perf_counter() - start)
    return first, min(runs), out


def throughput(sizes, repeat):
    rows = []
    for label, name, method in CASES:
        for n in sizes:
            params, m, v0 = population(name, n)
            call = functools.partial(
                impact_batch, name, params, m=m, v0=v0, method=method, progress=False
            )
            first, best, out = timed(call, repeat)
            ok = float(np.mean(out["status"] == ji.Status.separated))
            rows.append(dict(law=label, n=n, first_s=first, best_s=best, rate=n / best, ok=ok))
            print(
                f"{label:28s} n={n:>7d}  first {first:7.2f} s  best {best:8.4f} s  "
                f"{n / best:>10.0f} impacts/s  separated {ok:.3f}",
                flush=True,
            )
    return rows


def scipy_times(count):
    rows = []
    for _label, name, method in CASES:
        if method == "auto" and name == "kelvin_voigt":
            continue  # scipy integrates either way
        params, m, v0 = population(name, count, seed=3)
        start = time.perf_counter()
        for i in range(count):
            reference_impact(
                name, {k: v[i] for k, v in params.items()}, m=m[i], v0=v0[i], rtol=1e-10
            )
        per = (time.perf_counter() - start) / count
        rows.append(dict(law=name, per_impact_s=per))
        print(f"scipy DOP853 {name:14s} {1e3 * per:7.2f} ms per impact", flush=True)
    return rows


def cost_ordering(n, repeat):
    """The same wide batch run in the given order and sorted by the dimensionless groups."""
    rows = []
    for name in ("hertz_rate", "bingham", "maxwell"):
        params, m, v0 = wide_population(name, n)
        result = {}
        for order in ("given", "cost"):
            call = functools.partial(
                impact_batch,
                name,
                params,
                m=m,
                v0=v0,
                order=order,
                fields=("e", "T", "status", "num_steps"),
                progress=False,
            )
            first, best, out = timed(call, repeat)
            result[order] = (best, out)
        steps = result["given"][1]["num_steps"].astype(float)
        useful = {}
        for order in result:
            sequence = steps if order == "given" else np.sort(steps)  # approximate cost order
            if order == "cost":
                key = cost_key(("law", name), params, m, v0, np.zeros(n))
                sequence = steps[np.lexsort(key[::-1])]
            blocks = sequence[: len(sequence) // 1024 * 1024].reshape(-1, 1024)
            useful[order] = blocks.sum() / (blocks.max(axis=1).sum() * 1024)
        same = all(np.array_equal(result["given"][1][k], result["cost"][1][k]) for k in ("e", "T"))
        rows.append(
            dict(
                law=name,
                n=n,
                given_s=result["given"][0],
                cost_s=result["cost"][0],
                gain=result["given"][0] / result["cost"][0],
                useful_given=useful["given"],
                useful_cost=useful["cost"],
                steps_median=float(np.median(steps)),
                steps_max=float(steps.max()),
                identical=same,
            )
        )
        print(
            f"order {name:11s}: given {result['given'][0]:.2f} s, cost {result['cost'][0]:.2f} s "
            f"(x{rows[-1]['gain']:.2f}); useful step fraction {useful['given']:.2f} -> "
            f"{useful['cost']:.2f}; steps median {np.median(steps):.0f}, max {steps.max():.0f}; "
            f"identical results: {same}",
            flush=True,
        )
    return rows


_MEMORY_CHILD = r"""
import json, resource, sys, time
import jax, numpy as np
jax.config.update("jax_enable_x64", True)
import jaximpact as ji
from jaximpact._batch import impact_batch


def peak_rss_mib():  # the high-water mark of this process since the last reset (Linux)
    for line in open("/proc/self/status"):
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) / 1024


def reset_peak():  # Linux >= 4.0: "5" resets VmHWM to the current resident set
    with open("/proc/self/clear_refs", "w") as handle:
        handle.write("5")


n, mode = int(sys.argv[1]), sys.argv[2]
rng = np.random.default_rng(0)
params = dict(c=np.exp(rng.uniform(np.log(1e6), np.log(1e7), n)), b1=rng.uniform(200, 2000, n))
v0 = rng.uniform(1.0, 5.0, n)


def member(p, v):
    r = ji.impact(ji.law("hertz_rate", **p), m=1.0, v0=v)
    return dict(e=r.e, T=r.T, x_max=r.x_max, F_max=r.F_max, status=r.status)


if mode == "run_batch":  # compile on one block, then the whole batch in blocks of 1024
    run = lambda: impact_batch("hertz_rate", params, m=1.0, v0=v0, progress=False)
    impact_batch("hertz_rate", {k: v[:1024] for k, v in params.items()}, m=1.0, v0=v0[:1024],
                 progress=False)
else:  # the whole batch in one vmapped call, compiled ahead
    compiled = jax.jit(jax.vmap(member)).lower(params, v0).compile()
    run = lambda: jax.tree.map(np.asarray, compiled(params, v0))
before = peak_rss_mib()
reset_peak()
resident = peak_rss_mib()
start = time.perf_counter()
out = run()
seconds = time.perf_counter() - start
peak = peak_rss_mib()
print(json.dumps(dict(mode=mode, n=n, peak_mib=peak, resident_mib=resident, run_mib=peak - resident,
                      compile_peak_mib=before, seconds=seconds)))
"""


def memory(n):
    rows = []
    for mode in ("run_batch", "vmap"):
        proc = subprocess.run(
            [sys.executable, "-c", _MEMORY_CHILD, str(n), mode],
            capture_output=True,
            text=True,
            check=True,
        )
        row = json.loads(proc.stdout.strip().splitlines()[-1])
        rows.append(row)
        print(
            f"memory {mode:10s} n={n}: RSS before the run {row['resident_mib']:.0f} MiB, peak "
            f"during it {row['peak_mib']:.0f} MiB (+{row['run_mib']:.0f}); peak while "
            f"compiling {row['compile_peak_mib']:.0f} MiB; run {row['seconds']:.1f} s"
        )
    return rows


_SHARDED_CHILD = r"""
import json, sys, time
import jax, numpy as np
jax.config.update("jax_enable_x64", True)
from jaximpact._batch import impact_batch
n, repeat, spread = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
rng = np.random.default_rng(0)
lu = lambda a, b, k: np.exp(rng.uniform(np.log(a), np.log(b), k))
if spread == "paper":  # around the seed paper's set, m = 1 kg, v0 in 1-5 m/s
    params = dict(c=lu(1e6, 1e7, n), b1=rng.uniform(200, 2000, n))
    m, v0 = 1.0, rng.uniform(1.0, 5.0, n)
else:  # over decades: heavily damped members included
    params = dict(c=lu(1e5, 1e8, n), b1=lu(1, 1e4, n))
    m, v0 = lu(0.01, 10, n), lu(0.1, 10, n)
modes = (("1 device", dict(devices=1)), ("4 devices, exact", dict()),
         ("4 devices, SPMD", dict(exact=False)))
calls = {label: (lambda kw=kw: impact_batch("hertz_rate", params, m=m, v0=v0, progress=False, **kw))
         for label, kw in modes}
outs, first, runs = {}, {}, {label: [] for label, _ in modes}
for label, call in calls.items():
    start = time.perf_counter(); outs[label] = call(); first[label] = time.perf_counter() - start
for _ in range(repeat):  # interleaved, so that a change of load hits every mode alike
    for label, call in calls.items():
        start = time.perf_counter(); call(); runs[label].append(time.perf_counter() - start)
rows = [dict(mode=label, population=spread, n=n, devices=len(jax.local_devices()),
             first_s=first[label], best_s=min(runs[label]), rate=n / min(runs[label]))
        for label, _ in modes]
ref = outs["1 device"]
for row in rows:
    out = outs[row["mode"]]
    row["equal"] = all(np.array_equal(out[k], ref[k]) for k in ref)
    row["unequal_rows"] = int(np.sum(np.any([out[k] != ref[k] for k in ref], axis=0)))
    row["max_rel_diff"] = max(
        float(np.max(np.abs(out[k] - ref[k]) / np.maximum(np.abs(ref[k]), 1e-300)))
        for k in ("e", "T", "x_max", "F_max"))
print(json.dumps(rows))
"""


def sharded(sizes, repeat):
    env = dict(os.environ, XLA_FLAGS="--xla_force_host_platform_device_count=4")
    rows = []
    for spread, n in sizes.items():
        proc = subprocess.run(
            [sys.executable, "-c", _SHARDED_CHILD, str(n), str(repeat), spread],
            capture_output=True,
            text=True,
            env=env,
            check=True,
        )
        rows += json.loads(proc.stdout.strip().splitlines()[-1])
    for row in rows:
        print(
            f"sharded {row['population']:5s} n={row['n']} {row['mode']:18s}: first "
            f"{row['first_s']:.1f} s, best {row['best_s']:.3f} s, {row['rate']:.0f} impacts/s, "
            f"equal to 1 device: {row['equal']} ({row['unequal_rows']} rows differ, max rel "
            f"diff {row['max_rel_diff']:.1e})",
            flush=True,
        )
    return rows


def machine():
    lscpu = subprocess.run("lscpu | head -15", shell=True, capture_output=True, text=True).stdout
    return dict(
        lscpu=lscpu.rstrip(),
        python=platform.python_version(),
        jax=jax.__version__,
        numpy=np.__version__,
    )


def markdown(info, loads, tables, command):
    t, sp, order, mem, shard = (
        tables[k] for k in ("throughput", "scipy", "order", "memory", "sharded")
    )
    lines = [
        "# Batches of impacts: throughput, memory, cost ordering, devices",
        "",
        f"Produced by `{command}` (benchmarks/batch.py). Default options of `impact_batch`:",
        "`rtol=1e-10`, `peaks=True` (returns e, T, x_max, F_max, status), `chunk_size=1024` rows",
        'per device, `order="cost"`, `exact=True`. Times are the best of repeated runs after a',
        'first call that compiles ("first" includes the compilation of every block shape used).',
        "",
        "## Machine",
        "",
        "```",
        info["lscpu"],
        "```",
        "",
        f"Python {info['python']}, jax {info['jax']}, numpy {info['numpy']}. Load average "
        "(1, 5, 15 min) at the start and the end of each part: "
        + "; ".join(
            f"{part} {a[0]:.1f}, {a[1]:.1f}, {a[2]:.1f} -> {b[0]:.1f}, {b[1]:.1f}, {b[2]:.1f}"
            for part, (a, b) in loads.items()
        )
        + ". The VM's 2 cores are shared with other sessions: timings vary by up to 2x "
        "between runs.",
        "",
        "## Impacts per second against batch size",
        "",
        "m = 1 kg, v0 uniform in 1-5 m/s, parameters spread around the seed paper's sets "
        "(`population` in the script).",
        "",
    ]
    sizes = sorted({row["n"] for row in t})
    lines.append(
        "| law | " + " | ".join(f"n = {n:,}" for n in sizes) + " | first call at n = 1 (s) |"
    )
    lines.append("|---|" + "---:|" * (len(sizes) + 1))
    for label, *_ in CASES:
        cells = {row["n"]: row for row in t if row["law"] == label}
        lines.append(
            f"| {label} | "
            + " | ".join(f"{cells[n]['rate']:,.0f}" for n in sizes)
            + f" | {cells[sizes[0]]['first_s']:.1f} |"
        )
    lines += [
        "",
        "scipy `solve_ivp` (DOP853 with terminal events, rtol 1e-10, tests/reference.py: the same "
        "outputs, with F_max from the dense output), one impact at a time in the same run:",
        "",
        "| law | scipy ms per impact | scipy impacts/s | jaximpact, best over n (impacts/s) "
        "| ratio |",
        "|---|---:|---:|---|---:|",
    ]
    for row in sp:
        rate = 1 / row["per_impact_s"]
        for label, name, _ in CASES:
            if name != row["law"]:
                continue
            best = max(r["rate"] for r in t if r["law"] == label)
            lines.append(
                f"| {label} | {1e3 * row['per_impact_s']:.2f} | {rate:,.0f} | {best:,.0f} | "
                f"{best / rate:,.0f}x |"
            )
    lines += [
        "",
        f"## Memory for n = {mem[0]['n']:,} (hertz_rate, one fresh process per row)",
        "",
        "Resident set (RSS) of the process: before the run (after compiling, inputs in "
        "memory), its peak during the run (VmHWM reset through /proc/self/clear_refs just "
        "before), and the peak while compiling. XLA's compilation dominates the process's "
        "lifetime peak; the run itself adds what the table's last column says.",
        "",
        "| run | RSS before (MiB) | peak during the run (MiB) | added by the run (MiB) "
        "| peak while compiling (MiB) | run (s) |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    labels = {
        "run_batch": "`impact_batch` (blocks of 1024 rows)",
        "vmap": "one `jax.jit(jax.vmap(...))` over all rows",
    }
    for row in mem:
        lines.append(
            f"| {labels[row['mode']]} | {row['resident_mib']:.0f} | {row['peak_mib']:.0f} | "
            f"{row['run_mib']:.0f} | {row['compile_peak_mib']:.0f} | {row['seconds']:.1f} |"
        )
    lines += [
        "",
        "## Event termination under vmap, and ordering by cost",
        "",
        "A vmapped batch runs until its slowest member is done (shared/notes 4.4): a block of "
        "1024 rows costs 1024 x its largest step count. The rows below are wide populations "
        "(c from 1e5 to 1e8, damping over 3-4 decades, m and v0 from 0.1 to 10), run in the "
        'given (random) order and sorted by the dimensionless groups (`order="cost"`). '
        "'useful' is the fraction of the batch's step work that members needed "
        "(sum of steps / sum over blocks of 1024 x max steps).",
        "",
        "| law | n | given order (s) | cost order (s) | speed-up | useful, given | useful, cost "
        "| median / max steps | identical results |",
        "|---|---:|---:|---:|---:|---:|---:|---|---|",
    ]
    for row in order:
        lines.append(
            f"| {row['law']} | {row['n']:,} | {row['given_s']:.2f} | {row['cost_s']:.2f} | "
            f"{row['gain']:.2f}x | {row['useful_given']:.2f} | {row['useful_cost']:.2f} | "
            f"{row['steps_median']:.0f} / {row['steps_max']:.0f} | {row['identical']} |"
        )
    lines += [
        "",
        "## Sharded over 4 forced host devices (hertz_rate)",
        "",
        "One subprocess per population with `XLA_FLAGS=--xla_force_host_platform_device_count=4`"
        " on the same 2 cores; `1 device` is `devices=1` in that process. `exact` runs the "
        "one-device program on each device (compiled once per device); `SPMD` is one "
        "`jax.jit` with `NamedSharding` in and out (compiled once, devices in lockstep). "
        "Populations: `paper` as in the throughput table; `wide` over decades "
        "(c 1e5-1e8, b1 1-1e4, m 0.01-10 kg, v0 0.1-10 m/s).",
        "",
        "| population | n | run | first call (s) | best (s) | impacts/s "
        "| bitwise equal to 1 device "
        "| rows that differ | max rel. diff |",
        "|---|---:|---|---:|---:|---:|---|---:|---:|",
    ]
    for row in shard:
        lines.append(
            f"| {row['population']} | {row['n']:,} | {row['mode']} | {row['first_s']:.1f} | "
            f"{row['best_s']:.3f} | {row['rate']:,.0f} | {row['equal']} | {row['unequal_rows']} | "
            f"{row['max_rel_diff']:.1e} |"
        )
    lines += [
        "",
        "`exact` (the default of `impact_batch`) is what the issue asks for: every device "
        "runs the very program of the one-device run, so the results are bitwise equal. "
        "`SPMD` lets XLA compile one partitioned program, whose floating-point schedule may "
        "differ: a few rows of the wide population differ in the last digits (relative "
        "difference in the table). It is the faster choice on real multi-device machines "
        "when bitwise reproducibility is not needed.",
    ]
    return "\n".join(lines) + "\n"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--out", default=os.path.join(HERE, "batch.md"))
    parser.add_argument(
        "--parts",
        help="comma-separated subset of throughput,scipy,order,memory,sharded to run, merged "
        "into the tables saved beside --out (.json)",
    )
    parser.add_argument(
        "--markdown-only", action="store_true", help="rewrite the .md from the saved .json"
    )
    args = parser.parse_args()
    saved = os.path.splitext(args.out)[0] + ".json"
    command = "python benchmarks/batch.py" + (" --quick" if args.quick else "")
    sizes = SIZES[:-1] if args.quick else SIZES
    big = 10_000 if args.quick else 100_000
    parts = {
        "throughput": lambda: throughput(sizes, args.repeat),
        "scipy": lambda: scipy_times(10 if args.quick else 40),
        "order": lambda: cost_ordering(4096 if args.quick else 16384, args.repeat),
        "memory": lambda: memory(big),
        "sharded": lambda: sharded(
            {"paper": 8192, "wide": 4096} if args.quick else {"paper": 32768, "wide": 8192},
            args.repeat,
        ),
    }
    tables, loads = {}, {}
    if (args.parts or args.markdown_only) and os.path.exists(saved):
        with open(saved) as handle:
            data = json.load(handle)
        tables, loads = data["tables"], data["loads"]
    if not args.markdown_only:
        for part in list(parts) if args.parts is None else args.parts.split(","):
            start = os.getloadavg()
            tables[part] = parts[part]()
            loads[part] = [start, os.getloadavg()]
        with open(saved, "w") as handle:
            json.dump(
                dict(machine=machine(), loads=loads, tables=tables, command=command),
                handle,
                indent=1,
            )
    text = markdown(machine(), loads, tables, command)
    with open(args.out, "w") as handle:
        handle.write(text)
    print(text)


if __name__ == "__main__":
    main()
