// The optimiser's BBCOR constraints (issue 35): `rules: bbcor` (BBCOR <= 0.50) and
// `constraints.bbcor_max` (a margin below it) on a hollow design hold THE BBCOR, the flexible
// scan's maximum over the barrel (ComputeCertifiedBbcor, core/scene/scene_barrel.hpp).
//
// The scan (modal beam, ODE impacts, a grid then a polish) has no derivative the NLP can use, so
// the design model constrains the fixed-point estimate B_est(x) (design_bbcor.hpp: exact
// gradient and Hessian) shifted by an offset d held constant within one optimisation:
//   B_est(x) <= bound - d,   d = B_scan - B_est at the previous round's answer.
// Rounds (OptimizeWithCertifiedBbcor): optimise, certify the answer by the scan, update d, until
// the answer's scan value is in [bound - 2.5e-7, bound] (the constraint active; never above the
// bound, and within half the feasibility tolerance 1e-6 of 0.5) or below the bound with the
// constraint inactive; d by the secant on g(d) = B_scan(answer(d)) - (bound - 1.25e-7) after
// the first step (the first is the fixed-point step d' = B_scan - B_est). At most 8 rounds; the
// last answer is certified by BbcorRuleHolds whatever happens (over the bound: infeasible, the
// value in the message).
//
// What this is NOT: the NLP's gradient is the estimate's, not the scan maximum's (the offset's
// own gradient is left out), so at an active bound the answer is feasible for THE BBCOR to the
// tolerance, but its optimality is that of the estimate's constraint surface shifted to pass
// through it (docs/optimization.md, "BBCOR").
#pragma once

#include <functional>
#include <optional>

#include "core/optimize/design_problem.hpp"

namespace sweetspot::core {

/// The BBCOR bound of `problem`: min(0.50 with rules bbcor, constraints.bbcor_max), or nullopt
/// when neither is set.
std::optional<double> BbcorBoundOf(const DesignProblem& problem);

/// One optimisation of a problem (the rounds' step).
using OptimizeOnce = std::function<DesignResult(const DesignProblem&)>;

/// The rounds of the file comment around `once`; `once` itself when the problem has no BBCOR
/// bound or its base bat and its variables make no hollow design (the model then has no BBCOR
/// constraint). Never throws (as `once`).
DesignResult OptimizeWithCertifiedBbcor(const DesignProblem& problem, const OptimizeOnce& once);

}  // namespace sweetspot::core
