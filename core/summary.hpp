// The result report every solve returns, whatever happened (Ceres-style): a
// backend-neutral termination, the backend's raw status, counts, timings and
// the model(s) used. Solvers never throw; they fill a Summary.
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/refusal.hpp"

namespace sweetspot::core {

/// Backend-neutral outcome of a solve.
enum class Termination {
  kConverged,      ///< Converged to the requested tolerance; the result is usable.
  kNoConvergence,  ///< Stopped early (iterations, time, round-off); best point kept, usable with care.
  kInfeasible,     ///< No point satisfies the constraints; the closest point may be reported.
  kFailure,        ///< The solver failed; the result must not be used.
  kInvalidInput,   ///< The input was refused before solving; see message.
};

/// Stable lower-case name: "converged", "no_convergence", "infeasible", "failure", "invalid_input".
const char* TerminationName(Termination t);

/// What a solve reports. Sentinels: -1 = "not computed" for counts and times.
struct Summary {
  Termination termination = Termination::kInvalidInput;  ///< Outcome.
  std::string message;             ///< Human-readable reason, names fields for invalid input.
  std::string backend;             ///< "closed_form", "nlopt:<algorithm>", "ipopt", "newton", ...
  int raw_status = 0;              ///< The backend's own status code (NLopt result, Ipopt status).
  int iterations = -1;             ///< Iterations taken, -1 if not applicable.
  int evaluations = -1;            ///< Objective evaluations, -1 if not applicable.
  double objective = 0.0;          ///< Final objective value (problem units).
  double constraint_violation = 0.0;  ///< Largest constraint violation at the result (problem units).
  double error_estimate = 0.0;     ///< Estimated error of the main result (problem units).
  double solve_time_s = -1.0;      ///< Wall time of the solve, s.
  std::vector<std::string> models_used;  ///< Models evaluated, e.g. {"mass_properties", "rigid_pivot"}.
  std::vector<std::string> warnings;     ///< Non-fatal notes (e.g. NLopt round-off limited).
  /// For invalid input, the refusal as data (core's field names, the value, the rule): the
  /// one `message` states (or, for a solve that reports several outcomes, the first refused
  /// one). Empty when the solve did not refuse its input as data.
  std::optional<Refusal> refusal;

  /// Refuses the input: termination kInvalidInput, message = refusal.Message(), and the
  /// refusal kept as data.
  void SetRefusal(Refusal why);

  /// Every field as a default-constructed summary has it, the strings and vectors keeping
  /// their buffers.
  void Reset();

  /// True when the result may be used (converged, or no_convergence with a kept point).
  bool IsSolutionUsable() const {
    return termination == Termination::kConverged || termination == Termination::kNoConvergence;
  }
  /// One line: termination, backend, iterations, time.
  std::string BriefReport() const;
  /// Every field, one per line.
  std::string FullReport() const;
};

/// The message of the exception being handled: "internal error: " + what() for a
/// std::exception, "internal error" for anything else. Call only inside a catch block.
std::string InternalErrorMessage();

/// Runs `body()`; what it throws makes `*summary` a failure with InternalErrorMessage(), so
/// that no exception leaves a solve.
template <class Body>
void CatchInternalError(Summary* summary, Body&& body) {
  try {
    std::forward<Body>(body)();
  } catch (...) {
    summary->termination = Termination::kFailure;
    summary->message = InternalErrorMessage();
  }
}

}  // namespace sweetspot::core
