// What the contact models (hertz_contact.cpp, flexible_impact.cpp, barrel.cpp) share around the
// event integrator: the events of one contact, the integrator's settings for a contact, and the
// opening of a solve (backend, model, refusal of invalid input). Internal to core/collision/:
// included by .cpp files only, not part of core's API.
#pragma once

#include <cmath>
#include <span>
#include <string>
#include <string_view>

#include "core/numerics/event_integrator.hpp"
#include "core/refusal.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// The events of one contact (each crosses from > 0 to <= 0): the compression rate falls
/// through 0 (maximum compression), the compression falls through 0 (separation), the
/// compression rises back above its maximum (reload; it may already be above it when an
/// unloading step begins).
enum ContactEventId : int { kMaxCompression, kEnd, kReload };

/// The events watched on the loading branch (maximum compression, separation) or on the
/// unloading branch (separation, reload).
inline std::span<const EventSpec> ContactEvents(bool unloading) {
  static constexpr EventSpec kLoading[] = {{kMaxCompression, false}, {kEnd, false}};
  static constexpr EventSpec kUnloading[] = {{kEnd, false}, {kReload, true}};
  if (unloading) return kUnloading;
  return kLoading;
}

/// The value of contact event `id` (ContactEventId) for a compression `delta`, its rate
/// `delta_rate` and the branch's maximum compression `delta_max`, all on one scale: the rate
/// (maximum compression), the compression (separation), delta_max - delta (reload). For the
/// models whose compression and rate are state entries (hertz, barrel); the flexible model
/// computes them from modal sums only for the event asked.
inline double ContactEventValue(int id, double delta, double delta_rate, double delta_max) {
  switch (id) {
    case kMaxCompression:
      return delta_rate;
    case kEnd:
      return delta;
    default:
      return delta_max - delta;
  }
}

/// The integrator's settings for one contact: relative and absolute tolerance `tolerance` (on
/// the scaled state), at most `max_steps` accepted steps, `time_unit_s` seconds per unit of the
/// scaled time, messages about "the contact".
inline EventIntegratorOptions ContactIntegratorOptions(double tolerance, int max_steps,
                                                       double time_unit_s) {
  EventIntegratorOptions o;
  o.relative_tolerance = tolerance;
  o.absolute_tolerance = tolerance;
  o.max_steps = max_steps;
  o.time_unit_s = time_unit_s;
  o.subject = "the contact";
  return o;
}

/// The integrator rules both contact models' options share, checked in this order:
/// `relative_tolerance` in [1e-13, 1e-2] (dimensionless), `max_steps` >= 10. `model` ("hertz",
/// "flexible") prefixes the field names. False, with the refusal ("model.field") in *why (if
/// non-null), when one is broken.
inline bool ContactIntegrationValidate(std::string_view model, double relative_tolerance,
                                       int max_steps, Refusal* why) {
  const std::string prefix = std::string(model) + ".";
  if (!(std::isfinite(relative_tolerance) && relative_tolerance >= 1e-13 &&
        relative_tolerance <= 1e-2))
    return Refuse(why, Number17Refusal(prefix + "relative_tolerance", relative_tolerance,
                                       "must be in [1e-13, 1e-2]"));
  if (max_steps < 10)
    return Refuse(why, IntegerRefusal(prefix + "max_steps", max_steps, "must be >= 10"));
  return true;
}

/// The ball law's rules both contact models check, in this order: `ball_stiffness` (the power
/// law's constant, N/m^exponent) finite and > 0, `ball_exponent` in [1, 3]. False, with the
/// refusal ("ball.field") in *why (if non-null), when one is broken.
inline bool BallLawValidate(double ball_stiffness, double ball_exponent, Refusal* why) {
  if (!(std::isfinite(ball_stiffness) && ball_stiffness > 0.0))
    return Refuse(why, Number17Refusal("ball.stiffness", ball_stiffness, "must be finite and > 0"));
  if (!(std::isfinite(ball_exponent) && ball_exponent >= 1.0 && ball_exponent <= 3.0))
    return Refuse(why,
                  Number17Refusal("ball.stiffness_exponent", ball_exponent, "must be in [1, 3]"));
  return true;
}

/// Opens the summary of a contact model's solve: backend "odeint:runge_kutta_dopri5",
/// models_used {`model`}. False, with the first refusal as the summary's message (its
/// termination is left as it is, invalid input in a TimedSolve), when one of `checked` (in
/// order, each with `bool Validate(Refusal*) const`) is not valid.
template <class... Checked>
bool StartContactSolve(const char* model, Summary* summary, const Checked&... checked) {
  summary->backend = "odeint:runge_kutta_dopri5";
  summary->models_used = {model};
  Refusal why;
  if ((checked.Validate(&why) && ...)) return true;
  summary->message = why.Message();
  return false;
}

}  // namespace sweetspot::core
