// Internal to core/optimize: the backend OptimizeDesign uses when the options let it choose
// (DesignOptions::choose_backend, the api's default), and the refusal of NLopt SLSQP above the
// size where it was measured to stop short of the optimum (issue 36, item 2).
#pragma once

#include <string>

#include "core/optimize/design_problem.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core::design_detail {

/// Most variables for which a chosen backend is NLopt SLSQP: at 14 variables (16 knots,
/// bench/optimize_scaling.sh, 2026-11-28) SLSQP reaches Ipopt's optimum to 1.3e-10 relative in
/// 0.62 ms against lifted Ipopt's 3.4 ms; at 30 it is slower (7.2 ms against 4.7: its dense
/// quasi-Newton step is O(n^3)).
inline constexpr int kChosenSlsqpMaxVariables = 24;
/// Largest KKT residual (DesignResult's summary.error_estimate: the scaled stationarity
/// residual with least-squares multipliers, relative) of a certified SLSQP answer: 1e3 times
/// the solves' tolerance 1e-9, far below a point that stopped short (~1e-2 and more).
inline constexpr double kChosenSlsqpMaxKkt = 1e-6;
/// Most variables NLopt SLSQP is run with when asked for by name: with 30 variables (32 knots)
/// it reaches the optimum (2.9e-10 relative); with 62 (64 knots) it reported convergence at
/// 22.662 m/s where the optimum is 22.786 (bench/optimize_scaling.sh, issue 36).
inline constexpr int kSlsqpMaxVariables = 32;

/// The backend for `problem` when the options let the optimiser choose (see
/// DesignOptions::choose_backend); options.backend otherwise.
DesignBackend ChooseBackend(const DesignProblem& problem, const DesignOptions& options);

/// True when an answer of the chosen SLSQP is certified (converged, feasible: the termination
/// says so after the re-check, KKT residual at most kChosenSlsqpMaxKkt). The hook for the KKT
/// certificate of issue 36, item 1 (summary.certificate) when it lands.
bool ChosenAnswerCertified(const DesignResult& result);

/// The refusal of options.backend = nlopt_slsqp for a problem with more than
/// kSlsqpMaxVariables variables; true (no refusal) otherwise.
bool SlsqpSizeAllowed(const DesignProblem& problem, const DesignOptions& options, Refusal* why);

}  // namespace sweetspot::core::design_detail
