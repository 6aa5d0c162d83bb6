#include "core/summary.hpp"

#include <exception>
#include <sstream>
#include <utility>

namespace sweetspot::core {

const char* TerminationName(Termination t) {
  switch (t) {
    case Termination::kConverged:
      return "converged";
    case Termination::kNoConvergence:
      return "no_convergence";
    case Termination::kInfeasible:
      return "infeasible";
    case Termination::kFailure:
      return "failure";
    case Termination::kInvalidInput:
      return "invalid_input";
  }
  return "failure";
}

void Summary::SetRefusal(Refusal why) {
  termination = Termination::kInvalidInput;
  message = why.Message();
  refusal = std::move(why);
}

void Summary::Reset() {
  // A field added to Summary must be reset here too: on x86-64 (the size this list was
  // written for) the size check says so.
#if defined(__x86_64__)
  static_assert(sizeof(Summary) == 280, "Summary gained a field: reset it in Summary::Reset");
#endif
  termination = Termination::kInvalidInput;
  message.clear();
  backend.clear();
  raw_status = 0;
  iterations = -1;
  evaluations = -1;
  objective = 0.0;
  constraint_violation = 0.0;
  error_estimate = 0.0;
  solve_time_s = -1.0;
  models_used.clear();
  warnings.clear();
  refusal.reset();
}

std::string InternalErrorMessage() {
  try {
    throw;
  } catch (const std::exception& e) {
    return std::string("internal error: ") + e.what();
  } catch (...) {
    return "internal error";
  }
}

std::string Summary::BriefReport() const {
  std::ostringstream out;
  out << TerminationName(termination) << " (" << backend << ", raw " << raw_status
      << "): " << iterations << " iterations, " << evaluations << " evaluations, "
      << solve_time_s << " s";
  if (!message.empty()) out << " - " << message;
  return out.str();
}

std::string Summary::FullReport() const {
  std::ostringstream out;
  out.precision(17);
  out << "termination: " << TerminationName(termination) << "\n"
      << "message: " << message << "\n"
      << "backend: " << backend << "\n"
      << "raw_status: " << raw_status << "\n"
      << "iterations: " << iterations << "\n"
      << "evaluations: " << evaluations << "\n"
      << "objective: " << objective << "\n"
      << "constraint_violation: " << constraint_violation << "\n"
      << "error_estimate: " << error_estimate << "\n"
      << "solve_time_s: " << solve_time_s << "\n"
      << "models_used:";
  for (const auto& m : models_used) out << " " << m;
  out << "\nwarnings:";
  for (const auto& w : warnings) out << " [" << w << "]";
  out << "\n";
  return out.str();
}

}  // namespace sweetspot::core
