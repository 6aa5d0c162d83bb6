#!/usr/bin/env bash
# The speed-versus-error report: installs what is missing, builds the Release program
# sweetspot-speed-vs-error (bench/speed_vs_error.cpp) and runs it, writing
# docs/speed-vs-error.md (tables, how to choose), docs/speed-vs-error.svg (the plot) and
# docs/speed-vs-error.json (the data, also served at GET /v1/speed-vs-error after a rebuild).
# Takes about 15-30 s to run after the build.
#
#   scripts/speed-vs-error.sh [--build-dir DIR] [--out-dir DIR] [--quick]
#
# --build-dir (or SWEETSPOT_BUILD_DIR): the CMake build directory, default build/.
# --out-dir: where the three files go, default docs/. --quick: a short smoke run.
# SWEETSPOT_JOBS: parallel build jobs (default: nproc).
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir="${SWEETSPOT_BUILD_DIR:-build}"
out_dir="docs"
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --build-dir) build_dir="$2"; shift 2 ;;
    --out-dir) out_dir="$2"; shift 2 ;;
    --quick) extra+=(--quick); shift ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "unknown argument: $1 (see --help)" >&2; exit 2 ;;
  esac
done
scripts/install-deps.sh
jobs="${SWEETSPOT_JOBS:-$(nproc)}"
cmake -S . -B "$build_dir" -DCMAKE_BUILD_TYPE=Release -DSWEETSPOT_BUILD_BENCH=ON
cmake --build "$build_dir" -j"$jobs" --target sweetspot-speed-vs-error
mkdir -p "$out_dir"
"$build_dir/bench/sweetspot-speed-vs-error" --out-dir "$out_dir" \
  --command "scripts/speed-vs-error.sh" "${extra[@]}"
