// The `bbcor` rule of the design optimiser with the barrel model (issue 18 item 2): BBCOR <= 0.50
// is a nonlinear constraint of the design NLP with exact first and second derivatives
// (core/optimize/design_bbcor.hpp), so the wall thickness is a meaningful design variable. The
// reference is a bisection on the wall through ComputeBbcor; the optimiser's answer is checked by
// recomputing ComputeBbcor on it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/collision/barrel.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "tests/core/hollow_design_problems.hpp"

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

// The reference: the thinnest wall with BBCOR <= 0.50, by bisection to 1e-12 m (BBCOR falls
// monotonically with the wall here: docs/models.md's table).
double ThinnestLegalWall(const Bat& bat) {
  double thin = 0.001, thick = 0.008;
  while (thick - thin > 1e-12) {
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

const DesignActiveConstraint* FindActive(const DesignResult& r, const std::string& name) {
  for (const DesignActiveConstraint& a : r.active_constraints) {
    if (a.name == name) return &a;
  }
  return nullptr;
}

int BbcorRow(const DesignModel& model) {
  for (int k = 0; k < model.m(); ++k) {
    if (model.constraints()[static_cast<std::size_t>(k)].f.function == DesignFunction::kBbcor) {
      return k;
    }
  }
  return -1;
}

// Designs whose every variable reaches the BBCOR: the wall, the radii and position of the
// impact point's segment, the length (moves the impact point and the pivot arm), the density
// (I_pivot); a three-segment design whose impact point can fall in the taper; the slender-rod
// inertia model (the BBCOR keeps the rigid body's I_pivot, as ComputeBbcor).
std::vector<DesignProblem> GradientProblems() {
  std::vector<DesignProblem> out;
  DesignProblem a = ThinWall(FindPreset("bbcor-33-aluminium")->bat, 0.0020);
  a.variables = hollow_design_problems::PresetBarrelVariables();
  out.push_back(a);
  DesignProblem b = a;
  b.inertia_model = InertiaModel::kSlenderRod;
  b.variables.push_back(hollow_design_problems::PresetScaleVariable());
  out.push_back(b);
  DesignProblem c = hollow_design_problems::ThreeSegmentAluminium(0.55, 0.72);
  c.objective = DesignObjective::kMinMoi;
  c.constraints.rules = {RuleSet::kBbcor};
  out.push_back(c);
  return out;
}

// The BBCOR constraint's value equals ComputeBbcor on the design's bat, and its gradient and its
// Hessian (exact: design_bbcor.hpp's Newton steps on jets) match central differences, at random
// designs of each problem.
TEST(OptimizeBbcor, ConstraintValueGradientAndHessianMatchComputeBbcorAndFiniteDifferences) {
  std::mt19937_64 rng(18);
  double worst_value = 0.0, worst_gradient = 0.0, worst_hessian = 0.0;
  for (const DesignProblem& p : GradientProblems()) {
    DesignModel model;
    Refusal why;
    ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, &why)) << why.Message();
    const int k = BbcorRow(model);
    ASSERT_GE(k, 0);
    EXPECT_EQ(model.constraints()[static_cast<std::size_t>(k)].name, "rules.bbcor.bbcor");
    std::vector<double> weights(static_cast<std::size_t>(model.m()), 0.0);
    weights[static_cast<std::size_t>(k)] = 1.0;
    for (int trial = 0; trial < 4; ++trial) {
      std::vector<double> x(static_cast<std::size_t>(model.n()));
      for (int j = 0; j < model.n(); ++j) {
        const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
        const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
        x[static_cast<std::size_t>(j)] = v.lower + (0.1 + 0.8 * u) * (v.upper - v.lower);
      }
      DesignPoint point;
      ASSERT_TRUE(model.Evaluate(x.data(), true, &point));
      const double value = point.constraints[static_cast<std::size_t>(k)];
      const BbcorResult public_value = ComputeBbcor(model.BatAt(x.data()));
      ASSERT_TRUE(public_value.ok) << public_value.message;
      // The same closed forms in another order, and the same bisection for the force: rounding.
      EXPECT_NEAR(value, public_value.value, 1e-13);
      worst_value = std::max(worst_value, std::abs(value - public_value.value));
      Eigen::MatrixXd h;
      ASSERT_TRUE(model.Hessian(x.data(), 0.0, weights.data(), &h));
      EXPECT_LE((h - h.transpose()).norm(), 1e-12 * h.norm());
      for (int j = 0; j < model.n(); ++j) {
        const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
        const double step = 1e-5 * (v.upper - v.lower);
        std::vector<double> xp = x, xm = x;
        xp[static_cast<std::size_t>(j)] += step;
        xm[static_cast<std::size_t>(j)] -= step;
        // Central differences: truncation ~ step^2 |B'''| ~ 1e-10 of B / width; rounding ~ 1e-15
        // (the force's bisection stops at 1e-15 relative) / 1e-5 = 1e-10 of B / width. 1e-8 of
        // B / width bounds both with room (measured: 3.5e-11); a wrong term is of order 1.
        const double fd = (model.BbcorAt(xp.data()) - model.BbcorAt(xm.data())) / (2.0 * step);
        const double scale = 0.5 / (v.upper - v.lower);
        EXPECT_NEAR(point.jacobian(k, j), fd, 1e-8 * scale) << "d BBCOR / d " << v.path;
        worst_gradient = std::max(worst_gradient, std::abs(point.jacobian(k, j) - fd) / scale);
        DesignPoint pp, pm;
        ASSERT_TRUE(model.Evaluate(xp.data(), true, &pp));
        ASSERT_TRUE(model.Evaluate(xm.data(), true, &pm));
        for (int i = 0; i < model.n(); ++i) {
          const double column = (pp.jacobian(k, i) - pm.jacobian(k, i)) / (2.0 * step);
          const double width_i = model.variables()[static_cast<std::size_t>(i)].upper -
                                 model.variables()[static_cast<std::size_t>(i)].lower;
          const double hscale = 0.5 / ((v.upper - v.lower) * width_i);
          // The gradient is exact, so its difference quotient has truncation (~1e-10 of the
          // scale) and rounding (~1e-16 / 1e-5) only: 1e-8 of B / (width_i width_j) (measured:
          // 1.2e-11).
          EXPECT_NEAR(h(i, j), column, 1e-8 * hscale) << "H(" << i << ", " << j << ")";
          worst_hessian = std::max(worst_hessian, std::abs(h(i, j) - column) / hscale);
        }
      }
    }
  }
  RecordProperty("worst_value_error", std::to_string(worst_value));
  RecordProperty("worst_gradient_error_relative", std::to_string(worst_gradient));
  RecordProperty("worst_hessian_error_relative", std::to_string(worst_hessian));
  std::printf(
      "BBCOR constraint: value vs ComputeBbcor %.3g, gradient vs FD %.3g, Hessian vs FD %.3g "
      "(relative to 0.5 / widths)\n",
      worst_value, worst_gradient, worst_hessian);
}

// The test: the thinnest wall whose BBCOR <= 0.50, found by the optimiser (minimum MOI,
// the wall a variable down to 1.2 mm, where the drop limit alone would put it), equals the
// bisection's, and ComputeBbcor recomputed on the answer is <= 0.50 within the solver's
// tolerance; the constraint is active with a multiplier. With each backend and Hessian.
TEST(OptimizeBbcor, TheOptimiserFindsTheThinnestLegalWall) {
  const Bat bat = DenseAlloyBat();
  const double legal = ThinnestLegalWall(bat);
  EXPECT_GT(BbcorWithWall(bat, legal - 1e-9), 0.5);
  // The drop-3 wall (30 oz) of this alloy is thinner: without the BBCOR the wall would go there.
  {
    DesignProblem drop_only = ThinWall(bat, 0.0012);
    drop_only.constraints.rules.clear();
    drop_only.constraints.mass_kg = DesignRange::AtLeast(30.0 * 0.028349523125);
    const DesignResult r = OptimizeDesign(drop_only);
    ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
    EXPECT_LT(r.bat.wall_thickness_m, legal - 1e-4);
    EXPECT_GT(BbcorWithWall(bat, r.bat.wall_thickness_m), 0.5);
  }
  struct Case {
    const char* name;
    DesignBackend backend;
    HessianMode hessian;
  };
  for (const Case& c :
       {Case{"ipopt, limited memory", DesignBackend::kIpopt, HessianMode::kLimitedMemory},
        Case{"ipopt, exact Hessian", DesignBackend::kIpopt, HessianMode::kExact},
        Case{"nlopt slsqp", DesignBackend::kNloptSlsqp, HessianMode::kLimitedMemory}}) {
    DesignOptions o;
    o.backend = c.backend;
    o.hessian = c.hessian;
    const DesignResult r = OptimizeDesign(ThinWall(bat, 0.0012), o);
    ASSERT_EQ(r.summary.termination, Termination::kConverged) << c.name << "\n"
                                                              << r.summary.FullReport();
    // The wall: BBCOR's slope here is about -20 per m, so the solver's constraint tolerance
    // (1e-10 of the scale 0.5) is ~2.5e-12 m of wall and the bisection's bracket 1e-12 m: 1e-11 m
    // holds both with room (measured: 3.2e-13 m with Ipopt, 3.8e-13 m with SLSQP).
    EXPECT_NEAR(r.bat.wall_thickness_m, legal, 1e-11) << c.name;
    ASSERT_TRUE(r.bbcor.has_value()) << c.name;
    EXPECT_EQ(ComputeBbcor(r.bat).value, r.bbcor->value);  // recomputed
    // <= 0.50 plus the solver's constraint tolerance (options.constraint_tolerance = 1e-10 of
    // the constraint's scale 0.5).
    EXPECT_LE(r.bbcor->value, 0.5 + 0.5 * o.constraint_tolerance) << c.name;
    EXPECT_NEAR(r.bbcor->value, 0.5, 1e-10) << c.name;
    const DesignActiveConstraint* a = FindActive(r, "rules.bbcor.bbcor");
    ASSERT_NE(a, nullptr) << c.name;
    EXPECT_EQ(a->bound, 0.5);
    // Minimising the MOI: a higher limit allows a thinner wall, a lower MOI.
    EXPECT_LT(a->multiplier, 0.0) << c.name;
    EXPECT_EQ(FindActive(r, "rules.bbcor.drop"), nullptr) << c.name;
    std::printf(
        "%s: wall %.15g m (bisection %.15g, diff %.3g m), BBCOR recomputed %.17g, "
        "%d iterations\n",
        c.name, r.bat.wall_thickness_m, legal, r.bat.wall_thickness_m - legal, r.bbcor->value,
        r.summary.iterations);
  }
}

// Two variables: the wall and the barrel's radius (a smaller barrel is stiffer, so it allows a
// thinner wall), with the rule's drop and diameter limits. The answer's recomputed BBCOR is
// within the limit.
TEST(OptimizeBbcor, WallAndBarrelRadiusTogetherStayLegal) {
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.8382, 0.0111, 0.0333, 0.28, 0.52};
  p.bat.material = *FindMaterial("aluminium-7050");
  p.bat.material.name = "custom";
  p.bat.material.density_kg_m3 *= 1.2;
  p.bat.wall_thickness_m = 0.003;
  p.variables = {{"wall_thickness_m", 0.0012, 0.0045},
                 {"three_segment.barrel_radius_m", 0.030, 0.0334}};
  p.objective = DesignObjective::kMinMoi;
  p.constraints.rules = {RuleSet::kBbcor};
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  ASSERT_TRUE(r.bbcor.has_value());
  EXPECT_LE(r.bbcor->value, 0.5 + 0.5 * DesignOptions{}.constraint_tolerance);
  std::string active;
  for (const DesignActiveConstraint& a : r.active_constraints) active += a.name + " ";
  std::printf("wall %.9g m, barrel radius %.9g m, BBCOR %.17g, active: %s\n",
              r.bat.wall_thickness_m, r.three_segment->barrel_radius_m, r.bbcor->value,
              active.c_str());
}

// An upper bound on the wall below the legal wall: no design meets the rule. Infeasible, the
// conflict named, and the answer's recomputed BBCOR in the message.
TEST(OptimizeBbcor, AWallTooThinForTheRuleIsInfeasible) {
  const Bat bat = DenseAlloyBat();
  DesignProblem p = ThinWall(bat, 0.0012);
  p.variables[0].max = 0.0020;
  const DesignResult r = OptimizeDesign(p);
  EXPECT_EQ(r.summary.termination, Termination::kInfeasible) << r.summary.FullReport();
  ASSERT_TRUE(r.bbcor.has_value());
  EXPECT_GT(r.bbcor->value, 0.5);
  EXPECT_NE(r.summary.message.find("rules.bbcor: the design's BBCOR = "), std::string::npos)
      << r.summary.message;
}

// A solid bat keeps today's rule: the ball's COR, checked before solving; no BBCOR constraint.
TEST(OptimizeBbcor, SolidBatsHaveNoBbcorConstraint) {
  DesignProblem p;
  p.bat = FindPreset("wood-34-ash")->bat;
  p.variables = {{"profile.knots[12].radius_m", 0.030, 0.0331}};
  p.constraints.rules = {RuleSet::kBbcor};
  p.cor = 0.48;
  DesignModel model;
  Refusal why;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, &why)) << why.Message();
  EXPECT_EQ(BbcorRow(model), -1);
  EXPECT_FALSE(OptimizeDesign(p).bbcor.has_value());
}

}  // namespace
}  // namespace optimize_bbcor_test
}  // namespace sweetspot::core
