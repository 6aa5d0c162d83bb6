#!/usr/bin/env bash
# A 1,000,000-launch flight sweep in CSV (issue 34): `sweetspot explore` with a "flight"
# template (api/explore/flight_sweep.hpp), a grid of exit speed (60-120 mph) x launch angle
# (-10 to 60 deg) x wind (0-20 mph out), nathan-2016 with the Statcast spin relation, streamed
# to a pipe that counts its bytes and lines (nothing kept), under GNU time -v (its "Maximum
# resident set size"), on THREADS threads (default: every CPU the process may use) and on one.
#   bench/flight_sweep.sh [BUILD_DIR] [SPEEDS] [ANGLES] [WINDS] [THREADS]
#   (defaults 100 x 100 x 100 = 1,000,000 launches)
# Prints per run: threads, launches, rows written, bytes, wall s, CPU s (user + system), peak KiB,
# launches per wall second and per CPU second.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
speeds=${2:-100}
angles=${3:-100}
winds=${4:-100}
threads=${5:-$(nproc)}
cli=$build/server/sweetspot
work=$(mktemp -d /tmp/sweetspot-flight-sweep-XXXXXX)
trap 'rm -rf "$work"' EXIT
cat >"$work/sweep.json" <<EOF
{"flight": {"launch": {"exit_speed_mph": 100, "launch_angle_deg": 28}},
 "parameters": [{"path": "launch.exit_speed_mph", "min": 60, "max": 120, "count": $speeds},
                {"path": "launch.launch_angle_deg", "min": -10, "max": 60, "count": $angles},
                {"path": "environment.wind.speed_mph", "min": 0, "max": 20, "count": $winds}],
 "format": "csv"}
EOF
echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo "threads launches rows bytes wall_s cpu_s peak_KiB launches_per_wall_s launches_per_cpu_s"
for t in "$threads" 1; do
  counts=$( { /usr/bin/time -v -o "$work/time" "$cli" --progress=off explore \
                --explore-threads "$t" "$work/sweep.json"; } | wc -lc)
  lines=$(echo "$counts" | awk '{print $1}')
  bytes=$(echo "$counts" | awk '{print $2}')
  wall=$(awk -F': ' '/Elapsed \(wall clock\)/ {n = split($2, p, ":"); s = 0;
                     for (i = 1; i <= n; ++i) s = s * 60 + p[i]; print s}' "$work/time")
  cpu=$(awk -F': ' '/User time/ {u = $2} /System time/ {s = $2} END {print u + s}' "$work/time")
  peak=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$work/time")
  launches=$((speeds * angles * winds))
  awk -v t="$t" -v n="$launches" -v r="$((lines - 1))" -v b="$bytes" -v w="$wall" -v c="$cpu" \
      -v p="$peak" 'BEGIN {printf "%d %d %d %d %.2f %.2f %d %.0f %.0f\n", t, n, r, b, w, c, p,
                           n / w, n / c}'
done
