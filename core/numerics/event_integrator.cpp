// event_integrator: the parts that do not depend on the state type (see event_integrator.hpp).
#include "core/numerics/event_integrator.hpp"

#include <cmath>

#include "core/geometry_format.hpp"

namespace sweetspot::core {
namespace {

bool Fail(std::string* why, const std::string& m) {
  if (why != nullptr) *why = m;
  return false;
}

}  // namespace

bool EventIntegratorOptions::IsValid(std::string* why) const {
  auto positive = [](double v) { return std::isfinite(v) && v > 0.0; };
  if (!(std::isfinite(relative_tolerance) && relative_tolerance >= 1e-15 &&
        relative_tolerance <= 1.0))
    return Fail(why, "relative_tolerance = " + FormatNumber17(relative_tolerance) +
                         ": must be in [1e-15, 1]");
  if (!positive(absolute_tolerance))
    return Fail(why, "absolute_tolerance = " + FormatNumber17(absolute_tolerance) +
                         ": must be finite and > 0");
  if (!positive(max_step))
    return Fail(why, "max_step = " + FormatNumber17(max_step) + ": must be finite and > 0");
  if (!positive(initial_step))
    return Fail(why, "initial_step = " + FormatNumber17(initial_step) + ": must be finite and > 0");
  if (!positive(min_restart_step))
    return Fail(
        why, "min_restart_step = " + FormatNumber17(min_restart_step) + ": must be finite and > 0");
  if (max_steps < 1)
    return Fail(why, "max_steps = " + std::to_string(max_steps) + ": must be >= 1");
  if (!positive(time_unit_s))
    return Fail(why, "time_unit_s = " + FormatNumber17(time_unit_s) + ": must be finite and > 0");
  if (subject == nullptr) return Fail(why, "subject = null: must name what is integrated");
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
