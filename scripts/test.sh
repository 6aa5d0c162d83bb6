#!/usr/bin/env bash
# Installs what is missing, builds everything and runs every test twice:
# a Release build (build/, GCC, as a user builds it), then the same suite under
# AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/, Clang); then a
# short libFuzzer run of every fuzz target (scripts/fuzz.sh, about a minute) on
# that same sanitizer build, and the concurrency tests under ThreadSanitizer
# (scripts/tsan.sh). Any failure fails the script.
#
# The sanitizer build is Clang's because it compiles ASan + UBSan code about
# three times faster than GCC (measured per file in README "Build times"), and
# because one Clang build serves both the sanitized test suite and the fuzz
# targets (its core and api carry libFuzzer's coverage too).
#
# Each stage prints its wall time, and a table of them closes the run. New build
# trees use Ninja; every compilation goes through ccache (cmake/BuildSpeed.cmake).
# The sanitizer builds run in the background at idle priority while the previous
# pass's tests run (scripts/stages.sh: stage_background), on the cores those tests
# leave idle.
#   SWEETSPOT_JOBS=N   build and test parallelism (default: nproc)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/stages.sh

stage "install-deps" scripts/install-deps.sh
jobs="${SWEETSPOT_JOBS:-$(nproc)}"

echo "== Release build and tests" >&2
stage "release: configure" cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
stage "release: build" cmake --build build -j"$jobs"

# Only what ctest and fuzz.sh run: no benchmarks, no explorer bundle (its browser test runs
# in Release). -g1: line tables are all a sanitizer report needs, at a third less compile time.
# The code under test at -O2: Clang compiles it in about the time -O1 takes, and -O1 left
# std::array's operator[] and odeint's kernels out of line (a 400-design Hertz sweep: 3.8 s
# at -O1, 2.7 s at -O2). The test drivers at -O0 (SWEETSPOT_TEST_OPTIMIZE's default).
stage "asan: configure" env CC=clang CXX=clang++ cmake -S . -B build-asan \
  -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O2" \
  -DSWEETSPOT_SANITIZE=ON -DSWEETSPOT_FUZZ=ON -DSWEETSPOT_BUILD_BENCH=OFF -DSWEETSPOT_BUILD_WEB=OFF
# The Release tests leave a core idle most of the time (servers waiting on sockets, clients
# trickling on purpose): the sanitizer build uses it at idle priority, so the tests, the
# latency tests among them, are never kept waiting by it.
stage_background "asan: build" cmake --build build-asan -j"$jobs"
stage "release: ctest" ctest --test-dir build --output-on-failure -j"$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer build and tests (Clang)" >&2
stage_wait "asan: build"
# The same for the ThreadSanitizer build beside the sanitized tests and the fuzzing.
SWEETSPOT_TSAN_STEP=build SWEETSPOT_JOBS="$jobs" stage_background "tsan: build" scripts/tsan.sh
# The load test runs 30 s in the Release pass; 5 s is enough to exercise it here.
SWEETSPOT_LOAD_SECONDS=5 \
ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1" \
UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
  stage "asan: ctest" ctest --test-dir build-asan --output-on-failure -j"$jobs"

echo "== libFuzzer: every target for a few seconds (scripts/fuzz.sh, on build-asan/)" >&2
SWEETSPOT_FUZZ_BUILD=build-asan SWEETSPOT_JOBS="$jobs" stage "fuzz: build and run" scripts/fuzz.sh

echo "== ThreadSanitizer: the concurrency tests (scripts/tsan.sh)" >&2
stage_wait "tsan: build"
SWEETSPOT_TSAN_STEP=run SWEETSPOT_JOBS="$jobs" stage "tsan: run" scripts/tsan.sh

stages_report
