#!/usr/bin/env bash
# SciPy peers against sweetspot (issue 17), one run, ratios printed:
#   1. the 16-knot design: scipy.optimize.minimize SLSQP with finite differences against
#      BM_OptimizeSixteenKnots (Ipopt, limited-memory and exact Hessian) and the optimum of
#      `sweetspot optimize` on the same problem;
#   2. the per-design sweep: numpy mass properties + a bounded scalar search per design against
#      the whole `sweetspot explore` process over grids of bench/peer_sweep.json's bat (NDJSON
#      with max_exit_speed, then properties + max_exit_speed; the 2-column CSV on one thread and
#      on one per core), answers compared to 1e-9 on the peer's 100 x 200 grid.
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

# 2. The sweep: the whole CLI process, best of 3 (CPU = user + system), per outputs. The rows
# the peer is compared with come from the peer's own 100 x 200 grid; the times from a larger
# grid of the same bat (/usr/bin/time's 10 ms resolution is 0.5 us per design over 20,000):
# NDJSON over 300 x 500 (150,000 designs) and the 2-column CSV over 1000 x 1000 (1,000,000),
# on one thread (CPU per design) and on --explore-threads' default, one per core (wall).
sweep_request() {  # $1 = outputs JSON array, $2 = "A B" counts, $3 = format, $4 = columns JSON or null, $5 = file
  "$py" - "$here/peer_sweep.json" "$1" "$2" "$3" "$4" >"$5" <<'PYREQ'
import json, sys
r = json.load(open(sys.argv[1]))
r["outputs"] = json.loads(sys.argv[2])
a, b = (int(x) for x in sys.argv[3].split())
r["parameters"][0]["count"], r["parameters"][1]["count"] = a, b
r["format"] = sys.argv[4]
if json.loads(sys.argv[5]) is not None:
    r["columns"] = json.loads(sys.argv[5])
print(json.dumps(r))
PYREQ
}
sweep_ours() {  # $1 = request, $2 = name, $3.. = extra CLI flags
  local request=$1 name=$2
  shift 2
  for i in 1 2 3; do
    /usr/bin/time -f '%e %U %S' -o "$work/time_${name}_$i" "$cli" "$@" explore "$request" \
      >"$work/out_$name"
  done
  cat "$work"/time_"$name"_* >"$work/times_$name"
}
sweep_request '["max_exit_speed"]' "100 200" ndjson null "$work/sweep_rows.json"
"$cli" explore "$work/sweep_rows.json" >"$work/rows_mes.ndjson"
sweep_request '["max_exit_speed"]' "300 500" ndjson null "$work/sweep_mes.json"
sweep_request '["properties", "max_exit_speed"]' "300 500" ndjson null "$work/sweep_props.json"
sweep_request '["max_exit_speed"]' "1000 1000" csv \
  '["parameters.three_segment.taper_start_m", "max_exit_speed.exit_speed_mps"]' "$work/sweep_csv.json"
sweep_ours "$work/sweep_mes.json" mes
sweep_ours "$work/sweep_props.json" props
sweep_ours "$work/sweep_csv.json" csv1 --explore-threads 1
sweep_ours "$work/sweep_csv.json" csv
for v in bounded root; do
  "$py" "$here/scipy_peers.py" sweep "$here/peer_sweep.json" "$work/rows_mes.ndjson" \
    --variant "$v" >"$work/peer_$v.json"
done

"$py" - "$work" <<'PY'
import json, os, sys
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
for key, label, n in (("mes", "max_exit_speed, ndjson, 300 x 500", 150000),
                      ("props", "properties + max_exit_speed, ndjson, 300 x 500", 150000),
                      ("csv1", "csv, 2 columns, 1000 x 1000, one thread", 1000000),
                      ("csv", f"csv, 2 columns, 1000 x 1000, {os.cpu_count()} threads", 1000000)):
    rows = [list(map(float, line.split())) for line in open(f"{w}/times_{key}")]
    wall = min(r[0] for r in rows)
    cpu = min(r[1] + r[2] for r in rows)
    print(f"  sweetspot explore ({label}, whole process, best of 3): "
          f"{wall/n*1e6:.2f} us wall, {cpu/n*1e6:.2f} us CPU per design; "
          f"SciPy bounded / ours = {peers['bounded']['cpu_us_per_design']/(cpu/n*1e6):.1f}x (CPU), "
          f"{peers['bounded']['us_per_design']/(wall/n*1e6):.1f}x (wall)")
PY
echo "load average $(cut -d' ' -f1-3 /proc/loadavg) at the end"
