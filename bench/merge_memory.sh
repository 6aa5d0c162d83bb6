#!/usr/bin/env bash
# Peak memory and wall time of `sweetspot explore-merge` (issue 38: a 10,000,000-design merge
# in at most 100 MB). A Sobol sweep of the bat of bench/peer_sweep.json, outputs max_exit_speed
# and properties, a Pareto front over exit speed (max) and 6-in MOI (min): ~870 bytes a row in
# NDJSON, ~280 in CSV. It is run as SHARDS shards (`explore --shard I/N`) into a folder under
# /tmp, merged with GNU time -v (its "Maximum resident set size"), the merged bytes compared
# with the unsharded sweep's (both hashed as they stream, with the summary's timing_s, a
# measured time, taken out of the NDJSON), and the folder deleted.
#   bench/merge_memory.sh [BUILD_DIR] [DESIGNS] [SHARDS] [FORMAT]    (FORMAT ndjson or csv)
# Prints "format designs shards shard_MB merge_wall merge_cpu_s merge_peak_KiB same_bytes"
# (shard_MB: du -m; merge_cpu_s: user + system, steadier than the wall time on a shared machine).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
designs=${2:-1000000}
shards=${3:-4}
format=${4:-ndjson}
cli=$build/server/sweetspot
work=$(mktemp -d /tmp/sweetspot-merge-XXXXXX)
trap 'rm -rf "$work"' EXIT
/usr/bin/python3 - "$here/peer_sweep.json" "$work/sweep.json" "$designs" "$format" <<'PY'
import json, sys
body = json.load(open(sys.argv[1]))
body.update({"format": sys.argv[4], "sampling": "sobol", "samples": int(sys.argv[3]), "seed": 7,
             "outputs": ["max_exit_speed", "properties"],
             "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                                       {"output": "properties.moi_six_inch_kg_m2", "sense": "min"}]}})
body["parameters"] = [{"path": "three_segment.taper_start_m", "min": 0.20, "max": 0.40},
                      {"path": "three_segment.taper_end_m", "min": 0.45, "max": 0.70}]
json.dump(body, open(sys.argv[2], "w"))
PY
# The summary's timing_s is a measurement (the merge's is the shards' sum): not compared.
untimed() { sed -E 's/"timing_s":[-0-9.e+]+/"timing_s":T/'; }
files=()
for ((i = 0; i < shards; ++i)); do
  files+=("$work/shard-$i.$format")
  "$cli" --progress=off explore --shard "$i/$shards" "$work/sweep.json" >"$work/shard-$i.$format"
done
shard_mb=$(du -cm "${files[@]}" | tail -1 | cut -f1)
merged=$( { /usr/bin/time -v -o "$work/time" "$cli" --progress=off explore-merge "${files[@]}"; } |
          untimed | sha256sum | cut -d' ' -f1)
whole=$("$cli" --progress=off explore "$work/sweep.json" | untimed | sha256sum | cut -d' ' -f1)
wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {print $2}' "$work/time")
peak=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$work/time")
cpu=$(awk -F': ' '/User time/ {u = $2} /System time/ {s = $2} END {printf "%.1f", u + s}' "$work/time")
same=$([ "$merged" = "$whole" ] && echo yes || echo NO)
echo "format designs shards shard_MB merge_wall merge_cpu_s merge_peak_KiB same_bytes"
echo "$format $designs $shards $shard_mb $wall $cpu $peak $same"
