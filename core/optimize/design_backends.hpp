// Internal to core/optimize: one local solve of a ScaledDesignNlp by Ipopt, NLopt SLSQP or
// NLopt COBYLA. The solvers' headers stay in ipopt_backend.cpp and nlopt_design.cpp.
#pragma once

#include <chrono>
#include <string>
#include <vector>

#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/progress.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// How one local solve runs.
struct LocalSolveSettings {
  int max_iterations = 300;             ///< Iteration limit.
  double tolerance = 1e-9;              ///< Ipopt tol / NLopt relative tolerances.
  double constraint_tolerance = 1e-10;  ///< Ipopt constr_viol_tol (scaled constraints).
  HessianMode hessian = HessianMode::kLimitedMemory;  ///< Ipopt's Hessian.
  double max_cpu_time_s = 0.0;                        ///< Ipopt max_cpu_time; 0 = not set.
  std::chrono::steady_clock::time_point deadline;     ///< Stop (no_convergence) after this.
  Progress* progress = nullptr;                       ///< Polled for cancellation.
  /// COBYLA: a point whose largest scaled violation is at most this counts as feasible when
  /// the best evaluated point is chosen.
  double feasibility_tolerance = 1e-10;
  DerivativeCheck derivative_check = DerivativeCheck::kNone;  ///< Ipopt's checker.
  /// Ipopt's derivative_test_perturbation (relative step of its forward differences); 0 =
  /// Ipopt's default 1e-8. Raised for the first bending frequency, whose value carries
  /// ~1e-11 relative round-off (an eigenvalue): at 1e-8 the difference quotient is off by
  /// ~1e-3, above the checker's tolerance 1e-4, though the gradient is exact.
  double derivative_test_perturbation = 0.0;
  /// Ipopt: solve the lifted formulation (lifted_nlp.hpp, exact sparse Hessian whatever
  /// `hessian` says) when the problem qualifies.
  bool lift = true;
  /// Ipopt, lifted: with the taper's steps as variables when the knots form one taper chain
  /// (tapered_nlp.hpp).
  bool taper_steps = true;
};

/// The outcome of one local solve (scaled variables and multipliers).
struct LocalSolveOutcome {
  std::vector<double> s;         ///< Final point (scaled).
  std::vector<double> lambda;    ///< Constraint multipliers of the scaled NLP (Ipopt sign).
  std::vector<double> z_lower;   ///< Lower-bound multipliers (>= 0).
  std::vector<double> z_upper;   ///< Upper-bound multipliers (>= 0).
  bool has_multipliers = false;  ///< False for NLopt (estimated afterwards).
  bool has_point = false;        ///< False when the solver returned no usable point.
  Termination termination = Termination::kFailure;  ///< Mapped status.
  int raw_status = 0;                               ///< The solver's own status.
  std::string status_name;                          ///< Its name.
  int iterations = 0;                               ///< Iterations (NLopt: objective evaluations).
  int evaluations = 0;                              ///< Model evaluations.
  bool cancelled = false;                           ///< Stopped by Progress::Cancel().
  bool deadline_reached = false;                    ///< Stopped by the wall-clock budget.
  std::string message;                              ///< Extra detail (exceptions, ...).
  int derivative_check_errors = -1;     ///< Ipopt's checker: errors found (-1 = not run).
  std::string derivative_check_report;  ///< Ipopt's checker: its output.
  bool lifted = false;                  ///< Ipopt solved the lifted formulation (lifted_nlp.hpp).
  bool taper_steps = false;  ///< ... with the taper's steps as variables (tapered_nlp.hpp).
  /// The certificate CertifyRuns computed for this run (without the uniqueness check) and the
  /// point it was computed at (user units; empty: none), so that the answer's certificate at the
  /// same point reuses its multipliers instead of fitting them again (certificate_runs.cpp).
  DesignCertificate certificate;
  std::vector<double> certificate_x;
};

/// What Ipopt's intermediate callback does in every design solve (the dense and the lifted
/// formulation): records `iteration` in out->iterations and answers whether to go on (false,
/// with out->cancelled or out->deadline_reached set, on a cancel or past settings.deadline).
inline bool ContinueLocalSolve(int iteration, const LocalSolveSettings& settings,
                               LocalSolveOutcome* out) {
  out->iterations = iteration;
  if (IsCancelled(settings.progress)) {
    out->cancelled = true;
    return false;
  }
  if (std::chrono::steady_clock::now() >= settings.deadline) {
    out->deadline_reached = true;
    return false;
  }
  return true;
}

/// Solves from s0 with Ipopt (holds the process-wide Ipopt lock for the whole lifecycle of
/// the application and the TNLP). Never throws.
LocalSolveOutcome SolveWithIpopt(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                 const LocalSolveSettings& settings);

/// Solves from s0 with NLopt LD_SLSQP. Never throws.
LocalSolveOutcome SolveWithNlopt(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                 const LocalSolveSettings& settings);

/// Solves from s0 with NLopt LN_COBYLA, derivative-free: only values are asked of `nlp` (the
/// objective may have no derivative, as min_sting), bounds [0, 1] on s, every constraint as
/// NLopt inequalities / equalities with tolerance settings.constraint_tolerance, ftol_rel and
/// xtol_rel = max(settings.tolerance, kDerivativeFreeTolerance), maxeval = max_iterations.
/// Returns the best point evaluated (least violation beyond settings.feasibility_tolerance, then
/// least objective), so a stop by the deadline or cancellation keeps the best design so far.
/// No multipliers. Never throws.
LocalSolveOutcome SolveWithCobyla(ScaledDesignNlp& nlp, const std::vector<double>& s0,
                                  const LocalSolveSettings& settings);

}  // namespace sweetspot::core
