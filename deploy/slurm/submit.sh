#!/bin/bash
# Submits a sharded /v1/explore sweep to Slurm: an array of N shard tasks, then
# the merge, which runs once every task succeeded. Prints the two job ids; the
# result is OUT_DIR/sweep.ndjson, each task's log OUT_DIR/slurm-*.out.
#
#   deploy/slurm/submit.sh REQUEST.json OUT_DIR N [extra sbatch options...]
#
# The request is a /v1/explore body (its shard and format are set per task).
# SWEETSPOT_CLI (exported to the jobs) names the sweetspot executable.
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: deploy/slurm/submit.sh REQUEST.json OUT_DIR N [sbatch options...]" >&2
  exit 2
fi
here="$(cd "$(dirname "$0")" && pwd)"
request="$(realpath "$1")"
mkdir -p "$2"
out="$(realpath "$2")"
count="$3"
shift 3
array=$(sbatch --parsable --array="0-$((count - 1))" --chdir="$out" \
  --output="$out/slurm-%A_%a.out" --export=ALL "$@" "$here/explore.sbatch" "$request" "$out")
array="${array%%;*}"
merge=$(sbatch --parsable --dependency="afterok:$array" --chdir="$out" \
  --output="$out/slurm-%j-merge.out" --export=ALL "$@" "$here/explore-merge.sbatch" "$out" "$count")
echo "$array ${merge%%;*}"
