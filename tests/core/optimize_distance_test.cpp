// The max_distance objective: the carry of the design's distance sweet spot (the impact position
// and undercut that carry the ball farthest), maximised by NLopt COBYLA. Checked against the
// same quantity computed independently through the public scene path (EvaluateScene's
// distance_sweet_spot output for the returned bat); the improvement over the base bat; the
// smoothness of the carry in a design variable at macroscopic steps and its noise floor at small
// ones (the measured reason it is solved derivative-free, docs/optimization.md); refusals.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "core/bat/material.hpp"
#include "core/optimize/design_distance.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/optimize/frontier.hpp"
#include "core/scene/evaluate_scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_distance_test {
namespace {

// The contract's three-segment ash bat (0.8636 m, handle 0.0125 m, barrel 0.033 m, taper
// 0.30-0.55 m), in the scenes' default pitch and swing, with a 10 deg upswing against a 6 deg
// descending pitch (the example), the free bat and COR 0.5.
constexpr ThreeSegmentShape kBase{0.8636, 0.0125, 0.033, 0.30, 0.55};
constexpr double kCor = 0.5;

DesignProblem BaseProblem() {
  DesignProblem p;
  p.three_segment = kBase;
  p.bat.material = *FindMaterial("ash");
  p.cor = kCor;
  p.model = CollisionModel::kFreeBat;
  p.objective = DesignObjective::kMaxDistance;
  p.swing.attack_angle_deg = 10.0;
  p.ball.descent_angle_deg = 6.0;
  p.variables = {{"three_segment.barrel_radius_m", 0.030, 0.0345},
                 {"three_segment.taper_end_m", 0.45, 0.70}};
  return p;
}

// The distance sweet spot of `bat` through the public scene path (EvaluateScene, outputs
// distance_sweet_spot, the free bat), with the problem's ball, swing and COR: what
// /v1/sweet-spot answers for it.
double PublicDistance(const Bat& bat, const DesignProblem& p) {
  Scene scene;
  scene.bat = bat;
  scene.cor = p.cor;
  scene.ball = p.ball;
  scene.swing = p.swing;
  scene.environment = p.environment;
  scene.aero = p.aero;
  scene.outputs = {SceneOutput::kDistanceSweetSpot};
  SceneOptions options;
  options.model = CollisionModel::kFreeBat;
  options.distance = p.distance;
  const SceneResult s = EvaluateScene(scene, options);
  EXPECT_TRUE(s.distance_sweet_spot.has_value()) << s.summary.message;
  if (!s.distance_sweet_spot.has_value()) return std::nan("");
  return s.distance_sweet_spot->distance_m;
}

Bat BatOf(const ThreeSegmentShape& s) { return MakeThreeSegmentBat(s, *FindMaterial("ash")); }

TEST(OptimizeDistanceTest, MassBoundTwoVariablesBeatsTheBaseAndMatchesThePublicPath) {
  DesignProblem p = BaseProblem();
  // Without a mass limit the heaviest bat (widest barrel, longest taper) carries farthest;
  // capped at the base bat's mass, the design trades barrel radius against the taper.
  const double base_mass = ComputeMassProperties(BatOf(kBase), InertiaModel::kRigidBody).mass_kg;
  p.constraints.mass_kg = DesignRange{std::nullopt, base_mass};
  const double base = PublicDistance(BatOf(kBase), p);
  ASSERT_TRUE(std::isfinite(base));
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  EXPECT_EQ(r.summary.backend, "nlopt:LN_COBYLA");
  EXPECT_EQ(r.objective_unit, "m");
  ASSERT_TRUE(r.distance_sweet_spot.has_value());
  // The answer's distance is its distance sweet spot's (the same public re-evaluation).
  EXPECT_EQ(r.objective_value, r.distance_sweet_spot->distance_m);
  // And what the public scene path gives the returned bat: the same ResolveScene and search on
  // the same bat, so equal up to the mass properties' rounding; 1e-6 m is far below the
  // search's own resolution (position 1e-4 m, undercut 1e-5 m: ~1e-6 m of carry at a maximum)
  // and would catch any difference of scene (COR, swing, air) between the two paths (metres).
  EXPECT_NEAR(r.objective_value, PublicDistance(r.bat, p), 1e-6);
  // It improves on the base bat: by more than 0.05 m, i.e. well beyond the carry's noise floor
  // (~1e-6 m, the test below) — the base bat is not the optimum of this problem.
  EXPECT_GT(r.objective_value, base + 0.05) << "base " << base;
  // The mass bound holds (COBYLA's answer re-checked through the public mass properties).
  EXPECT_LE(r.properties.mass_kg, base_mass * (1.0 + 1e-6));
  // Derivative-free: no certificate, no KKT residual, NaN multipliers.
  EXPECT_TRUE(std::isnan(r.summary.error_estimate));
  for (const DesignActiveConstraint& a : r.active_constraints) {
    EXPECT_TRUE(std::isnan(a.multiplier)) << a.name;
  }
  std::printf("max_distance: base %.4f m, optimum %.4f m (%d evaluations, %.3f s)\n", base,
              r.objective_value, r.summary.evaluations, r.summary.solve_time_s);
}

TEST(OptimizeDistanceTest, OneVariableGoesToTheHeavierBound) {
  // One variable, no constraint: a wider barrel is a heavier bat, whose free-bat effective mass
  // at the sweet spot is larger, so the ball leaves faster and carries farther: the optimum is
  // the upper bound (a check that the sense is maximise and the objective moves with the bat).
  DesignProblem p = BaseProblem();
  p.variables = {{"three_segment.barrel_radius_m", 0.031, 0.034}};
  const DesignResult r = OptimizeDesign(p);
  ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.message;
  ASSERT_EQ(r.variables.size(), 1u);
  // COBYLA's xtol_rel 1e-6 of the scaled variable: within 1e-7 m of the bound, 1e-6 m allowed.
  EXPECT_NEAR(r.variables[0].value, 0.034, 1e-6);
  ThreeSegmentShape narrow = kBase;
  narrow.barrel_radius_m = 0.031;
  EXPECT_GT(r.objective_value, PublicDistance(BatOf(narrow), p));
}

// The measurement behind docs/optimization.md ("max_distance"): central differences of the
// carry in the barrel radius, (F(r + h) - F(r - h)) / 2h, from h = 1e-3 m down to 1e-12 m, and
// the second differences of F along a sweep. The carry is smooth in the design (the envelope
// theorem: the maximum over (x, D) moves with the partial derivative at (x*, D*), and neither the
// flight's adaptive steps nor the search's iterations jump for these changes): no noise floor
// shows down to 1e-11 m, so noise is not why the objective is derivative-free (the flight has no
// derivative code: the docs say so). The table is printed for the docs.
TEST(OptimizeDistanceTest, CarryIsSmoothInTheDesignDownToTinySteps) {
  const DesignProblem p = BaseProblem();
  DistanceScene scene;
  scene.ball = p.ball;
  scene.swing = p.swing;
  scene.cor = kCor;
  scene.model = CollisionModel::kFreeBat;
  auto carry = [&](double r) {
    ThreeSegmentShape s = kBase;
    s.barrel_radius_m = r;
    const DistanceEvaluation e = EvaluateDistance(BatOf(s), scene);
    EXPECT_TRUE(e.ok) << e.message;
    return e.distance_m;
  };
  const double r0 = kBase.barrel_radius_m;
  std::vector<double> quotient;
  for (double h : {1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12}) {
    const double d = (carry(r0 + h) - carry(r0 - h)) / (2.0 * h);
    quotient.push_back(d);
    std::printf("h = %.0e m: dF/dr = %.6g m/m\n", h, d);
  }
  // Smooth at macroscopic steps: h = 1e-4 and 3e-5 m agree to 1 % (an O(h^2) truncation of a
  // smooth function of curvature ~|F''| r^2 / F ~ 1 moves the quotient by far less).
  EXPECT_NEAR(quotient[3], quotient[2], 0.01 * std::abs(quotient[2]));
  // And no noise floor at h = 1e-7 m: a jump of 1e-10 m in F would move the quotient by 5e-4
  // m/m, 4e-7 relative; measured 1e-6 relative agreement (1225.83 both), 1e-4 allowed.
  EXPECT_NEAR(quotient[6], quotient[2], 1e-4 * std::abs(quotient[2]));
  EXPECT_GT(quotient[2], 0.0);  // a wider barrel carries farther (the test above)
  // The carry along a sweep of the barrel radius, its first and second differences: where the
  // coarse scan's best cell or the flight's step sequence changes, a jump shows in them.
  const int n = 181;
  std::vector<double> f(n);
  for (int i = 0; i < n; ++i) f[i] = carry(0.030 + 0.0045 * i / (n - 1));
  double worst2 = 0.0, median2 = 0.0;
  std::vector<double> second;
  for (int i = 1; i + 1 < n; ++i) second.push_back(std::abs(f[i + 1] - 2.0 * f[i] + f[i - 1]));
  for (double s : second) worst2 = std::max(worst2, s);
  std::vector<double> sorted = second;
  std::sort(sorted.begin(), sorted.end());
  median2 = sorted[sorted.size() / 2];
  // No jump along the sweep: the largest second difference is the smooth curvature's (measured
  // 1.12 x the median); a jump of the size of the search's resolution (~1e-6 m) would not show,
  // one of the coarse cell's change (the optimum moving to another local maximum) would.
  EXPECT_LT(worst2, 3.0 * median2);
  std::printf(
      "sweep r in [0.030, 0.0345] m, step 2.5e-5 m: F %.6f..%.6f m, |2nd diff| median "
      "%.3g m, max %.3g m\n",
      f.front(), f.back(), median2, worst2);
}

TEST(OptimizeDistanceTest, Refusals) {
  DesignProblem p = BaseProblem();
  p.model = CollisionModel::kHertz;
  DesignResult r = OptimizeDesign(p);
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  ASSERT_TRUE(r.summary.refusal.has_value());
  EXPECT_EQ(r.summary.refusal->field, "model");
  EXPECT_NE(r.summary.message.find("max_distance"), std::string::npos) << r.summary.message;
  p.model = CollisionModel::kFlexible;
  r = OptimizeDesign(p);
  ASSERT_TRUE(r.summary.refusal.has_value());
  EXPECT_EQ(r.summary.refusal->field, "model");

  p = BaseProblem();
  DesignOptions o;
  o.derivative_check = DerivativeCheck::kFirstOrder;
  r = OptimizeDesign(p, o);
  ASSERT_TRUE(r.summary.refusal.has_value());
  EXPECT_EQ(r.summary.refusal->field, "options.derivative_check");
  EXPECT_NE(r.summary.message.find("max_distance"), std::string::npos) << r.summary.message;

  p.distance.coarse_positions = 1;
  r = OptimizeDesign(p);
  ASSERT_TRUE(r.summary.refusal.has_value());
  EXPECT_EQ(r.summary.refusal->field, "distance.coarse_positions");

  // No frontier: its continuation needs multipliers.
  p = BaseProblem();
  FrontierSpec spec;
  spec.quantity = FrontierQuantity::kMassKg;
  spec.values = {0.8, 0.85};
  Refusal why;
  EXPECT_FALSE(spec.Validate(p, &why));
  EXPECT_EQ(why.field, "objective");
}

TEST(OptimizeDistanceTest, AnotherBackendIsSolvedByCobylaWithAWarning) {
  DesignProblem p = BaseProblem();
  p.variables = {{"three_segment.barrel_radius_m", 0.031, 0.034}};
  DesignOptions o;
  o.backend = DesignBackend::kIpopt;
  const DesignResult r = OptimizeDesign(p, o);
  EXPECT_EQ(r.summary.backend, "nlopt:LN_COBYLA");
  bool warned = false;
  for (const std::string& w : r.summary.warnings) {
    warned = warned || w.rfind("objective = max_distance: solved by NLopt LN_COBYLA", 0) == 0;
  }
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace optimize_distance_test
}  // namespace sweetspot::core
