// Many optimisations at once: Ipopt 3.11 with MUMPS is not thread-safe, so core serialises
// Ipopt's whole lifecycle behind one process-wide lock (shared/docs/pitfalls.md: without it
// the process crashes or exits). Every concurrent answer must equal the serial one.
#include <gtest/gtest.h>

#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include "core/bat/material.hpp"
#include "core/optimize/design_problem.hpp"
#include "tests/sanitizers.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_concurrency_test {
namespace {

DesignProblem Problem(int i) {
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.8636, 0.0125, 0.033, 0.30, 0.55};
  p.bat.material = *FindMaterial("ash");
  p.variables = {{"three_segment.taper_start_m", 0.1, 0.5},
                 {"three_segment.barrel_radius_m", 0.028, 0.0331},
                 {"three_segment.taper_end_m", 0.3, 0.8}};
  p.constraints.mass_kg = DesignRange::Equal(0.86 + 0.005 * (i % 5));  // 0.86 ... 0.88 kg
  p.constraints.balance_point_m = DesignRange::Between(0.56, 0.60);
  p.constraints.rules = {RuleSet::kMlbWood};
  if (i % 3 == 2) p.objective = DesignObjective::kMinMoi;
  return p;
}

TEST(OptimizeConcurrency, EightThreadsTimesTenSolvesAllMatchTheSerialAnswers) {
  constexpr int kThreads = 8;
  // Under ASan a solve costs several times its Release time: half the problems there (40
  // concurrent solves, NLopt's among them) still queue every thread behind the lock at once.
  constexpr int kSolves = SWEETSPOT_UNDER_ASAN ? 5 : 10;
  DesignOptions options;
  options.starts = 1;
  options.hessian = HessianMode::kExact;  // fewer iterations: keeps the test fast under ASan
  // Equality with the serial answers, not speed: a solve cut by the time budget (10 s by
  // default, reached on a loaded machine under the sanitizers) would differ from a whole one.
  options.max_time_s = 120.0;
  std::vector<DesignResult> serial;
  for (int i = 0; i < kSolves; ++i) serial.push_back(OptimizeDesign(Problem(i), options));
  for (const DesignResult& r : serial) {
    ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  }
  std::atomic<int> mismatches{0}, done{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&, t] {
      for (int k = 0; k < kSolves; ++k) {
        const int i = (t + k) % kSolves;
        DesignOptions o = options;
        // Alternate the backends: NLopt solves run in parallel with the serialised Ipopt ones.
        if (k == 3) o.backend = DesignBackend::kNloptSlsqp;
        const DesignResult r = OptimizeDesign(Problem(i), o);
        const DesignResult& s = serial[static_cast<std::size_t>(i)];
        bool same = r.summary.termination == Termination::kConverged;
        if (o.backend == DesignBackend::kIpopt) {
          // Ipopt is deterministic: the same solve gives the same bits on any thread.
          same = same && r.objective_value == s.objective_value;
          for (std::size_t j = 0; j < r.variables.size(); ++j) {
            same = same && r.variables[j].value == s.variables[j].value;
          }
        } else {
          // SLSQP stops by its own rule: same optimum to 1e-7 relative.
          same = same && std::abs(r.objective_value - s.objective_value) <=
                             1e-7 * std::abs(s.objective_value);
        }
        if (!same) ++mismatches;
        ++done;
      }
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(done.load(), kThreads * kSolves);
  EXPECT_EQ(mismatches.load(), 0);
}

// min_sting (COBYLA over the flexible beam, no lock) beside Ipopt solves: the flexible model and
// each solve's modes cache are per call, so every thread gets the serial answer bit for bit.
TEST(OptimizeConcurrency, StingSolvesBesideIpoptSolvesMatchTheSerialAnswer) {
  DesignProblem sting;
  sting.three_segment = ThreeSegmentShape{0.8636, 0.0125, 0.033, 0.30, 0.55};
  sting.bat.material = *FindMaterial("ash");
  sting.cor = 0.5;
  sting.objective = DesignObjective::kMinSting;
  sting.variables = {{"three_segment.taper_end_m", 0.45, 0.75}};
  sting.constraints.mass_kg = DesignRange::Between(0.85, 1.25);
  DesignOptions options;
  options.hessian = HessianMode::kExact;
  options.max_time_s = 120.0;  // as above: whole solves only
  const DesignResult serial = OptimizeDesign(sting, options);
  const DesignResult serial_ipopt = OptimizeDesign(Problem(0), options);
  ASSERT_EQ(serial.summary.termination, Termination::kConverged) << serial.summary.FullReport();
  std::atomic<int> mismatches{0};
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      const bool ipopt = t % 2 == 1;
      const DesignResult r = OptimizeDesign(ipopt ? Problem(0) : sting, options);
      const DesignResult& s = ipopt ? serial_ipopt : serial;
      bool same = r.summary.termination == Termination::kConverged &&
                  r.objective_value == s.objective_value;
      for (std::size_t j = 0; j < r.variables.size(); ++j) {
        same = same && r.variables[j].value == s.variables[j].value;
      }
      if (!same) ++mismatches;
    });
  }
  for (std::thread& t : threads) t.join();
  EXPECT_EQ(mismatches.load(), 0);
}

}  // namespace
}  // namespace optimize_concurrency_test
}  // namespace sweetspot::core
