#!/usr/bin/env bash
# Installs what is missing, builds everything and runs every test twice:
# a Release build (build/), then the same suite under AddressSanitizer +
# UndefinedBehaviorSanitizer (build-asan/); then a short libFuzzer run of every
# fuzz target (scripts/fuzz.sh, about a minute) and the concurrency tests under
# ThreadSanitizer (scripts/tsan.sh). Any failure fails the script.
#
# Each stage prints its wall time, and a table of them closes the run. New build
# trees use Ninja; every compilation goes through ccache (cmake/BuildSpeed.cmake).
#   SWEETSPOT_JOBS=N   build and test parallelism (default: nproc)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/stages.sh

stage "install-deps" scripts/install-deps.sh
jobs="${SWEETSPOT_JOBS:-$(nproc)}"

echo "== Release build and tests" >&2
stage "release: configure" cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
stage "release: build" cmake --build build -j"$jobs"
stage "release: ctest" ctest --test-dir build --output-on-failure -j"$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests" >&2
# Only what ctest runs: no benchmarks, no explorer bundle (its browser test runs in Release).
stage "asan: configure" cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=Debug \
  -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" -DSWEETSPOT_SANITIZE=ON -DSWEETSPOT_BUILD_BENCH=OFF \
  -DSWEETSPOT_BUILD_WEB=OFF
stage "asan: build" cmake --build build-asan -j"$jobs"
# The load test runs 30 s in the Release pass; 5 s is enough to exercise it here.
SWEETSPOT_LOAD_SECONDS=5 \
ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1" \
UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
  stage "asan: ctest" ctest --test-dir build-asan --output-on-failure -j"$jobs"

echo "== libFuzzer: every target for a few seconds (scripts/fuzz.sh)" >&2
SWEETSPOT_JOBS="$jobs" stage "fuzz: build and run" scripts/fuzz.sh

echo "== ThreadSanitizer: the concurrency tests (scripts/tsan.sh)" >&2
SWEETSPOT_JOBS="$jobs" stage "tsan: build and run" scripts/tsan.sh

stages_report
