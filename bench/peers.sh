#!/usr/bin/env bash
# SciPy peers against sweetspot (issue 17), one run, ratios printed:
#   1. the 16-knot design: scipy.optimize.minimize SLSQP with finite differences against
#      BM_OptimizeSixteenKnots (Ipopt, limited-memory and exact Hessian) and the optimum of
#      `sweetspot optimize` on the same problem;
#   2. the per-design sweep: numpy mass properties + a bounded scalar search per design against
#      the whole `sweetspot explore` process over the 100 x 200 grid of bench/peer_sweep.json
#      (outputs max_exit_speed, then properties + max_exit_speed), answers compared to 1e-9.
#   bench/peers.sh [BUILD_DIR]          (default: build; needs its bench/ and server/ programs)
# Needs Debian's python3-scipy (`apt-get install python3-scipy`) for /usr/bin/python3. Never
# run by the service, ctest or CI.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
py=/usr/bin/python3
cli=$build/server/sweetspot
bench=$build/bench/sweetspot_bench_core
if ! "$py" -c 'import numpy, scipy' 2>/dev/null; then
  echo "peers.sh: $py has no numpy/scipy: apt-get install python3-scipy" >&2
  exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start"

# 1. The 16-knot design.
"$py" "$here/scipy_peers.py" design16 --repeat 5 >"$work/design16.json"
"$py" -c 'import json,sys; print(json.dumps(json.load(open(sys.argv[1]))["request"]))' \
  "$work/design16.json" >"$work/optimize.json"
for h in limited_memory exact; do
  "$py" -c 'import json,sys; r=json.load(open(sys.argv[1])); r["options"]={"hessian": sys.argv[2], "model": "rigid_pivot"}; print(json.dumps(r))' \
    "$work/optimize.json" "$h" >"$work/optimize_$h.json"
  "$cli" optimize "$work/optimize_$h.json" >"$work/ours_$h.json"
done
"$bench" --benchmark_filter='BM_OptimizeSixteenKnots' --benchmark_min_time=0.5 \
  --benchmark_format=json >"$work/bench.json" 2>/dev/null

# 2. The sweep: the whole CLI process, best of 3 (CPU = user + system), per outputs.
sweep_ours() {  # $1 = outputs JSON array, $2 = name
  "$py" -c 'import json,sys; r=json.load(open(sys.argv[1])); r["outputs"]=json.loads(sys.argv[2]); print(json.dumps(r))' \
    "$here/peer_sweep.json" "$1" >"$work/sweep_$2.json"
  for i in 1 2 3; do
    /usr/bin/time -f '%e %U %S' -o "$work/time_$2_$i" "$cli" explore "$work/sweep_$2.json" \
      >"$work/rows_$2.ndjson"
  done
  cat "$work"/time_"$2"_* >"$work/times_$2"
}
sweep_ours '["max_exit_speed"]' mes
sweep_ours '["properties", "max_exit_speed"]' props
for v in bounded root; do
  "$py" "$here/scipy_peers.py" sweep "$here/peer_sweep.json" "$work/rows_mes.ndjson" \
    --variant "$v" >"$work/peer_$v.json"
done

"$py" - "$work" <<'PY'
import json, sys
w = sys.argv[1]
load = lambda name: json.load(open(f"{w}/{name}"))
d = load("design16.json")
bench = {b["name"]: b for b in load("bench.json")["benchmarks"]}
print("\n16-knot design")
print(f"  SciPy SLSQP (finite differences): {d['time_s']*1e3:.1f} ms wall, {d['cpu_s']*1e3:.1f} ms CPU "
      f"(best of {d['repeat']}), {d['iterations']} iterations, {d['function_evaluations']} "
      f"evaluations, success {d['success']} ({d['message']}), objective {d['objective_mps']!r} m/s")
for name, h in (("BM_OptimizeSixteenKnots/exact:0", "limited_memory"),
                ("BM_OptimizeSixteenKnots/exact:1", "exact")):
    b = bench[name]
    cpu_ms = b["cpu_time"] if b["time_unit"] == "ms" else b["cpu_time"] / 1e6
    real_ms = b["real_time"] if b["time_unit"] == "ms" else b["real_time"] / 1e6
    ours = load(f"ours_{h}.json")
    radii = [k["radius_m"] for k in ours["bat"]["profile"]["knots"]]
    dr = max(abs(a - b) for a, b in zip(radii, d["radii_m"]))
    dobj = abs(ours["objective_value"] - d["objective_mps"])
    print(f"  Ipopt {h}: {cpu_ms:.2f} ms CPU ({real_ms:.2f} ms wall); SciPy/ours = "
          f"{d['cpu_s']*1e3/cpu_ms:.1f}x (CPU), {d['time_s']*1e3/real_ms:.1f}x (wall); "
          f"objective {ours['objective_value']!r} m/s (|diff| {dobj:.1e}), "
          f"radii |diff| max {dr:.1e} m, {ours['summary']['termination']}")
print("\nSweep: 100 x 200 three-segment designs (bench/peer_sweep.json)")
peers = {v: load(f"peer_{v}.json") for v in ("bounded", "root")}
for v, p in peers.items():
    print(f"  SciPy ({p['peer']}): {p['us_per_design']:.1f} us wall, {p['cpu_us_per_design']:.1f} us "
          f"CPU per design over {p['designs']} designs; |diff| max: exit speed "
          f"{p['max_abs_diff_exit_speed_mps']:.1e} m/s, position {p['max_abs_diff_position_m']:.1e} m")
for key, label in (("mes", "max_exit_speed"), ("props", "properties + max_exit_speed")):
    rows = [list(map(float, line.split())) for line in open(f"{w}/times_{key}")]
    wall = min(r[0] for r in rows)
    cpu = min(r[1] + r[2] for r in rows)
    n = 20000
    print(f"  sweetspot explore ({label}, ndjson, whole process, best of 3): "
          f"{wall/n*1e6:.2f} us wall, {cpu/n*1e6:.2f} us CPU per design; "
          f"SciPy bounded / ours = {peers['bounded']['cpu_us_per_design']/(cpu/n*1e6):.1f}x (CPU), "
          f"{peers['bounded']['us_per_design']/(wall/n*1e6):.1f}x (wall)")
PY
echo "load average $(cut -d' ' -f1-3 /proc/loadavg) at the end"
