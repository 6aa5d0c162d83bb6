#!/usr/bin/env bash
# Installs what is missing, builds everything and runs every test twice:
# a Release build (build/), then the same suite under AddressSanitizer +
# UndefinedBehaviorSanitizer (build-asan/); then a short libFuzzer run of every
# fuzz target (scripts/fuzz.sh, about a minute) and the concurrency tests under
# ThreadSanitizer (scripts/tsan.sh). Any failure fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs="${SWEETSPOT_JOBS:-$(nproc)}"

echo "== Release build and tests" >&2
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
ctest --test-dir build --output-on-failure -j"$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests" >&2
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" \
  -DSWEETSPOT_SANITIZE=ON -DSWEETSPOT_BUILD_BENCH=OFF -DSWEETSPOT_BUILD_WEB=OFF
cmake --build build-asan -j"$jobs"
# The load test runs 30 s in the Release pass; 5 s is enough to exercise it here.
SWEETSPOT_LOAD_SECONDS=5 \
ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1" \
UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
  ctest --test-dir build-asan --output-on-failure -j"$jobs"

echo "== libFuzzer: every target for a few seconds (scripts/fuzz.sh)" >&2
SWEETSPOT_JOBS="$jobs" scripts/fuzz.sh

echo "== ThreadSanitizer: the concurrency tests (scripts/tsan.sh)" >&2
SWEETSPOT_JOBS="$jobs" scripts/tsan.sh
