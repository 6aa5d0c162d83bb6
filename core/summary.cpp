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
