#!/usr/bin/env bash
# Where one n-knot design solve's work goes, deterministically: valgrind's callgrind counts the
# instructions executed inside one OptimizeDesign (BM_OptimizeKnots/knots:N/backend:B, one
# iteration of the benchmark) and prints the inclusive share of each phase. Instruction counts
# do not move with the machine's load (CPU times do, by tens of percent on the shared 2-core
# machine), so options and formulations can be compared one run each; they do not count cache
# misses. Issue 36 (docs/benchmarks.md, "Issue 36: fine profiles").
#   bench/optimize_instructions.sh [BUILD_DIR] [KNOTS...]   (default: build; 64 128 256)
#   BACKEND=0 ... Ipopt exact; 4 the default request over the knot radii (without the taper's
#   steps as variables); default 3 (the default request).
# Needs valgrind. Not run by ctest or CI.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=${1:-$here/../build}
shift || true
knots=("$@")
[ ${#knots[@]} -gt 0 ] || knots=(64 128 256)
bench=$build/bench/sweetspot_bench_core
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for n in "${knots[@]}"; do
  valgrind --tool=callgrind --callgrind-out-file="$work/cg.$n" \
    --toggle-collect='sweetspot::core::OptimizeDesign*' "$bench" \
    --benchmark_filter="BM_OptimizeKnots/knots:$n/backend:${BACKEND:-3}" \
    --benchmark_min_time=0.000001 >"$work/out.$n" 2>/dev/null
  callgrind_annotate --inclusive=yes --threshold=100 "$work/cg.$n" 2>/dev/null >"$work/ann.$n"
  total=$(grep -E 'OptimizeDesign\(' "$work/ann.$n" | head -1 | awk '{print $1}' | tr -d ,)
  echo "== $n knots: $(grep -o 'iterations=[0-9]*' "$work/out.$n" | head -1), $((total / 1000000)) M instructions in OptimizeDesign"
  share() {  # the first (largest) inclusive count of a symbol matching $2
    local v
    v=$(grep -E -- "$2" "$work/ann.$n" | head -1 | awk '{print $1}' | tr -d , || true)
    awk -v v="${v:-0}" -v t="$total" -v l="$1" 'BEGIN { printf "  %-58s %5.1f %%\n", l, 100 * v / t }'
  }
  share "SolveWithIpopt (the lock held)" 'SolveWithIpopt'
  share "  MUMPS (dmumps_c)" 'dmumps_c '
  share "    factorisations" 'MumpsSolverInterface::Factorization'
  share "    solves" 'MumpsSolverInterface::Solve\('
  share "    MUMPS 5.5's per-call bookkeeping (compute_memory_save)" 'dmumps_compute_memory_save'
  share "  our lifted callbacks: eval_h" 'LiftedTnlp<[^>]*>::eval_h'
  share "  our lifted callbacks: eval_grad_f" 'LiftedTnlp<[^>]*>::eval_grad_f'
  share "  IpoptApplicationFactory" 'IpoptApplicationFactory'
  share "the certificate (Certify: runs and answer)" 'design_detail::Certify\('
  share "the merge of duplicated constraints" 'MergeDuplicateConstraints\(sweetspot::core::DesignModel\*\) \['
  share "DesignModel::Build" 'DesignModel::Build\('
  share "ReportActiveConstraints" 'ReportActiveConstraints'
  share "RecheckConstraints" 'RecheckConstraints'
done
