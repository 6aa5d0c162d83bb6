// event_integrator: the one adaptive ODE integrator with event location of the contact models
// (core/collision/hertz_contact.cpp, core/collision/flexible_impact.cpp; docs/models.md,
// "Contact integration").
//
// Method: Boost.Odeint's Dormand-Prince 5(4) (runge_kutta_dopri5) with dense output
// (make_dense_output(absolute, relative, max_step)). After every accepted step [ta, tb] each
// active event function g (an event is g crossing from > 0 to <= 0) is evaluated at ta and tb;
// a crossing is located on the step's dense output (calc_state) by TOMS 748 (Boost.Math) to
// full double precision. An event flagged `fires_if_already_passed` whose function is already
// <= 0 at ta and still < 0 at tb fires at ta: the state slid past it before the step began
// (a touching maximum, or an event sitting exactly on a restart point). The earliest event of
// a step (ties: the first listed) goes to the system, which stops the run or switches its
// right-hand side (a new branch); the stepper then restarts at the event with half the last
// step. Failures, reported in the summary and never thrown: max_steps accepted steps over all
// runs of one integrator, a non-finite state after a step, Odeint's step-size-adjustment error.
//
// Internal to core: included by .cpp files only, so Boost.Odeint stays out of public headers.
// Header-only because the state type (std::array for a fixed size, std::vector otherwise) and
// the system are template parameters: the right-hand side is then inlined into the stepper.
#pragma once

#include <algorithm>
#include <cmath>
#include <exception>
#include <span>
#include <string>
#include <utility>

#include <boost/math/tools/roots.hpp>
#include <boost/numeric/odeint.hpp>

#include "core/summary.hpp"

namespace sweetspot::core {

/// Settings of one event integrator (the time unit is the system's own, often a scaled time).
struct EventIntegratorOptions {
  double relative_tolerance = 1e-8;  ///< Dopri5 relative tolerance per step, in [1e-15, 1].
  double absolute_tolerance = 1e-8;  ///< Dopri5 absolute tolerance, state units (> 0).
  double max_step = 0.25;            ///< Largest step, time units (> 0).
  double initial_step = 1e-2;        ///< First step of each run, time units (> 0).
  double min_restart_step = 1e-6;    ///< Smallest first step after an event, time units (> 0).
  int max_steps = 20000;             ///< Accepted steps over all runs; reaching it fails (>= 1).
  double time_unit_s = 1.0;          ///< Seconds per time unit (messages only; > 0).
  /// What is integrated, for the step-bound message ("<subject> did not end within ...").
  const char* subject = "the integration";

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// How a run ended.
enum class EventTermination {
  kStopped,         ///< An event handler stopped it: the result is usable.
  kStepBound,       ///< max_steps reached (failure).
  kNonFinite,       ///< A step gave a non-finite state (failure).
  kStepperError,    ///< Odeint failed (step-size adjustment) or an event search threw (failure).
  kInvalidOptions,  ///< EventIntegratorOptions::IsValid failed (nothing integrated).
};

/// Stable lower-case name: "stopped", "step_bound", "non_finite", "stepper_error",
/// "invalid_options".
const char* EventTerminationName(EventTermination termination);

/// What an integrator has done so far (counts are cumulative over its runs).
struct EventIntegrationSummary {
  EventTermination termination = EventTermination::kInvalidOptions;  ///< Of the last run.
  int steps = 0;                                                     ///< Accepted steps, all runs.
  long evaluations = 0;  ///< Right-hand-side evaluations, all runs.
  double time = 0.0;     ///< Where the last run ended, time units.
  std::string message;   ///< Empty when stopped by an event; otherwise what failed, t in seconds.

  /// True when the last run was stopped by an event (its result is usable).
  bool Stopped() const { return termination == EventTermination::kStopped; }
};

/// An event function the integrator watches.
struct EventSpec {
  int id = 0;                            ///< The system's name for it.
  bool fires_if_already_passed = false;  ///< Fire at a step's start when g <= 0 there already.
};

/// What the system asks for at an event.
enum class EventAction {
  kContinue,  ///< Restart the stepper at the event (the right-hand side may have changed).
  kStop,      ///< End the run: the event's time and state are the result.
};

/// The dense-output Dormand-Prince stepper of a state type.
template <class State>
using DenseDopri5 =
    boost::numeric::odeint::dense_output_runge_kutta<boost::numeric::odeint::controlled_runge_kutta<
        boost::numeric::odeint::runge_kutta_dopri5<State>>>;

/// One accepted step as the system sees it (valid during OnStep only).
template <class State>
struct DenseStep {
  double t_start = 0.0;                         ///< ta, time units.
  double t_end = 0.0;                           ///< tb, time units.
  const State* y_start = nullptr;               ///< The state at ta.
  const State* y_end = nullptr;                 ///< The state at tb.
  const DenseDopri5<State>* stepper = nullptr;  ///< Its dense output.

  /// The interpolated state at t in [t_start, t_end] into *y (sized like the state).
  void StateAt(double t, State* y) const { stepper->calc_state(t, *y); }
};

/// Integrates a system with events. The System provides
///   void operator()(const State& y, State& dydt, double t) const;  // the right-hand side
///   std::span<const EventSpec> ActiveEvents() const;  // watched after each step, in priority
///   double EventFunction(int id, const State& y) const;  // > 0 before the event, <= 0 after
///   void OnStep(const DenseStep<State>& step);  // after each accepted step
///   EventAction OnEvent(int id, double t, const State& y);  // at each located event
/// Fresh per solve (not shared between threads); its summary accumulates over Run calls.
template <class State>
class EventIntegrator {
 public:
  /// An integrator with `options` (checked by Run).
  explicit EventIntegrator(const EventIntegratorOptions& options)
      : options_(options),
        stepper_(boost::numeric::odeint::make_dense_output(
            options.absolute_tolerance, options.relative_tolerance, options.max_step,
            boost::numeric::odeint::runge_kutta_dopri5<State>())) {}

  /// Integrates from (*y, *t) until the system stops at an event (true) or a failure (false,
  /// described in summary()). On return *y and *t hold the event's state and time, or where the
  /// failure happened. Never throws.
  template <class System>
  bool Run(System& system, State* y, double* t);

  /// Counts and the last run's termination and message.
  const EventIntegrationSummary& summary() const { return summary_; }

 private:
  template <class System>
  bool Locate(const System& system, const EventSpec& event, double ta, double tb, const State& ya,
              const State& yb, double* root);
  bool Fail(EventTermination termination, std::string message, double t, double* t_out);

  EventIntegratorOptions options_;
  DenseDopri5<State> stepper_;
  State scratch_{};  // dense-output evaluations during event location
  State event_state_{};
  EventIntegrationSummary summary_;
};

/// "<subject> did not end within max_steps = N integrator steps (t = T s): too stiff for the
/// explicit integrator at this tolerance".
std::string StepBoundMessage(const char* subject, int max_steps, double t_s);
/// "the integrated state became non-finite at t = T s".
std::string NonFiniteMessage(double t_s);

/// The error estimates of the contact models compare the run at the requested tolerance with a
/// run at tolerance / kRefineToleranceDivisor (the refine check).
inline constexpr double kRefineToleranceDivisor = 16.0;

/// The two runs of a refine check.
template <class Run>
struct RefinedRuns {
  Run coarse;            ///< At the requested tolerance.
  bool refined = false;  ///< The fine run was made (refine check on and the coarse run ok).
  Run fine;              ///< At tolerance / kRefineToleranceDivisor (when refined).
};

/// Runs `solve(tolerance)` and, when `refine_check` is on and that run succeeded (Run::ok),
/// `solve(tolerance / kRefineToleranceDivisor)`.
template <class Run, class Solve>
RefinedRuns<Run> SolveWithRefineCheck(double tolerance, bool refine_check, Solve&& solve) {
  RefinedRuns<Run> out;
  out.coarse = solve(tolerance);
  if (refine_check && out.coarse.ok) {
    out.refined = true;
    out.fine = solve(tolerance / kRefineToleranceDivisor);
  }
  return out;
}

/// Counts the runs of a refine check into a model's `summary`: iterations = the steps of both
/// runs (also returned, for the result's own step count), evaluations = theirs. A failed coarse
/// run makes `summary` a failure with the run's message (Run::ok, Run::message).
template <class Run>
int CountRefinedRuns(const RefinedRuns<Run>& runs, Summary* summary) {
  const int steps = runs.coarse.steps + (runs.refined ? runs.fine.steps : 0);
  summary->iterations = steps;
  summary->evaluations = static_cast<int>(runs.coarse.evaluations);
  if (runs.refined) summary->evaluations += static_cast<int>(runs.fine.evaluations);
  if (!runs.coarse.ok) {
    summary->termination = Termination::kFailure;
    summary->message = runs.coarse.message;
  }
  return steps;
}

/// "the refinement run at tolerance / 16 failed: <message>".
std::string RefineFailedWarning(const std::string& message);

// Implementation.

template <class State>
bool EventIntegrator<State>::Fail(EventTermination termination, std::string message, double t,
                                  double* t_out) {
  summary_.termination = termination;
  summary_.message = std::move(message);
  summary_.time = t;
  *t_out = t;
  return false;
}

template <class State>
template <class System>
bool EventIntegrator<State>::Locate(const System& system, const EventSpec& event, double ta,
                                    double tb, const State& ya, const State& yb, double* root) {
  const double ga = system.EventFunction(event.id, ya);
  const double gb = system.EventFunction(event.id, yb);
  if (!(gb <= 0.0)) return false;
  if (ga > 0.0) {
    *root = tb;
    if (gb < 0.0) {
      auto g = [&](double tt) {
        stepper_.calc_state(tt, scratch_);
        return system.EventFunction(event.id, scratch_);
      };
      boost::uintmax_t iterations = 100;
      const auto r = boost::math::tools::toms748_solve(
          g, ta, tb, ga, gb, boost::math::tools::eps_tolerance<double>(52), iterations);
      *root = 0.5 * (r.first + r.second);
    }
    return true;
  }
  if (event.fires_if_already_passed && gb < 0.0) {
    *root = ta;  // already past the event when the step began
    return true;
  }
  return false;
}

template <class State>
template <class System>
bool EventIntegrator<State>::Run(System& system, State* y, double* t) {
  if (Refusal why; !options_.Validate(&why))
    return Fail(EventTermination::kInvalidOptions, why.Message(), *t, t);
  long& evaluations = summary_.evaluations;
  auto rhs = [&system, &evaluations](const State& s, State& ds, double tt) {
    ++evaluations;
    system(s, ds, tt);
  };
  try {
    scratch_ = *y;
    event_state_ = *y;
    stepper_.initialize(*y, *t, options_.initial_step);
    while (true) {
      if (summary_.steps >= options_.max_steps) {
        const double tc = stepper_.current_time();
        *y = stepper_.current_state();
        return Fail(
            EventTermination::kStepBound,
            StepBoundMessage(options_.subject, options_.max_steps, tc * options_.time_unit_s), tc,
            t);
      }
      const std::pair<double, double> step = stepper_.do_step(rhs);
      ++summary_.steps;
      const double ta = step.first;
      const double tb = step.second;
      const State& ya = stepper_.previous_state();
      const State& yb = stepper_.current_state();
      for (double v : yb) {
        if (!std::isfinite(v)) {
          *y = yb;
          return Fail(EventTermination::kNonFinite, NonFiniteMessage(tb * options_.time_unit_s), tb,
                      t);
        }
      }
      system.OnStep(DenseStep<State>{ta, tb, &ya, &yb, &stepper_});
      int event = -1;
      double te = tb;
      for (const EventSpec& spec : system.ActiveEvents()) {
        double root = tb;
        if (!Locate(system, spec, ta, tb, ya, yb, &root)) continue;
        if (event < 0 || root < te) {
          event = spec.id;
          te = root;
        }
      }
      if (event < 0) continue;
      stepper_.calc_state(te, event_state_);
      if (system.OnEvent(event, te, event_state_) == EventAction::kStop) {
        *y = event_state_;
        *t = te;
        summary_.termination = EventTermination::kStopped;
        summary_.time = te;
        summary_.message.clear();
        return true;
      }
      stepper_.initialize(event_state_, te, std::max(options_.min_restart_step, 0.5 * (tb - ta)));
    }
  } catch (const std::exception& e) {
    return Fail(EventTermination::kStepperError, std::string("the integrator failed: ") + e.what(),
                stepper_.current_time(), t);
  }
}

}  // namespace sweetspot::core
