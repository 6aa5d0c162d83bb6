// Internal to core: the one NLopt trampoline. Every NLopt run of core (the scalar search, the
// NLopt design backends, the shape fit) goes through RunNlopt, which owns the nlopt::opt, the
// C callbacks that never let an exception cross NLopt, the deadline and cancellation checks,
// the seeding of stochastic algorithms, and the exception ladder that keeps the round-off point.
// NLopt's headers stay in nlopt_run.cpp; this header speaks std types only.
#pragma once

#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "core/numerics/nlopt_search.hpp"
#include "core/progress.hpp"

namespace sweetspot::core {

/// A function NLopt calls: its value at x (n values) and, when `gradient` is not null, its
/// gradient into gradient[0..n). A non-finite value stops the run (FORCED_STOP with
/// NloptRunOutcome::callback_failed); an exception thrown by it is caught, stops the run the
/// same way and is described in NloptRunOutcome::message.
using NloptFunction = std::function<double(const double* x, double* gradient)>;

/// One constraint of a run: value(x) <= 0 (inequality) or value(x) = 0 (equality).
struct NloptConstraintFunction {
  NloptFunction value;     ///< The constraint function (same contract as the objective).
  bool equality = false;   ///< True: value(x) = 0; false: value(x) <= 0.
  double tolerance = 0.0;  ///< NLopt's tolerance on the constraint (its units, >= 0).
};

/// Settings of one NLopt run; a zero tolerance or budget is left unset.
struct NloptRunSettings {
  NloptAlgorithm algorithm = NloptAlgorithm::kLdSlsqp;  ///< The algorithm.
  std::vector<double> lower;     ///< Lower bounds (empty = none); the start is clamped into them.
  std::vector<double> upper;     ///< Upper bounds (empty = none).
  double x_tolerance_rel = 0.0;  ///< NLopt xtol_rel (dimensionless).
  double x_tolerance_abs = 0.0;  ///< NLopt xtol_abs, the same for every variable (x units).
  double f_tolerance_rel = 0.0;  ///< NLopt ftol_rel (dimensionless).
  double f_tolerance_abs = 0.0;  ///< NLopt ftol_abs (objective units).
  int max_evaluations = 0;       ///< NLopt maxeval (0 = unlimited).
  double max_time_s = 0.0;       ///< NLopt maxtime, s (0 = unlimited).
  double initial_step = 0.0;  ///< NLopt's initial step for derivative-free methods (0 = its own).
  std::optional<unsigned> seed;  ///< nlopt::srand(seed) in this thread right before optimize().
  /// The objective stops the run (FORCED_STOP, deadline_reached) when called after this.
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
  const Progress* progress = nullptr;  ///< The objective stops the run when it is cancelled.
};

/// What one run gave.
struct NloptRunOutcome {
  int raw_status = -1;            ///< NLopt's result code (exceptions mapped by the ladder).
  double minimum = 0.0;           ///< The objective NLopt reports at x (meaningless on failures).
  int evaluations = 0;            ///< Objective evaluations NLopt counted.
  bool cancelled = false;         ///< Stopped because `progress` was cancelled.
  bool deadline_reached = false;  ///< Stopped because the deadline passed.
  bool callback_failed = false;   ///< Stopped because a function gave no finite value or threw.
  std::string message;            ///< NLopt's or a callback's error, empty when none.
};

/// Minimises `objective` subject to `constraints` from *x, leaving in *x the point NLopt
/// returns (also on ROUNDOFF_LIMITED, where it is NLopt's best; on other stops whatever NLopt
/// left). Never throws.
NloptRunOutcome RunNlopt(const NloptFunction& objective,
                         const std::vector<NloptConstraintFunction>& constraints,
                         const NloptRunSettings& settings, std::vector<double>* x);

}  // namespace sweetspot::core
