// The design model behind the optimiser: its mass integrals against the public mass
// properties, its gradients and Hessians against finite differences and against
// ComputeMassPropertiesWithGradient, Ipopt's own derivative checker, the status mapping,
// variable paths and rule sets.
#include "core/optimize/design_model.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/ball/ball_catalogue.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/numerics/jet.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_model_test {
namespace {

// A hollow aluminium profile with a fill, every kind of profile variable.
DesignProblem HollowFilledProfile(DesignObjective objective) {
  DesignProblem p;
  p.bat = FindPreset("bbcor-33-aluminium")->bat;
  Fill fill;
  fill.material = *FindMaterial("rubber");
  fill.diameter_m = 0.03;
  fill.depth_m = 0.2;
  p.bat.fill = fill;
  p.variables = {{"profile.knots[5].radius_m", 0.010, 0.013},
                 {"profile.knots[10].radius_m", 0.030, 0.0334},
                 {"profile.knots[10].x_m", 0.50, 0.54},
                 {"profile.knots[12].x_m", 0.835, 0.845},
                 {"material.density_kg_m3", 2500.0, 3000.0},
                 {"wall_thickness_m", 0.0022, 0.0032},
                 {"fill.diameter_m", 0.02, 0.04},
                 {"fill.depth_m", 0.1, 0.3},
                 {"fill.material.density_kg_m3", 500.0, 1500.0}};
  p.constraints.mass_kg = DesignRange::Between(0.8, 0.9);
  p.constraints.balance_point_m = DesignRange::AtMost(0.6);
  p.constraints.moi_six_inch_kg_m2 = DesignRange::AtMost(0.25);
  p.constraints.rules = {RuleSet::kBbcor};
  p.objective = objective;
  return p;
}

// A solid three-segment bat with a cork fill, every three-segment variable.
DesignProblem FilledThreeSegment(DesignObjective objective) {
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.86, 0.0125, 0.033, 0.30, 0.55};
  p.bat.material = *FindMaterial("ash");
  Fill fill;
  fill.material = *FindMaterial("cork");
  fill.diameter_m = 0.0254;
  fill.depth_m = 0.254;
  p.bat.fill = fill;
  p.variables = {{"three_segment.length_m", 0.84, 0.88},
                 {"three_segment.handle_radius_m", 0.011, 0.014},
                 {"three_segment.barrel_radius_m", 0.030, 0.034},
                 {"three_segment.taper_start_m", 0.2, 0.4},
                 {"three_segment.taper_end_m", 0.45, 0.60},
                 {"fill.depth_m", 0.1, 0.2}};
  p.constraints.mass_kg = DesignRange::Equal(0.9);
  p.constraints.taper = TaperRule::kMaxSlope;
  p.constraints.max_taper_slope = 0.2;
  p.swing.pivot_from_knob_m = 0.1;
  p.objective = objective;
  return p;
}

// The hollow profile hit by an MLB ball (its COR law) at 90 mph with the COR of each design its
// own barrel's (cor_from_barrel: the exit-speed objectives only).
DesignProblem HollowProfileWithBarrelCor(DesignObjective objective) {
  DesignProblem p = HollowFilledProfile(objective);
  ApplyBallPreset(*FindBallPreset("mlb"), &p.ball);
  p.ball.speed_mps = 40.0;
  p.cor_from_barrel = true;
  return p;
}

bool ExitSpeedObjective(DesignObjective objective) {
  return objective != DesignObjective::kMinMoi && objective != DesignObjective::kMinSting;
}

const DesignObjective kObjectives[] = {DesignObjective::kMaxExitSpeed,
                                       DesignObjective::kMaxExitSpeedSwingWeight,
                                       DesignObjective::kWidestSweetZone, DesignObjective::kMinMoi};

DesignModel Build(const DesignProblem& p) {
  DesignModel model;
  Refusal why;
  EXPECT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, &why)) << why.Message();
  return model;
}

std::vector<double> RandomPoint(const DesignModel& model, std::mt19937_64& rng) {
  std::vector<double> x;
  for (const auto& v : model.variables()) {
    const double u = static_cast<double>(rng() >> 11) * 0x1.0p-53;
    x.push_back(v.lower + (0.05 + 0.9 * u) * (v.upper - v.lower));
  }
  return x;
}

TEST(OptimizeJet, SecondOrderDerivativesOfAKnownFunction) {
  // f(x, y) = x^2 y / (1 + sqrt(y)) at (1.5, 4): f = 3, by hand:
  // f_x = 2 x y / 3 = 4, f_y = x^2 (1 + sqrt(y) - y / (2 sqrt(y))) / 9 = 0.5,
  // f_xx = 2 y / 3 = 8/3, f_xy = 2 x (1 + 1) / 9 = 2/3.
  using J = jet::Jet<2, true>;
  const J x = J::Variable(1.5, 0), y = J::Variable(4.0, 1);
  const J f = x * x * y / (1.0 + jet::Sqrt(y));
  EXPECT_DOUBLE_EQ(f.v, 3.0);
  EXPECT_DOUBLE_EQ(f.g[0], 4.0);
  EXPECT_DOUBLE_EQ(f.g[1], 0.5);
  EXPECT_DOUBLE_EQ(f.h[0], 8.0 / 3.0);
  EXPECT_DOUBLE_EQ(f.h[1], 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(f.h[2], f.h[1]);
  const J p = jet::Pow(y, -0.5);  // d/dy = -y^-1.5 / 2, d2/dy2 = 0.75 y^-2.5
  EXPECT_DOUBLE_EQ(p.g[1], -0.0625);
  EXPECT_DOUBLE_EQ(p.h[3], 0.75 / 32.0);
}

TEST(OptimizeModel, PropertiesMatchThePublicMassProperties) {
  for (const DesignProblem& p : {HollowFilledProfile(DesignObjective::kMinMoi),
                                 FilledThreeSegment(DesignObjective::kMinMoi)}) {
    const DesignModel model = Build(p);
    std::mt19937_64 rng(3);
    for (int trial = 0; trial < 20; ++trial) {
      const std::vector<double> x = RandomPoint(model, rng);
      DesignPoint point;
      ASSERT_TRUE(model.Evaluate(x.data(), false, &point));
      const Bat bat = model.BatAt(x.data());
      ASSERT_TRUE(bat.Validate(nullptr));
      const MassProperties props = ComputeMassProperties(bat);
      // Same integrals, other summation order and reference point: rounding only.
      EXPECT_NEAR(point.mass_kg, props.mass_kg, 1e-13);
      EXPECT_NEAR(point.balance_point_m, props.balance_point_m, 1e-13);
      EXPECT_NEAR(point.moi_six_inch_kg_m2, props.MoiSixInchKgM2(), 1e-13);
      EXPECT_NEAR(point.objective, props.MoiSixInchKgM2(), 1e-13);
    }
  }
}

// The model's exit-speed objectives equal the public closed forms of the design's bat, for
// both models: the same algebra on moments about another point, so rounding only.
TEST(OptimizeModel, ExitSpeedObjectivesMatchThePublicClosedForms) {
  for (CollisionModel exit : {CollisionModel::kRigidPivot, CollisionModel::kFreeBat}) {
    DesignProblem p = FilledThreeSegment(DesignObjective::kMaxExitSpeed);
    p.model = exit;
    const DesignModel model = Build(p);
    std::mt19937_64 rng(5);
    double spread = 0.0;  // how far the sweet spots of the designs are apart, m
    double first = std::nan("");
    for (int trial = 0; trial < 10; ++trial) {
      const std::vector<double> x = RandomPoint(model, rng);
      DesignPoint point;
      ASSERT_TRUE(model.Evaluate(x.data(), false, &point));
      const Bat bat = model.BatAt(x.data());
      const MassProperties props = ComputeMassProperties(bat);
      const MaxExitSpeedResult max = ClosedFormMaxExitSpeed(
          ClosedFormProfileFor(exit, props, p.ball, p.swing, model.cor()), bat.LengthM());
      // Exit speeds of ~20 m/s from the same integrals: rounding, 1e-11 m/s.
      EXPECT_NEAR(point.objective, max.exit_speed_mps, 1e-11) << CollisionModelName(exit);
      if (std::isnan(first)) first = max.position_from_knob_m;
      spread = std::max(spread, std::abs(max.position_from_knob_m - first));
    }
    EXPECT_GT(spread, 1e-3);  // the designs differ, so the comparison means something
  }
  // The free bat is not the pinned bat: their objectives differ at the base design.
  DesignProblem rigid = FilledThreeSegment(DesignObjective::kMaxExitSpeed);
  DesignProblem free = rigid;
  free.model = CollisionModel::kFreeBat;
  DesignPoint a, b;
  ASSERT_TRUE(Build(rigid).Evaluate(Build(rigid).BaseX().data(), false, &a));
  ASSERT_TRUE(Build(free).Evaluate(Build(free).BaseX().data(), false, &b));
  EXPECT_GT(std::abs(a.objective - b.objective), 1e-3);  // 0.014 m/s here; rounding is 1e-11
  // Only the closed forms can be optimised.
  DesignProblem hertz = rigid;
  hertz.model = CollisionModel::kHertz;
  Refusal why;
  EXPECT_FALSE(hertz.Validate(&why));
  EXPECT_EQ(why.field, "model");
}

// A swing given by its bat speed on designs whose length varies: the model's exit-speed
// objectives equal the public closed forms at the omega ResolveSwing gives each design's bat
// (omega0 = v / (L - from_tip - pivot)), for both problems (three-segment: pivot 0.1 m).
TEST(OptimizeModel, BatSpeedObjectivesUseEachDesignsOwnLength) {
  for (const DesignObjective objective :
       {DesignObjective::kMaxExitSpeed, DesignObjective::kMaxExitSpeedSwingWeight}) {
    for (DesignProblem p : {HollowFilledProfile(objective), FilledThreeSegment(objective)}) {
      p.swing.bat_speed_mps = 32.0;
      p.model = CollisionModel::kRigidPivot;
      const DesignModel model = Build(p);
      std::mt19937_64 rng(7);
      double lengths[2] = {1e9, 0.0};  // the least and largest length met, m
      for (int trial = 0; trial < 10; ++trial) {
        const std::vector<double> x = RandomPoint(model, rng);
        DesignPoint point;
        ASSERT_TRUE(model.Evaluate(x.data(), false, &point));
        const Bat bat = model.BatAt(x.data());
        const MassProperties props = ComputeMassProperties(bat);
        Swing swing;
        ASSERT_TRUE(ResolveSwing(p.swing, bat.LengthM(), &swing, nullptr));
        if (objective == DesignObjective::kMaxExitSpeedSwingWeight) {
          swing.angular_speed_rad_s *=
              std::pow(props.MoiSixInchKgM2() / model.reference_moi_six_inch_kg_m2(),
                       -p.swing_weight_exponent);
        }
        EXPECT_DOUBLE_EQ(model.AngularSpeedFor(props.MoiSixInchKgM2(), bat.LengthM()),
                         swing.angular_speed_rad_s);
        const MaxExitSpeedResult max = ClosedFormMaxExitSpeed(
            ClosedFormProfileFor(p.model, props, p.ball, swing, model.cor()), bat.LengthM());
        // Exit speeds of ~30 m/s from the same integrals: rounding, 1e-11 m/s.
        EXPECT_NEAR(point.objective, max.exit_speed_mps, 1e-11) << DesignObjectiveName(objective);
        lengths[0] = std::min(lengths[0], bat.LengthM());
        lengths[1] = std::max(lengths[1], bat.LengthM());
      }
      EXPECT_GT(lengths[1] - lengths[0], 1e-3);  // the lengths differ, so omega0 does
    }
  }
}

// An optimisation with the swing given by its bat speed and the length a variable: the answer
// reports its own omega, v over its own arm; Ipopt's derivative checker (first and second
// order, so the gradient's and the exact Hessian's d omega0 / dL terms) finds no errors, and
// the exact Hessian converges to the limited-memory answer.
TEST(OptimizeModel, BatSpeedDesignReportsItsOwnOmega) {
  DesignProblem p = FilledThreeSegment(DesignObjective::kMaxExitSpeed);
  const double v = 32.0;
  p.swing.bat_speed_mps = v;
  const DesignResult r = OptimizeDesign(p, DesignOptions{});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  const double arm = r.bat.LengthM() - p.swing.bat_speed_from_tip_m - p.swing.pivot_from_knob_m;
  // The same division as ResolveSwing: a few ulps at most.
  EXPECT_NEAR(r.angular_speed_rad_s * arm, v, 1e-12 * v);
  DesignOptions exact;
  exact.hessian = HessianMode::kExact;
  const DesignResult e = OptimizeDesign(p, exact);
  ASSERT_EQ(e.summary.termination, Termination::kConverged) << e.summary.FullReport();
  // Two converged solves of the same problem (tol 1e-9 on the scaled problem): their objectives
  // agree far within 1e-7 of ~30 m/s.
  EXPECT_NEAR(e.objective_value, r.objective_value, 1e-7 * r.objective_value);
  for (DerivativeCheck check : {DerivativeCheck::kFirstOrder, DerivativeCheck::kSecondOrder}) {
    DesignOptions o;
    o.derivative_check = check;
    o.hessian =
        check == DerivativeCheck::kSecondOrder ? HessianMode::kExact : HessianMode::kLimitedMemory;
    o.max_iterations = 1;
    o.explain_infeasibility = false;
    const DesignResult c = OptimizeDesign(p, o);
    EXPECT_EQ(c.derivative_check_errors, 0) << c.derivative_check_report;
  }
  // A bat-speed point behind the pivot for the shortest bat the bounds allow is refused there.
  p.swing.pivot_from_knob_m = 0.69;  // 0.84 - 0.1524 = 0.6876 m from the knob
  Refusal why;
  ASSERT_FALSE(p.Validate(&why));
  EXPECT_EQ(why.field, "swing.bat_speed_from_tip_m");
  EXPECT_NE(why.Message().find("for the shortest bat the variables allow, L = 0.84 m"),
            std::string::npos)
      << why.Message();
}

// A linked variable ("paths"): both fields take the value, in the model and in the answer.
TEST(OptimizeModel, LinkedFieldsTakeTheVariablesValue) {
  DesignProblem p = HollowFilledProfile(DesignObjective::kMaxExitSpeed);
  p.variables = {{"profile.knots[10].radius_m", 0.030, 0.0334}};
  p.variables[0].linked_paths = {"profile.knots[11].radius_m", "profile.knots[12].radius_m"};
  p.constraints = {};
  const DesignResult r = OptimizeDesign(p, DesignOptions{});
  ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.FullReport();
  ASSERT_EQ(r.variables.size(), 3u);
  EXPECT_EQ(r.variables[1].path, "profile.knots[11].radius_m");
  EXPECT_EQ(r.variables[0].value, r.variables[1].value);
  EXPECT_EQ(r.variables[0].value, r.variables[2].value);
  EXPECT_EQ(r.bat.knots[10].radius_m, r.variables[0].value);
  EXPECT_EQ(r.bat.knots[11].radius_m, r.variables[0].value);
  EXPECT_EQ(r.bat.knots[12].radius_m, r.variables[0].value);
  // A wider barrel hits harder here with no mass limit: the upper bound, to Ipopt's 1e-8.
  EXPECT_NEAR(r.variables[0].value, 0.0334, 1e-8);
  // A linked field is checked as a variable: a repeated one is refused, naming it.
  p.variables[0].linked_paths = {"profile.knots[10].radius_m"};
  Refusal why;
  EXPECT_FALSE(p.Validate(&why));
  EXPECT_NE(why.Message().find("appears more than once"), std::string::npos) << why.Message();
}

// A scale variable ("scale_paths") over every radius of a solid wooden bat, with the mass
// fixed: the mass of a solid bat is the base mass times s^2 exactly (every cross-section's area
// scales by s^2), so the only feasible factor is s = sqrt(M / M0), whatever the objective. The
// answer lists the factor under its name, then each field = its base value times the factor,
// exactly (the product the model's parameters hold), and the bat has those radii.
TEST(OptimizeModel, ScaledFieldsAreTheBaseValueTimesTheFactor) {
  DesignProblem p;
  p.bat = FindPreset("wood-34-ash")->bat;
  const double base_mass_kg = ComputeMassProperties(p.bat).mass_kg;
  DesignVariable scale{"all_radii", 0.8, 1.2};
  for (std::size_t k = 0; k < p.bat.knots.size(); ++k) {
    scale.scale_paths.push_back("profile.knots[" + std::to_string(k) + "].radius_m");
  }
  p.variables = {scale};
  p.constraints.mass_kg = DesignRange::Equal(0.85);
  p.objective = DesignObjective::kMaxExitSpeed;
  const DesignResult r = OptimizeDesign(p, DesignOptions{});
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  ASSERT_EQ(r.variables.size(), p.bat.knots.size() + 1);
  EXPECT_EQ(r.variables[0].path, "all_radii");
  EXPECT_TRUE(r.variables[0].scale_factor);
  const double s = r.variables[0].value;
  // Ipopt holds the mass to constr_viol_tol = 1e-10 of its scale (0.85 kg), so |dM| <= 1e-10
  // kg and |ds| = s |dM| / (2 M) <= 6e-11; 1e-9 leaves room for the integrals' rounding.
  EXPECT_NEAR(s, std::sqrt(0.85 / base_mass_kg), 1e-9);
  EXPECT_NEAR(r.properties.mass_kg, 0.85, 1e-9);  // the re-checked mass, same budget
  for (std::size_t k = 0; k < p.bat.knots.size(); ++k) {
    const DesignValue& v = r.variables[k + 1];
    EXPECT_EQ(v.path, scale.scale_paths[k]);
    EXPECT_FALSE(v.scale_factor);
    EXPECT_EQ(v.value, p.bat.knots[k].radius_m * s) << v.path;  // exactly: one product
    EXPECT_EQ(r.bat.knots[k].radius_m, v.value) << v.path;
    EXPECT_EQ(r.bat.knots[k].x_m, p.bat.knots[k].x_m);  // positions untouched
  }
}

// A scale variable is checked as its fields would be: each field's rules over [min, max] times
// its base value, a field that is 0 in the base design, its name, and its fields' uniqueness.
TEST(OptimizeModel, ScaleVariablesAreCheckedPerField) {
  DesignProblem p;
  p.bat = FindPreset("wood-34-ash")->bat;
  p.variables = {
      {"handle", 0.9, 1.1, {}, {"profile.knots[4].radius_m", "profile.knots[5].radius_m"}}};
  Refusal why;
  ASSERT_TRUE(p.Validate(&why)) << why.Message();
  // A radius must stay positive: min = -0.1 gives knot 4 a negative radius.
  p.variables[0].min = -0.1;
  ASSERT_FALSE(p.Validate(&why));
  EXPECT_EQ(why.field, "variables[0].min");
  EXPECT_NE(why.Message().find("gives profile.knots[4].radius_m = "), std::string::npos)
      << why.Message();
  EXPECT_NE(why.Message().find("must be positive"), std::string::npos) << why.Message();
  p.variables[0].min = 0.9;
  // The wall of a solid bat is 0: a factor cannot move it.
  p.variables[0].scale_paths.push_back("wall_thickness_m");
  ASSERT_FALSE(p.Validate(&why));
  EXPECT_EQ(why.field, "variables[0].scale_paths[2]");
  EXPECT_NE(why.Message().find("is 0 in the base design"), std::string::npos) << why.Message();
  p.variables[0].scale_paths.pop_back();
  // A field set by two variables.
  p.variables.push_back({"profile.knots[5].radius_m", 0.01, 0.02});
  ASSERT_FALSE(p.Validate(&why));
  EXPECT_EQ(why.field, "variables[1].path");
  EXPECT_NE(why.Message().find("appears more than once"), std::string::npos) << why.Message();
  p.variables.pop_back();
  // The name is not a field, and a scale variable links nothing.
  p.variables[0].path = "profile.knots[6].radius_m";
  ASSERT_FALSE(p.Validate(&why));
  EXPECT_EQ(why.field, "variables[0].path");
  p.variables[0].path = "handle";
  p.variables[0].linked_paths = {"profile.knots[6].radius_m"};
  ASSERT_FALSE(p.Validate(&why));
  EXPECT_EQ(why.field, "variables[0].linked_paths");
}

// Three-segment designs through x1 = 0 and x1 = x2, where ThreeSegmentShape::Knots() merges
// knots: the model keeps 4 knots (coincident allowed), so it is smooth there, and equals the
// merged bat's properties (the step of width 1e-12 L changes them by < 1e-12 relative).
TEST(OptimizeModel, ThreeSegmentDesignsAreSmoothWhereKnotsMerge) {
  DesignProblem p = FilledThreeSegment(DesignObjective::kMinMoi);
  p.bat.fill.reset();
  p.variables = {{"three_segment.taper_start_m", 0.0, 0.5},
                 {"three_segment.taper_end_m", 0.0, 0.7}};
  p.constraints = DesignConstraints{};
  const DesignModel model = Build(p);
  for (const std::vector<double>& x : {std::vector<double>{0.0, 0.5}, {0.4, 0.4}, {0.0, 0.0}}) {
    DesignPoint point;
    ASSERT_TRUE(model.Evaluate(x.data(), true, &point));
    const MassProperties props = ComputeMassProperties(model.BatAt(x.data()));
    EXPECT_NEAR(point.mass_kg, props.mass_kg, 1e-12 * props.mass_kg);
    EXPECT_NEAR(point.moi_six_inch_kg_m2, props.MoiSixInchKgM2(), 1e-12);
    // One-sided differences into the feasible side agree with the gradient (exact on both
    // sides of the merge: the integrals are polynomial in x1, x2).
    for (int j = 0; j < 2; ++j) {
      const double h = 1e-7;
      std::vector<double> xp = x;
      xp[static_cast<std::size_t>(j)] += h;
      if (j == 0 && xp[0] > xp[1]) continue;
      const double fd = (model.Value(model.objective(), xp.data()) - point.objective) / h;
      // Forward difference: error ~ h |f''| / 2 ~ 1e-7 relative to |f'| ~ 0.1.
      EXPECT_NEAR(point.objective_gradient[j], fd, 1e-6 + 1e-5 * std::abs(fd)) << j;
    }
  }
}

// The model's mass-property gradients against ComputeMassPropertiesWithGradient (independent
// implementation of the same integrals' derivatives) for a profile design.
TEST(OptimizeModel, GradientsMatchComputeMassPropertiesWithGradient) {
  DesignProblem p = HollowFilledProfile(DesignObjective::kMinMoi);
  p.constraints = DesignConstraints{};
  p.constraints.mass_kg = DesignRange::AtLeast(0.1);
  p.constraints.balance_point_m = DesignRange::AtLeast(0.1);
  const DesignModel model = Build(p);
  std::mt19937_64 rng(5);
  const std::vector<double> x = RandomPoint(model, rng);
  DesignPoint point;
  ASSERT_TRUE(model.Evaluate(x.data(), true, &point));
  const Bat bat = model.BatAt(x.data());
  const MassPropertiesWithGradient ref = ComputeMassPropertiesWithGradient(bat);
  const DesignParameterLayout& lay = ref.layout;
  for (int j = 0; j < model.n(); ++j) {
    const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
    int idx = -1;
    switch (v.ref.kind) {
      case DesignVariableKind::kKnotRadius:
        idx = lay.KnotRadius(v.ref.knot);
        break;
      case DesignVariableKind::kKnotPosition:
        idx = lay.KnotPosition(v.ref.knot);
        break;
      case DesignVariableKind::kDensity:
        idx = lay.Density();
        break;
      case DesignVariableKind::kWallThickness:
        idx = lay.WallThickness();
        break;
      case DesignVariableKind::kFillDiameter:
        idx = lay.FillDiameter();
        break;
      case DesignVariableKind::kFillDepth:
        idx = lay.FillDepth();
        break;
      case DesignVariableKind::kFillDensity:
        idx = lay.FillDensity();
        break;
      default:
        break;
    }
    ASSERT_GE(idx, 0) << v.path;
    const double dm = ref.mass_gradient[idx], dc = ref.balance_point_gradient[idx];
    const double di6 = ref.MoiSixInchGradient()[idx];
    // Rounding of two exact derivatives of the same integrals: 1e-10 relative to the scale.
    EXPECT_NEAR(point.jacobian(0, j), dm, 1e-10 * (1.0 + std::abs(dm))) << v.path;
    EXPECT_NEAR(point.jacobian(1, j), dc, 1e-10 * (1.0 + std::abs(dc))) << v.path;
    EXPECT_NEAR(point.objective_gradient[j], di6, 1e-10 * (1.0 + std::abs(di6))) << v.path;
  }
}

// Gradients of every objective and constraint, and the exact Hessian of a random Lagrangian,
// against central differences of the model's own values and gradients.
TEST(OptimizeModel, GradientsAndHessiansMatchFiniteDifferences) {
  std::mt19937_64 rng(11);
  for (DesignObjective objective : kObjectives) {
    for (int variant = 0; variant < 11; ++variant) {
      // Both problems with both exit-speed models: rigid_pivot, then free_bat; then the
      // profile with a linked variable (two knots' radii set to one value); then a scale
      // variable ("scale_paths") in each problem; then a swing given by its bat speed with the
      // length a variable (omega0 = v / (L - from_tip - pivot) moves with L): the scaled
      // three-segment problem (L scaled) and the profile (the last knot's position); then the
      // profile with the COR of each design its barrel's (cor_from_barrel), with the rigid pivot
      // and with the free bat and a bat speed (exit-speed objectives only).
      if (variant >= 9 && !ExitSpeedObjective(objective)) continue;
      DesignProblem p = variant >= 9       ? HollowProfileWithBarrelCor(objective)
                        : variant % 2 == 0 ? HollowFilledProfile(objective)
                                           : FilledThreeSegment(objective);
      p.model = variant == 2 || variant == 3 || variant == 10 ? CollisionModel::kFreeBat
                                                              : CollisionModel::kRigidPivot;
      if (variant == 4) p.variables[1].linked_paths = {"profile.knots[11].radius_m"};
      if (variant == 6) {
        // Two knots' radii (coefficients ~0.033 m) and a knot's position (~0.83 m) by one
        // factor: the chain rule's coefficients differ by 25x, so a missing one shows.
        p.variables.push_back({"barrel",
                               0.95,
                               1.003,
                               {},
                               {"profile.knots[11].radius_m", "profile.knots[12].radius_m",
                                "profile.knots[11].x_m"}});
      }
      if (variant == 5 || variant == 7) {
        // The length (the integrals' L row), a radius that is two parameters (knots 0 and 1)
        // and the fill's diameter (the fill's own factor 0.5 as well) by one factor.
        p.variables[0] = {
            "length_handle_bore",
            0.97,
            1.03,
            {},
            {"three_segment.length_m", "three_segment.handle_radius_m", "fill.diameter_m"}};
        p.variables.erase(p.variables.begin() + 1);  // three_segment.handle_radius_m
      }
      if (variant >= 7 && variant != 9) p.swing.bat_speed_mps = 32.0;  // 72 mph, 6 in from the tip
      const DesignModel model = Build(p);
      ASSERT_GT(model.m(), 3);
      EXPECT_EQ(model.cor_from_barrel(), variant >= 9);
      if (variant % 2 == 0) {
        // The hollow profile's rules bbcor: its BBCOR constraint is among those checked here.
        EXPECT_TRUE(std::any_of(
            model.constraints().begin(), model.constraints().end(),
            [](const DesignConstraintSpec& c) { return c.f.function == DesignFunction::kBbcor; }));
      }
      for (int trial = 0; trial < 3; ++trial) {
        const std::vector<double> x = RandomPoint(model, rng);
        DesignPoint point;
        ASSERT_TRUE(model.Evaluate(x.data(), true, &point));
        std::vector<double> weights(static_cast<std::size_t>(model.m()));
        for (double& w : weights) w = static_cast<double>(rng() >> 11) * 0x1.0p-53 - 0.5;
        Eigen::MatrixXd h;
        ASSERT_TRUE(model.Hessian(x.data(), 0.7, weights.data(), &h));
        EXPECT_LE((h - h.transpose()).norm(), 1e-12 * h.norm());
        auto lagrangian_gradient = [&](const std::vector<double>& at) {
          DesignPoint q;
          EXPECT_TRUE(model.Evaluate(at.data(), true, &q));
          Eigen::VectorXd g = 0.7 * q.objective_gradient;
          for (int k = 0; k < model.m(); ++k)
            g += weights[static_cast<std::size_t>(k)] * q.jacobian.row(k).transpose();
          return g;
        };
        for (int j = 0; j < model.n(); ++j) {
          const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
          const double step = 1e-6 * (v.upper - v.lower);
          std::vector<double> xp = x, xm = x;
          xp[static_cast<std::size_t>(j)] += step;
          xm[static_cast<std::size_t>(j)] -= step;
          DesignPoint pp, pm;
          ASSERT_TRUE(model.Evaluate(xp.data(), false, &pp));
          ASSERT_TRUE(model.Evaluate(xm.data(), false, &pm));
          // Central differences: truncation ~ step^2 |f'''| and rounding ~ eps |f| / step;
          // both are below 1e-7 of the terms' scale here.
          const double fd = (pp.objective - pm.objective) / (2.0 * step);
          const double scale_f = std::abs(point.objective) / (v.upper - v.lower);
          EXPECT_NEAR(point.objective_gradient[j], fd, 1e-6 * scale_f + 1e-7 * std::abs(fd))
              << DesignObjectiveName(objective) << " d/d " << v.path;
          for (int k = 0; k < model.m(); ++k) {
            const double fdk = (pp.constraints[static_cast<std::size_t>(k)] -
                                pm.constraints[static_cast<std::size_t>(k)]) /
                               (2.0 * step);
            const double scale_k =
                model.constraints()[static_cast<std::size_t>(k)].scale / (v.upper - v.lower);
            EXPECT_NEAR(point.jacobian(k, j), fdk, 1e-6 * scale_k + 1e-7 * std::abs(fdk))
                << model.constraints()[static_cast<std::size_t>(k)].name << " d/d " << v.path;
          }
          const Eigen::VectorXd column =
              (lagrangian_gradient(xp) - lagrangian_gradient(xm)) / (2.0 * step);
          for (int i = 0; i < model.n(); ++i) {
            const double scale =
                (std::abs(h(i, j)) + std::abs(column[i]) + h.col(j).lpNorm<Eigen::Infinity>());
            EXPECT_NEAR(h(i, j), column[i], 1e-5 * scale + 1e-12)
                << DesignObjectiveName(objective) << " H(" << i << ", " << j << ")";
          }
        }
      }
    }
  }
}

// Ipopt's own derivative checker (derivative_test = first-order and, with the exact Hessian,
// second-order) at the start of each problem: no errors reported. The checker's output is
// captured by a journal at J_WARNING on the J_NLP category (print_level 0 keeps the console
// silent).
TEST(OptimizeModel, IpoptDerivativeCheckerFindsNoErrors) {
  for (DesignObjective objective : kObjectives) {
    std::vector<DesignProblem> problems = {HollowFilledProfile(objective),
                                           FilledThreeSegment(objective)};
    if (ExitSpeedObjective(objective)) problems.push_back(HollowProfileWithBarrelCor(objective));
    for (const DesignProblem& p : problems) {
      for (DerivativeCheck check : {DerivativeCheck::kFirstOrder, DerivativeCheck::kSecondOrder}) {
        DesignOptions o;
        o.derivative_check = check;
        o.hessian = check == DerivativeCheck::kSecondOrder ? HessianMode::kExact
                                                           : HessianMode::kLimitedMemory;
        o.max_iterations = 1;
        o.explain_infeasibility = false;
        const DesignResult r = OptimizeDesign(p, o);
        EXPECT_EQ(r.derivative_check_errors, 0) << DesignObjectiveName(objective) << "\n"
                                                << r.derivative_check_report;
        EXPECT_NE(r.derivative_check_report.find(check == DerivativeCheck::kSecondOrder
                                                     ? "Starting derivative checker for second"
                                                     : "Starting derivative checker for first"),
                  std::string::npos);
      }
    }
  }
}

// Max iterations reached maps to no_convergence with the point kept; Ipopt's raw status is kept.
TEST(OptimizeStatus, IterationLimitIsNoConvergenceWithTheRawStatus) {
  DesignOptions o;
  o.max_iterations = 2;
  const DesignResult r = OptimizeDesign(FilledThreeSegment(DesignObjective::kMaxExitSpeed), o);
  EXPECT_EQ(r.summary.raw_status, -1);
  EXPECT_EQ(r.summary.termination, Termination::kNoConvergence) << r.summary.FullReport();
  EXPECT_NE(r.summary.message.find("Maximum_Iterations_Exceeded"), std::string::npos);
}

TEST(OptimizeNames, PathsObjectivesAndRuleSetsRoundTrip) {
  for (const char* path :
       {"profile.knots[0].radius_m", "profile.knots[12].x_m", "three_segment.length_m",
        "three_segment.handle_radius_m", "three_segment.barrel_radius_m",
        "three_segment.taper_start_m", "three_segment.taper_end_m", "material.density_kg_m3",
        "wall_thickness_m", "fill.diameter_m", "fill.depth_m", "fill.material.density_kg_m3"}) {
    const auto ref = ParseDesignVariablePath(path);
    ASSERT_TRUE(ref.has_value()) << path;
    EXPECT_EQ(DesignVariablePath(*ref), path);
  }
  for (const char* bad : {"profile.knots[01].radius_m", "profile.knots[].x_m", "profile.knots[1]",
                          "profile.knots[1].r", "fill.material.density", "length_m"}) {
    EXPECT_FALSE(ParseDesignVariablePath(bad).has_value()) << bad;
  }
  for (const char* name : {"max_exit_speed", "max_exit_speed_swing_weight", "widest_sweet_zone",
                           "min_moi", "min_sting"}) {
    EXPECT_STREQ(DesignObjectiveName(*ParseDesignObjective(name)), name);
  }
  for (RuleSet rule : AllRuleSets()) {
    EXPECT_EQ(ParseRuleSet(RuleSetName(rule)), rule);
    EXPECT_FALSE(LimitsOf(rule).source.empty());
  }
  EXPECT_NEAR(LimitsOf(RuleSet::kMlbWood).max_diameter_m, 0.066294, 1e-15);  // 2.61 in
  EXPECT_NEAR(LimitsOf(RuleSet::kBbcor).max_diameter_m, 0.066675, 1e-15);    // 2 5/8 in
  EXPECT_NEAR(LimitsOf(RuleSet::kUsssa).max_diameter_m, 0.06985, 1e-15);     // 2 3/4 in
  EXPECT_NEAR(*LimitsOf(RuleSet::kMlbWood).max_length_m, 1.0668, 1e-15);     // 42 in
  EXPECT_TRUE(IsWoodMaterial(*FindMaterial("hard-maple")));
  EXPECT_FALSE(IsWoodMaterial(*FindMaterial("aluminium-7046")));
  // Issue 19: the kind and the base decide, not the name.
  Material based = *FindMaterial("maple");  // an alias
  based.name = "hard-maple-30oz";
  based.density_kg_m3 = 650.0;
  EXPECT_TRUE(IsWoodMaterial(based));
  Material metal = *FindMaterial("aluminium-7050");
  metal.name = "hard-maple";
  EXPECT_FALSE(IsWoodMaterial(metal));
  Material custom;  // no base, no kind
  custom.name = "ash";
  EXPECT_FALSE(IsWoodMaterial(custom));
}

}  // namespace
}  // namespace optimize_model_test
}  // namespace sweetspot::core
