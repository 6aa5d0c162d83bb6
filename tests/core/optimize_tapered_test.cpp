// The lifted formulation with the taper's steps as variables (core/optimize/tapered_nlp.hpp):
// which problems form a taper chain, its gradient, Jacobian and Hessian (over blocks) against
// central differences, its multipliers mapped back to the design's, and the same optimum as the
// lifted formulation over the radii.
#include "core/optimize/tapered_nlp.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/design_backends.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "tests/core/knot_design_problems.hpp"
#include "tests/core/nlp_derivative_check.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_tapered_test {
namespace {

// bench/core_optimize.cpp's KnotProblem, at the base bat's mass.
using knot_design_problems::SolidAshKnotsAtBaseMass;

DesignModel Build(const DesignProblem& p) {
  DesignModel model;
  Refusal why;
  EXPECT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, &why)) << why.Message();
  return model;
}

TEST(OptimizeTapered, OnlyForOneTaperChain) {
  const DesignModel with_taper = Build(SolidAshKnotsAtBaseMass(40));
  ScaledDesignNlp dense(with_taper);
  LiftedDesignNlp lifted(dense);
  const TaperedLiftedNlp tapered(lifted, dense.ToScaled(with_taper.BaseX()), kTaperBlockSize);
  ASSERT_TRUE(tapered.ok());
  // 38 steps in blocks of 16: every taper row between two variables is a bound, so the rows
  // are the lifted problem's others (mass, balance point, the three definitions) and the last
  // knot's upper bound (the fixed tip's taper row, implied for no other knot).
  EXPECT_EQ(tapered.n(), 38 + 3);
  EXPECT_EQ(tapered.m(), 5 + 2 + 1);  // and the taper rows into the two later blocks' heads
  DesignProblem no_taper = SolidAshKnotsAtBaseMass(40);
  no_taper.constraints.taper = TaperRule::kNone;
  const DesignModel without = Build(no_taper);
  ScaledDesignNlp dense2(without);
  LiftedDesignNlp lifted2(dense2);
  EXPECT_FALSE(TaperedLiftedNlp(lifted2, dense2.ToScaled(without.BaseX()), kTaperBlockSize).ok());
}

// The gradient, the Jacobian and the Lagrangian's Hessian against central differences at a
// random point with random multipliers, 38 steps in three blocks (the Hessian's structure
// across blocks included: a value outside it makes Hessian() return false).
TEST(OptimizeTapered, DerivativesMatchCentralDifferences) {
  const DesignModel model = Build(SolidAshKnotsAtBaseMass(40));
  ScaledDesignNlp dense(model);
  LiftedDesignNlp lifted(dense);
  TaperedLiftedNlp nlp(lifted, dense.ToScaled(model.BaseX()), kTaperBlockSize);
  ASSERT_TRUE(nlp.ok());
  const int m = nlp.m();
  std::vector<double> w;
  ASSERT_TRUE(nlp.Start(dense.ToScaled(model.BaseX()), &w));
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  // Steps and heads moved by up to 1e-3 (scaled; the profile stays valid), q off P(x).
  for (double& v : w) v += 1e-3 * u(rng);
  std::vector<double> lambda(static_cast<std::size_t>(m));
  for (double& l : lambda) l = u(rng);
  // Step 1e-6 on variables of order 1e-3..1 (steps, heads in [0, 1], q ~ 1), values of order 1
  // and derivatives up to ~1e2 (a head's s moves its whole block): truncation ~h^2 |f'''| and
  // round-off ~1e-16 / 1e-6 of the values are ~1e-10; 1e-6 absolute plus 1e-6 relative is far
  // above both and far below a wrong entry (off by a factor or a sign).
  nlp_derivative_check::ExpectDerivativesMatchCentralDifferences(nlp, w, lambda, 0.7, 1e-6, 1e-6,
                                                                 1e-6);
}

// Ipopt on the steps: its multipliers, mapped back (steps' bounds to taper rows, heads' bounds
// and kept bound rows to the radii's bounds and limits), make the dense problem stationary; on
// the 64-knot design and with knot 45 held to 30 mm (a kept bound row, active).
TEST(OptimizeTapered, MultipliersMapBackToTheDesignsKkt) {
  DesignProblem limited = SolidAshKnotsAtBaseMass(64);
  limited.variables[44].max = 0.030;
  for (const DesignProblem& p : {SolidAshKnotsAtBaseMass(64), limited}) {
    const DesignModel model = Build(p);
    ScaledDesignNlp nlp(model);
    LocalSolveSettings settings;
    settings.hessian = HessianMode::kExact;
    settings.deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    const LocalSolveOutcome out = SolveWithIpopt(nlp, nlp.ToScaled(model.BaseX()), settings);
    ASSERT_EQ(out.termination, Termination::kConverged) << out.status_name;
    ASSERT_TRUE(out.has_multipliers);
    ASSERT_TRUE(nlp.Evaluate(out.s.data(), true));
    double worst = 0.0, scale = 1.0;
    for (int j = 0; j < nlp.n(); ++j) {
      double r = nlp.grad_f()(j) - out.z_lower[static_cast<std::size_t>(j)] +
                 out.z_upper[static_cast<std::size_t>(j)];
      for (int k = 0; k < nlp.m(); ++k)
        r += out.lambda[static_cast<std::size_t>(k)] * nlp.jacobian()(k, j);
      worst = std::max(worst, std::abs(r));
      scale = std::max(scale, std::abs(nlp.grad_f()(j)));
    }
    // Ipopt's tol 1e-9 on its scaled dual infeasibility; mapped through the steps (A^T,
    // entries up to ~1e2 at 64 knots) 1e-7 of the gradient's scale covers it, and a sign or a
    // missing multiplier leaves residuals of order the multipliers (~1e-2..1).
    EXPECT_LE(worst, 1e-7 * scale);
  }
}

// The same optimum as the lifted formulation over the radii, certified, at 64 and 128 knots
// and on the hollow 69-station profile.
void ExpectSameOptimum(const DesignProblem& p) {
  {  // the problem forms one taper chain (else both runs would be the radii's)
    const DesignModel model = Build(p);
    ScaledDesignNlp dense(model);
    LiftedDesignNlp lifted(dense);
    EXPECT_TRUE(TaperedLiftedNlp(lifted, dense.ToScaled(model.BaseX()), kTaperBlockSize).ok());
  }
  DesignOptions steps;
  DesignOptions radii;
  radii.taper_steps = false;
  const DesignResult a = OptimizeDesign(p, steps);
  const DesignResult b = OptimizeDesign(p, radii);
  ASSERT_EQ(a.summary.termination, Termination::kConverged) << a.summary.message;
  ASSERT_EQ(b.summary.termination, Termination::kConverged) << b.summary.message;
  EXPECT_TRUE(a.certificate.certified);
  // Both converge to Ipopt's tol 1e-9 on the scaled problem (objective ~1): the objectives
  // agree to that, relative (22.8 m/s).
  EXPECT_NEAR(a.objective_value, b.objective_value, 1e-9 * std::abs(b.objective_value));
  EXPECT_LT(a.summary.error_estimate, 1e-7);
  // The answer says which formulation Ipopt solved (summary.models_used).
  const auto uses = [](const DesignResult& r, const char* name) {
    return std::find(r.summary.models_used.begin(), r.summary.models_used.end(), name) !=
           r.summary.models_used.end();
  };
  EXPECT_TRUE(uses(a, "lifted_integrals") && uses(a, "taper_steps"));
  EXPECT_TRUE(uses(b, "lifted_integrals"));
  EXPECT_FALSE(uses(b, "taper_steps"));
}

TEST(OptimizeTapered, SameOptimumAsTheRadiiAtSixtyFourKnots) {
  ExpectSameOptimum(SolidAshKnotsAtBaseMass(64));
}
TEST(OptimizeTapered, SameOptimumAsTheRadiiAtOneHundredTwentyEightKnots) {
  ExpectSameOptimum(SolidAshKnotsAtBaseMass(128));
}
// A knot's own limit the taper does not imply (knot 45 of 64 at most 30 mm, in the barrel of
// the unconstrained optimum, 32.5 mm): it stays a row of the steps' problem (and with it every
// knot before it is held to 30 mm by the taper), active at the optimum, its multiplier mapped
// back to the knot's bound.
TEST(OptimizeTapered, SameOptimumWithALimitTheTaperDoesNotImply) {
  DesignProblem p = SolidAshKnotsAtBaseMass(64);
  p.variables[44].max = 0.030;
  {
    const DesignModel model = Build(p);
    ScaledDesignNlp dense(model);
    LiftedDesignNlp lifted(dense);
    const TaperedLiftedNlp tapered(lifted, dense.ToScaled(model.BaseX()), kTaperBlockSize);
    ASSERT_TRUE(tapered.ok());
    // The 64-knot problem's 9 rows and knot 45's upper limit.
    EXPECT_EQ(tapered.m(), 10);
  }
  ExpectSameOptimum(p);
  const DesignResult r = OptimizeDesign(p);
  // The limit holds the design back: knot 45 on it, to Ipopt's tolerance (1e-9 of the scaled
  // variable, 22.2 mm wide: 2.2e-11 m; 1e-10 m covers it, far below the 2.5 mm the limit takes
  // off the unconstrained barrel).
  EXPECT_NEAR(r.variables[44].value, 0.030, 1e-10);
}

TEST(OptimizeTapered, SameOptimumAsTheRadiiForAHollowSixtyNineStationProfile) {
  DesignProblem p = SolidAshKnotsAtBaseMass(69);
  p.bat.material = *FindMaterial("aluminium-7050");
  p.bat.wall_thickness_m = 0.003;
  for (auto& v : p.variables) v.min = 0.0115;
  p.constraints.mass_kg = DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg);
  ExpectSameOptimum(p);
}

}  // namespace
}  // namespace optimize_tapered_test
}  // namespace sweetspot::core
