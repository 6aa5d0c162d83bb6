// Design optimisation: optima derivable by hand, constraints re-checked through the public mass
// properties, multipliers as sensitivities, NLopt agreeing with Ipopt, infeasible and
// ill-posed requests, rule sets, reproducible multi-start, cancellation and time budget.
#include "core/optimize/design_problem.hpp"

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/optimize/design_model.hpp"
#include "core/units.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_design_test {
namespace {

constexpr double kL = 0.86;  // m
constexpr double kXs = 0.5;  // m: where the handle cylinder steps up to the barrel
constexpr double kAsh = 0.60 * 1000.0 * 1.12;  // kg/m^3, the catalogue's ash (672)

// A "step" bat: handle cylinder r1 on [0, 0.5], barrel cylinder r2 on [0.5, 0.86] (a
// three-segment shape with x1 = x2), solid ash. Its mass and moments are elementary.
DesignProblem StepProblem(double r1_min, double r1_max, double r2_min, double r2_max) {
  DesignProblem p;
  p.three_segment =
      ThreeSegmentShape{kL, 0.5 * (r1_min + r1_max), 0.5 * (r2_min + r2_max), kXs, kXs};
  p.bat.material = *FindMaterial("ash");
  p.variables = {{"three_segment.handle_radius_m", r1_min, r1_max},
                 {"three_segment.barrel_radius_m", r2_min, r2_max}};
  return p;
}

double StepMass(double r1, double r2) {
  return kAsh * kPi * (r1 * r1 * kXs + r2 * r2 * (kL - kXs));
}

// v2max = ((1 + e) S - (1 - e) u) / 2, S = sqrt(u^2 + omega^2 J / m) (paper-notes.md, sec. 3),
// for the default scene (pivot at the knob).
double HandMaxExitSpeed(const MassProperties& p) {
  const Ball ball;
  const Swing swing;
  const double e = 0.5, u = ball.speed_mps, w = swing.angular_speed_rad_s, m = ball.mass_kg;
  const double s = std::sqrt(u * u + w * w * p.MoiAboutKgM2(0.0) / m);
  return 0.5 * ((1.0 + e) * s - (1.0 - e) * u);
}

const DesignActiveConstraint* FindActive(const DesignResult& r, const std::string& name) {
  for (const auto& a : r.active_constraints) {
    if (a.name == name) return &a;
  }
  return nullptr;
}

double ValueOf(const DesignResult& r, const std::string& path) {
  for (const auto& v : r.variables) {
    if (v.path == path) return v.value;
  }
  return std::nan("");
}

// Max exit speed at a fixed mass, by hand. For the step bat, mass moved from the handle to the
// barrel at fixed M raises J about the knob: per unit mass the slender part is
// (x_s^2 + x_s L + L^2)/3 - x_s^2/3 in favour of the barrel, and the disk part r^2/4 favours
// the barrel when r1 < r2. v2max grows with J (dS/dJ > 0), so the optimum puts r1 on its lower
// bound and r2 where the mass equality holds: r2 = sqrt((M/(rho pi) - r1^2 x_s)/(L - x_s)).
TEST(OptimizeHandDerived, MaxExitSpeedAtFixedMassPutsTheHandleOnItsBound) {
  DesignProblem p = StepProblem(0.010, 0.016, 0.020, 0.040);
  p.constraints.mass_kg = DesignRange::Equal(0.85);
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  const double r1 = ValueOf(r, "three_segment.handle_radius_m");
  const double r2 = ValueOf(r, "three_segment.barrel_radius_m");
  const double r2_hand = std::sqrt((0.85 / (kAsh * kPi) - 0.010 * 0.010 * kXs) / (kL - kXs));
  // Interior-point end: within ~1e-11 of the bound in the scaled variable (range 6e-3 m);
  // r2 follows from the mass equality met to ~1e-12 kg (dM/dr2 ~ 50 kg/m).
  EXPECT_NEAR(r1, 0.010, 1e-10);
  EXPECT_NEAR(r2, r2_hand, 1e-10);
  ASSERT_TRUE(r.three_segment.has_value());
  EXPECT_EQ(r.three_segment->taper_start_m, kXs);
  // The objective is the closed form of the returned bat (independent formula), to rounding.
  const MassProperties props = ComputeMassProperties(r.bat);
  EXPECT_NEAR(r.objective_value, HandMaxExitSpeed(props), 1e-12);
  EXPECT_NEAR(props.mass_kg, 0.85, 1e-10);
  EXPECT_EQ(r.objective_unit, "mps");
  EXPECT_EQ(r.summary.backend, "ipopt");
  EXPECT_LE(r.summary.error_estimate, 1e-6);
  // What holds the design back: the mass and the handle's lower bound. Raising the allowed
  // mass or the least handle radius changes the exit speed in the directions the physics says.
  const DesignActiveConstraint* mass = FindActive(r, "mass_kg");
  const DesignActiveConstraint* handle = FindActive(r, "three_segment.handle_radius_m.min");
  ASSERT_NE(mass, nullptr);
  ASSERT_NE(handle, nullptr);
  EXPECT_GT(mass->multiplier, 0.0);
  EXPECT_LT(handle->multiplier, 0.0);
  EXPECT_EQ(handle->unit, "m");
  EXPECT_EQ(FindActive(r, "three_segment.barrel_radius_m.max"), nullptr);
}

// The multipliers are first-order sensitivities: re-solving with the bound moved by h changes
// the objective by multiplier * h (to O(h^2)).
TEST(OptimizeHandDerived, MultipliersAreSensitivitiesOfTheObjective) {
  DesignProblem p = StepProblem(0.010, 0.016, 0.020, 0.040);
  p.constraints.mass_kg = DesignRange::Equal(0.85);
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged);
  const double h = 1e-4;
  DesignProblem heavier = p;
  heavier.constraints.mass_kg = DesignRange::Equal(0.85 + h);
  const double dm = (OptimizeDesign(heavier).objective_value - r.objective_value) / h;
  DesignProblem thicker = p;
  thicker.variables[0].min = 0.010 + 1e-6;
  const double dr = (OptimizeDesign(thicker).objective_value - r.objective_value) / 1e-6;
  // Second-order terms: |f''| h / 2 relative to f' is below 1e-3 for these steps.
  EXPECT_NEAR(FindActive(r, "mass_kg")->multiplier, dm, 1e-3 * std::abs(dm));
  EXPECT_NEAR(FindActive(r, "three_segment.handle_radius_m.min")->multiplier, dr,
              1e-3 * std::abs(dr));
}

// Least MOI about the 6-in point at a fixed mass. Per unit mass the handle costs
// ((x_s - p)^3 + p^3) / (3 x_s) + r1^2/4 ~ 0.030 m^2 and the barrel
// ((L - p)^3 - (x_s - p)^3) / (3 (L - x_s)) + r2^2/4 ~ 0.289 m^2 (p = 0.1524 m), so the
// optimum puts r2 on its lower bound and r1 where the mass equality holds.
TEST(OptimizeHandDerived, MinMoiAtFixedMassPutsTheBarrelOnItsBound) {
  DesignProblem p = StepProblem(0.010, 0.030, 0.020, 0.040);
  p.objective = DesignObjective::kMinMoi;
  p.constraints.mass_kg = DesignRange::Equal(0.85);
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  const double r1_hand = std::sqrt((0.85 / (kAsh * kPi) - 0.020 * 0.020 * (kL - kXs)) / kXs);
  EXPECT_NEAR(ValueOf(r, "three_segment.barrel_radius_m"), 0.020, 1e-10);
  EXPECT_NEAR(ValueOf(r, "three_segment.handle_radius_m"), r1_hand, 1e-10);
  EXPECT_EQ(r.objective_unit, "kg_m2");
  EXPECT_NEAR(r.objective_value, ComputeMassProperties(r.bat).MoiSixInchKgM2(), 1e-15);
  ASSERT_NE(FindActive(r, "three_segment.barrel_radius_m.min"), nullptr);
  // Raising the least barrel radius raises the least MOI.
  EXPECT_GT(FindActive(r, "three_segment.barrel_radius_m.min")->multiplier, 0.0);
}

// Two linear equalities in two unknowns: a solid cylinder (radius R, length L) with a fill of
// volume V_f at the barrel end, densities rho (bat) and rho_f (fill) free. M and M C are
// linear in (rho, rho_f):
//   rho (V_b - V_f) + rho_f V_f = M*,   rho (V_b L/2 - V_f e) + rho_f V_f e = M* C*,
// e = L - D/2, so rho = M* (e - C*) / (V_b (e - L/2)) and rho_f = (M* - rho (V_b - V_f)) / V_f.
TEST(OptimizeHandDerived, MassAndBalancePointFixTwoDensities) {
  const double radius = 0.03, diameter = 0.0254, depth = 0.254;
  DesignProblem p;
  p.bat.knots = {{0.0, radius}, {kL, radius}};
  p.bat.material = *FindMaterial("ash");
  Fill fill;
  fill.material = *FindMaterial("cork");
  fill.diameter_m = diameter;
  fill.depth_m = depth;
  p.bat.fill = fill;
  p.variables = {{"material.density_kg_m3", 300.0, 1200.0},
                 {"fill.material.density_kg_m3", 0.0, 3000.0}};
  const double m_star = 1.4, c_star = 0.47;
  p.constraints.mass_kg = DesignRange::Equal(m_star);
  p.constraints.balance_point_m = DesignRange::Equal(c_star);
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  const double vb = kPi * radius * radius * kL;
  const double vf = kPi * 0.25 * diameter * diameter * depth;
  const double e = kL - 0.5 * depth;
  const double rho = m_star * (e - c_star) / (vb * (e - 0.5 * kL));
  const double rho_f = (m_star - rho * (vb - vf)) / vf;
  // Relative 1e-9: the equalities are met to ~1e-12 and the 2x2 system is well conditioned.
  EXPECT_NEAR(ValueOf(r, "material.density_kg_m3"), rho, 1e-9 * rho);
  EXPECT_NEAR(ValueOf(r, "fill.material.density_kg_m3"), rho_f, 1e-9 * rho_f);
  EXPECT_NEAR(r.properties.mass_kg, m_star, 1e-10);
  EXPECT_NEAR(r.properties.balance_point_m, c_star, 1e-10);
}

// ---------------------------------------------------------------------------------------------
// Realistic designs: every constraint re-checked through ComputeMassProperties.

Bat SixteenKnotBat() {
  Bat bat;
  for (int i = 0; i < 16; ++i) {
    const double x = 0.86 * i / 15.0;
    bat.knots.push_back({x, 0.0125 + 0.020 / (1.0 + std::exp(-14.0 * (x / 0.86 - 0.55)))});
  }
  bat.material = *FindMaterial("ash");
  return bat;
}

DesignProblem SixteenKnotProblem() {
  DesignProblem p;
  p.bat = SixteenKnotBat();
  for (int i = 1; i <= 14; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.011, 0.0332});
  }
  p.constraints.mass_kg = DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg);
  p.constraints.balance_point_m = DesignRange::AtMost(0.60);
  p.constraints.max_barrel_diameter_m = InchesToMetres(2.61);
  p.constraints.min_handle_diameter_m = InchesToMetres(0.9);
  p.constraints.taper = TaperRule::kNonDecreasing;
  return p;
}

DesignProblem ContractExample() {  // the request of shared/docs/api-contract.md
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.8636, 0.0125, 0.033, 0.30, 0.55};
  p.bat.material = *FindMaterial("ash");
  p.variables = {{"three_segment.taper_start_m", 0.1, 0.5},
                 {"three_segment.barrel_radius_m", 0.028, 0.0331},
                 {"three_segment.taper_end_m", 0.3, 0.8}};
  p.constraints.mass_kg = DesignRange::Equal(0.88);
  p.constraints.balance_point_m = DesignRange::Between(0.56, 0.60);
  p.constraints.moi_six_inch_kg_m2 = DesignRange::AtMost(0.20);
  p.constraints.rules = {RuleSet::kMlbWood};
  return p;
}

TEST(OptimizeConstraints, SixteenKnotDesignMeetsEveryConstraintWhenRecomputed) {
  const DesignProblem p = SixteenKnotProblem();
  for (HessianMode h : {HessianMode::kLimitedMemory, HessianMode::kExact}) {
    DesignOptions o;
    o.hessian = h;
    const DesignResult r = OptimizeDesign(p, o);
    ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
    const MassProperties props = ComputeMassProperties(r.bat);
    // 1e-8 (the re-check tolerance); observed ~1e-12.
    EXPECT_NEAR(props.mass_kg, *p.constraints.mass_kg->min, 1e-8);
    EXPECT_LE(props.balance_point_m, 0.60 + 1e-8);
    for (std::size_t i = 0; i < r.bat.knots.size(); ++i) {
      EXPECT_LE(2.0 * r.bat.knots[i].radius_m, InchesToMetres(2.61) + 1e-8) << i;
      EXPECT_GE(2.0 * r.bat.knots[i].radius_m, InchesToMetres(0.9) - 1e-8) << i;
      if (i > 0) {
        EXPECT_GE(r.bat.knots[i].radius_m, r.bat.knots[i - 1].radius_m - 1e-8) << i;
      }
    }
    EXPECT_LE(r.summary.constraint_violation, 1e-8);
    EXPECT_GT(r.objective_value, HandMaxExitSpeed(ComputeMassProperties(p.bat)));
    EXPECT_NEAR(r.objective_value, HandMaxExitSpeed(props), 1e-12);
    // The mass, the balance point and the taper hold the design back (the barrel stays below
    // 2.61 in: a thicker barrel would move the balance point beyond 0.60 m). Requiring a
    // steeper taper (raising its lower limit 0) can only lower the exit speed.
    EXPECT_NE(FindActive(r, "mass_kg"), nullptr);
    EXPECT_NE(FindActive(r, "balance_point_m.max"), nullptr);
    EXPECT_EQ(FindActive(r, "max_barrel_diameter_m.knots[14]"), nullptr);
    const DesignActiveConstraint* taper = FindActive(r, "taper.knots[13]");
    ASSERT_NE(taper, nullptr);
    EXPECT_LT(taper->multiplier, 0.0);
  }
}

TEST(OptimizeConstraints, ContractExampleMeetsTheRulesAndReportsActiveOnes) {
  const DesignProblem p = ContractExample();
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  const MassProperties props = ComputeMassProperties(r.bat);
  EXPECT_NEAR(props.mass_kg, 0.88, 1e-8);
  EXPECT_GE(props.balance_point_m, 0.56 - 1e-8);
  EXPECT_LE(props.balance_point_m, 0.60 + 1e-8);
  EXPECT_LE(props.MoiSixInchKgM2(), 0.20 + 1e-8);
  EXPECT_LE(2.0 * r.three_segment->barrel_radius_m, InchesToMetres(2.61) + 1e-8);
  EXPECT_TRUE(r.bat.Validate(nullptr));
  EXPECT_EQ(r.bat.wall_thickness_m, 0.0);
  ASSERT_EQ(r.variables.size(), 3u);
  EXPECT_EQ(r.variables[0].path, "three_segment.taper_start_m");
  EXPECT_EQ(r.variables[0].value, r.three_segment->taper_start_m);
  // The MOI limit and the mass hold it back (it ends as a step: x1 ~ x2 ~ 0.45 m).
  EXPECT_NE(FindActive(r, "moi_six_inch_kg_m2.max"), nullptr);
  EXPECT_NE(FindActive(r, "mass_kg"), nullptr);
  EXPECT_GT(r.sweet_spot_from_knob_m, 0.0);
  EXPECT_LT(r.sweet_spot_from_knob_m, r.bat.LengthM());
}

TEST(OptimizeConstraints, RuleLimitsBecomeNamedConstraints) {
  // MLB: a barrel allowed up to 0.04 m is held to 2.61 in by the rule.
  DesignProblem p = ContractExample();
  p.variables[1].max = 0.04;
  p.constraints.moi_six_inch_kg_m2.reset();
  p.constraints.mass_kg = DesignRange::AtMost(0.95);
  DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  const DesignActiveConstraint* d =
      FindActive(r, "rules.mlb-wood.diameter.three_segment.barrel_radius_m");
  ASSERT_NE(d, nullptr);
  EXPECT_NEAR(d->value, InchesToMetres(2.61), 1e-10);
  EXPECT_GT(d->multiplier, 0.0);

  // BBCOR: an aluminium shell whose wall may thin until length_in - weight_oz = 3.
  DesignProblem b;
  b.bat = FindPreset("bbcor-33-aluminium")->bat;
  b.variables = {{"wall_thickness_m", 0.0015, 0.0040}};
  b.objective = DesignObjective::kMinMoi;
  b.constraints.rules = {RuleSet::kBbcor};
  r = OptimizeDesign(b);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  ASSERT_NE(FindActive(r, "rules.bbcor.drop"), nullptr);
  const ImperialProperties imp = ToImperial(r.properties, r.bat.LengthM());
  EXPECT_NEAR(imp.drop, 3.0, 1e-8);
}

// ---------------------------------------------------------------------------------------------
// NLopt (SLSQP) agrees with Ipopt.

TEST(OptimizeBackends, NloptSlsqpAgreesWithIpopt) {
  for (const DesignProblem& p :
       {ContractExample(), SixteenKnotProblem(), StepProblem(0.010, 0.016, 0.020, 0.040)}) {
    DesignProblem q = p;
    if (!q.constraints.mass_kg.has_value()) q.constraints.mass_kg = DesignRange::Equal(0.85);
    const DesignResult ipopt = OptimizeDesign(q);
    DesignOptions o;
    o.backend = DesignBackend::kNloptSlsqp;
    const DesignResult nlopt = OptimizeDesign(q, o);
    ASSERT_EQ(ipopt.summary.termination, Termination::kConverged) << ipopt.summary.FullReport();
    ASSERT_TRUE(nlopt.summary.IsSolutionUsable()) << nlopt.summary.FullReport();
    EXPECT_EQ(nlopt.summary.backend, "nlopt:LD_SLSQP");
    // Two solvers, two stopping rules: objectives to 1e-7 relative; variables to 1e-4 m,
    // since near a flat optimum an objective error of 1e-9 relative moves x by about
    // sqrt(1e-9) times its length scale (the contract example's taper ends differ by 2e-5 m).
    EXPECT_NEAR(nlopt.objective_value, ipopt.objective_value, 1e-7 * ipopt.objective_value);
    for (std::size_t j = 0; j < ipopt.variables.size(); ++j) {
      EXPECT_NEAR(nlopt.variables[j].value, ipopt.variables[j].value, 1e-4)
          << ipopt.variables[j].path;
    }
    EXPECT_LE(nlopt.summary.constraint_violation, 1e-8);
  }
}

// ---------------------------------------------------------------------------------------------
// Infeasible and ill-posed requests.

TEST(OptimizeInfeasible, MassBelowTheLightestBatNamesTheConflictAndTheLimit) {
  DesignProblem p = StepProblem(0.010, 0.016, 0.020, 0.040);
  p.constraints.mass_kg = DesignRange::Equal(0.3);
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kInfeasible) << r.summary.FullReport();
  ASSERT_EQ(r.conflicts.size(), 1u);
  const DesignConflict& c = r.conflicts[0];
  ASSERT_EQ(c.constraints, std::vector<std::string>({"mass_kg"}));
  // The lightest step bat has both radii on their lower bounds.
  const double lightest = StepMass(0.010, 0.020);
  EXPECT_NEAR(c.achievable_min, lightest, 1e-9);
  EXPECT_NEAR(c.achievable_max, StepMass(0.016, 0.040), 1e-9);
  EXPECT_NEAR(c.shortfall, lightest - 0.3, 1e-9);
  EXPECT_NE(c.message.find("mass_kg = 0.3 kg is below the lightest bat within the variable "
                           "bounds: 0.40956"),
            std::string::npos)
      << c.message;
  EXPECT_NE(r.summary.message.find("mass_kg = 0.3 kg is below the lightest bat"),
            std::string::npos);
  EXPECT_FALSE(r.summary.IsSolutionUsable());
  // The least-violating design comes back: the lightest bat.
  EXPECT_NEAR(r.properties.mass_kg, lightest, 1e-8);
}

TEST(OptimizeInfeasible, APairOfConstraintsThatConflictIsNamedWithTheReachableRange) {
  // Alone, M = 0.6 kg and C in [0.62, 0.63] m are both reachable; together they are not: with
  // C >= 0.62 the barrel must carry m_b >= m_h (0.62 - 0.25) / (0.68 - 0.62), so the lightest
  // such bat has r1 on its bound: M = m_h(0.010) (1 + 0.37 / 0.06).
  DesignProblem p = StepProblem(0.010, 0.016, 0.020, 0.040);
  p.constraints.mass_kg = DesignRange::Equal(0.6);
  p.constraints.balance_point_m = DesignRange::Between(0.62, 0.63);
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kInfeasible) << r.summary.FullReport();
  ASSERT_EQ(r.conflicts.size(), 1u);
  const DesignConflict& c = r.conflicts[0];
  EXPECT_EQ(c.constraints, std::vector<std::string>({"mass_kg", "balance_point_m"}));
  const double handle = StepMass(0.010, 0.0);
  EXPECT_NEAR(c.achievable_min, handle * (1.0 + 0.37 / 0.06), 1e-8);
  EXPECT_NE(c.message.find("with balance_point_m in [0.62, 0.63 m]"), std::string::npos)
      << c.message;
}

TEST(OptimizeInfeasible, AConstraintNoVariableCanChangeIsReportedWithoutSolving) {
  // The preset's knob is wider than its handle: a non-decreasing taper over every knot can
  // never hold when only the barrel may change.
  DesignProblem p;
  p.bat = FindPreset("wood-34-ash")->bat;
  p.variables = {{"profile.knots[12].radius_m", 0.030, 0.034}};
  p.constraints.taper = TaperRule::kNonDecreasing;
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kInfeasible);
  ASSERT_FALSE(r.conflicts.empty());
  EXPECT_EQ(r.conflicts[0].constraints[0], "taper.knots[2]");
  EXPECT_NE(r.summary.message.find("no design variable changes it"), std::string::npos)
      << r.summary.message;
  EXPECT_EQ(r.summary.iterations, 0);
  // Limited to the taper's knots (9 to 12), the same rule is fine.
  p.constraints.taper_first_knot = 9;
  p.constraints.taper_last_knot = 12;
  EXPECT_EQ(OptimizeDesign(p).summary.termination, Termination::kConverged);
}

TEST(OptimizeInvalid, IllPosedRequestsAreRefusedByName) {
  const DesignProblem good = StepProblem(0.010, 0.016, 0.020, 0.040);
  struct Case {
    const char* what;
    DesignProblem problem;
    std::string message;
  };
  std::vector<Case> cases;
  auto with = [&](const char* what, auto edit, std::string message) {
    DesignProblem p = good;
    edit(p);
    cases.push_back({what, p, std::move(message)});
  };
  with(
      "unbounded", [](DesignProblem& p) { p.variables[1].max = INFINITY; },
      "variables[1].max = inf: must be finite (an optimisation needs bounded variables)");
  with(
      "empty range", [](DesignProblem& p) { p.variables[0].max = 0.005; },
      "variables[0].max = 0.005: must be greater than variables[0].min = 0.01");
  with(
      "no variables", [](DesignProblem& p) { p.variables.clear(); },
      "variables.size() = 0: must be between 1 and 1000");
  with(
      "unknown path", [](DesignProblem& p) { p.variables[0].path = "three_segment.radius_m"; },
      "variables[0].path = three_segment.radius_m: not a design variable (known: ");
  with(
      "duplicate", [](DesignProblem& p) { p.variables[1].path = p.variables[0].path; },
      "variables[1].path = three_segment.handle_radius_m: appears more than once");
  with(
      "profile path", [](DesignProblem& p) { p.variables[0].path = "profile.knots[1].radius_m"; },
      "variables[0].path = profile.knots[1].radius_m: the design is a three_segment shape");
  with(
      "fill",
      [](DesignProblem& p) {
        p.variables[0] = {"fill.depth_m", 0.0, 0.1};
      },
      "variables[0].path = fill.depth_m: the bat has no fill");
  with(
      "hollow wood",
      [](DesignProblem& p) {
        p.bat.wall_thickness_m = 0.003;
        p.constraints.rules = {RuleSet::kMlbWood};
      },
      "rules.mlb-wood: one piece of solid wood: wall_thickness_m = 0.003 makes a hollow shell");
  with(
      "hot bat",
      [](DesignProblem& p) {
        p.cor = 0.55;
        p.constraints.rules = {RuleSet::kBbcor};
      },
      "rules.bbcor: cor = 0.55 exceeds the BBCOR limit 0.5");
  with(
      "sting settings",
      [](DesignProblem& p) {
        p.objective = DesignObjective::kMinSting;
        p.flexible.max_elements = 1;
      },
      "flexible.max_elements = 1: must be in [2, 4096]");
  with(
      "range", [](DesignProblem& p) { p.constraints.mass_kg = DesignRange::Between(1.0, 0.9); },
      "constraints.mass_kg.max = 0.9: must not be less than constraints.mass_kg.min = 1");
  with(
      "exponent", [](DesignProblem& p) { p.swing_weight_exponent = 0.6; },
      "swing_weight_exponent = 0.6: must be in [0, 0.5]");
  // The ranges of the constraints and of the objective's settings are core's alone (the api
  // reads their types): each written from its bound.
  with(
      "length cap", [](DesignProblem& p) { p.constraints.length_m = DesignRange::Equal(150.0); },
      "constraints.length_m = 150: must be in (0, 100]");
  with(
      "mass limit 0",
      [](DesignProblem& p) { p.constraints.mass_kg = DesignRange::Between(0.0, 1.0); },
      "constraints.mass_kg.min = 0: must be in (0, 10000]");
  with(
      "balance cap",
      [](DesignProblem& p) { p.constraints.balance_point_m = DesignRange::AtMost(200.0); },
      "constraints.balance_point_m.max = 200: must be in (0, 100]");
  with(
      "moi cap",
      [](DesignProblem& p) { p.constraints.moi_six_inch_kg_m2 = DesignRange::AtLeast(2e4); },
      "constraints.moi_six_inch_kg_m2.min = 20000: must be in (0, 10000]");
  with(
      "barrel cap", [](DesignProblem& p) { p.constraints.max_barrel_diameter_m = 11.0; },
      "constraints.max_barrel_diameter_m = 11: must be in (0, 10]");
  with(
      "handle 0", [](DesignProblem& p) { p.constraints.min_handle_diameter_m = 0.0; },
      "constraints.min_handle_diameter_m = 0: must be in (0, 10]");
  with(
      "grip order",
      [](DesignProblem& p) {
        p.constraints.min_handle_diameter_m = 0.02;
        p.constraints.handle_region_from_knob_m = std::pair{0.3, 0.1};
      },
      "constraints.handle_region_from_knob_m[1] = 0.1: must be greater than "
      "constraints.handle_region_from_knob_m[0] = 0.3");
  with(
      "grip start",
      [](DesignProblem& p) {
        p.constraints.min_handle_diameter_m = 0.02;
        p.constraints.handle_region_from_knob_m = std::pair{-0.1, 0.3};
      },
      "constraints.handle_region_from_knob_m[0] = -0.1: must be in [0, 100]");
  with(
      "grip alone",
      [](DesignProblem& p) {
        p.constraints.handle_region_from_knob_m = std::pair{0.0, 0.3};
      },
      "constraints.handle_region_from_knob_m: needs constraints.min_handle_diameter_m");
  with(
      "reference 0",
      [](DesignProblem& p) {
        p.objective = DesignObjective::kMaxExitSpeedSwingWeight;
        p.swing_weight_reference_kg_m2 = 0.0;
      },
      "swing_weight_reference_kg_m2 = 0: must be in (0, 10000]");
  with(
      "reference elsewhere", [](DesignProblem& p) { p.swing_weight_reference_kg_m2 = 0.2; },
      "swing_weight_reference_kg_m2 = 0.2: applies only to objective max_exit_speed_swing_weight "
      "(objective is max_exit_speed)");
  with(
      "slope cap",
      [](DesignProblem& p) {
        p.constraints.taper = TaperRule::kMaxSlope;
        p.constraints.max_taper_slope = 150.0;
      },
      "constraints.max_taper_slope = 150: must be in (0, 100]");
  with(
      "first knot",
      [](DesignProblem& p) {
        p.constraints.taper = TaperRule::kMaxSlope;
        p.constraints.max_taper_slope = 0.1;
        p.constraints.taper_first_knot = -1;
      },
      "constraints.taper_first_knot = -1: must be a knot index (>= 0)");
  with(
      "last knot",
      [](DesignProblem& p) {
        p.constraints.taper = TaperRule::kMaxSlope;
        p.constraints.max_taper_slope = 0.1;
        p.constraints.taper_last_knot = -2;
      },
      "constraints.taper_last_knot = -2: must be -1 (the last knot) or a knot index");
  with(
      "zone tolerance",
      [](DesignProblem& p) {
        p.objective = DesignObjective::kWidestSweetZone;
        p.sweet_zone_tolerance_mps = 150.0;
      },
      "sweet_zone_tolerance_mps = 150: must be in (0, 100]");
  with(
      "variable bound", [](DesignProblem& p) { p.variables[1].max = 2e12; },
      "variables[1].max = 2e+12: must be in [-1e+12, 1e+12]");
  for (const Case& c : cases) {
    std::string why;
    EXPECT_FALSE(Validates(c.problem, &why)) << c.what;
    EXPECT_EQ(why.substr(0, c.message.size()), c.message) << c.what << ": " << why;
    const DesignResult r = OptimizeDesign(c.problem);
    EXPECT_EQ(r.summary.termination, Termination::kInvalidInput) << c.what;
    EXPECT_EQ(r.summary.message, why) << c.what;
    EXPECT_TRUE(std::isnan(r.objective_value)) << c.what;
  }
  std::string why;
  EXPECT_TRUE(Validates(good, &why)) << why;
}

TEST(OptimizeInvalid, OptionsAreCheckedAndDefaultsAreValid) {
  std::string why;
  EXPECT_TRUE(Validates(DesignOptions{}, &why)) << why;
  DesignOptions o;
  o.starts = 0;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "starts = 0: must be between 1 and 64");
  const DesignResult r = OptimizeDesign(StepProblem(0.01, 0.016, 0.02, 0.04), o);
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(r.summary.message, "options.starts = 0: must be between 1 and 64");
  o = DesignOptions{};
  o.derivative_check = DerivativeCheck::kSecondOrder;
  EXPECT_FALSE(Validates(o, &why));
  o.max_time_s = 0.0;
  EXPECT_FALSE(Validates(o, &why));
  EXPECT_EQ(why, "max_time_s = 0: must be finite and positive");
}

// A problem bounded only by its variables' bounds is well posed: max exit speed wants the
// heaviest wood, so the density ends on its upper bound.
TEST(OptimizeInvalid, OnlyBoundsLimitTheDesign) {
  DesignProblem p;
  p.bat = FindPreset("paper-wood")->bat;
  p.variables = {{"material.density_kg_m3", 400.0, 900.0}};
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  EXPECT_NEAR(r.variables[0].value, 900.0, 1e-6);
  ASSERT_NE(FindActive(r, "material.density_kg_m3.max"), nullptr);
  EXPECT_EQ(FindActive(r, "material.density_kg_m3.max")->unit, "kg_m3");
  EXPECT_GT(FindActive(r, "material.density_kg_m3.max")->multiplier, 0.0);
}

// ---------------------------------------------------------------------------------------------
// Multi-start, objectives, cancellation.

TEST(OptimizeMultiStart, TheSameSeedGivesTheSameAnswer) {
  DesignProblem p = ContractExample();
  p.variables.push_back({"three_segment.handle_radius_m", 0.011, 0.014});
  DesignOptions o;
  o.starts = 5;
  o.seed = 42;
  o.hessian = HessianMode::kExact;  // fewer iterations than limited memory (fast under ASan)
  const DesignResult a = OptimizeDesign(p, o);
  const DesignResult b = OptimizeDesign(p, o);
  ASSERT_EQ(a.summary.termination, Termination::kConverged) << a.summary.FullReport();
  ASSERT_EQ(a.spread.runs.size(), 5u);
  EXPECT_EQ(a.spread.starts, 5);
  for (std::size_t j = 0; j < a.variables.size(); ++j) {
    EXPECT_EQ(a.variables[j].value, b.variables[j].value);  // bit for bit
  }
  for (std::size_t i = 0; i < a.spread.runs.size(); ++i) {
    EXPECT_EQ(a.spread.runs[i].objective, b.spread.runs[i].objective) << i;
    EXPECT_EQ(a.spread.runs[i].iterations, b.spread.runs[i].iterations) << i;
  }
  EXPECT_EQ(a.objective_value, b.objective_value);
  EXPECT_LE(a.spread.objective_min, a.spread.objective_median);
  EXPECT_LE(a.spread.objective_median, a.spread.objective_max);
  // The answer is the best converged start.
  EXPECT_NEAR(a.objective_value, a.spread.objective_max, 1e-9);
  EXPECT_GE(a.spread.converged, 1);
  // Another seed starts elsewhere (the first start is always the base design).
  o.seed = 43;
  const DesignResult c = OptimizeDesign(p, o);
  EXPECT_EQ(c.spread.runs[0].iterations, a.spread.runs[0].iterations);
  bool differs = false;
  for (std::size_t i = 1; i < c.spread.runs.size(); ++i) {
    differs = differs || c.spread.runs[i].iterations != a.spread.runs[i].iterations ||
              c.spread.runs[i].objective != a.spread.runs[i].objective;
  }
  EXPECT_TRUE(differs);
}

TEST(OptimizeObjectives, SwingWeightAndSweetZoneObjectivesAreReportedThroughThePublicPath) {
  DesignProblem p = ContractExample();
  p.objective = DesignObjective::kMaxExitSpeedSwingWeight;
  p.swing_weight_exponent = 0.0;  // n = 0: the plain max exit speed
  const DesignResult plain = OptimizeDesign(ContractExample());
  DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged);
  EXPECT_NEAR(r.objective_value, plain.objective_value, 1e-9);

  p.swing_weight_exponent = 0.27;
  r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  // omega = omega0 (I6 / I6_ref)^-n with I6_ref the base design's.
  const double i6_ref =
      ComputeMassProperties(MakeThreeSegmentBat(*p.three_segment, p.bat.material)).MoiSixInchKgM2();
  const double omega =
      Swing{}.angular_speed_rad_s * std::pow(r.properties.MoiSixInchKgM2() / i6_ref, -0.27);
  EXPECT_NEAR(r.angular_speed_rad_s, omega, 1e-12);
  EXPECT_EQ(r.objective_value, r.max_exit_speed_mps);

  p.objective = DesignObjective::kWidestSweetZone;
  p.sweet_zone_tolerance_mps = 1.0;
  r = OptimizeDesign(p);
  ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.FullReport();
  EXPECT_EQ(r.objective_unit, "m");
  EXPECT_GT(r.objective_value, 0.3);
  EXPECT_LE(r.objective_value, r.bat.LengthM());
}

TEST(OptimizeObjectives, SwingWeightReferenceIsTheOneThatSwingsAtOmega0) {
  // A reference of one's own: omega0 belongs to that swing weight instead of the base design's.
  // The reference 0.20 kg m^2 is the contract's MOI limit.
  DesignProblem p = ContractExample();
  p.objective = DesignObjective::kMaxExitSpeedSwingWeight;
  p.swing_weight_reference_kg_m2 = 0.20;
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  const double omega_own =
      Swing{}.angular_speed_rad_s * std::pow(r.properties.MoiSixInchKgM2() / 0.20, -0.27);
  // 1e-12 rad/s: the answer's omega is this closed form of the returned bat's I6 (round-off).
  EXPECT_NEAR(r.angular_speed_rad_s, omega_own, 1e-12);
  EXPECT_EQ(r.objective_value, r.max_exit_speed_mps);
  // The base design's I6 is not 0.20, so that omega is not the one the base design's reference
  // would give (the field is used): 1e-3 rad/s is far above round-off.
  const double i6_base =
      ComputeMassProperties(MakeThreeSegmentBat(*p.three_segment, p.bat.material)).MoiSixInchKgM2();
  ASSERT_GT(std::abs(i6_base - 0.20), 1e-3);
  EXPECT_GT(std::abs(r.angular_speed_rad_s -
                     Swing{}.angular_speed_rad_s *
                         std::pow(r.properties.MoiSixInchKgM2() / i6_base, -0.27)),
            1e-3);
}

TEST(OptimizeConstraints, HandleRegionBoundsOnlyTheKnotsThatReachTheGrip) {
  // The sixteen-knot profile (knots every 0.0573 m) with the handle limit over the grip [0,
  // 0.2 m] only: knots 0 to 4 (knot 4 at 0.229 m sets the radius on (0.172, 0.287)) carry the
  // constraint, the others not.
  DesignProblem p = SixteenKnotProblem();
  p.constraints.min_handle_diameter_m = InchesToMetres(0.95);
  p.constraints.handle_region_from_knob_m = std::pair{0.0, 0.2};
  DesignModel model;
  Refusal why;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, &why)) << why.Message();
  std::vector<std::string> names;
  for (const auto& c : model.constraints()) {
    if (c.name.rfind("min_handle_diameter_m", 0) == 0) names.push_back(c.name);
  }
  // Knot 0 is fixed (not a variable) and meets the limit (its diameter 0.985 in), so it is
  // checked at build time and not added.
  EXPECT_EQ(names, (std::vector<std::string>{
                       "min_handle_diameter_m.knots[1]", "min_handle_diameter_m.knots[2]",
                       "min_handle_diameter_m.knots[3]", "min_handle_diameter_m.knots[4]"}));
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  // The profile is linear between knots: over the grip the diameter is at least 0.95 in (1e-8
  // m, the re-check tolerance of the other constraints), sampled every mm.
  for (double x = 0.0; x <= 0.2; x += 0.001) {
    EXPECT_GE(2.0 * r.bat.RadiusAtM(x), InchesToMetres(0.95) - 1e-8) << x;
  }
  // Without the region the same limit binds at every knot (the whole bat), a different design.
  DesignProblem whole = p;
  whole.constraints.handle_region_from_knob_m.reset();
  ASSERT_TRUE(DesignModel::Build(whole, DesignOptions{}, &model, &why)) << why.Message();
  int count = 0;
  for (const auto& c : model.constraints()) count += c.name.rfind("min_handle", 0) == 0 ? 1 : 0;
  EXPECT_EQ(count, 14);  // the 14 variable knots

  // Three segments: r2 sets the radius on (x1, L], x1 in [0.1, 0.5] here. A grip ending before
  // x1 can start leaves the barrel radius free; one reaching past 0.1 m bounds it too (r1 is
  // not a variable in this problem and meets the limit, so it is checked at build time).
  DesignProblem three = ContractExample();
  three.constraints.min_handle_diameter_m = InchesToMetres(0.95);
  auto handle_names = [&](double to) {
    three.constraints.handle_region_from_knob_m = std::pair{0.0, to};
    std::vector<std::string> out;
    EXPECT_TRUE(DesignModel::Build(three, DesignOptions{}, &model, &why)) << why.Message();
    for (const auto& c : model.constraints()) {
      if (c.name.rfind("min_handle", 0) == 0) out.push_back(c.name);
    }
    return out;
  };
  EXPECT_TRUE(handle_names(0.08).empty());
  EXPECT_EQ(handle_names(0.2),
            (std::vector<std::string>{"min_handle_diameter_m.three_segment.barrel_radius_m"}));
}

TEST(OptimizeMultiStart, CancellationAndTheTimeBudgetKeepTheBestDesign) {
  Progress progress;
  progress.Cancel();
  DesignOptions o;
  o.starts = 3;
  DesignResult r = OptimizeDesign(ContractExample(), o, &progress);
  EXPECT_EQ(r.summary.termination, Termination::kNoConvergence) << r.summary.FullReport();
  EXPECT_EQ(r.summary.raw_status, 5);  // User_Requested_Stop
  EXPECT_NE(r.summary.message.find("cancelled"), std::string::npos);
  EXPECT_EQ(r.spread.starts, 1);
  EXPECT_TRUE(r.bat.Validate(nullptr));

  o.max_time_s = 1e-9;
  r = OptimizeDesign(ContractExample(), o);
  EXPECT_EQ(r.summary.termination, Termination::kNoConvergence);
  EXPECT_NE(r.summary.message.find("time budget max_time_s = 1e-09 s reached"), std::string::npos)
      << r.summary.message;

  Progress counted;
  o = DesignOptions{};
  o.starts = 2;
  r = OptimizeDesign(ContractExample(), o, &counted);
  EXPECT_EQ(counted.Fraction(), 1.0);
}

TEST(OptimizeMaterials, TheBestMaterialIsChosenAndEveryMaterialIsReported) {
  DesignProblem p = ContractExample();
  p.constraints.mass_kg = DesignRange::Between(0.80, 0.90);
  const std::vector<Material> materials = {*FindMaterial("ash"), *FindMaterial("aluminium-7050"),
                                           *FindMaterial("hard-maple")};
  const MaterialChoiceResult r = OptimizeOverMaterials(p, materials);
  ASSERT_EQ(r.per_material.size(), 3u);
  EXPECT_EQ(r.per_material[1].material, "aluminium-7050");
  EXPECT_EQ(r.per_material[1].result.summary.termination, Termination::kInvalidInput);
  EXPECT_NE(r.per_material[1].result.summary.message.find("rules.mlb-wood"), std::string::npos);
  ASSERT_GE(r.best, 0);
  EXPECT_NE(r.best, 1);
  EXPECT_EQ(r.summary.termination, Termination::kConverged);
  for (const auto& m : r.per_material) {
    if (m.result.summary.termination == Termination::kConverged) {
      EXPECT_LE(m.result.objective_value,
                r.per_material[static_cast<std::size_t>(r.best)].result.objective_value);
    }
  }
  EXPECT_EQ(OptimizeOverMaterials(p, {}).summary.termination, Termination::kInvalidInput);
}

// design.cpp tells its outcomes apart by kinds, never by reading a message back: a conflict's
// ConflictKind (a geometric conflict makes the answer infeasible) and the summary message's
// DesignMessageKind (a chosen start cut by a cancel keeps its own "cancelled (...)" message
// rather than being wrapped in "cancelled after i of n starts").
TEST(OptimizeKinds, ConflictsAndMessagesSayWhatTheyAreAsData) {
  DesignProblem unreachable = StepProblem(0.010, 0.016, 0.020, 0.040);
  unreachable.constraints.mass_kg = DesignRange::Equal(0.3);
  DesignResult r = OptimizeDesign(unreachable);
  ASSERT_EQ(r.conflicts.size(), 1u);
  EXPECT_EQ(r.conflicts[0].kind, ConflictKind::kUnreachable);
  EXPECT_EQ(r.message_kind, DesignMessageKind::kInfeasible);

  DesignProblem pair = StepProblem(0.010, 0.016, 0.020, 0.040);
  pair.constraints.mass_kg = DesignRange::Equal(0.6);
  pair.constraints.balance_point_m = DesignRange::Between(0.62, 0.63);
  r = OptimizeDesign(pair);
  ASSERT_EQ(r.conflicts.size(), 1u);
  EXPECT_EQ(r.conflicts[0].kind, ConflictKind::kPair);
  EXPECT_EQ(r.message_kind, DesignMessageKind::kInfeasible);

  DesignProblem fixed;
  fixed.bat = FindPreset("wood-34-ash")->bat;
  fixed.variables = {{"profile.knots[12].radius_m", 0.030, 0.034}};
  fixed.constraints.taper = TaperRule::kNonDecreasing;
  r = OptimizeDesign(fixed);
  ASSERT_FALSE(r.conflicts.empty());
  for (const DesignConflict& c : r.conflicts) EXPECT_EQ(c.kind, ConflictKind::kFixed);
  EXPECT_EQ(r.message_kind, DesignMessageKind::kInfeasible);

  r = OptimizeDesign(ContractExample());
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  EXPECT_EQ(r.message_kind, DesignMessageKind::kConverged);

  // The chosen (only) start is itself cancelled: its message stands, not rewrapped.
  Progress progress;
  progress.Cancel();
  DesignOptions o;
  o.starts = 3;
  r = OptimizeDesign(ContractExample(), o, &progress);
  EXPECT_EQ(r.message_kind, DesignMessageKind::kCancelled) << r.summary.message;
  EXPECT_EQ(r.summary.message.rfind("cancelled (", 0), 0u) << r.summary.message;

  o = DesignOptions{};
  o.max_time_s = 1e-9;
  r = OptimizeDesign(ContractExample(), o);
  EXPECT_EQ(r.message_kind, DesignMessageKind::kTimeBudget) << r.summary.message;

  DesignProblem refused = ContractExample();
  o = DesignOptions{};
  o.max_iterations = 0;
  r = OptimizeDesign(refused, o);
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(r.message_kind, DesignMessageKind::kRefused);
}

}  // namespace
}  // namespace optimize_design_test
}  // namespace sweetspot::core
