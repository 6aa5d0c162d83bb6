#!/usr/bin/env bash
# Runs the concurrency tests under ThreadSanitizer: a Clang build with
# -fsanitize=thread in build-tsan/ (server_tests and the executables it starts),
# then the tests that use threads or a live server. Any race or lock-order
# report, from the test process or from a server it started, fails the script;
# the reports are in build-tsan/tsan-logs/.
#
# Clang, as for the ASan build: the same TSan build took 238 CPU-seconds with
# Clang 14 against 385 with GCC 12 (README "Build times"). Only server_tests: the one
# concurrency test api_tests had (concurrent /v1/optimize solves) moved there as
# ServerLimitsTest.ConcurrentOptimisationsAllAgree, run by the server's own threads, so
# api_tests is not built a third time.
#
#   SWEETSPOT_TSAN_FILTER='Job*'   gtest filter (default below)
#   SWEETSPOT_JOBS=N               build parallelism (default: nproc)
#   SWEETSPOT_TSAN_STEP=build|run  only build, or only run what is built (default: both;
#                                  scripts/test.sh builds while the ASan tests run)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/stages.sh
jobs="${SWEETSPOT_JOBS:-$(nproc)}"
filter="${SWEETSPOT_TSAN_FILTER:-Job*:*Concurrent*:ServerTest.*:ServerLimits*:ExploreStream*:FaultsTest.*:ServingTest.ConnectionsPast*:ServingTest.IdleKeepAlive*:PostgresJobsTest.*:AttackTest.Abandoned*:AttackTest.Shutdown*:AttackTest.ComputeRequestsHaveATimeBudget}"
step="${SWEETSPOT_TSAN_STEP:-all}"
build=build-tsan

if [ "$step" != run ]; then
  echo "== ThreadSanitizer build in $build/" >&2
  # A tree configured with another compiler (GCC, before) is started afresh: CMake keeps
  # the compiler a tree was first configured with.
  if [ -f "$build/CMakeCache.txt" ] && ! grep -q '^CMAKE_CXX_COMPILER:.*clang' "$build/CMakeCache.txt"; then
    rm -rf "$build"
  fi
  # The test drivers at -O0: they only call the code under test, which keeps -O1.
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O1" \
    -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" \
    -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" -DSWEETSPOT_TEST_OPTIMIZE=-O0 \
    -DSWEETSPOT_BUILD_BENCH=OFF -DSWEETSPOT_BUILD_WEB=OFF >/dev/null
  stage "tsan: build" cmake --build "$build" -j"$jobs" --target server_tests
fi
[ "$step" = build ] && exit 0

logs="$build/tsan-logs"
rm -rf "$logs"
mkdir -p "$logs"
# log_path: one file per process (the tests and every server they start).
# Suppressions: scripts/tsan.supp says what is suppressed and why.
export TSAN_OPTIONS="log_path=$PWD/$logs/tsan:second_deadlock_stack=1:history_size=4:suppressions=$PWD/scripts/tsan.supp"
status=0
for suite in server_tests; do
  echo "== $suite --gtest_filter=$filter (TSan)" >&2
  stage "tsan: $suite" "$build/tests/$suite" --gtest_filter="$filter" --gtest_brief=1 || status=1
done
if compgen -G "$logs/tsan.*" >/dev/null; then
  echo "tsan.sh: ThreadSanitizer reports:" >&2
  for f in "$logs"/tsan.*; do
    echo "--- $f" >&2
    grep -E '^(WARNING|SUMMARY): ThreadSanitizer' "$f" >&2 || head -n 20 "$f" >&2
  done
  status=1
fi
[ "$status" -eq 0 ] && echo "tsan.sh: clean" >&2
exit "$status"
