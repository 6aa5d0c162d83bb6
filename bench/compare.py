#!/usr/bin/env python3
"""Compares two builds' benchmarks, alternating them so that both see the same machine.

    bench/compare.py BASE_BENCH_DIR HEAD_BENCH_DIR [ROUNDS]

Each benchmark of sweetspot_bench_core and sweetspot_bench_api runs ROUNDS times (default 3)
in each build, base then head, one benchmark at a time (--benchmark_min_time=0.1); each
build keeps its minimum CPU time. Prints a Markdown table (benchmark, base, head, head/base)
and the median and geometric mean of the ratios (docs/benchmarks.md, issue 16).
"""
import json
import statistics
import subprocess
import sys

UNIT_NS = {"ns": 1.0, "us": 1e3, "ms": 1e6, "s": 1e9}


def run(bench_dir, program, name):
    """CPU time in ns of benchmark `name` (exact match) of one program, or None."""
    out = subprocess.run([f"{bench_dir}/{program}", f"--benchmark_filter=^{name}$",
                          "--benchmark_min_time=0.1", "--benchmark_format=json"],
                         capture_output=True, text=True, check=False).stdout
    try:
        runs = json.loads(out)["benchmarks"]
    except (ValueError, KeyError):
        return None
    times = [b["cpu_time"] * UNIT_NS[b["time_unit"]] for b in runs if not b.get("error_occurred")]
    return min(times) if times else None


def show(ns):
    if ns >= 1e6:
        return f"{ns / 1e6:.3g} ms"
    return f"{ns / 1e3:.3g} µs" if ns >= 1e3 else f"{ns:.3g} ns"


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    base, head = sys.argv[1], sys.argv[2]
    rounds = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    rows = []
    for program in ("sweetspot_bench_core", "sweetspot_bench_api"):
        names = subprocess.run([f"{head}/{program}", "--benchmark_list_tests"], capture_output=True,
                               text=True, check=True).stdout.split()
        for name in names:
            best = {"base": None, "head": None}
            for _ in range(rounds):
                for key, bench_dir in (("base", base), ("head", head)):
                    t = run(bench_dir, program, name)
                    if t is not None and (best[key] is None or t < best[key]):
                        best[key] = t
            if best["base"] and best["head"]:
                rows.append((name, best["base"], best["head"], best["head"] / best["base"]))
    print("| benchmark | base | head | ratio |\n|---|---|---|---|")
    for name, b, h, r in rows:
        print(f"| `{name}` | {show(b)} | {show(h)} | {r:.2f} |")
    ratios = [r[3] for r in rows]
    print(f"\n{len(rows)} benchmarks: median ratio {statistics.median(ratios):.3f}, "
          f"geometric mean {statistics.geometric_mean(ratios):.3f}")


if __name__ == "__main__":
    main()
