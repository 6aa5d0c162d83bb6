#!/usr/bin/env bash
# Where an Ipopt design's time goes: perf (DWARF call graphs) over BM_OptimizeSixteenKnots, and
# the inclusive share of each phase's entry point. Proportions only (perf samples); the CPU time
# per solve comes from the benchmark's own line.
#   bench/ipopt_phases.sh [BENCH_BINARY] [FILTER]
# Needs perf (linux-perf). Not run by ctest or CI.
set -euo pipefail
bin=${1:-build/bench/sweetspot_bench_core}
filter=${2:-BM_OptimizeSixteenKnots/exact:1}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin" --benchmark_filter="$filter" --benchmark_min_time=1 2>/dev/null | grep '^BM_' || true
perf record -q --call-graph dwarf,32768 -F 1500 -o "$work/perf.data" \
  "$bin" --benchmark_filter="$filter" --benchmark_min_time=1 >/dev/null 2>&1
perf report -i "$work/perf.data" --children --sort symbol --stdio 2>/dev/null |
  grep -E '^ +[0-9]' | sed -E 's/[ -]*$//' >"$work/children.txt"
share() {  # the largest inclusive share of a symbol matching $2
  local v
  v=$(grep -E -- "$2" "$work/children.txt" | awk '{print $1}' | tr -d % | sort -g | tail -1 || true)
  printf '%-58s %6s %%\n' "$1" "${v:-0}"
}
echo "inclusive share of the samples (perf report --children):"
share "OptimizeDesign (everything)" '\] sweetspot::core::OptimizeDesign$'
share "SolveWithIpopt (the lock held: app + TNLP lifetime)" 'SolveWithIpopt$'
share "  IpoptApplicationFactory (app, RegisterAllIpoptOptions)" 'IpoptApplicationFactory$'
share "  IpoptApplication::Initialize (options)" 'IpoptApplication::Initialize$'
share "  OptimizeTNLP set-up: AlgorithmBuilder" 'AlgorithmBuilder::BuildBasicAlgorithm$'
share "  OptimizeTNLP set-up: OrigIpoptNLP::Initialize(Structures)" 'OrigIpoptNLP::Initialize'
share "  IpoptAlgorithm::Optimize (the iterations)" 'IpoptAlgorithm::Optimize$'
share "    mu oracle (QualityFunction / Probing)" 'MuOracle::CalculateMu$'
share "    MUMPS factorisation" 'MumpsSolverInterface::Factorization$'
share "    MUMPS solves" 'MumpsSolverInterface::Solve$'
share "    MUMPS symbolic factorisation" 'MumpsSolverInterface::SymbolicFactorization$'
share "    our callbacks: eval_h" 'DesignTnlp::eval_h$'
share "    our callbacks: eval_f" 'DesignTnlp::eval_f$'
share "    our callbacks: eval_grad_f" 'DesignTnlp::eval_grad_f$'
share "    our callbacks: eval_g" 'DesignTnlp::eval_g$'
share "    our callbacks: eval_jac_g" 'DesignTnlp::eval_jac_g$'
share "    lifted callbacks: eval_h" 'LiftedTnlp::eval_h$'
share "    lifted callbacks: eval_f" 'LiftedTnlp::eval_f$'
share "    lifted callbacks: eval_grad_f" 'LiftedTnlp::eval_grad_f$'
share "    lifted callbacks: eval_g" 'LiftedTnlp::eval_g$'
share "    lifted callbacks: eval_jac_g" 'LiftedTnlp::eval_jac_g$'
share "  tear-down: ~IpoptApplication" 'IpoptApplication::~IpoptApplication$'
share "getrusage (Ipopt's TimedTask: CpuTime, SysTime)" '\] __getrusage$'
share "malloc" '\] __GI___libc_malloc \(inlined\)$'
share "free" '\] __GI___libc_free \(inlined\)$'
share "page faults" '\] asm_exc_page_fault$'
share "our model outside Ipopt: Finish" 'design_detail::Finish$'
share "our model outside Ipopt: DesignModel::Build" 'DesignModel::Build$'
share "our model outside Ipopt: ReportActiveConstraints" 'ReportActiveConstraints$'
share "our model outside Ipopt: AnswerAt (public re-evaluation)" 'design_detail::AnswerAt$'
share "our model outside Ipopt: RecheckConstraints" 'RecheckConstraints$'
share "MUMPS's per-call bookkeeping: dmumps_save_restore_structure" 'dmumps_save_restore_structure$'
share "gfortran string compares (SELECT CASE on strings)" '_gfortran_(select|compare)_string$'
share "memcmp" '\] __memcmp_evex_movbe$'
