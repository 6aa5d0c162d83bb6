#!/usr/bin/env bash
# Issue 36's scaling table, regenerated: the n-knot design (bench/scipy_peers.py `design
# --knots n`: maximise the rigid-pivot exit speed over the radii of knots 1..n-2 of a solid ash
# bat, equal mass, balance point <= 0.60 m, diameter bounds, non-decreasing taper) at 16, 32, 64,
# 128 and 256 knots: the SciPy SLSQP peer (finite-difference gradients, best CPU time of R
# solves) against sweetspot in the same run (BM_OptimizeKnots: the default request, whose
# backend the optimiser chooses (DesignOptions::choose_backend; the cell names the one that ran),
# the same over the knot radii (DesignOptions::taper_steps false: the formulation before the
# taper's steps, core/optimize/tapered_nlp.hpp),
# Ipopt exact Hessian, Ipopt limited memory (both the lifted formulation here), NLopt SLSQP
# (refused above 32 variables); CPU time per solve), the ratios and the optima's relative
# differences from the best objective found at that size.
#   bench/optimize_scaling.sh [BUILD_DIR] [KNOTS...]   (default: build; 16 32 64 128 256)
# Needs Debian's python3-scipy for /usr/bin/python3. Never run by the service, ctest or CI.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
shift || true
knots=("$@")
[ ${#knots[@]} -gt 0 ] || knots=(16 32 64 128 256)
py=/usr/bin/python3
bench=$build/bench/sweetspot_bench_core
if ! "$py" -c 'import numpy, scipy' 2>/dev/null; then
  echo "optimize_scaling.sh: $py has no numpy/scipy: apt-get install python3-scipy" >&2
  exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start"
filter=""
for n in "${knots[@]}"; do
  repeat=5
  [ "$n" -ge 128 ] && repeat=2
  "$py" "$here/scipy_peers.py" design --knots "$n" --repeat "$repeat" >"$work/peer_$n.json"
  filter="$filter${filter:+|}knots:$n/"
done
"$bench" --benchmark_filter="BM_OptimizeKnots/($filter)" --benchmark_min_time=0.2 \
  --benchmark_format=json >"$work/bench.json" 2>/dev/null
echo "machine: load average $(cut -d' ' -f1-3 /proc/loadavg) at the end"
"$py" - "$work" "${knots[@]}" <<'PY'
import json, sys
work, knots = sys.argv[1], [int(k) for k in sys.argv[2:]]
bench = {b["name"]: b for b in json.load(open(f"{work}/bench.json"))["benchmarks"]}
names = {3: "default request", 4: "default request over the radii", 0: "Ipopt exact",
         1: "Ipopt limited memory", 2: "NLopt SLSQP"}
print("| knots | SciPy SLSQP (CPU) | " + " | ".join(f"{names[b]} (CPU, ratio)" for b in names) + " |")
print("|---|---|" + "---|" * len(names))
for n in knots:
    peer = json.load(open(f"{work}/peer_{n}.json"))
    runs = {b: bench.get(f"BM_OptimizeKnots/knots:{n}/backend:{b}") for b in names}
    best = max([peer["objective_mps"]] + [r["objective_mps"] for r in runs.values() if r and not r["refused"]])
    def rel(v):
        return abs(v - best) / best
    cells = []
    for b, r in runs.items():
        if r is None:
            cells.append("—")
        elif r["refused"]:
            cells.append("refused: " + r.get("label", ""))
        else:
            ms = r["cpu_time"] if r["time_unit"] == "ms" else r["cpu_time"] / 1e6
            ok = "converged" if r["converged"] else "not converged"
            ran = f" ({r.get('label', '')})" if b in (3, 4) else ""
            cells.append(f"{ms:.2f} ms{ran}, {peer['cpu_s'] * 1e3 / ms:.1f}x, {r['objective_mps']:.6f} m/s"
                         f" (rel. {rel(r['objective_mps']):.1e}), {ok}")
    print(f"| {n} | {peer['cpu_s'] * 1e3:.1f} ms, {peer['objective_mps']:.6f} m/s "
          f"(rel. {rel(peer['objective_mps']):.1e}), success {peer['success']} | " + " | ".join(cells) + " |")
PY
