// event_integrator: the parts that do not depend on the state type (see event_integrator.hpp).
#include "core/numerics/event_integrator.hpp"

#include <cmath>

#include "core/geometry_format.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {

bool EventIntegratorOptions::Validate(Refusal* why) const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  const char* const kPositive = "must be finite and > 0";
  if (!(std::isfinite(relative_tolerance) && relative_tolerance >= 1e-15 &&
        relative_tolerance <= 1.0))
    return Refuse(
        why, Number17Refusal("relative_tolerance", relative_tolerance, "must be in [1e-15, 1]"));
  if (!positive(absolute_tolerance))
    return Refuse(why, Number17Refusal("absolute_tolerance", absolute_tolerance, kPositive));
  if (!positive(max_step)) return Refuse(why, Number17Refusal("max_step", max_step, kPositive));
  if (!positive(initial_step))
    return Refuse(why, Number17Refusal("initial_step", initial_step, kPositive));
  if (!positive(min_restart_step))
    return Refuse(why, Number17Refusal("min_restart_step", min_restart_step, kPositive));
  if (max_steps < 1) return Refuse(why, IntegerRefusal("max_steps", max_steps, "must be >= 1"));
  if (!positive(time_unit_s))
    return Refuse(why, Number17Refusal("time_unit_s", time_unit_s, kPositive));
  if (subject == nullptr) {
    return Refuse(why, Refusal{"subject", std::numeric_limits<double>::quiet_NaN(), "null",
                               "must name what is integrated"});
  }
  return true;
}

const char* EventTerminationName(EventTermination termination) {
  switch (termination) {
    case EventTermination::kStopped:
      return "stopped";
    case EventTermination::kStepBound:
      return "step_bound";
    case EventTermination::kNonFinite:
      return "non_finite";
    case EventTermination::kStepperError:
      return "stepper_error";
    case EventTermination::kInvalidOptions:
      return "invalid_options";
  }
  return "invalid_options";
}

std::string StepBoundMessage(const char* subject, int max_steps, double t_s) {
  return std::string(subject) + " did not end within max_steps = " + std::to_string(max_steps) +
         " integrator steps (t = " + FormatNumber17(t_s) +
         " s): too stiff for the explicit integrator at this tolerance";
}

std::string NonFiniteMessage(double t_s) {
  return "the integrated state became non-finite at t = " + FormatNumber17(t_s) + " s";
}

std::string RefineFailedWarning(const std::string& message) {
  return "the refinement run at tolerance / " + FormatNumber17(kRefineToleranceDivisor) +
         " failed: " + message;
}

}  // namespace sweetspot::core
