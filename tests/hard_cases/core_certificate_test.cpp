// Hard cases of the design answer's certificate (core/optimize/certificate.*): backends that
// report convergence away from the optimum, a rule that repeats a target, limits that meet.
// Issue 36 item 1: each row failed before the certificate (a converged answer 0.2 % to 0.5 %
// below the optimum, a multiplier of 2e5 m/s per kg, multipliers of dependent constraints).
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/units.hpp"
#include "tests/hard_cases/hard_case.hpp"

namespace sweetspot::hard_cases {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace core_certificate_test {
namespace {

// bench/scipy_peers.py's design16 with n knots over `length_m`: the inner knots' radii of a
// solid ash bat in [0.011, 0.0332] m, the base mass, balance point at most 0.60 m, diameters in
// [0.9, 2.61] in, a non-decreasing taper, the rigid-pivot max exit speed.
core::DesignProblem KnotProblem(int n, double length_m) {
  core::DesignProblem p;
  for (int i = 0; i < n; ++i) {
    const double x = length_m * i / (n - 1);
    p.bat.knots.push_back({x, 0.0125 + 0.020 / (1.0 + std::exp(-14.0 * (x / length_m - 0.55)))});
  }
  p.bat.material = *core::FindMaterial("ash");
  for (int i = 1; i <= n - 2; ++i) {
    p.variables.push_back({"profile.knots[" + std::to_string(i) + "].radius_m", 0.011, 0.0332});
  }
  p.constraints.mass_kg = core::DesignRange::Equal(core::ComputeMassProperties(p.bat).mass_kg);
  p.constraints.balance_point_m = core::DesignRange::AtMost(0.60);
  p.constraints.max_barrel_diameter_m = core::InchesToMetres(2.61);
  p.constraints.min_handle_diameter_m = core::InchesToMetres(0.9);
  p.constraints.taper = core::TaperRule::kNonDecreasing;
  p.model = core::CollisionModel::kRigidPivot;
  return p;
}

// The 16-knot problem at 33 in with a 30 oz target and the bbcor rules, whose drop <= 3 repeats
// the weight (33 - 30 = 3: the two limits meet).
core::DesignProblem BbcorAtThirtyOunces(std::optional<core::DesignRange> mass_oz) {
  core::DesignProblem p = KnotProblem(16, core::InchesToMetres(33.0));
  p.constraints.mass_kg.reset();
  if (mass_oz) {
    core::DesignRange r;
    if (mass_oz->min) r.min = core::OuncesToKilograms(*mass_oz->min);
    if (mass_oz->max) r.max = core::OuncesToKilograms(*mass_oz->max);
    p.constraints.mass_kg = r;
  }
  p.constraints.rules = {core::RuleSet::kBbcor};
  return p;
}

// The optimum by Ipopt with the exact Hessian, NaN unless certified converged.
long double IpoptOptimum(const core::DesignProblem& p) {
  core::DesignOptions o;
  o.hessian = core::HessianMode::kExact;
  const core::DesignResult r = core::OptimizeDesign(p, o);
  const bool ok = r.summary.termination == core::Termination::kConverged && r.certificate.certified;
  return ok ? static_cast<long double>(r.objective_value) : kNaN;
}

// The relative shortfall of a converged answer below the optimum (0 for an answer that does not
// claim convergence: it says it stopped early). The rows require it within +-1e-7: the optimum's
// own accuracy (Ipopt tol 1e-9 on the scaled problem; both backends agree to 1e-10 where they
// both converge, e.g. 16 knots without the rule: 22.77121249600 and 22.77121249303 m/s; SLSQP
// may end above Ipopt by as much, on the mass equality's tolerance).
Outcome ShortfallIfConverged(const core::DesignProblem& p, const core::DesignOptions& o) {
  const core::DesignResult r = core::OptimizeDesign(p, o);
  if (r.summary.termination != core::Termination::kConverged) return FromSummary(r.summary, 0);
  const long double best = IpoptOptimum(p);
  return FromSummary(r.summary, (best - r.objective_value) / best);
}

// The active constraint `name`'s multiplier (NaN when absent or not reported).
double MultiplierOf(const core::DesignResult& r, const std::string& name) {
  for (const core::DesignActiveConstraint& a : r.active_constraints) {
    if (a.name == name) return a.multiplier;
  }
  return std::nan("");
}

std::vector<CoreCase> CertificateCases() {
  return {
      // 64 knots: SLSQP stopped by its ftol at 22.662 m/s, the optimum is 22.786 m/s (0.5 %
      // below); it reported FTOL_REACHED as converged. The certificate now fails such a
      // stop (Certificate.*), and since issue 36's size limit SLSQP is refused at this
      // size with the reason: never a converged answer short of the optimum.
      {"NloptSlsqpAtSixtyFourKnotsIsRefusedWithTheReason",
       [] {
         core::DesignOptions o;
         o.backend = core::DesignBackend::kNloptSlsqp;
         return ShortfallIfConverged(KnotProblem(64, 0.86), o);
       },
       Refused("invalid_input", "at most 32 variables")},
      // 30 knots (28 variables, within SLSQP's limit): converged only at the optimum.
      {"NloptSlsqpAtThirtyKnotsConvergesAtTheOptimum",
       [] {
         core::DesignOptions o;
         o.backend = core::DesignBackend::kNloptSlsqp;
         return ShortfallIfConverged(KnotProblem(30, 0.86), o);
       },
       Within(-1e-7, 1e-7).With("usable")},
      // 33 in, 30 oz and bbcor (drop <= 3): SLSQP reported FTOL_REACHED 0.2 % below Ipopt's
      // optimum; with the drop merged into the mass it must converge there or say it did not.
      {"NloptSlsqpAtThirtyOuncesUnderBbcorIsNotConvergedBelowTheOptimum",
       [] {
         core::DesignOptions o;
         o.backend = core::DesignBackend::kNloptSlsqp;
         return ShortfallIfConverged(BbcorAtThirtyOunces(core::DesignRange::Equal(30.0)), o);
       },
       Within(-1e-7, 1e-7).With("usable")},
      // The same problem by Ipopt: its multiplier of the mass was 2.1e5 m/s per kg, split
      // arbitrarily with the drop's. The mass's multiplier must be the sensitivity of the
      // optimum: the forward difference over +0.001 oz (the drop forbids lighter bats).
      // Tolerance 1e-4 relative: the difference quotient is off by half the multiplier's change
      // over the step (6.39131 to 6.39126 m/s per kg, 4e-6 relative) plus the two optima's
      // error over their difference (1e-11 / 1.8e-4 m/s, 6e-8).
      {"IpoptMassMultiplierUnderBbcorIsTheSensitivity",
       [] {
         core::DesignOptions o;
         o.hessian = core::HessianMode::kExact;
         const core::DesignResult r =
             core::OptimizeDesign(BbcorAtThirtyOunces(core::DesignRange::Equal(30.0)), o);
         return FromSummary(r.summary, MultiplierOf(r, "mass_kg"));
       },
       Reference(
           [] {
             const long double v0 =
                 IpoptOptimum(BbcorAtThirtyOunces(core::DesignRange::Equal(30.0)));
             const long double v1 =
                 IpoptOptimum(BbcorAtThirtyOunces(core::DesignRange::Equal(30.001)));
             return (v1 - v0) / core::OuncesToKilograms(0.001);
           },
           1e-4)},
      // ... and the drop is reported merged into the mass, not as an active constraint.
      {"IpoptUnderBbcorReportsTheDropMergedIntoTheMass",
       [] {
         const core::DesignResult r =
             core::OptimizeDesign(BbcorAtThirtyOunces(core::DesignRange::Equal(30.0)));
         const bool merged = r.merged_constraints.size() == 1 &&
                             r.merged_constraints[0].name == "rules.bbcor.drop" &&
                             r.merged_constraints[0].into == "mass_kg";
         return FromSummary(r.summary,
                            merged && std::isnan(MultiplierOf(r, "rules.bbcor.drop")) ? 1 : 0);
       },
       Exactly(1, 0)},
      // A cap of 30 oz meets the drop's floor of 30 oz: neither range contains the other, so
      // both stay, both are active, and their gradients are parallel: no unique multipliers,
      // none reported (NaN), yet the answer is certified (the fit's residual is ~1e-16).
      {"MassCapMeetingTheDropFloorHasNoUniqueMultipliers",
       [] {
         const core::DesignResult r =
             core::OptimizeDesign(BbcorAtThirtyOunces(core::DesignRange::AtMost(30.0)));
         const double mass = MultiplierOf(r, "mass_kg.max");
         const double drop = MultiplierOf(r, "rules.bbcor.drop");
         int named = 0;
         for (const auto& a : r.active_constraints) {
           named += a.name == "mass_kg.max" || a.name == "rules.bbcor.drop";
         }
         const bool both_active = named == 2;
         const bool ok = both_active && std::isnan(mass) && std::isnan(drop) &&
                         !r.certificate.multipliers_unique && r.certificate.certified;
         return FromSummary(r.summary, ok ? 1 : 0);
       },
       Exactly(1, 0)},
  };
}

class HardCaseCertificate : public testing::TestWithParam<CoreCase> {};
TEST_P(HardCaseCertificate, Holds) { CheckCoreCase(GetParam()); }
INSTANTIATE_TEST_SUITE_P(Core, HardCaseCertificate, testing::ValuesIn(CertificateCases()),
                         RowName<CoreCase>);

}  // namespace
}  // namespace core_certificate_test
}  // namespace sweetspot::hard_cases
