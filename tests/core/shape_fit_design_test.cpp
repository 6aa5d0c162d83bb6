// The shape fit beside the design optimiser (issue 33, item 3: the fit as a DesignProblem
// solved by OptimizeDesign). The same question asked both ways: every fit unknown is the
// design variable of its kind (kFitUnknownKinds), the targets equality constraints. Where the
// targets are attainable and the roots isolated both find the same bat to the fit's tolerance;
// where they are not (the paper's Table 2) the optimiser can only say "infeasible", while the
// fit returns the closest bat in its least-squares metric: why the fit is a DesignProblem with
// the least-squares objective (DesignObjective::kLeastSquares), which gives that bat.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/optimize/shape_fit.hpp"
#include "core/optimize/shape_fit_checks.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace shape_fit_design_test {
namespace {

constexpr double kL = 0.855;

ShapeFitProblem TaperProblem(double mass_kg, double balance_point_m) {
  ShapeFitProblem problem;
  problem.shape = PaperThreeSegmentShape();
  problem.material = *FindMaterial("paper-wood");
  problem.unknowns = {{DesignVariableKind::kTaperStart, 0.0, kL},
                      {DesignVariableKind::kTaperEnd, 0.0, kL}};
  problem.targets.mass_kg = mass_kg;
  problem.targets.balance_point_m = balance_point_m;
  return problem;
}

// The fit's question as a design problem: the unknowns as variables, the targets as equality
// constraints, objective min_moi (a tie-break; the roots here are isolated).
DesignProblem AsDesignProblem(const ShapeFitProblem& fit) {
  DesignProblem p;
  p.three_segment = fit.shape;
  p.bat.material = fit.material;
  p.bat.wall_thickness_m = fit.wall_thickness_m;
  p.bat.fill = fit.fill;
  for (const FitUnknown& u : fit.unknowns) {
    DesignVariableRef ref;
    ref.kind = u.variable;
    p.variables.push_back({DesignVariablePath(ref), u.min, u.max});
  }
  if (fit.targets.mass_kg) p.constraints.mass_kg = DesignRange::Equal(*fit.targets.mass_kg);
  if (fit.targets.balance_point_m) {
    p.constraints.balance_point_m = DesignRange::Equal(*fit.targets.balance_point_m);
  }
  p.objective = DesignObjective::kMinMoi;
  return p;
}

double ValueOf(const DesignResult& r, const std::string& path) {
  for (const DesignValue& v : r.variables) {
    if (v.path == path) return v.value;
  }
  return std::nan("");
}

TEST(ShapeFitAsDesignProblem, EveryFitUnknownIsADesignVariablePath) {
  for (DesignVariableKind kind : kFitUnknownKinds) {
    DesignVariableRef ref;
    ref.kind = kind;
    const auto parsed = ParseDesignVariablePath(DesignVariablePath(ref));
    ASSERT_TRUE(parsed.has_value()) << FitUnknownName(kind);
    EXPECT_EQ(parsed->kind, kind) << FitUnknownName(kind);
  }
}

TEST(ShapeFitAsDesignProblem, AnAttainableTaperIsTheSameRootBothWays) {
  ThreeSegmentShape truth = PaperThreeSegmentShape();
  truth.taper_start_m = 0.30;
  truth.taper_end_m = 0.60;
  const MassProperties p =
      ComputeMassProperties(MakeThreeSegmentBat(truth, *FindMaterial("paper-wood")));
  const ShapeFitProblem problem = TaperProblem(p.mass_kg, p.balance_point_m);
  const ShapeFitResult fit = FitShape(problem);
  ASSERT_EQ(fit.summary.termination, Termination::kConverged) << fit.summary.FullReport();
  for (DesignBackend backend : {DesignBackend::kIpopt, DesignBackend::kNloptSlsqp}) {
    DesignOptions options;
    options.backend = backend;
    const DesignResult design = OptimizeDesign(AsDesignProblem(problem), options);
    ASSERT_EQ(design.summary.termination, Termination::kConverged) << design.summary.FullReport();
    // The fit's tolerance is 1e-9 on the scaled residuals; the root is well conditioned
    // (dM, dC independent there), so the shapes agree to ~1e-7 m.
    EXPECT_NEAR(ValueOf(design, "three_segment.taper_start_m"), fit.values[0], 1e-6);
    EXPECT_NEAR(ValueOf(design, "three_segment.taper_end_m"), fit.values[1], 1e-6);
    EXPECT_NEAR(design.properties.mass_kg, p.mass_kg, 1e-8 * p.mass_kg);
    EXPECT_NEAR(design.properties.balance_point_m, p.balance_point_m, 1e-8 * p.balance_point_m);
  }
}

TEST(ShapeFitAsDesignProblem, DensityFromTheMassIsTheSameBothWays) {
  ShapeFitProblem problem = TaperProblem(0.90, 0.0);
  problem.targets.balance_point_m.reset();
  problem.unknowns = {{DesignVariableKind::kDensity, 100.0, 2000.0}};
  const ShapeFitResult fit = FitShape(problem);
  ASSERT_EQ(fit.summary.termination, Termination::kConverged) << fit.summary.FullReport();
  const DesignResult design = OptimizeDesign(AsDesignProblem(problem));
  ASSERT_EQ(design.summary.termination, Termination::kConverged) << design.summary.FullReport();
  // Linear in the density: the one root, to the fit's tolerance (relative 1e-9).
  EXPECT_NEAR(ValueOf(design, "material.density_kg_m3"), fit.values[0], 1e-7 * fit.values[0]);
}

TEST(ShapeFitAsDesignProblem, Table2IsInfeasibleBothWaysButOnlyTheFitGivesTheClosestBat) {
  const ShapeFitProblem problem = TaperProblem(0.885, 0.564);
  const ShapeFitResult fit = FitShape(problem);
  ASSERT_EQ(fit.summary.termination, Termination::kInfeasible) << fit.summary.FullReport();
  EXPECT_EQ(fit.values[1], kL);  // on the x2 = L bound
  const DesignResult design = OptimizeDesign(AsDesignProblem(problem));
  // Equality targets that no bat meets: the optimiser refuses with its conflicts; the closest
  // bat in the fit's metric, ((M - M*)/M*)^2 + ((C - C*)/C*)^2, is not what it returns.
  EXPECT_EQ(design.summary.termination, Termination::kInfeasible) << design.summary.FullReport();
  EXPECT_FALSE(design.summary.IsSolutionUsable());
}

// The same question with the least-squares objective (the fit's own problem,
// fit_detail::FitDesignProblem) gives the fit's closest bat through OptimizeDesign, from the
// problem's start alone and with either backend (FitShape adds only the scan's starts).
TEST(ShapeFitAsDesignProblem, Table2WithTheLeastSquaresObjectiveIsTheFitsClosestBat) {
  const ShapeFitProblem problem = TaperProblem(0.885, 0.564);
  const ShapeFitResult fit = FitShape(problem);
  ASSERT_EQ(fit.summary.termination, Termination::kInfeasible) << fit.summary.FullReport();
  const DesignProblem least_squares = fit_detail::FitDesignProblem(
      problem, ShapeFitOptions{}, fit_detail::StartParameters(problem));
  for (DesignBackend backend : {DesignBackend::kIpopt, DesignBackend::kNloptSlsqp}) {
    DesignOptions options;
    options.backend = backend;
    const DesignResult design = OptimizeDesign(least_squares, options);
    ASSERT_EQ(design.summary.termination, Termination::kConverged) << design.summary.FullReport();
    // x2 on the bound to the bit; x1 where the metric is stationary on it (flat to its
    // rounding within ~1e-8 m, and the polish locates the stationary point to ~1e-13 m).
    EXPECT_EQ(ValueOf(design, "three_segment.taper_end_m"), fit.values[1]);
    EXPECT_NEAR(ValueOf(design, "three_segment.taper_start_m"), fit.values[0], 1e-10);
    EXPECT_NEAR(design.objective_value, fit.metric, 1e-16);  // phi ~ 1e-3, its rounding
  }
}

}  // namespace
}  // namespace shape_fit_design_test
}  // namespace sweetspot::core
