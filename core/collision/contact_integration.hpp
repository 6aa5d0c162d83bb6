// What the two contact models (hertz_contact.cpp and flexible_impact.cpp) share around the
// event integrator: the events of one contact, the integrator's settings for a contact, and the
// opening of a solve (backend, model, refusal of invalid input). Internal to core/collision/:
// included by .cpp files only, not part of core's API.
#pragma once

#include <span>
#include <string>

#include "core/numerics/event_integrator.hpp"
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

/// Opens the summary of a contact model's solve: backend "odeint:runge_kutta_dopri5",
/// models_used {`model`}. False, with the first refusal as the summary's message (its
/// termination is left as it is, invalid input in a TimedSolve), when one of `checked` (in
/// order, each with `bool IsValid(std::string*) const`) is not valid.
template <class... Checked>
bool StartContactSolve(const char* model, Summary* summary, const Checked&... checked) {
  summary->backend = "odeint:runge_kutta_dopri5";
  summary->models_used = {model};
  std::string why;
  if ((checked.IsValid(&why) && ...)) return true;
  summary->message = why;
  return false;
}

}  // namespace sweetspot::core
