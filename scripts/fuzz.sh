#!/usr/bin/env bash
# Builds the libFuzzer targets with clang in build-fuzz/ (-DSWEETSPOT_FUZZ=ON:
# coverage + AddressSanitizer + UndefinedBehaviorSanitizer) and runs each one
# for a few seconds on its seeds (fuzz/corpus/<target>/) plus what earlier runs
# found (<build>/corpus/<target>/, kept between runs), as many targets at once
# as there are cores. About half a minute in all on 2 cores.
#
# A crash, a sanitizer report, a timeout or a broken contract fails the script;
# the input is in build-fuzz/artifacts/<target>/. Fix the bug and keep the
# input as fuzz/regressions/<target>/<what-it-does> (tests/api/
# fuzz_regressions_test.cpp replays it in the normal build). fuzz/README.md
# has the details.
#
#   SWEETSPOT_FUZZ_SECONDS=N   seconds per target (default 6: ~60 s of CPU for the 8 targets)
#   SWEETSPOT_FUZZ_BUILD=DIR   the build tree (default build-fuzz). A tree already configured
#                              with -DSWEETSPOT_FUZZ=ON is used as it is (scripts/test.sh passes
#                              its Clang sanitizer tree, build-asan/, whose tests share the build)
#   SWEETSPOT_FUZZ_TARGETS="parse_body dispatch"   run only these targets
#   SWEETSPOT_FUZZ_STRICT=1    a handler's deliberate 500 fails too (default: listed)
#   SWEETSPOT_JOBS=N           build parallelism and targets run at once (default: nproc)
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/stages.sh
seconds="${SWEETSPOT_FUZZ_SECONDS:-6}"
targets="${SWEETSPOT_FUZZ_TARGETS:-parse_body parse_bat dispatch bat_fit sweet_spot collision compare explore flight}"
jobs="${SWEETSPOT_JOBS:-$(nproc)}"
build="${SWEETSPOT_FUZZ_BUILD:-build-fuzz}"

if ! command -v clang++ >/dev/null ||
   ! clang++ -print-file-name=libclang_rt.fuzzer-x86_64.a | grep -q /; then
  echo "fuzz.sh: needs clang++ with libFuzzer (Debian 12: clang clang-14 libclang-rt-14-dev)" >&2
  exit 1
fi

if grep -qs '^SWEETSPOT_FUZZ:BOOL=ON' "$build/CMakeCache.txt"; then
  echo "== libFuzzer targets of $build/ (configured already)" >&2
else
  echo "== libFuzzer build (clang, ASan + UBSan) in $build/" >&2
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DSWEETSPOT_FUZZ=ON -DBUILD_TESTING=OFF -DSWEETSPOT_BUILD_BENCH=OFF -DSWEETSPOT_BUILD_WEB=OFF >/dev/null
fi
stage "fuzz: build" cmake --build "$build" -j"$jobs" --target fuzz_targets

# run_target <name>: one target for $seconds; its log is $build/logs/<name>.log.
run_target() {
  local t="$1"
  mkdir -p "$build/corpus/$t" "$build/artifacts/$t" "$build/notes/$t" "$build/logs"
  SWEETSPOT_FUZZ_NOTES_DIR="$build/notes/$t" \
  ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:strict_string_checks=1" \
  UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1" \
    "$build/fuzz/fuzz_$t" -max_total_time="$seconds" -timeout=20 -rss_limit_mb=2048 \
    -max_len=4096 -dict=fuzz/sweetspot.dict -print_final_stats=1 \
    -artifact_prefix="$build/artifacts/$t/" "$build/corpus/$t" "fuzz/corpus/$t" \
    >"$build/logs/$t.log" 2>&1
}

# Up to $jobs targets at once (each is one process on one core); results in the given order.
failed=()
start=$SECONDS
declare -A pid_of status_of
for t in $targets; do
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n || true; done
  run_target "$t" &
  pid_of[$t]=$!
done
for t in $targets; do
  status=0
  wait "${pid_of[$t]}" || status=$?
  log="$build/logs/$t.log"
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n1)
  cov=$(grep -oE 'cov: [0-9]+ ft: [0-9]+ corp: [0-9]+' "$log" | tail -n1 || true)
  notes=$(grep -c '^fuzz note:' "$log" || true)
  printf 'fuzz %-11s %8s runs  %s  notes: %s  %s\n' "$t" "${runs:-?}" "${cov:-?}" "$notes" \
    "$([ "$status" -eq 0 ] && echo ok || echo FAILED)" >&2
  grep '^fuzz note:' "$log" | cut -c1-300 >&2 || true
  if [ "$status" -ne 0 ]; then
    failed+=("$t")
    grep -E '^fuzz problem:|ERROR: |SUMMARY: |runtime error|what\(\)|Test unit written to' "$log" \
      | head -n 20 >&2 || true
    echo "fuzz.sh: $t failed; full log: $log; input in $build/artifacts/$t/" >&2
  fi
done
echo "== fuzz: run: $(( SECONDS - start )) s" >&2
if [ ${#failed[@]} -ne 0 ]; then
  echo "fuzz.sh: FAILED: ${failed[*]}" >&2
  exit 1
fi
