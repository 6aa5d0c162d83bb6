// Internal to core/optimize: the frontier's continuation step (frontier.hpp) as a local solve.
// Started next to the answer with a neighbour's active set, the optimum is the root of the KKT
// conditions on that set: Newton's method on them with exact derivatives (the constraints'
// Jacobian; the Lagrangian's Hessian when the active set leaves free directions), the set
// updated when a constraint it left out is violated or a multiplier has the wrong sign. No
// line search and no quasi-Newton start-up: a handful of model evaluations where SLSQP,
// restarting its BFGS matrix from the identity at every value, needs ~10 iterations.
// Nothing here decides convergence for the answer: the certificate (certificate.hpp) checks
// the point as it checks every backend's.
#pragma once

#include <vector>

#include "core/optimize/design_backends.hpp"
#include "core/optimize/design_model.hpp"

namespace sweetspot::core {

/// A guess of the active set of a ScaledDesignNlp, in the certificate's signs (Ipopt's): one
/// entry per constraint, > 0 at its upper limit, < 0 at its lower one, 0 inactive (equalities
/// are always active); one per variable, 1 at its lower bound (s = 0), 2 at its upper one
/// (s = 1), 0 free. A neighbour's certificate gives it (lambda, z_lower, z_upper nonzero).
struct ActiveSetGuess {
  std::vector<double> constraint_side;  ///< Per constraint: sign of the side, 0 = inactive.
  std::vector<int> bound;               ///< Per variable: 0 free, 1 lower bound, 2 upper bound.
};

/// The guess of a certificate's multipliers (lambda, z_lower, z_upper of the scaled problem).
ActiveSetGuess GuessFromMultipliers(const std::vector<double>& lambda,
                                    const std::vector<double>& z_lower,
                                    const std::vector<double>& z_upper);

/// The summary's backend of a design answered by this step.
inline constexpr const char* kActiveSetNewtonName = "active_set_newton";

/// Most changes of the active set one solve makes before it gives up (no_convergence).
inline constexpr int kActiveSetNewtonMaxChanges = 8;
/// Most Newton iterations on one active set.
inline constexpr int kActiveSetNewtonMaxIterations = 12;

/// Solves from s0 by Newton's method on the KKT conditions of the active set `guess` (sizes
/// n and m of `nlp`; otherwise failure). Converged when the point holds the active set's
/// constraints to settings.constraint_tolerance (scaled), every other constraint and bound,
/// its stationarity on the free variables is at most settings.tolerance (relative to
/// max(1, |grad f|)) and every inequality's multiplier has its sign; the outcome carries the
/// multipliers (has_multipliers). iterations = Newton steps, evaluations = model evaluations
/// (a Hessian counts as one). Never throws.
LocalSolveOutcome SolveWithActiveSetNewton(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                           const ActiveSetGuess& guess,
                                           const LocalSolveSettings& settings);

}  // namespace sweetspot::core
