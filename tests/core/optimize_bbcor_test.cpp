// The `bbcor` rule of the design optimiser with the barrel model (issue 18 item 2): the wall
// thickness as a design variable, the thinnest wall whose BBCOR <= 0.50 (by bisection through
// ComputeBbcor, the reference), checked by recomputing the optimiser's answer.
#include <algorithm>

#include <gtest/gtest.h>

#include "core/collision/barrel.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/presets.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_bbcor_test {
namespace {

// The aluminium preset in a 20 % denser alloy: its drop-3 wall is thinner than its BBCOR-legal
// wall, so the drop limit alone would give an illegal bat.
Bat DenseAlloyBat() {
  Bat bat = FindPreset("bbcor-33-aluminium")->bat;
  bat.material.name = "custom";
  bat.material.density_kg_m3 *= 1.2;
  return bat;
}

double BbcorWithWall(Bat bat, double wall_m) {
  bat.wall_thickness_m = wall_m;
  return ComputeBbcor(bat).value;
}

// The reference: the thinnest wall with BBCOR <= 0.50, by bisection to 1e-7 m.
double ThinnestLegalWall(const Bat& bat) {
  double thin = 0.001, thick = 0.008;
  while (thick - thin > 1e-7) {
    const double mid = 0.5 * (thin + thick);
    (BbcorWithWall(bat, mid) > 0.5 ? thin : thick) = mid;
  }
  return thick;
}

DesignProblem ThinWall(const Bat& bat, double min_wall_m) {
  DesignProblem p;
  p.bat = bat;
  p.variables = {{"wall_thickness_m", min_wall_m, 0.0045}};
  p.objective = DesignObjective::kMinMoi;
  p.constraints.rules = {RuleSet::kBbcor};
  return p;
}

TEST(OptimizeBbcor, TheRuleIsCheckedOnTheAnswerAndTheThinnestLegalWallPassesIt) {
  const Bat bat = DenseAlloyBat();
  // Thinning the wall to the drop limit alone gives a BBCOR over 0.50: infeasible, by the rule.
  const DesignResult drop_only = OptimizeDesign(ThinWall(bat, 0.0012));
  ASSERT_TRUE(drop_only.bbcor.has_value()) << drop_only.summary.FullReport();
  EXPECT_GT(drop_only.bbcor->value, 0.5);
  EXPECT_EQ(drop_only.summary.termination, Termination::kInfeasible);
  EXPECT_NE(drop_only.summary.message.find("rules.bbcor: the design's BBCOR = "), std::string::npos)
      << drop_only.summary.message;

  // The thinnest legal wall (bisection) as the wall's lower bound: the optimiser goes there,
  // and the answer's BBCOR, recomputed, is within the limit.
  const double legal = ThinnestLegalWall(bat);
  EXPECT_GT(legal, drop_only.bat.wall_thickness_m);
  const DesignResult r = OptimizeDesign(ThinWall(bat, legal));
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  EXPECT_NEAR(r.bat.wall_thickness_m, legal, 1e-9);
  ASSERT_TRUE(r.bbcor.has_value());
  EXPECT_LE(r.bbcor->value, 0.5);
  EXPECT_NEAR(r.bbcor->value, 0.5, 1e-4);
  EXPECT_EQ(ComputeBbcor(r.bat).value, r.bbcor->value);  // recomputed
  EXPECT_GT(BbcorWithWall(bat, legal - 1e-6), 0.5);      // any thinner is illegal
}

}  // namespace
}  // namespace optimize_bbcor_test
}  // namespace sweetspot::core
