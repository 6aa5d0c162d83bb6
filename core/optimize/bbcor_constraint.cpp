// The optimiser's BBCOR constraints: the certification rounds (bbcor_constraint.hpp).
#include "core/optimize/bbcor_constraint.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/collision/barrel.hpp"
#include "core/geometry_format.hpp"
#include "core/optimize/design_public.hpp"
#include "core/optimize/rules.hpp"
#include "core/scene/scene_barrel.hpp"

namespace sweetspot::core {
namespace {

constexpr int kMaxRounds = 8;
// At an active bound the rounds aim at bound - kCertifiedTolerance / 2 and accept B_scan in
// [bound - kCertifiedTolerance, bound]: never above the bound (a strict "<= 0.50" downstream
// holds), and within half the re-check's feasibility tolerance (kFeasibleRelative 1e-6 of 0.5).
constexpr double kCertifiedTolerance = 2.5e-7;
// The estimate's constraint counts as active within this of its shifted bound.
constexpr double kActiveTolerance = 1e-6;

}  // namespace

std::optional<double> BbcorBoundOf(const DesignProblem& problem) {
  std::optional<double> bound;
  const auto& rules = problem.constraints.rules;
  if (std::find(rules.begin(), rules.end(), RuleSet::kBbcor) != rules.end()) {
    bound = *LimitsOf(RuleSet::kBbcor).max_bbcor;
  }
  if (problem.constraints.bbcor_max.has_value()) {
    bound =
        std::min(bound.value_or(*problem.constraints.bbcor_max), *problem.constraints.bbcor_max);
  }
  return bound;
}

DesignResult OptimizeWithCertifiedBbcor(const DesignProblem& problem, const OptimizeOnce& once) {
  const std::optional<double> bound = BbcorBoundOf(problem);
  if (!bound.has_value()) return once(problem);
  DesignProblem p = problem;
  // The first offset: the base bat's, when it is hollow and both values exist.
  double offset = 0.0;
  if (problem.bat.IsHollow()) {
    // The base design's mass properties when the request has them (the rigid body's: the
    // protocol's I_pivot), not computed again.
    const MassProperties* base =
        problem.base_mass_properties.has_value()
            ? design_detail::RigidBodyPropertiesOrNull(*problem.base_mass_properties)
            : nullptr;
    const BbcorResult c =
        ComputeCertifiedBbcor(problem.bat, FlexibleOptions{}, BarrelOptions{}, base);
    if (c.ok) offset = c.value - c.estimate_value;
  }
  double prev_offset = 0.0, prev_g = 0.0;
  bool have_prev = false;
  DesignResult r;
  int iterations = 0, evaluations = 0;
  for (int round = 1; round <= kMaxRounds; ++round) {
    p.constraints.bbcor_estimate_offset = offset;
    r = once(p);
    // The work of every round (the last round's alone otherwise).
    iterations += std::max(r.summary.iterations, 0);
    evaluations += std::max(r.summary.evaluations, 0);
    if (r.summary.iterations >= 0) r.summary.iterations = iterations;
    if (r.summary.evaluations >= 0) r.summary.evaluations = evaluations;
    r.bbcor_rounds = round;
    r.bbcor_estimate_offset = offset;
    // The active BBCOR constraint reported in THE BBCOR's terms: the certified value and the
    // bound itself (the model held the estimate below bound - offset; the multiplier is that
    // surface's, the same unit).
    if (r.bbcor.has_value() && r.bbcor->ok) {
      for (DesignActiveConstraint& a : r.active_constraints) {
        if (a.name == "bbcor_max" || a.name == "rules.bbcor.bbcor") {
          a.value = r.bbcor->value;
          a.bound = *bound;
        }
      }
    }
    // No certified value (no BBCOR constraint on a solid design, a refusal, a failure): the
    // rounds have nothing to correct. Nor after a round that did not finish (cancelled, out of
    // time, no convergence): its answer stands with its termination. An infeasible round goes
    // on when the scan's check made it so (the estimate's constraint held: `held` below).
    if (!r.bbcor.has_value() || !r.bbcor->ok) return r;
    if (r.summary.termination != Termination::kConverged &&
        r.summary.termination != Termination::kInfeasible) {
      return r;
    }
    const double g = r.bbcor->value - (*bound - 0.5 * kCertifiedTolerance);
    const bool active = r.bbcor->estimate_value >= *bound - offset - kActiveTolerance;
    // The estimate's own constraint not met: the design problem is infeasible as it stands.
    const bool held = r.bbcor->estimate_value <= *bound - offset + kActiveTolerance;
    if (std::abs(g) <= 0.5 * kCertifiedTolerance || (r.bbcor->value <= *bound && !active) ||
        !held) {
      return r;
    }
    double next = offset + g;  // the fixed-point step: d' = B_scan - B_est at an active answer
    if (have_prev && g != prev_g) next = offset - g * (offset - prev_offset) / (g - prev_g);
    prev_offset = offset;
    prev_g = g;
    have_prev = true;
    if (!std::isfinite(next)) return r;
    offset = next;
  }
  r.summary.warnings.push_back(
      "bbcor: the certification rounds stopped after " + std::to_string(kMaxRounds) +
      " optimisations with the answer's BBCOR " + FormatNumber(r.bbcor->value) +
      " not within [bound - " + FormatNumber(kCertifiedTolerance) + ", bound], bound " +
      FormatNumber(*bound) + " (the estimate's offset " + FormatNumber(offset) + ")");
  return r;
}

}  // namespace sweetspot::core
