// The min_sting objective: the hands' vibration energy of an impact at the design's rigid
// max-exit-speed point, minimised by NLopt COBYLA. Checked against the same quantity computed
// independently through the public scene functions (EvaluateScene for the sweet spot, Collide
// with the flexible model there) on a grid of designs; constraints re-checked through the mass
// properties; reproducibility; time budget and cancellation; refusals; infeasible requests.
#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/scene/collide.hpp"
#include "core/scene/evaluate_scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_sting_test {
namespace {

// The contract's three-segment ash bat (0.8636 m, handle 0.0125 m, barrel 0.033 m, taper
// 0.30-0.55 m): its sting at the sweet spot is least for a taper ending near 0.56 m (1.31 J
// against 2.8 J at 0.45 m and 6.1 J at 0.75 m), its mass falls linearly from 1.22 to 0.89 kg
// over that range.
constexpr ThreeSegmentShape kBase{0.8636, 0.0125, 0.033, 0.30, 0.55};
constexpr double kTaperEndMin = 0.45;  // m
constexpr double kTaperEndMax = 0.75;  // m

DesignProblem TaperEndProblem(double mass_min_kg, double mass_max_kg) {
  DesignProblem p;
  p.three_segment = kBase;
  p.bat.material = *FindMaterial("ash");
  p.cor = 0.5;
  p.objective = DesignObjective::kMinSting;
  p.variables = {{"three_segment.taper_end_m", kTaperEndMin, kTaperEndMax}};
  p.constraints.mass_kg = DesignRange::Between(mass_min_kg, mass_max_kg);
  return p;
}

Bat BatWithTaperEnd(double taper_end_m) {
  ThreeSegmentShape s = kBase;
  s.taper_end_m = taper_end_m;
  return MakeThreeSegmentBat(s, *FindMaterial("ash"));
}

// The sting through the public scene functions, independently of core/optimize: the rigid-pivot
// sweet spot from EvaluateScene (closed form), then Collide(kFlexible) there (default flexible
// settings, refine_check on), the hands' vibration energy in J.
double PublicSting(const Bat& bat, double* sweet_spot_m = nullptr) {
  Scene scene;
  scene.bat = bat;
  scene.cor = 0.5;
  scene.outputs = {SceneOutput::kMaxExitSpeed};
  SceneOptions options;
  options.model = CollisionModel::kRigidPivot;  // the optimiser's sweet spot
  const SceneResult s = EvaluateScene(scene, options);
  EXPECT_TRUE(s.max_exit_speed.has_value()) << s.summary.message;
  if (!s.max_exit_speed.has_value()) return std::nan("");
  const double x = s.max_exit_speed->position_from_knob_m;
  if (sweet_spot_m != nullptr) *sweet_spot_m = x;
  const CollisionResult c = Collide(scene, x, CollisionModel::kFlexible);
  EXPECT_TRUE(c.summary.IsSolutionUsable()) << c.summary.message;
  if (!c.flexible.has_value()) return std::nan("");
  return c.flexible->hands_vibration_energy_j;
}

double TaperEnd(const DesignResult& r) {
  for (const auto& v : r.variables) {
    if (v.path == "three_segment.taper_end_m") return v.value;
  }
  return std::nan("");
}

bool HasWarning(const DesignResult& r, const std::string& text) {
  return std::any_of(r.summary.warnings.begin(), r.summary.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

// (1) The optimum is the least sting: below the base design, both bounds and every point of a
// grid over the whole range, and a local minimum when probed on either side.
// Options whose time budget never decides the answer: these tests assert what a whole solve
// finds, and each COBYLA solve over the flexible beam takes 4-6 s of CPU under the sanitizers,
// so the default 10 s budget cut runs short on a loaded machine (ASan ctest beside other work).
DesignOptions StingTestOptions() {
  DesignOptions o;
  o.max_time_s = 120.0;
  return o;
}

TEST(OptimizeSting, TheTaperEndWithTheLeastStingBeatsEveryGridDesign) {
  // Every design of the range meets the mass range: the sting alone decides.
  const DesignProblem p = TaperEndProblem(0.85, 1.25);
  // backend ipopt asked (the default): COBYLA runs
  const DesignResult r = OptimizeDesign(p, StingTestOptions());
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  EXPECT_EQ(r.summary.backend, "nlopt:LN_COBYLA");
  EXPECT_TRUE(HasWarning(r, "solved by NLopt LN_COBYLA, not ipopt")) << r.summary.FullReport();
  EXPECT_EQ(r.objective_unit, "j");
  EXPECT_EQ(r.summary.models_used, (std::vector<std::string>{"mass_properties", "rigid_pivot",
                                                             "flexible_beam", "flexible"}));
  const double x = TaperEnd(r);
  ASSERT_TRUE(r.three_segment.has_value());
  EXPECT_EQ(r.three_segment->taper_end_m, x);

  // The reported sting is the public path's for the returned bat: the same model on the same
  // inputs (only the order of the computations differs), so equal to rounding.
  double sweet_spot = 0.0;
  const double sting = PublicSting(r.bat, &sweet_spot);
  EXPECT_NEAR(r.objective_value, sting, 1e-12 * sting);
  EXPECT_EQ(r.summary.objective, r.objective_value);
  ASSERT_TRUE(r.sting.has_value());
  EXPECT_NEAR(r.sting->impact_from_knob_m, sweet_spot, 1e-12);
  EXPECT_EQ(r.sting->impact_from_knob_m, r.sweet_spot_from_knob_m);
  EXPECT_EQ(r.sting->hands_vibration_energy_j, r.objective_value);
  EXPECT_EQ(r.sting->impact.hands_vibration_energy_j, r.objective_value);
  // Its own error estimate (integration + mode truncation) is far below the differences below.
  EXPECT_LT(r.sting->error_estimate_j, 1e-5);

  // COBYLA stops when a step changes the scaled objective by less than 1e-6 relative (the
  // sting's own jumps where the FE mesh changes are ~3e-5 relative, none near this optimum):
  // 2e-6 relative covers that stop. Observed: 1.31258 J at 0.56238 m; the grid's best is 1.5 %
  // higher (1.3323 J at 0.55 m), so a wrong local answer cannot pass.
  const double tol = 2e-6 * r.objective_value;
  EXPECT_LE(r.objective_value, PublicSting(BatWithTaperEnd(kBase.taper_end_m)) + tol);
  EXPECT_LE(r.objective_value, PublicSting(BatWithTaperEnd(kTaperEndMin)) + tol);
  EXPECT_LE(r.objective_value, PublicSting(BatWithTaperEnd(kTaperEndMax)) + tol);
  double grid_best = INFINITY;
  for (int i = 0; i <= 24; ++i) {
    const double xi = kTaperEndMin + (kTaperEndMax - kTaperEndMin) * i / 24.0;
    grid_best = std::min(grid_best, PublicSting(BatWithTaperEnd(xi)));
  }
  EXPECT_LE(r.objective_value, grid_best + tol);
  EXPECT_GT(x, 0.55);
  EXPECT_LT(x, 0.575);
  // A local minimum: 1 mm either way costs more than the tolerance (f'' ~ 1.6e3 J/m^2 here:
  // 8e-4 J per mm).
  EXPECT_GT(PublicSting(BatWithTaperEnd(x - 1e-3)), r.objective_value + tol);
  EXPECT_GT(PublicSting(BatWithTaperEnd(x + 1e-3)), r.objective_value + tol);
  // No derivative, hence no multipliers and no KKT residual (said in a warning).
  EXPECT_TRUE(std::isnan(r.summary.error_estimate));
  EXPECT_TRUE(HasWarning(r, "no multipliers"));
  EXPECT_TRUE(r.active_constraints.empty());
}

// (2) With a mass limit that binds, the optimum sits on it, and the constraint holds when the
// returned bat is re-checked through the public mass properties. The mass of this family is
// linear in the taper's end, so the design on the limit is known in closed form.
TEST(OptimizeSting, AMassLimitThatBindsHoldsWhenRecomputed) {
  const DesignProblem p = TaperEndProblem(0.90, 1.05);
  DesignOptions o = StingTestOptions();
  o.backend = DesignBackend::kNloptCobyla;
  const DesignResult r = OptimizeDesign(p, o);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.FullReport();
  EXPECT_FALSE(HasWarning(r, "not ipopt"));
  const MassProperties props = ComputeMassProperties(r.bat);
  // COBYLA's end is projected onto the constraints (exact gradients): 1e-8 relative is the
  // re-check tolerance of the other objectives' tests; observed ~1e-15.
  EXPECT_LE(props.mass_kg, 1.05 * (1.0 + 1e-8));
  EXPECT_NEAR(props.mass_kg, 1.05, 1.05e-8);
  EXPECT_LE(r.summary.constraint_violation, 1.05e-8);
  const double m0 = ComputeMassProperties(BatWithTaperEnd(0.60)).mass_kg;
  const double m1 = ComputeMassProperties(BatWithTaperEnd(0.61)).mass_kg;
  const double x_limit = 0.60 + 0.01 * (1.05 - m0) / (m1 - m0);
  // dM/dx2 = -2.3 kg/m: 1e-8 kg of mass is 4e-9 m.
  EXPECT_NEAR(TaperEnd(r), x_limit, 1e-8);
  ASSERT_EQ(r.active_constraints.size(), 1u);
  EXPECT_EQ(r.active_constraints[0].name, "mass_kg.max");
  EXPECT_TRUE(std::isnan(r.active_constraints[0].multiplier));
  // The unconstrained least sting (near 0.56 m) is too heavy; every lighter design of a grid
  // stings more.
  const double tol = 2e-6 * r.objective_value;
  for (int i = 0; i <= 24; ++i) {
    const double xi = kTaperEndMin + (kTaperEndMax - kTaperEndMin) * i / 24.0;
    if (xi < x_limit) continue;
    EXPECT_LE(r.objective_value, PublicSting(BatWithTaperEnd(xi)) + tol) << xi;
  }
  EXPECT_NEAR(r.objective_value, PublicSting(BatWithTaperEnd(x_limit)), 1e-6 * r.objective_value);
}

// (3) The same seed gives the same answer, bit for bit (COBYLA and the flexible model are
// deterministic; the random starts come from the seed).
TEST(OptimizeSting, TheSameSeedGivesTheSameAnswer) {
  const DesignProblem p = TaperEndProblem(0.85, 1.25);
  // Determinism, not speed: a run cut by the time budget differs from a whole one.
  DesignOptions o = StingTestOptions();
  o.backend = DesignBackend::kNloptCobyla;
  o.starts = 3;
  o.seed = 7;
  const DesignResult a = OptimizeDesign(p, o);
  const DesignResult b = OptimizeDesign(p, o);
  ASSERT_EQ(a.summary.termination, Termination::kConverged) << a.summary.FullReport();
  ASSERT_EQ(a.spread.runs.size(), 3u);
  // b must have run every start too before its runs are compared one by one (a b cut short by
  // the time budget on a starved machine ran fewer).
  ASSERT_EQ(b.spread.runs.size(), a.spread.runs.size()) << b.summary.FullReport();
  EXPECT_EQ(TaperEnd(a), TaperEnd(b));
  EXPECT_EQ(a.objective_value, b.objective_value);
  for (std::size_t i = 0; i < a.spread.runs.size(); ++i) {
    EXPECT_EQ(a.spread.runs[i].objective, b.spread.runs[i].objective) << i;
    EXPECT_EQ(a.spread.runs[i].iterations, b.spread.runs[i].iterations) << i;
  }
  // One minimum in the range: every start finds it (to COBYLA's tolerance), and the answer is
  // the least of them.
  EXPECT_EQ(a.spread.converged, 3);
  EXPECT_LE(a.spread.objective_max - a.spread.objective_min, 2e-6 * a.objective_value);
  EXPECT_NEAR(a.objective_value, a.spread.objective_min, 1e-12 * a.objective_value);
}

// (5) The time budget and cancellation stop COBYLA with the best design so far.
TEST(OptimizeSting, TheTimeBudgetAndCancellationKeepTheBestDesign) {
  const DesignProblem p = TaperEndProblem(0.85, 1.25);
  const double base = PublicSting(BatWithTaperEnd(kBase.taper_end_m));
  DesignOptions o;
  o.backend = DesignBackend::kNloptCobyla;
  o.max_time_s = 1e-9;
  DesignResult r = OptimizeDesign(p, o);
  EXPECT_EQ(r.summary.termination, Termination::kNoConvergence) << r.summary.FullReport();
  EXPECT_NE(r.summary.message.find("time budget max_time_s = 1e-09 s reached"), std::string::npos)
      << r.summary.message;
  EXPECT_EQ(r.summary.raw_status, -5);  // FORCED_STOP, before any evaluation: the start
  EXPECT_NEAR(r.objective_value, base, 1e-12 * base);
  EXPECT_TRUE(r.bat.Validate(nullptr));

  // A budget shorter than the solve (~20 evaluations of ~5 ms, plus the start's when the problem
  // is built): stopped on the way, or before the first evaluation on a slow machine, with a
  // design at least as good as the start (the start is the first point evaluated).
  o.max_time_s = 0.015;
  r = OptimizeDesign(p, o);
  EXPECT_EQ(r.summary.termination, Termination::kNoConvergence) << r.summary.FullReport();
  EXPECT_NE(r.summary.message.find("time budget"), std::string::npos) << r.summary.message;
  EXPECT_LE(r.objective_value, base * (1.0 + 1e-12));

  Progress progress;
  progress.Cancel();
  o = DesignOptions{};
  o.starts = 3;
  r = OptimizeDesign(p, o, &progress);
  EXPECT_EQ(r.summary.termination, Termination::kNoConvergence) << r.summary.FullReport();
  EXPECT_NE(r.summary.message.find("cancelled"), std::string::npos);
  EXPECT_EQ(r.spread.starts, 1);
  EXPECT_NEAR(r.objective_value, base, 1e-12 * base);
}

TEST(OptimizeSting, RefusalsNameTheField) {
  DesignProblem p = TaperEndProblem(0.85, 1.25);
  p.flexible.max_elements = 1;
  std::string why;
  EXPECT_FALSE(Validates(p, &why));
  EXPECT_EQ(why, "flexible.max_elements = 1: must be in [2, 4096]");
  EXPECT_EQ(OptimizeDesign(p).summary.termination, Termination::kInvalidInput);

  // Ipopt's derivative checker has nothing to check.
  p = TaperEndProblem(0.85, 1.25);
  DesignOptions o;
  o.derivative_check = DerivativeCheck::kFirstOrder;
  DesignResult r = OptimizeDesign(p, o);
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(r.summary.message,
            "options.derivative_check: objective = min_sting has no derivatives to check (it is "
            "solved derivative-free by COBYLA)");

  // A bat the beam model refuses at the start is refused by name.
  p = TaperEndProblem(1e-3, 100.0);  // the mass limits are in (0, 10000] kg
  p.three_segment = ThreeSegmentShape{0.12, 0.0125, 0.033, 0.03, 0.05};  // L < 4 x 0.033 m
  p.swing.hands_from_knob_m = 0.05;
  p.variables = {{"three_segment.taper_end_m", 0.04, 0.06}};
  EXPECT_FALSE(Validates(p, &why));
  EXPECT_EQ(why.rfind("objective = min_sting: the sting of the start", 0), 0u) << why;
  EXPECT_NE(why.find("slender"), std::string::npos) << why;
  r = OptimizeDesign(p);
  EXPECT_EQ(r.summary.termination, Termination::kInvalidInput);
  EXPECT_EQ(r.summary.message, why);
}

// An impossible mass: COBYLA cannot meet it, and the smooth infeasibility analysis (Ipopt on
// the mass alone) names the conflict and the lightest reachable bat.
TEST(OptimizeSting, AnImpossibleMassIsExplained) {
  const DesignProblem p = TaperEndProblem(0.50, 0.60);
  const DesignResult r = OptimizeDesign(p, StingTestOptions());
  EXPECT_EQ(r.summary.termination, Termination::kInfeasible) << r.summary.FullReport();
  ASSERT_FALSE(r.conflicts.empty());
  EXPECT_EQ(r.conflicts[0].constraints, (std::vector<std::string>{"mass_kg"}));
  // The lightest bat has the taper ending at the tip-side bound.
  const double lightest = ComputeMassProperties(BatWithTaperEnd(kTaperEndMax)).mass_kg;
  EXPECT_NEAR(r.conflicts[0].achievable_min, lightest, 1e-9);
  EXPECT_NE(r.conflicts[0].message.find("is below the lightest bat"), std::string::npos)
      << r.conflicts[0].message;
}

// A discrete choice of material: the least sting wins (minimised, not maximised).
TEST(OptimizeSting, TheMaterialWithTheLeastStingIsChosen) {
  const DesignProblem p = TaperEndProblem(0.70, 1.25);
  const MaterialChoiceResult r = OptimizeOverMaterials(
      p, {*FindMaterial("ash"), *FindMaterial("hard-maple")}, StingTestOptions());
  ASSERT_EQ(r.per_material.size(), 2u);
  ASSERT_GE(r.best, 0);
  EXPECT_EQ(r.summary.backend, "nlopt:LN_COBYLA");
  for (const auto& m : r.per_material) {
    ASSERT_EQ(m.result.summary.termination, Termination::kConverged) << m.material;
    EXPECT_GE(m.result.objective_value,
              r.per_material[static_cast<std::size_t>(r.best)].result.objective_value);
  }
}

}  // namespace
}  // namespace optimize_sting_test
}  // namespace sweetspot::core
