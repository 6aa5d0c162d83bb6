// The frontier (core/optimize/frontier.hpp): one optimisation per value, each from its
// neighbour's answer, the same optima as independent solves; its refusals, the fallback when
// a warm start fails, and the Pareto front.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/frontier.hpp"
#include "core/units.hpp"
#include "tests/core/knot_design_problems.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_frontier_test {
namespace {

// A 10-knot solid ash bat (bench/core_frontier.cpp's problem, smaller: knot_design_problems.hpp).
DesignProblem TenKnotProblem() { return knot_design_problems::SolidAshKnots(10); }

// Masses from the base mass - 1.5 oz to + 1.5 oz.
FrontierSpec Masses(const DesignProblem& p, int count) {
  FrontierSpec spec;
  const double base = ComputeMassProperties(p.bat).mass_kg;
  for (int i = 0; i < count; ++i) {
    spec.values.push_back(base + OuncesToKilograms(-1.5 + 3.0 * i / (count - 1)));
  }
  return spec;
}

std::vector<FrontierPoint> Collect(const DesignProblem& p, const FrontierSpec& spec,
                                   FrontierSummary* summary) {
  std::vector<FrontierPoint> points;
  *summary = OptimizeFrontier(p, spec, DesignOptions{}, true, [&](const FrontierPoint& point) {
    points.push_back(point);
    return true;
  });
  return points;
}

TEST(FrontierTest, WarmStartedValuesReachTheOptimaOfIndependentSolves) {
  const DesignProblem p = TenKnotProblem();
  const FrontierSpec spec = Masses(p, 6);
  FrontierSummary warm_summary, cold_summary;
  const std::vector<FrontierPoint> warm = Collect(p, spec, &warm_summary);
  FrontierSpec independent = spec;
  independent.warm_start = false;
  const std::vector<FrontierPoint> cold = Collect(p, independent, &cold_summary);
  ASSERT_EQ(warm.size(), 6u);
  ASSERT_EQ(cold.size(), 6u);
  EXPECT_EQ(warm_summary.summary.termination, Termination::kConverged) << warm_summary.summary.message;
  EXPECT_EQ(warm_summary.converged, 6);
  // Every value after the first is a continuation step (the active-set Newton step from the
  // predicted start with the neighbour's active set), certified like any answer.
  EXPECT_EQ(warm_summary.continued, 5);
  for (std::size_t i = 1; i < warm.size(); ++i) {
    EXPECT_EQ(warm[i].result.summary.backend, "active_set_newton") << "value " << i;
    EXPECT_TRUE(warm[i].result.certificate.certified) << "value " << i;
  }
  EXPECT_EQ(cold_summary.continued, 0);
  for (std::size_t i = 0; i < warm.size(); ++i) {
    EXPECT_EQ(warm[i].index, static_cast<int>(i));
    EXPECT_EQ(warm[i].warm_started, i > 0);
    EXPECT_FALSE(cold[i].warm_started);
    ASSERT_EQ(cold[i].result.summary.termination, Termination::kConverged);
    // Same optimum: both solvers stop at a relative KKT tolerance of 1e-9 (DesignOptions::
    // tolerance), which leaves the objective (a smooth function at a regular optimum) equal to
    // far better than 1e-7 relative, the bound for "the same optima".
    EXPECT_NEAR(warm[i].result.objective_value, cold[i].result.objective_value,
                1e-7 * cold[i].result.objective_value)
        << "value " << i;
    // And the mass holds at each value (constraint tolerance 1e-10 relative).
    EXPECT_NEAR(warm[i].result.properties.mass_kg, spec.values[i], 1e-9);
  }
  // The best exit speed rises with the mass over this range (more mass in the barrel): each
  // value is on the Pareto front only if no lighter bat is at least as fast.
  for (std::size_t i = 1; i < warm.size(); ++i) {
    EXPECT_GT(warm[i].result.objective_value, warm[i - 1].result.objective_value);
  }
  EXPECT_EQ(warm_summary.pareto.size(), 6u);
  // (Iteration counts of SLSQP and Ipopt are not comparable; the speed is the benchmark's:
  // bench/core_frontier.cpp.)
}

TEST(FrontierTest, AnInfeasibleValueFallsBackToTheBaseDesignAndIsReported) {
  DesignProblem p = TenKnotProblem();
  FrontierSpec spec = Masses(p, 3);
  // 0.3 kg: below the lightest bat the radius bounds allow (every inner radius at 0.011 m
  // already weighs more), so no start can meet it.
  spec.values.push_back(0.3);
  FrontierSummary summary;
  const std::vector<FrontierPoint> points = Collect(p, spec, &summary);
  ASSERT_EQ(points.size(), 4u);
  EXPECT_EQ(points[3].result.summary.termination, Termination::kInfeasible);
  EXPECT_TRUE(points[3].restarted);
  EXPECT_FALSE(points[3].continued);
  EXPECT_EQ(summary.restarts, 1);
  EXPECT_EQ(summary.converged, 3);
  EXPECT_EQ(summary.summary.termination, Termination::kNoConvergence);
  // The infeasible value is not on the front.
  for (int i : summary.pareto) EXPECT_NE(i, 3);
}

TEST(FrontierTest, TheSinkStopsTheFrontier) {
  const DesignProblem p = TenKnotProblem();
  int seen = 0;
  const FrontierSummary s =
      OptimizeFrontier(p, Masses(p, 4), DesignOptions{}, true, [&](const FrontierPoint&) {
        return ++seen < 2;
      });
  EXPECT_EQ(seen, 2);
  EXPECT_TRUE(s.stopped);
  EXPECT_EQ(s.summary.termination, Termination::kNoConvergence);
}

TEST(FrontierTest, RefusesWhatItCannotSolve) {
  const DesignProblem p = TenKnotProblem();
  const auto refusal = [&](const FrontierSpec& spec, const DesignProblem& problem) {
    Refusal why;
    EXPECT_FALSE(spec.Validate(problem, &why));
    return why;
  };
  FrontierSpec empty;
  EXPECT_EQ(refusal(empty, p).field, "frontier.values");
  FrontierSpec twice = Masses(p, 3);
  twice.values.push_back(twice.values[1]);
  const Refusal repeated = refusal(twice, p);
  EXPECT_EQ(repeated.field, "frontier.values[3]");
  EXPECT_NE(repeated.rule.find("repeats"), std::string::npos);
  FrontierSpec nan = Masses(p, 3);
  nan.values[0] = std::nan("");
  EXPECT_EQ(refusal(nan, p).field, "frontier.values[0]");
  FrontierSpec many = Masses(p, 3);
  many.max_values = 2;
  EXPECT_EQ(refusal(many, p).field, "frontier.values");
  FrontierSpec exponent;
  exponent.quantity = FrontierQuantity::kSpeedModelExponent;
  exponent.values = {0.1, 0.2};
  EXPECT_EQ(refusal(exponent, p).field, "frontier.constraint");  // max_exit_speed: no weight
  FrontierSpec bounded;
  bounded.quantity = FrontierQuantity::kMinFrequencyHz;
  bounded.bound = FrontierBound::kAtMost;
  bounded.values = {150.0};
  EXPECT_EQ(refusal(bounded, p).field, "frontier.bound");
  DesignProblem sting = p;
  sting.objective = DesignObjective::kMinSting;
  EXPECT_EQ(refusal(Masses(p, 3), sting).field, "objective");
  // A refused spec is answered, not thrown: invalid_input with the refusal.
  const FrontierSummary s = OptimizeFrontier(p, empty, DesignOptions{}, true,
                                             [](const FrontierPoint&) { return true; });
  EXPECT_EQ(s.summary.termination, Termination::kInvalidInput);
  ASSERT_TRUE(s.summary.refusal.has_value());
  EXPECT_EQ(s.summary.refusal->field, "frontier.values");
}

TEST(FrontierTest, EachQuantitySetsItsConstraint) {
  const DesignProblem p = TenKnotProblem();
  FrontierSpec spec;
  spec.quantity = FrontierQuantity::kLengthM;
  spec.bound = FrontierBound::kAtMost;
  EXPECT_EQ(*FrontierProblemAt(p, spec, 0.85).constraints.length_m->max, 0.85);
  EXPECT_FALSE(FrontierProblemAt(p, spec, 0.85).constraints.length_m->min.has_value());
  spec.quantity = FrontierQuantity::kMoiSixInchKgM2;
  spec.bound = FrontierBound::kEqual;
  EXPECT_TRUE(FrontierProblemAt(p, spec, 0.2).constraints.moi_six_inch_kg_m2->IsEquality());
  spec.quantity = FrontierQuantity::kBalancePointM;
  spec.bound = FrontierBound::kAtLeast;
  EXPECT_EQ(*FrontierProblemAt(p, spec, 0.55).constraints.balance_point_m->min, 0.55);
  spec.quantity = FrontierQuantity::kMinFrequencyHz;
  EXPECT_EQ(*FrontierProblemAt(p, spec, 150.0).constraints.min_frequency_hz, 150.0);
  spec.quantity = FrontierQuantity::kMaxBarrelDiameterM;
  EXPECT_EQ(*FrontierProblemAt(p, spec, 0.066).constraints.max_barrel_diameter_m, 0.066);
  spec.quantity = FrontierQuantity::kSpeedModelExponent;
  EXPECT_EQ(FrontierProblemAt(p, spec, 0.3).swing_weight_exponent, 0.3);
  for (const char* name : {"length_m", "mass_kg", "balance_point_m", "moi_six_inch_kg_m2",
                           "min_frequency_hz", "max_barrel_diameter_m", "swing_weight_exponent"}) {
    const auto q = ParseFrontierQuantity(name);
    ASSERT_TRUE(q.has_value()) << name;
    EXPECT_STREQ(FrontierQuantityName(*q), name);
  }
  EXPECT_FALSE(ParseFrontierQuantity("mass_oz").has_value());  // trade forms are the api's
}

}  // namespace
}  // namespace optimize_frontier_test
}  // namespace sweetspot::core
