// Internal to core/optimize: what the solver layer does with the least-squares objective
// (DesignObjective::kLeastSquares, least_squares_objective.hpp) after the optimiser's stop: a
// Gauss-Newton polish of the residuals to round-off, and the first-order check that certifies a
// closest point. Both in the solvers' scaled variables s in [0, 1]^n (x = lower + (upper -
// lower) s), through the design model's residuals and constraints. No solver headers.
#pragma once

#include <vector>

#include "core/optimize/design_model.hpp"
#include "core/summary.hpp"

namespace sweetspot::core::design_detail {

/// With the least-squares objective (else nothing), Gauss-Newton on the model's residuals
/// from x (in place): minimum-norm steps in s, clamped
/// into the bounds, halved until phi decreases at a point that meets every constraint; ends
/// when every scaled residual is at most 1e-3 of the targets' tolerance, no step is accepted,
/// or after 50 steps. Adds the accepted steps to summary->iterations and the evaluations to
/// summary->evaluations.
void PolishLeastSquares(const DesignModel& model, std::vector<double>* x, Summary* summary);

/// The relative first-order (KKT) residual of phi at x: min over multipliers >= 0 of the
/// active bounds and constraints of |grad phi + A^T lambda|, relative to 2 |J| |r| (in s); 0
/// where phi is flat to rounding over the bounds. NaN when the residuals are not finite.
double LeastSquaresKktError(const DesignModel& model, const std::vector<double>& x);

/// Start i of a multi-start: given[i] (one value per variable, field units) clamped into the
/// bounds when there is one of the model's size (DesignOptions::start_points), else `otherwise`.
std::vector<double> GivenStartOr(const DesignModel& model,
                                 const std::vector<std::vector<double>>& given, int i,
                                 std::vector<double> otherwise);

}  // namespace sweetspot::core::design_detail
