// Hard cases of the solvers that design bats: the shape fit (core/optimize/shape_fit.*) and the
// design optimisation (core/optimize/*, Ipopt and NLopt SLSQP): starts far from feasible,
// infeasible requests, flat objectives, parameters across nine decades, budgets too small.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/optimize/shape_fit.hpp"
#include "tests/hard_cases/hard_case.hpp"
#include "tests/hard_cases/reference.hpp"

namespace sweetspot::hard_cases {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace core_optimize_test {
namespace {

// ------------------------------------------------------------------------------ shape fit

// The paper's shape (diameters reading) in paper-wood.
core::ShapeFitProblem PaperFit() {
  core::ShapeFitProblem p;
  p.shape = {0.855, 0.0125, 0.035, 0.3459, 0.6423};
  p.material = *core::FindMaterial("paper-wood");
  return p;
}

// The fitted density (kg/m^3) for a target mass: closed form M* / V, V the shape's volume
// (long double reference).
CoreCase DensityFitRow(std::string name, double mass_kg) {
  return {std::move(name),
          [mass_kg] {
            core::ShapeFitProblem p = PaperFit();
            p.unknowns = {{core::DesignVariableKind::kDensity, 1e-6, 1e6}};
            p.targets.mass_kg = mass_kg;
            const core::ShapeFitResult r = core::FitShape(p);
            return FromSummary(r.summary, r.material.density_kg_m3);
          },
          // The fit stops when |M - M*| / M* <= 1e-9 (its tolerance); the density is linear in
          // the mass, so it is within 1e-9 relative of M* / V.
          Reference(
              [mass_kg] {
                const core::ShapeFitProblem p = PaperFit();
                const core::Bat bat = core::MakeThreeSegmentBat(p.shape, p.material);
                return mass_kg / ReferenceMassProperties(bat, true).volume_m3;
              },
              1e-9)};
}

std::vector<CoreCase> ShapeFitCases() {
  return {
      // Densities 0.6 and 6.4e5 kg/m^3 from bounds spanning twelve decades.
      DensityFitRow("DensityForAOneGramBat", 1e-3),
      DensityFitRow("DensityForAThousandKilogramBat", 1e3),
      // The paper's Table 2 targets: no bat of the family meets them (paper-notes.md); the
      // closest one is certified.
      {"PaperTable2TargetsAreInfeasible",
       [] {
         core::ShapeFitProblem p = PaperFit();
         p.unknowns = {{core::DesignVariableKind::kTaperStart, 0.0, 0.855},
                       {core::DesignVariableKind::kTaperEnd, 0.0, 0.855}};
         p.targets.mass_kg = 0.885;
         p.targets.balance_point_m = 0.564;
         return FromSummary(core::FitShape(p).summary, kNaN);
       },
       Refused("infeasible", "no bat with taper_start_m in [0, 0.855]")},
      // A wall from 1e-12 m up to the handle's radius, fitted to a 0.3 kg bat: the metric's
      // residual |M - M*| / M* must meet the tolerance 1e-9.
      {"WallFromAPicometreToTheRadius",
       [] {
         core::ShapeFitProblem p = PaperFit();
         p.wall_thickness_m = 0.002;
         p.unknowns = {{core::DesignVariableKind::kWallThickness, 1e-12, 0.0125 * (1 - 1e-12)}};
         p.targets.mass_kg = 0.3;
         const core::ShapeFitResult r = core::FitShape(p);
         return FromSummary(r.summary, std::abs(r.properties.mass_kg - 0.3) / 0.3);
       },
       Within(0, 1e-9)},
      {"EqualBoundsAreRefused",
       [] {
         core::ShapeFitProblem p = PaperFit();
         p.unknowns = {{core::DesignVariableKind::kDensity, 600.0, 600.0}};
         p.targets.mass_kg = 0.95;
         return FromSummary(core::FitShape(p).summary, kNaN);
       },
       Refused("invalid_input", "unknowns[0]")},
  };
}

class HardCaseShapeFit : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseShapeFit, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseShapeFit, testing::ValuesIn(ShapeFitCases()),
                         RowName<CoreCase>);

// ---------------------------------------------------------------------- design optimisation

// The contract's example family (api.md): ash, 34 in, x1 in [0.1, 0.5], r2 in [0.028, 0.0331].
// Within those bounds the mass spans [0.7294, 1.2858] kg.
core::DesignProblem Family(double taper_start_m, double barrel_radius_m) {
  core::DesignProblem p;
  p.bat.material = *core::FindMaterial("ash");
  p.three_segment = core::ThreeSegmentShape{0.8636, 0.0125, barrel_radius_m, taper_start_m, 0.55};
  p.bat.knots = p.three_segment->Knots();
  p.variables = {{"three_segment.taper_start_m", 0.1, 0.5},
                 {"three_segment.barrel_radius_m", 0.028, 0.0331}};
  p.cor = 0.5;
  return p;
}

// The mass of the answer's bat re-computed through the mass properties, minus the target.
Outcome MassError(const core::DesignProblem& p, const core::DesignOptions& o, double target) {
  const core::DesignResult r = core::OptimizeDesign(p, o);
  return FromSummary(r.summary, core::ComputeMassProperties(r.bat).mass_kg - target);
}

// Ipopt's constraint tolerance is 1e-10 relative to each constraint's scale: the mass equality
// holds to 1e-9 kg (re-checked through the mass properties).
constexpr double kMassTolerance = 1e-9;

std::vector<CoreCase> DesignCases() {
  std::vector<CoreCase> rows = {
      // Started at the heaviest corner (1.2858 kg), asked for 0.74 kg: 0.0106 kg above the
      // lightest design.
      {"IpoptFromTheHeaviestCornerToNearlyTheLightest",
       [] {
         core::DesignProblem p = Family(0.1, 0.0331);
         p.constraints.mass_kg = core::DesignRange::Equal(0.74);
         return MassError(p, {}, 0.74);
       },
       Exactly(0, kMassTolerance)},
      {"IpoptFromTheLightestCornerToNearlyTheHeaviest",
       [] {
         core::DesignProblem p = Family(0.5, 0.028);
         p.constraints.mass_kg = core::DesignRange::Equal(1.28);
         return MassError(p, {}, 1.28);
       },
       Exactly(0, kMassTolerance)},
      {"NloptSlsqpFromTheHeaviestCorner",
       [] {
         core::DesignProblem p = Family(0.1, 0.0331);
         p.constraints.mass_kg = core::DesignRange::Equal(0.74);
         core::DesignOptions o;
         o.backend = core::DesignBackend::kNloptSlsqp;
         return MassError(p, o, 0.74);
       },
       Exactly(0, kMassTolerance)},
      // The exact Hessian path from the same far start.
      {"IpoptExactHessianFromTheHeaviestCorner",
       [] {
         core::DesignProblem p = Family(0.1, 0.0331);
         p.constraints.mass_kg = core::DesignRange::Equal(0.74);
         core::DesignOptions o;
         o.hessian = core::HessianMode::kExact;
         return MassError(p, o, 0.74);
       },
       Exactly(0, kMassTolerance)},
      // Eleven decades of density for a 1 g bat: rho = M* / V exactly at the optimum.
      {"DensityAcrossElevenDecadesForAOneGramBat",
       [] {
         core::DesignProblem p = Family(0.3, 0.033);
         p.variables = {{"material.density_kg_m3", 1e-6, 1e5}};
         p.constraints.mass_kg = core::DesignRange::Equal(1e-3);
         const core::DesignResult r = core::OptimizeDesign(p);
         return FromSummary(r.summary, r.bat.material.density_kg_m3);
       },
       Reference(
           [] {
             const core::DesignProblem p = Family(0.3, 0.033);
             return 1e-3L / ReferenceMassProperties(p.bat, true).volume_m3;
           },
           1e-8)},
      // Infeasible: 0.5 kg is below the lightest design (0.7294 kg); the conflict is named.
      {"MassBelowTheLightestDesignIsInfeasible",
       [] {
         core::DesignProblem p = Family(0.3, 0.033);
         p.constraints.mass_kg = core::DesignRange::Equal(0.5);
         const core::DesignResult r = core::OptimizeDesign(p);
         return FromSummary(r.summary, kNaN);
       },
       Refused("infeasible", "mass_kg")},
      {"MassBelowTheLightestDesignConflictShortfall",
       [] {
         core::DesignProblem p = Family(0.3, 0.033);
         p.constraints.mass_kg = core::DesignRange::Equal(0.5);
         const core::DesignResult r = core::OptimizeDesign(p);
         return FromSummary(r.summary, r.conflicts.empty() ? kNaN : r.conflicts[0].shortfall);
       },
       // The lightest design: x1 = 0.5, r2 = 0.028 (closed form through the mass
       // properties), 0.2294 kg above 0.5; the conflict's own solve is converged to 1e-8.
       Reference(
           [] {
             const core::DesignProblem p = Family(0.5, 0.028);
             return ReferenceMassProperties(p.bat, true).mass_kg - 0.5L;
           },
           1e-8)
           .With("infeasible")},
      // A flat objective: nothing moves (u = 0, omega = 0), the exit speed is 0 for every
      // design: refused before solving.
      {"NothingMovesIsRefused",
       [] {
         core::DesignProblem p = Family(0.3, 0.033);
         p.ball.speed_mps = 0.0;
         p.swing.angular_speed_rad_s = 0.0;
         return FromSummary(core::OptimizeDesign(p).summary, kNaN);
       },
       Refused("invalid_input", "nothing moves")},
      // e = 0 and no swing: the best exit speed of every design is 0 (at the pivot): a flat
      // objective; each backend must stop usable with exactly 0.
      {"IpoptOnAFlatZeroObjective",
       [] {
         core::DesignProblem p = Family(0.3, 0.033);
         p.cor = 0.0;
         p.swing.angular_speed_rad_s = 0.0;
         const core::DesignResult r = core::OptimizeDesign(p);
         return FromSummary(r.summary, r.objective_value);
       },
       Exactly(0, 0).With("usable")},
      {"NloptSlsqpOnAFlatZeroObjective",
       [] {
         core::DesignProblem p = Family(0.3, 0.033);
         p.cor = 0.0;
         p.swing.angular_speed_rad_s = 0.0;
         core::DesignOptions o;
         o.backend = core::DesignBackend::kNloptSlsqp;
         const core::DesignResult r = core::OptimizeDesign(p, o);
         return FromSummary(r.summary, r.objective_value);
       },
       Exactly(0, 0).With("usable")},
      // One iteration from far away: stopped early, the best point kept and usable (its
      // objective is an exit speed of this family: 13.85 .. 30 m/s).
      {"OneIterationIsNoConvergence",
       [] {
         core::DesignProblem p = Family(0.1, 0.0331);
         p.constraints.mass_kg = core::DesignRange::Equal(0.74);
         core::DesignOptions o;
         o.max_iterations = 1;
         const core::DesignResult r = core::OptimizeDesign(p, o);
         return FromSummary(r.summary, r.objective_value);
       },
       Within(13.85, 30.0).With("no_convergence")},
  };
  return rows;
}

class HardCaseDesign : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseDesign, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseDesign, testing::ValuesIn(DesignCases()), RowName<CoreCase>);

}  // namespace
}  // namespace core_optimize_test
}  // namespace sweetspot::hard_cases
