#!/usr/bin/env bash
# The SciPy peer of one batted-ball flight (issue 34), side by side with sweetspot:
#   1. Nathan's sheet: the peer runs the sheet's own 0.01 s scheme on its two worked cases and
#      prints the sheet's distances (421.486 and 400.550 ft): the model both programs write is
#      the sheet's;
#   2. one flight (100 mph, 28 deg, the Statcast spin relation, 70 F, sea level, calm):
#      `sweetspot flight` at the default tolerance and at 1e-12, the peer (solve_ivp RK45 with a
#      terminal event) at the same tolerances, and the CPU time per flight of each
#      (BM_FlightNathan/5 = the default; the peer's best time.process_time() of 200 flights):
#      the answers and the ratio;
#   3. the same flight as a batch: sweetspot's FlyMany (BM_FlyManyNathan, 1024 flights side by
#      side) against the peer's loop of 200 flights (best of 3 loops), CPU time per flight, and
#      against the peer's best single flight of step 2 (the stricter ratio: issue 34's target).
#   bench/flight_peer.sh [BUILD_DIR]   (default: build; needs bench/ and server/ programs)
# Needs Debian's python3-scipy for /usr/bin/python3. Never run by the service, ctest or CI.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
py=/usr/bin/python3
cli=$build/server/sweetspot
bench=$build/bench/sweetspot_bench_core
if ! "$py" -c 'import numpy, scipy' 2>/dev/null; then
  echo "flight_peer.sh: $py has no numpy/scipy: apt-get install python3-scipy" >&2
  exit 2
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "1. Nathan's sheet, its own scheme (peer):"
"$py" "$here/scipy_flight_peer.py" sheet
launch='"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}'
echo "{$launch}" >"$work/default.json"
echo "{$launch, \"options\": {\"relative_tolerance\": 1e-12, \"absolute_tolerance_m\": 1e-12}}" \
  >"$work/tight.json"
"$cli" flight "$work/default.json" >"$work/ours.json"
"$cli" flight "$work/tight.json" >"$work/ours_tight.json"
"$py" "$here/scipy_flight_peer.py" flight --rtol 1e-5 --atol 1e-3 --repeat 200 --batch 200 \
  >"$work/peer.json"
"$bench" --benchmark_filter='BM_FlightNathan/5$|BM_FlyManyNathan' --benchmark_min_time=0.5 \
  --benchmark_format=json >"$work/bench.json" 2>/dev/null
"$py" - "$work" <<'PY'
import json, sys
w = sys.argv[1]
ours, tight, peer = (json.load(open(f"{w}/{n}.json")) for n in ("ours", "ours_tight", "peer"))
benches = {b["name"]: b for b in json.load(open(f"{w}/bench.json"))["benchmarks"]}
bench = benches["BM_FlightNathan/5"]
many = benches["BM_FlyManyNathan"]
ft = 0.3048
cpu_ours = bench["cpu_time"] * {"ns": 1e-9, "us": 1e-6, "ms": 1e-3}[bench["time_unit"]]
print("2. one flight, 100 mph at 28 deg, Statcast spin relation:")
print(f"   sweetspot  default: {ours['distance_m']/ft:.4f} ft, {ours['hang_time_s']:.5f} s; "
      f"1e-12: {tight['distance_m']/ft:.6f} ft, {tight['hang_time_s']:.6f} s")
print(f"   SciPy peer 1e-5:    {peer['distance_ft']:.4f} ft, {peer['hang_time_s']:.5f} s; "
      f"1e-12: {peer['reference_distance_m']/ft:.6f} ft, {peer['reference_hang_time_s']:.6f} s")
print(f"   converged answers differ by {abs(tight['distance_m']-peer['reference_distance_m'])/ft:.2e} ft")
print(f"   CPU per flight: sweetspot {cpu_ours*1e6:.2f} us (error {bench['err_ft']:.1e} ft), "
      f"peer {peer['cpu_s_per_flight']*1e6:.0f} us (error {peer['err_ft']:.1e} ft): "
      f"ratio {peer['cpu_s_per_flight']/cpu_ours:.0f}x")
many_us = many["us_per_flight"]
print(f"3. the same flight as a batch (sweetspot: 1024 through FlyMany; peer: {peer['batch']} in "
      f"one loop): sweetspot {many_us:.3f} us per flight (error {many['err_ft']:.1e} ft), peer "
      f"{peer['batch_cpu_s_per_flight']*1e6:.0f} us per flight: "
      f"ratio {peer['batch_cpu_s_per_flight']*1e6/many_us:.0f}x; against the peer's best single "
      f"flight ({peer['cpu_s_per_flight']*1e6:.0f} us): "
      f"ratio {peer['cpu_s_per_flight']*1e6/many_us:.0f}x")
PY
