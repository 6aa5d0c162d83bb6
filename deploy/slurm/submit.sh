#!/bin/bash
# Submits a sharded /v1/explore sweep to Slurm: an array of N shard tasks, then
# the merge, which runs once every task succeeded and is cancelled by Slurm
# (--kill-on-invalid-dep=yes) as soon as one failed. Prints the two job ids
# ("-" for no array); the result is OUT_DIR/sweep.ndjson, each task's log
# OUT_DIR/slurm-*.out. N is typed here only: it is passed to every task and to
# the merge as an argument.
#
#   deploy/slurm/submit.sh [--only-missing] REQUEST.json OUT_DIR N [extra sbatch options...]
#
# --only-missing: submit only the shards whose OUT_DIR/shard-i.ndjson does not
# exist (after a failure: the failed shards alone), then the merge.
# The request is a /v1/explore body (its shard and format are set per task).
# SWEETSPOT_CLI (exported to the jobs) names the sweetspot executable. Extra
# sbatch options go to both jobs and override the scripts' --mem and --time.
set -euo pipefail
only_missing=0
if [ "${1:-}" = "--only-missing" ]; then
  only_missing=1
  shift
fi
if [ $# -lt 3 ]; then
  echo "usage: deploy/slurm/submit.sh [--only-missing] REQUEST.json OUT_DIR N [sbatch options...]" >&2
  exit 2
fi
here="$(cd "$(dirname "$0")" && pwd)"
request="$(realpath "$1")"
mkdir -p "$2"
out="$(realpath "$2")"
count="$3"
shift 3
case "$count" in '' | *[!0-9]* | 0) echo "submit.sh: N = '$count': not a positive integer" >&2; exit 2 ;; esac
tasks="0-$((count - 1))"
if [ "$only_missing" = 1 ]; then
  tasks=""
  for ((i = 0; i < count; i++)); do
    [ -f "$out/shard-$i.ndjson" ] || tasks="${tasks:+$tasks,}$i"
  done
fi
array="-"
dependency=()
if [ -n "$tasks" ]; then
  array=$(sbatch --parsable --array="$tasks" --chdir="$out" \
    --output="$out/slurm-%A_%a.out" --export=ALL "$@" "$here/explore.sbatch" "$request" "$out" "$count")
  array="${array%%;*}"
  dependency=(--dependency="afterok:$array" --kill-on-invalid-dep=yes)
fi
merge=$(sbatch --parsable "${dependency[@]}" --chdir="$out" \
  --output="$out/slurm-%j-merge.out" --export=ALL "$@" "$here/explore-merge.sbatch" "$out" "$count")
echo "$array ${merge%%;*}"
