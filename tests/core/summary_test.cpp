#include "core/summary.hpp"

#include <stdexcept>

#include <gtest/gtest.h>

#include "core/version.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace summary_test {
namespace {

TEST(SummaryTest, TerminationNamesAreTheContractNames) {
  EXPECT_STREQ(TerminationName(Termination::kConverged), "converged");
  EXPECT_STREQ(TerminationName(Termination::kNoConvergence), "no_convergence");
  EXPECT_STREQ(TerminationName(Termination::kInfeasible), "infeasible");
  EXPECT_STREQ(TerminationName(Termination::kFailure), "failure");
  EXPECT_STREQ(TerminationName(Termination::kInvalidInput), "invalid_input");
}

TEST(SummaryTest, DefaultIsInvalidInputAndNotUsable) {
  const Summary summary;
  EXPECT_EQ(summary.termination, Termination::kInvalidInput);
  EXPECT_FALSE(summary.IsSolutionUsable());
  EXPECT_EQ(summary.iterations, -1);
  EXPECT_EQ(summary.solve_time_s, -1.0);
}

TEST(SummaryTest, UsableOnlyForConvergedOrKeptPoint) {
  Summary summary;
  summary.termination = Termination::kConverged;
  EXPECT_TRUE(summary.IsSolutionUsable());
  summary.termination = Termination::kNoConvergence;
  EXPECT_TRUE(summary.IsSolutionUsable());
  summary.termination = Termination::kInfeasible;
  EXPECT_FALSE(summary.IsSolutionUsable());
  summary.termination = Termination::kFailure;
  EXPECT_FALSE(summary.IsSolutionUsable());
}

TEST(SummaryTest, ReportsNameEveryField) {
  Summary summary;
  summary.termination = Termination::kConverged;
  summary.backend = "closed_form";
  summary.iterations = 3;
  summary.models_used = {"mass_properties", "rigid_pivot"};
  EXPECT_EQ(summary.BriefReport().rfind("converged (closed_form, raw 0): 3 iterations", 0), 0u);
  const std::string full = summary.FullReport();
  for (const char* field : {"termination: converged", "backend: closed_form", "iterations: 3",
                            "models_used: mass_properties rigid_pivot"}) {
    EXPECT_NE(full.find(field), std::string::npos) << field;
  }
}

TEST(SummaryTest, CatchInternalErrorTurnsWhatIsThrownIntoAFailure) {
  Summary summary;
  summary.termination = Termination::kConverged;
  summary.message = "kept";
  CatchInternalError(&summary, [] {});
  EXPECT_EQ(summary.termination, Termination::kConverged);
  EXPECT_EQ(summary.message, "kept");
  CatchInternalError(&summary, [] { throw std::runtime_error("the mesh is empty"); });
  EXPECT_EQ(summary.termination, Termination::kFailure);
  EXPECT_EQ(summary.message, "internal error: the mesh is empty");
  summary = Summary{};
  CatchInternalError(&summary, [] { throw 42; });
  EXPECT_EQ(summary.termination, Termination::kFailure);
  EXPECT_EQ(summary.message, "internal error");
}

TEST(SummaryTest, InternalErrorMessageNamesTheStandardException) {
  try {
    throw std::out_of_range("index 7");
  } catch (...) {
    EXPECT_EQ(InternalErrorMessage(), "internal error: index 7");
  }
  try {
    throw "text";
  } catch (...) {
    EXPECT_EQ(InternalErrorMessage(), "internal error");
  }
}

TEST(VersionTest, DependencyVersionsAreTheDebian12Ones) {
  EXPECT_EQ(SweetspotVersion(), "0.1.0");
  EXPECT_EQ(NloptVersion(), "2.7.1");
  EXPECT_EQ(IpoptVersion(), "3.11.9");
  EXPECT_EQ(EigenVersion().rfind("3.4", 0), 0u);
}

}  // namespace
}  // namespace summary_test
}  // namespace sweetspot::core
