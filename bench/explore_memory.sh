#!/usr/bin/env bash
# Peak memory (and wall time) of the whole `sweetspot explore` process for sweeps larger than a
# request (issue 17: "memory stays bounded"): the bat of bench/peer_sweep.json, 2 swept
# parameters, CSV with 2 columns, N designs (default 3,000,000) drawn by
#   sobol    the Sobol sequence (each design made from its index)
#   lhs      a Latin hypercube (its table drawn first: 8 bytes per design and parameter)
#   pareto   the Sobol sweep with a Pareto front over exit speed (max) and 6-in MOI (min)
# Prints "case designs wall_s peak_KiB" per case (GNU time's %e and %M).
#   bench/explore_memory.sh [BUILD_DIR] [DESIGNS]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
designs=${2:-3000000}
cli=$build/server/sweetspot
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 - "$here/peer_sweep.json" "$work" "$designs" <<'PY'
import json, sys
base = json.load(open(sys.argv[1]))
work, n = sys.argv[2], int(sys.argv[3])
base.update({"format": "csv", "samples": n, "seed": 7,
             "columns": ["parameters.three_segment.taper_start_m", "max_exit_speed.exit_speed_mps"]})
for name, sampling in (("sobol", "sobol"), ("lhs", "lhs")):
    json.dump(dict(base, sampling=sampling), open(f"{work}/{name}.json", "w"))
pareto = dict(base, sampling="sobol", outputs=["max_exit_speed", "properties"],
              pareto={"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                                     {"output": "properties.moi_six_inch_kg_m2", "sense": "min"}]})
json.dump(pareto, open(f"{work}/pareto.json", "w"))
PY
echo "case designs wall_s peak_KiB"
for c in sobol lhs pareto; do
  /usr/bin/time -f "%e %M" -o "$work/t" "$cli" explore "$work/$c.json" >/dev/null
  echo "$c $designs $(cat "$work/t")"
done
