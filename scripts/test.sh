#!/usr/bin/env bash
# Installs what is missing, builds everything and runs every test twice:
# a Release build (build/, GCC, as a user builds it), then the same suite under
# AddressSanitizer + UndefinedBehaviorSanitizer (build-asan/, Clang); then the
# concurrency tests under ThreadSanitizer (scripts/tsan.sh, build-tsan/, Clang) and,
# beside them, a short libFuzzer run of every fuzz target (scripts/fuzz.sh, about
# half a minute) on the ASan build. Any failure fails the script.
#
# The sanitizer builds are Clang's because it compiles sanitized code much faster
# than GCC (ASan + UBSan about three times, per file; TSan 238 against 385 CPU-s: README
# "Build times"), and because one Clang build serves both the sanitized test suite and
# the fuzz targets (its core and api carry libFuzzer's coverage too).
#
# Each stage prints its wall time and its CPU time (user + system: unlike wall time it hardly
# depends on what else the machine runs, so two runs on a shared machine compare by it), and a
# table of them closes the run. New build trees use Ninja; every compilation goes through
# ccache and every link through lld when installed (cmake/BuildSpeed.cmake).
# The sanitizer builds start at once, in the background at idle priority
# (scripts/stages.sh: stage_background), and use the cores the Release build and
# the tests leave idle.
#   SWEETSPOT_JOBS=N   build and test parallelism (default: nproc)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/stages.sh

stage "install-deps" scripts/install-deps.sh
jobs="${SWEETSPOT_JOBS:-$(nproc)}"

# The sanitizer builds start first, in the background at idle priority (SCHED_IDLE: they get
# a core only when nothing else wants one), one after the other: the ASan build, which the
# ASan tests wait for, then the TSan build, which only the last stage needs. They take what the
# Release build leaves idle (its serial steps, npm's downloads) and what its tests leave idle
# (servers waiting on sockets, clients trickling on purpose), so the tests, the latency tests
# among them, are never kept waiting by them.
#
# ASan: only what ctest and fuzz.sh run: no benchmarks, no explorer bundle (its browser test
# runs in Release). -g1: line tables are all a sanitizer report needs, at a third less compile
# time. The code under test at -O2: Clang compiles it in about the time -O1 takes, and -O1 left
# std::array's operator[] and odeint's kernels out of line (a 400-design Hertz sweep: 3.8 s
# at -O1, 2.7 s at -O2). The test drivers at -O0 (SWEETSPOT_TEST_OPTIMIZE's default).
stage "asan: configure" env CC=clang CXX=clang++ cmake -S . -B build-asan \
  -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O2" \
  -DSWEETSPOT_SANITIZE=ON -DSWEETSPOT_FUZZ=ON -DSWEETSPOT_BUILD_BENCH=OFF -DSWEETSPOT_BUILD_WEB=OFF
# The ASan build leaves a mark when it ends (a finished process stays a zombie until this
# script waits for it, so its pid cannot tell); the TSan build waits for the mark. Their times
# are counted from their common start.
mkdir -p stage-logs
rm -f stage-logs/asan-build.done
stage_background "asan: build" bash -c \
  'status=0; cmake --build build-asan -j"$1" || status=$?; touch stage-logs/asan-build.done
   exit "$status"' _ "$jobs"
SWEETSPOT_TSAN_STEP=build SWEETSPOT_JOBS="$jobs" stage_background "tsan: build (after asan)" \
  bash -c 'while [ ! -e stage-logs/asan-build.done ]; do sleep 1; done; exec scripts/tsan.sh'

echo "== Release build and tests" >&2
stage "release: configure" cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
stage "release: build" cmake --build build -j"$jobs"
stage "release: ctest" ctest --test-dir build --output-on-failure -j"$jobs"

echo "== AddressSanitizer + UndefinedBehaviorSanitizer tests (Clang)" >&2
stage_wait "asan: build"
# The load test and the attack soak run 30 s in the Release pass; 5 s is enough to exercise
# them here.
SWEETSPOT_LOAD_SECONDS=5 SWEETSPOT_SOAK_SECONDS=5 \
ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1" \
UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
  stage "asan: ctest" ctest --test-dir build-asan --output-on-failure -j"$jobs"

echo "== ThreadSanitizer: the concurrency tests (scripts/tsan.sh), beside libFuzzer" >&2
stage_wait "tsan: build (after asan)"
# libFuzzer (every target for a few seconds, on build-asan/) in the background at idle
# priority beside the TSan tests, which leave most of the CPU idle (servers waiting on
# sockets): each target runs for its fixed time either way.
SWEETSPOT_FUZZ_BUILD=build-asan SWEETSPOT_JOBS="$jobs" stage_background "fuzz: build and run" \
  scripts/fuzz.sh
SWEETSPOT_TSAN_STEP=run SWEETSPOT_JOBS="$jobs" stage "tsan: run" scripts/tsan.sh
stage_wait "fuzz: build and run"
cat stage-logs/fuzz--build-and-run.log >&2

stages_report
