// The termination mapping of every backend (core/numerics/termination.hpp) and the NLopt
// trampoline (core/numerics/nlopt_run.hpp): every NLopt result code and exception type, every
// Ipopt status, and the trampoline's stops (callback failure, cancellation, deadline).
#include "core/numerics/termination.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

// The test throws NLopt's own exception types (header-only classes; no solver code runs).
#include <nlopt.hpp>

#include "core/numerics/nlopt_run.hpp"

namespace sweetspot::core {
namespace {

TEST(TerminationTest, EveryNloptResultCodeMapsToATermination) {
  EXPECT_EQ(TerminationFromNloptResult(1), Termination::kConverged);      // SUCCESS
  EXPECT_EQ(TerminationFromNloptResult(2), Termination::kConverged);      // STOPVAL_REACHED
  EXPECT_EQ(TerminationFromNloptResult(3), Termination::kConverged);      // FTOL_REACHED
  EXPECT_EQ(TerminationFromNloptResult(4), Termination::kConverged);      // XTOL_REACHED
  EXPECT_EQ(TerminationFromNloptResult(5), Termination::kNoConvergence);  // MAXEVAL_REACHED
  EXPECT_EQ(TerminationFromNloptResult(6), Termination::kNoConvergence);  // MAXTIME_REACHED
  EXPECT_EQ(TerminationFromNloptResult(-1), Termination::kFailure);       // FAILURE
  EXPECT_EQ(TerminationFromNloptResult(-2), Termination::kInvalidInput);  // INVALID_ARGS
  EXPECT_EQ(TerminationFromNloptResult(-3), Termination::kFailure);       // OUT_OF_MEMORY
  EXPECT_EQ(TerminationFromNloptResult(-4),
            Termination::kNoConvergence);                            // ROUNDOFF_LIMITED: point kept
  EXPECT_EQ(TerminationFromNloptResult(-5), Termination::kFailure);  // FORCED_STOP
  EXPECT_EQ(TerminationFromNloptResult(42), Termination::kFailure);  // unknown
  EXPECT_STREQ(NloptResultName(-4), "ROUNDOFF_LIMITED");
  EXPECT_STREQ(NloptResultName(7), "UNKNOWN");
}

TEST(TerminationTest, EveryIpoptStatusMapsToATermination) {
  const struct {
    int status;
    const char* name;
    Termination termination;
  } cases[] = {
      {0, "Solve_Succeeded", Termination::kConverged},
      {1, "Solved_To_Acceptable_Level", Termination::kConverged},
      {2, "Infeasible_Problem_Detected", Termination::kInfeasible},
      {3, "Search_Direction_Becomes_Too_Small", Termination::kNoConvergence},
      {4, "Diverging_Iterates", Termination::kFailure},
      {5, "User_Requested_Stop", Termination::kNoConvergence},
      {6, "Feasible_Point_Found", Termination::kNoConvergence},
      {-1, "Maximum_Iterations_Exceeded", Termination::kNoConvergence},
      {-2, "Restoration_Failed", Termination::kFailure},
      {-3, "Error_In_Step_Computation", Termination::kFailure},
      {-4, "Maximum_CpuTime_Exceeded", Termination::kNoConvergence},
      {-10, "Not_Enough_Degrees_Of_Freedom", Termination::kInvalidInput},
      {-11, "Invalid_Problem_Definition", Termination::kInvalidInput},
      {-12, "Invalid_Option", Termination::kInvalidInput},
      {-13, "Invalid_Number_Detected", Termination::kFailure},
      {-100, "Unrecoverable_Exception", Termination::kFailure},
      {-101, "NonIpopt_Exception_Thrown", Termination::kFailure},
      {-102, "Insufficient_Memory", Termination::kFailure},
      {-199, "Internal_Error", Termination::kFailure},
      {42, "Unknown", Termination::kFailure},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(TerminationFromIpoptStatus(c.status), c.termination) << c.status;
    EXPECT_STREQ(IpoptStatusName(c.status), c.name);
  }
}

TEST(TerminationTest, EveryNloptResultCodeHasItsName) {
  const struct {
    int code;
    const char* name;
  } cases[] = {
      {kNloptForcedStop, "FORCED_STOP"},
      {kNloptRoundoffLimited, "ROUNDOFF_LIMITED"},
      {kNloptOutOfMemory, "OUT_OF_MEMORY"},
      {kNloptInvalidArgs, "INVALID_ARGS"},
      {kNloptFailure, "FAILURE"},
      {kNloptSuccess, "SUCCESS"},
      {kNloptStopvalReached, "STOPVAL_REACHED"},
      {kNloptFtolReached, "FTOL_REACHED"},
      {kNloptXtolReached, "XTOL_REACHED"},
      {kNloptMaxevalReached, "MAXEVAL_REACHED"},
      {kNloptMaxtimeReached, "MAXTIME_REACHED"},
  };
  for (const auto& c : cases) EXPECT_STREQ(NloptResultName(c.code), c.name) << c.code;
}

// The exception ladder: each exception NLopt's C++ wrapper throws (and anything else) becomes
// its result code, with the text where it has one.
TEST(TerminationTest, EveryNloptExceptionMapsToItsResultCode) {
  std::string message = "unchanged";
  EXPECT_EQ(NloptResultFromException(std::make_exception_ptr(nlopt::roundoff_limited()), &message),
            kNloptRoundoffLimited);
  EXPECT_EQ(message, "");
  EXPECT_EQ(TerminationFromNloptResult(kNloptRoundoffLimited), Termination::kNoConvergence);
  EXPECT_EQ(NloptResultFromException(std::make_exception_ptr(nlopt::forced_stop()), &message),
            kNloptForcedStop);
  EXPECT_EQ(message, "");
  EXPECT_EQ(NloptResultFromException(
                std::make_exception_ptr(std::invalid_argument("nlopt invalid argument")), &message),
            kNloptInvalidArgs);
  EXPECT_EQ(message, "NLopt refused the problem: nlopt invalid argument");
  EXPECT_EQ(NloptResultFromException(std::make_exception_ptr(std::bad_alloc()), &message),
            kNloptOutOfMemory);
  EXPECT_EQ(message, "NLopt ran out of memory");
  EXPECT_EQ(NloptResultFromException(std::make_exception_ptr(std::runtime_error("nlopt failure")),
                                     &message),
            kNloptFailure);
  EXPECT_EQ(message, "NLopt failed: nlopt failure");
  EXPECT_EQ(NloptResultFromException(std::make_exception_ptr(42), &message), kNloptFailure);
  EXPECT_EQ(message, "NLopt failed: an unknown exception");
  EXPECT_EQ(NloptResultFromException(nullptr, &message), kNloptFailure);
}

// (x - 0.3)^2 on [0, 1]: the trampoline's normal path.
double TerminationTestParabola(const double* x, double* grad) {
  if (grad != nullptr) grad[0] = 2.0 * (x[0] - 0.3);
  return (x[0] - 0.3) * (x[0] - 0.3);
}

NloptRunSettings TerminationTestSettings() {
  NloptRunSettings s;
  s.algorithm = NloptAlgorithm::kLdSlsqp;
  s.lower = {0.0};
  s.upper = {1.0};
  s.x_tolerance_abs = 1e-12;
  s.max_evaluations = 200;
  return s;
}

TEST(NloptRunTest, ConvergesOnAParabola) {
  std::vector<double> x{0.9};
  const NloptRunOutcome r = RunNlopt(TerminationTestParabola, {}, TerminationTestSettings(), &x);
  EXPECT_GT(r.raw_status, 0);
  EXPECT_EQ(TerminationFromNloptResult(r.raw_status), Termination::kConverged);
  // SLSQP on an exact quadratic lands on the minimiser to within the x tolerance (1e-12).
  EXPECT_NEAR(x[0], 0.3, 1e-9);
  EXPECT_FALSE(r.callback_failed);
  EXPECT_GT(r.evaluations, 0);
}

TEST(NloptRunTest, AThrowingObjectiveStopsTheRunWithoutCrossingNlopt) {
  std::vector<double> x{0.9};
  const NloptFunction throws = [](const double*, double*) -> double {
    throw std::runtime_error("model exploded");
  };
  const NloptRunOutcome r = RunNlopt(throws, {}, TerminationTestSettings(), &x);
  EXPECT_EQ(r.raw_status, kNloptForcedStop);
  EXPECT_TRUE(r.callback_failed);
  EXPECT_EQ(r.message, "a function NLopt called threw: model exploded");
}

TEST(NloptRunTest, ANonFiniteConstraintStopsTheRun) {
  std::vector<double> x{0.9};
  const std::vector<NloptConstraintFunction> constraints{
      {[](const double*, double*) { return std::nan(""); }, false, 0.0}};
  const NloptRunOutcome r =
      RunNlopt(TerminationTestParabola, constraints, TerminationTestSettings(), &x);
  EXPECT_EQ(r.raw_status, kNloptForcedStop);
  EXPECT_TRUE(r.callback_failed);
}

TEST(NloptRunTest, CancellationAndTheDeadlineStopTheRun) {
  Progress progress;
  progress.Cancel();
  NloptRunSettings s = TerminationTestSettings();
  s.progress = &progress;
  std::vector<double> x{0.9};
  NloptRunOutcome r = RunNlopt(TerminationTestParabola, {}, s, &x);
  EXPECT_EQ(r.raw_status, kNloptForcedStop);
  EXPECT_TRUE(r.cancelled);
  EXPECT_FALSE(r.callback_failed);

  s = TerminationTestSettings();
  s.deadline = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  x = {0.9};
  r = RunNlopt(TerminationTestParabola, {}, s, &x);
  EXPECT_EQ(r.raw_status, kNloptForcedStop);
  EXPECT_TRUE(r.deadline_reached);
}

TEST(NloptRunTest, InvalidArgumentsAreReportedNotThrown) {
  NloptRunSettings s = TerminationTestSettings();
  s.lower = {2.0};  // lower > upper: NLopt refuses the problem
  std::vector<double> x{0.9};
  const NloptRunOutcome r = RunNlopt(TerminationTestParabola, {}, s, &x);
  EXPECT_EQ(r.raw_status, kNloptInvalidArgs);
  EXPECT_EQ(TerminationFromNloptResult(r.raw_status), Termination::kInvalidInput);
}

}  // namespace
}  // namespace sweetspot::core
