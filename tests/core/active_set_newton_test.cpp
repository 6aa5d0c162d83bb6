// The frontier's continuation step (core/optimize/active_set_newton.hpp): Newton's method on
// the KKT conditions of a neighbour's active set reaches the optimum an independent solve
// finds, changes the active set when the neighbour's is no longer right, and refuses a guess
// that does not fit; and the model a frontier builds once equals the one Build makes.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/active_set_newton.hpp"
#include "core/optimize/certificate.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/units.hpp"
#include "tests/core/knot_design_problems.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace active_set_newton_test {
namespace {

// bench/core_frontier.cpp's 16-knot solid ash bat (knot_design_problems.hpp) with its mass
// `delta_oz` from the base bat's.
DesignProblem SixteenKnotProblem(double delta_oz) {
  DesignProblem p = knot_design_problems::SolidAshKnots(16);
  p.constraints.mass_kg =
      DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg + OuncesToKilograms(delta_oz));
  return p;
}

DesignOptions Slsqp() {
  DesignOptions o;
  o.backend = DesignBackend::kNloptSlsqp;
  return o;
}

// The variables' values of an answer (the problem's variables, in order).
std::vector<double> VariablesOf(const DesignResult& r, std::size_t n) {
  std::vector<double> x;
  for (std::size_t j = 0; j < n && j < r.variables.size(); ++j) x.push_back(r.variables[j].value);
  return x;
}

struct Step {
  LocalSolveOutcome outcome;
  double objective = 0.0;  // at the step's point, m/s
  DesignCertificate certificate;
};

// The step at `to_oz` from the answer at `from_oz`, with the active set `guess` (the answer's
// own when null).
Step StepFrom(double from_oz, double to_oz, const ActiveSetGuess* guess) {
  const DesignResult from = OptimizeDesign(SixteenKnotProblem(from_oz), Slsqp());
  EXPECT_TRUE(from.certificate.certified) << from.summary.message;
  DesignModel model;
  EXPECT_TRUE(DesignModel::Build(SixteenKnotProblem(to_oz), Slsqp(), &model, nullptr));
  ScaledDesignNlp nlp(model);
  const ActiveSetGuess own = GuessFromMultipliers(from.certificate.lambda, from.certificate.z_lower,
                                                  from.certificate.z_upper);
  LocalSolveSettings settings;
  settings.deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  Step step;
  step.outcome = SolveWithActiveSetNewton(
      nlp, nlp.ToScaled(VariablesOf(from, static_cast<std::size_t>(model.n()))),
      guess != nullptr ? *guess : own, settings);
  if (step.outcome.has_point) {
    std::vector<double> x = nlp.ToUser(step.outcome.s.data());
    DesignPoint at;
    EXPECT_TRUE(model.Evaluate(x.data(), false, &at));
    step.objective = at.objective;
    step.certificate = design_detail::Certify(model, x, {}, true);
  }
  return step;
}

TEST(ActiveSetNewtonTest, ReachesTheIndependentOptimumFromTheNeighboursActiveSet) {
  // 0.2 oz apart, as the benchmark's 20 values over 4 oz: the active set is the neighbour's.
  const Step step = StepFrom(0.0, 0.2, nullptr);
  ASSERT_EQ(step.outcome.termination, Termination::kConverged) << step.outcome.message;
  EXPECT_TRUE(step.outcome.has_multipliers);
  // Newton on a vertex (14 active constraints, 14 variables) converges quadratically: a few
  // steps, against SLSQP's ~10 iterations from the same start.
  EXPECT_LE(step.outcome.iterations, 4);
  EXPECT_TRUE(step.certificate.certified) << step.certificate.failed;
  const DesignResult independent = OptimizeDesign(SixteenKnotProblem(0.2), Slsqp());
  ASSERT_EQ(independent.summary.termination, Termination::kConverged);
  // The same optimum: SLSQP stops at a relative tolerance of 1e-9 (DesignOptions::tolerance)
  // and Newton at the active set's root; the objective at a regular optimum agrees far below
  // 1e-9 relative (the benchmark's max_rel_diff: ~1e-11).
  EXPECT_NEAR(step.objective, independent.objective_value, 1e-9 * independent.objective_value);
}

TEST(ActiveSetNewtonTest, ChangesTheActiveSetWhereTheOptimumChangesIt) {
  // From -2 oz to -1.2 oz the optimum's taper changes which knots it ties (the benchmark's
  // frontier: two taper constraints swap between its values 1 and 2); the step swaps them.
  const Step step = StepFrom(-2.0, -1.2, nullptr);
  ASSERT_EQ(step.outcome.termination, Termination::kConverged) << step.outcome.message;
  EXPECT_NE(step.outcome.message, "0 active-set changes");
  EXPECT_TRUE(step.certificate.certified) << step.certificate.failed;
  const DesignResult independent = OptimizeDesign(SixteenKnotProblem(-1.2), Slsqp());
  ASSERT_EQ(independent.summary.termination, Termination::kConverged);
  EXPECT_NEAR(step.objective, independent.objective_value, 1e-9 * independent.objective_value);
}

TEST(ActiveSetNewtonTest, AWrongGuessIsDeclinedNotAnsweredWrongly) {
  // The neighbour's set without its last inequality (a taper constraint): 13 held for 14
  // variables, so the step takes the Lagrangian's Hessian; on this problem its curvature in the
  // freed direction sends Newton out of the box, and the step declines (the frontier then runs
  // SLSQP). It must never report convergence at another point.
  const DesignResult from = OptimizeDesign(SixteenKnotProblem(0.0), Slsqp());
  ASSERT_TRUE(from.certificate.certified);
  ActiveSetGuess guess = GuessFromMultipliers(from.certificate.lambda, from.certificate.z_lower,
                                              from.certificate.z_upper);
  DesignModel model;
  ASSERT_TRUE(DesignModel::Build(SixteenKnotProblem(0.2), Slsqp(), &model, nullptr));
  int dropped = -1;
  for (int k = model.m() - 1; k >= 0 && dropped < 0; --k) {
    const DesignConstraintSpec& c = model.constraints()[static_cast<std::size_t>(k)];
    if (guess.constraint_side[static_cast<std::size_t>(k)] != 0.0 && c.lower != c.upper) {
      guess.constraint_side[static_cast<std::size_t>(k)] = 0.0;
      dropped = k;
    }
  }
  ASSERT_GE(dropped, 0);
  const Step step = StepFrom(0.0, 0.2, &guess);
  if (step.outcome.termination == Termination::kConverged) {
    const DesignResult independent = OptimizeDesign(SixteenKnotProblem(0.2), Slsqp());
    EXPECT_NEAR(step.objective, independent.objective_value, 1e-9 * independent.objective_value);
  } else {
    EXPECT_EQ(step.outcome.termination, Termination::kNoConvergence) << step.outcome.message;
    EXPECT_FALSE(step.outcome.has_multipliers);
  }
}

TEST(ActiveSetNewtonTest, RefusesAGuessThatDoesNotFit) {
  ActiveSetGuess wrong;
  wrong.constraint_side = {1.0};
  wrong.bound = {0};
  const Step step = StepFrom(0.0, 0.2, &wrong);
  EXPECT_EQ(step.outcome.termination, Termination::kFailure);
  EXPECT_FALSE(step.outcome.has_point);
}

TEST(ActiveSetNewtonTest, TheModelWithNewLimitsIsTheModelBuildMakes) {
  // The frontier builds the model once and changes the swept constraint's limits
  // (DesignModel::WithConstraintLimits); Build at the new value must give the same model:
  // the same limits and the same scale, bit for bit (the same formula on the same numbers).
  DesignModel first, built;
  ASSERT_TRUE(DesignModel::Build(SixteenKnotProblem(-2.0), Slsqp(), &first, nullptr));
  ASSERT_TRUE(DesignModel::Build(SixteenKnotProblem(1.5), Slsqp(), &built, nullptr));
  int mass = -1;
  for (int k = 0; k < first.m(); ++k) {
    if (first.constraints()[static_cast<std::size_t>(k)].name == "mass_kg") mass = k;
  }
  ASSERT_GE(mass, 0);
  const double value = built.constraints()[static_cast<std::size_t>(mass)].lower;
  const DesignModel moved = first.WithConstraintLimits(mass, value, value);
  ASSERT_EQ(moved.m(), built.m());
  for (int k = 0; k < built.m(); ++k) {
    const DesignConstraintSpec& a = moved.constraints()[static_cast<std::size_t>(k)];
    const DesignConstraintSpec& b = built.constraints()[static_cast<std::size_t>(k)];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.lower, b.lower) << b.name;
    EXPECT_EQ(a.upper, b.upper) << b.name;
    EXPECT_EQ(a.scale, b.scale) << b.name;
  }
  EXPECT_EQ(moved.objective_scale(), built.objective_scale());
  // And the mass constraint did move (the test compares two different values).
  EXPECT_NE(first.constraints()[static_cast<std::size_t>(mass)].lower, value);
}

}  // namespace
}  // namespace active_set_newton_test
}  // namespace sweetspot::core
