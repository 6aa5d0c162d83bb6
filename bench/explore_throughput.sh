#!/usr/bin/env bash
# Sweep throughput of the whole `sweetspot explore` process (issue 17's targets), one run:
#   csv2     a 1000 x 1000 grid of three-segment bats (1,000,000 designs), outputs
#            max_exit_speed, "format": "csv" with 2 columns
#   ndjson   a 300 x 500 grid of the bat of bench/peer_sweep.json (150,000 designs), the default outputs
#            (properties + max_exit_speed), full NDJSON rows
#   ndjson1  the same grid, outputs max_exit_speed only (the issue's first table row)
# each with --explore-threads 1 and with one thread per core, best of 3 by CPU time
# (user + system); designs per CPU-second is the per-core rate. With BEFORE (another
# build's sweetspot CLI, e.g. of the commit before the sweep engine), the same cases run
# alternately with it (without --explore-threads, which it may not know) and the ratios
# are printed. The outputs of both are compared byte for byte.
#   bench/explore_throughput.sh [BUILD_DIR] [BEFORE_CLI]
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
before=${2:-}
cli=$build/server/sweetspot
py=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cores=$(nproc)
echo "machine: $cores cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start"

make_request() {  # $1 = name, $2 = counts "A B", $3 = outputs JSON, $4 = format, $5 = columns JSON or null
  "$py" - "$here/peer_sweep.json" "$work/$1.json" "$2" "$3" "$4" "$5" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
a, b = (int(x) for x in sys.argv[3].split())
r["parameters"][0]["count"] = a
r["parameters"][1]["count"] = b
r["outputs"] = json.loads(sys.argv[4])
r["format"] = sys.argv[5]
columns = json.loads(sys.argv[6])
if columns is not None:
    r["columns"] = columns
json.dump(r, open(sys.argv[2], "w"))
PY
}
make_request csv2 "1000 1000" '["max_exit_speed"]' csv \
  '["parameters.three_segment.taper_start_m", "max_exit_speed.exit_speed_mps"]'
make_request ndjson "300 500" '["properties", "max_exit_speed"]' ndjson null
make_request ndjson1 "300 500" '["max_exit_speed"]' ndjson null
declare -A designs=([csv2]=1000000 [ndjson]=150000 [ndjson1]=150000)

# best of 3: prints "wall cpu" (s) of the run with the least CPU; the output in $work/$2.out
best() {  # $1 = label, $2.. = command
  local label=$1; shift
  local best_cpu="" best_wall=""
  for i in 1 2 3; do
    if ! /usr/bin/time -f '%e %U %S' -o "$work/t" "$@" >"$work/$label.out" 2>/dev/null; then
      echo "failed"  # e.g. a before-build that does not know "format": "csv"
      return 0
    fi
    read -r wall user sys <"$work/t"
    cpu=$(echo "$user + $sys" | bc -l)
    if [ -z "$best_cpu" ] || (( $(echo "$cpu < $best_cpu" | bc -l) )); then
      best_cpu=$cpu best_wall=$wall
    fi
  done
  echo "$best_wall $best_cpu"
}

printf '%-8s %-16s %10s %10s %14s %14s\n' case run wall_s cpu_s "us/design cpu" "designs/s wall"
for c in csv2 ndjson ndjson1; do
  n=${designs[$c]}
  for t in 1 "$cores"; do
    read -r wall cpu < <(best "${c}_t$t" "$cli" --explore-threads "$t" explore "$work/$c.json")
    printf '%-8s %-16s %10s %10s %14.3f %14.0f\n' "$c" "threads $t" "$wall" "$cpu" \
      "$(echo "$cpu * 1000000 / $n" | bc -l)" "$(echo "$n / $wall" | bc -l)"
    eval "ours_${c}_$t=$cpu"
  done
  if [ -n "$before" ]; then
    read -r wall cpu < <(best "${c}_before" "$before" explore "$work/$c.json")
    if [ "$wall" = failed ]; then
      echo "$c      before: the request failed (a build before this format?)"
      before_failed=1
    fi
  fi
  if [ -n "$before" ] && [ -z "${before_failed:-}" ]; then
    printf '%-8s %-16s %10s %10s %14.3f %14.0f\n' "$c" "before" "$wall" "$cpu" \
      "$(echo "$cpu * 1000000 / $n" | bc -l)" "$(echo "$n / $wall" | bc -l)"
    ours=$(eval echo "\$ours_${c}_1")
    printf '%-8s before / ours (CPU, one thread) = %.1fx\n' "$c" "$(echo "$cpu / $ours" | bc -l)"
    if [ "$c" = csv2 ]; then
      cmp -s "$work/${c}_before.out" "$work/${c}_t1.out" && echo "$c: the same bytes as before" \
        || echo "$c: OUTPUT DIFFERS from before"
    else  # ndjson: the rows (the summary's timing differs)
      if cmp -s <(head -n -1 "$work/${c}_before.out") <(head -n -1 "$work/${c}_t1.out"); then
        echo "$c: the same rows as before"
      else
        echo "$c: ROWS DIFFER from before"
      fi
    fi
  fi
  before_failed=
  cmp -s <(head -n -1 "$work/${c}_t1.out") <(head -n -1 "$work/${c}_t$cores.out") \
    && echo "$c: threads 1 and $cores give the same rows" || echo "$c: ROWS DIFFER by threads"
done
