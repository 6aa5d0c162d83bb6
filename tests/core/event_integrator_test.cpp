// The contact models' event integrator (core/numerics/event_integrator.hpp) on problems with
// closed-form answers: a harmonic oscillator's first zero crossing, an event already passed
// when a step begins, the step bound, the non-finite guard, option checks and the refine check.
#include "core/numerics/event_integrator.hpp"

#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include "core/units.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace event_integrator_test {
namespace {

// y'' = -w^2 y, y(0) = 1, y'(0) = 0: y = cos(w t), first zero at pi / (2 w), where y' = -w.
// One event: y falls through 0 (stops the run).
template <class State>
struct Oscillator {
  double w = 3.0;
  int steps_seen = 0;
  static constexpr EventSpec kEvents[] = {{0, false}};
  void operator()(const State& y, State& dy, double /*t*/) const {
    dy[0] = y[1];
    dy[1] = -w * w * y[0];
  }
  std::span<const EventSpec> ActiveEvents() const { return kEvents; }
  double EventFunction(int /*id*/, const State& y) const { return y[0]; }
  void OnStep(const DenseStep<State>& /*step*/) { ++steps_seen; }
  EventAction OnEvent(int /*id*/, double /*t*/, const State& /*y*/) { return EventAction::kStop; }
};

EventIntegratorOptions Tight() {
  EventIntegratorOptions o;
  o.relative_tolerance = 1e-10;
  o.absolute_tolerance = 1e-10;
  return o;
}

TEST(EventIntegrator, DefaultOptionsAreValid) {
  std::string why;
  EXPECT_TRUE(Validates(EventIntegratorOptions{}, &why)) << why;
}

TEST(EventIntegrator, HarmonicOscillatorFirstZeroCrossing) {
  using State = std::array<double, 2>;
  Oscillator<State> sys;
  EventIntegrator<State> integrator(Tight());
  State y{1.0, 0.0};
  double t = 0.0;
  ASSERT_TRUE(integrator.Run(sys, &y, &t)) << integrator.summary().message;
  EXPECT_EQ(integrator.summary().termination, EventTermination::kStopped);
  EXPECT_TRUE(integrator.summary().message.empty());
  const int steps = integrator.summary().steps;
  EXPECT_EQ(sys.steps_seen, steps);
  EXPECT_GT(steps, 2);  // max_step 0.25 alone needs 3 steps to reach pi/6 = 0.52
  EXPECT_LT(steps, 60);
  // Tolerance: Dopri5 keeps each step's local error near abs + rel |y| <= 2e-10; over fewer
  // than 60 steps (asserted above) of a problem whose solution does not grow, the global error
  // of y is below 60 x 2e-10 = 1.2e-8, and the event time's error is that divided by the
  // crossing slope |y'| = w = 3 (the location on the dense output itself is exact to ~1e-16).
  // 1e-8 for the time and 1.2e-8 / 3 relative for y' are therefore safe upper bounds.
  EXPECT_NEAR(t, kPi / (2.0 * sys.w), 1e-8);
  EXPECT_NEAR(y[0], 0.0, 1e-15);  // located to full precision on the dense output
  EXPECT_NEAR(y[1] / -sys.w, 1.0, 4e-9);
  EXPECT_EQ(integrator.summary().time, t);
  // FSAL Dopri5: one derivative to start, then 6 new evaluations per attempted step.
  EXPECT_GE(integrator.summary().evaluations, 1 + 6L * steps);
}

TEST(EventIntegrator, DynamicStateGivesTheSameAnswerAsAFixedOne) {
  using Fixed = std::array<double, 2>;
  using Dynamic = std::vector<double>;
  Oscillator<Fixed> a;
  Oscillator<Dynamic> b;
  EventIntegrator<Fixed> ia(Tight());
  EventIntegrator<Dynamic> ib(Tight());
  Fixed ya{1.0, 0.0};
  Dynamic yb{1.0, 0.0};
  double ta = 0.0, tb = 0.0;
  ASSERT_TRUE(ia.Run(a, &ya, &ta));
  ASSERT_TRUE(ib.Run(b, &yb, &tb));
  // The same arithmetic in the same order: bit-identical.
  EXPECT_EQ(ta, tb);
  EXPECT_EQ(ya[1], yb[1]);
  EXPECT_EQ(ia.summary().steps, ib.summary().steps);
}

// y' = 1 from y(0) = 0 (Dopri5 integrates it exactly: y = t). Event 0 at y = 1 switches to a
// second phase whose event 1 (y above `threshold`) is already passed at the restart point:
// threshold = 1 - 1e-9. Event 2 (y = 3) stops the run if event 1 never fires.
struct AlreadyPassed {
  bool flag = true;
  int phase = 0;
  double threshold = 0.0;
  double first_event_t = -1.0;
  int fired = -1;
  EventSpec phase0[1] = {{0, false}};
  EventSpec phase1[2] = {{1, true}, {2, false}};
  void operator()(const std::array<double, 1>& /*y*/, std::array<double, 1>& dy,
                  double /*t*/) const {
    dy[0] = 1.0;
  }
  std::span<const EventSpec> ActiveEvents() const {
    if (phase == 0) return phase0;
    return phase1;
  }
  double EventFunction(int id, const std::array<double, 1>& y) const {
    if (id == 0) return 1.0 - y[0];
    if (id == 1) return threshold - y[0];
    return 3.0 - y[0];
  }
  void OnStep(const DenseStep<std::array<double, 1>>& /*step*/) {}
  EventAction OnEvent(int id, double t, const std::array<double, 1>& y) {
    if (id == 0) {
      phase = 1;
      first_event_t = t;
      threshold = y[0] - 1e-9;  // already below y: the event lies before the restart
      phase1[0].fires_if_already_passed = flag;
      return EventAction::kContinue;
    }
    fired = id;
    return EventAction::kStop;
  }
};

TEST(EventIntegrator, AnEventAlreadyPassedAtAStepsStartFiresThere) {
  AlreadyPassed sys;
  EventIntegrator<std::array<double, 1>> integrator(Tight());
  std::array<double, 1> y{0.0};
  double t = 0.0;
  ASSERT_TRUE(integrator.Run(sys, &y, &t)) << integrator.summary().message;
  EXPECT_EQ(sys.fired, 1);
  // y = t exactly (a constant right-hand side), so the first event is at 1 to rounding; the
  // already-passed event fires at the start of the first step after the restart: that time.
  EXPECT_NEAR(sys.first_event_t, 1.0, 1e-15);
  EXPECT_EQ(t, sys.first_event_t);
}

TEST(EventIntegrator, WithoutTheFlagAnAlreadyPassedEventNeverFires) {
  AlreadyPassed sys;
  sys.flag = false;
  EventIntegrator<std::array<double, 1>> integrator(Tight());
  std::array<double, 1> y{0.0};
  double t = 0.0;
  ASSERT_TRUE(integrator.Run(sys, &y, &t)) << integrator.summary().message;
  EXPECT_EQ(sys.fired, 2);
  EXPECT_NEAR(t, 3.0, 1e-14);  // y = t exactly: the stop event at y = 3, to rounding
}

TEST(EventIntegrator, TheStepBoundIsAReportedFailureCountedOverRuns) {
  using State = std::array<double, 2>;
  Oscillator<State> sys;
  EventIntegratorOptions o = Tight();
  o.max_steps = 1000;
  o.subject = "the oscillation";
  EventIntegrator<State> integrator(o);
  State y{1.0, 0.0};
  double t = 0.0;
  ASSERT_TRUE(integrator.Run(sys, &y, &t));
  const int first = integrator.summary().steps;
  // A second run from the same start continues the count.
  y = {1.0, 0.0};
  t = 0.0;
  ASSERT_TRUE(integrator.Run(sys, &y, &t));
  EXPECT_EQ(integrator.summary().steps, 2 * first);

  o.max_steps = 2;  // fewer than the 3 steps the first zero needs
  EventIntegrator<State> bounded(o);
  y = {1.0, 0.0};
  t = 0.0;
  EXPECT_FALSE(bounded.Run(sys, &y, &t));
  EXPECT_EQ(bounded.summary().termination, EventTermination::kStepBound);
  EXPECT_EQ(bounded.summary().steps, 2);
  EXPECT_GT(t, 0.0);
  EXPECT_LE(t, 0.5);  // two steps of at most max_step = 0.25
  EXPECT_EQ(t, bounded.summary().time);
  EXPECT_EQ(bounded.summary().message, StepBoundMessage("the oscillation", 2, t));
  EXPECT_EQ(bounded.summary().message.rfind("the oscillation did not end within max_steps = 2 "
                                            "integrator steps (t = ",
                                            0),
            0u);
}

// y' = 1 until y passes 0.5, then a NaN derivative: the step that samples it gives a NaN
// state (Odeint's error norm is NaN, which no controller rejects), and the guard stops there.
struct Poisoned {
  static constexpr EventSpec kEvents[] = {{0, false}};
  void operator()(const std::array<double, 1>& y, std::array<double, 1>& dy, double) const {
    dy[0] = y[0] > 0.5 ? std::numeric_limits<double>::quiet_NaN() : 1.0;
  }
  std::span<const EventSpec> ActiveEvents() const { return kEvents; }
  double EventFunction(int, const std::array<double, 1>& y) const { return 10.0 - y[0]; }
  void OnStep(const DenseStep<std::array<double, 1>>&) {}
  EventAction OnEvent(int, double, const std::array<double, 1>&) { return EventAction::kStop; }
};

TEST(EventIntegrator, ANonFiniteStateIsAReportedFailure) {
  Poisoned sys;
  EventIntegratorOptions o;
  o.time_unit_s = 2e-3;  // messages are in seconds
  EventIntegrator<std::array<double, 1>> integrator(o);
  std::array<double, 1> y{0.0};
  double t = 0.0;
  EXPECT_FALSE(integrator.Run(sys, &y, &t));
  EXPECT_EQ(integrator.summary().termination, EventTermination::kNonFinite);
  EXPECT_TRUE(std::isnan(y[0]));
  EXPECT_GT(t, 0.0);
  EXPECT_LE(t, 0.5 + 0.25);  // the poisoned step starts at most at y = t = 0.5
  EXPECT_EQ(integrator.summary().message, NonFiniteMessage(t * 2e-3));
  EXPECT_EQ(integrator.summary().message.rfind("the integrated state became non-finite at t = ", 0),
            0u);
}

TEST(EventIntegrator, InvalidOptionsAreReportedNotIntegrated) {
  using State = std::array<double, 2>;
  Oscillator<State> sys;
  EventIntegratorOptions o;
  o.relative_tolerance = 0.0;
  std::string why;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "relative_tolerance = 0: must be in [1e-15, 1]");
  EventIntegrator<State> integrator(o);
  State y{1.0, 0.0};
  double t = 0.0;
  EXPECT_FALSE(integrator.Run(sys, &y, &t));
  EXPECT_EQ(integrator.summary().termination, EventTermination::kInvalidOptions);
  EXPECT_EQ(integrator.summary().message, why);
  EXPECT_EQ(integrator.summary().steps, 0);
  EXPECT_EQ(sys.steps_seen, 0);
  o = EventIntegratorOptions{};
  o.max_steps = 0;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "max_steps = 0: must be >= 1");
  o = EventIntegratorOptions{};
  o.time_unit_s = -1.0;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "time_unit_s = -1: must be finite and > 0");
}

struct FakeRun {
  bool ok = false;
  double tolerance = 0.0;
};

TEST(EventIntegrator, TheRefineCheckRunsAtASixteenthOfTheTolerance) {
  auto solve = [](bool ok) { return [ok](double tol) { return FakeRun{ok, tol}; }; };
  const RefinedRuns<FakeRun> r = SolveWithRefineCheck<FakeRun>(1e-8, true, solve(true));
  EXPECT_TRUE(r.refined);
  EXPECT_EQ(r.coarse.tolerance, 1e-8);
  EXPECT_EQ(r.fine.tolerance, 1e-8 / 16.0);
  EXPECT_FALSE((SolveWithRefineCheck<FakeRun>(1e-8, false, solve(true)).refined));
  EXPECT_FALSE((SolveWithRefineCheck<FakeRun>(1e-8, true, solve(false)).refined));
  EXPECT_EQ(RefineFailedWarning("x"), "the refinement run at tolerance / 16 failed: x");
  EXPECT_STREQ(EventTerminationName(EventTermination::kStepBound), "step_bound");
}

struct CountedRun {
  bool ok = false;
  int steps = 0;
  long evaluations = 0;
  std::string message;
};

TEST(EventIntegrator, CountRefinedRunsAddsBothRunsAndReportsAFailedCoarseRun) {
  RefinedRuns<CountedRun> runs;
  runs.coarse = {true, 40, 250, ""};
  runs.fine = {false, 90, 560, "the step bound"};
  Summary s;
  EXPECT_EQ(CountRefinedRuns(runs, &s), 40);  // the fine run was not made
  EXPECT_EQ(s.iterations, 40);
  EXPECT_EQ(s.evaluations, 250);
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  runs.refined = true;  // a failed fine run is counted, and is the caller's warning
  EXPECT_EQ(CountRefinedRuns(runs, &s), 130);
  EXPECT_EQ(s.iterations, 130);
  EXPECT_EQ(s.evaluations, 810);
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  EXPECT_EQ(s.message, "");
  runs = RefinedRuns<CountedRun>{};
  runs.coarse = {false, 12, 80, "the contact: non-finite state"};
  EXPECT_EQ(CountRefinedRuns(runs, &s), 12);
  EXPECT_EQ(s.evaluations, 80);
  EXPECT_EQ(s.termination, Termination::kFailure);
  EXPECT_EQ(s.message, "the contact: non-finite state");
}

}  // namespace
}  // namespace event_integrator_test
}  // namespace sweetspot::core
