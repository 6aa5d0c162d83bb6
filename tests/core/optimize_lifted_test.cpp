// The lifted formulation (core/optimize/lifted_nlp.hpp): which problems qualify, its gradient,
// Jacobian and Hessian against central differences, and the same optimum as the dense
// formulation at 16 and 64 knots.
#include "core/optimize/lifted_nlp.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/units.hpp"
#include "tests/core/knot_design_problems.hpp"
#include "tests/core/nlp_derivative_check.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_lifted_test {
namespace {

// bench/core_optimize.cpp's KnotProblem, at the base bat's mass.
using knot_design_problems::SolidAshKnotsAtBaseMass;

DesignModel Build(const DesignProblem& p) {
  DesignModel model;
  Refusal why;
  EXPECT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, &why)) << why.Message();
  return model;
}

TEST(OptimizeLifted, QualifiesOnlyForKnotRadiiAndFunctionsOfP) {
  std::string why;
  EXPECT_TRUE(LiftedDesignNlp::Qualifies(Build(SolidAshKnotsAtBaseMass(16)), &why)) << why;
  // A knot position moves the length's neighbours' integrals: not lifted (the dense path).
  DesignProblem positions = SolidAshKnotsAtBaseMass(16);
  positions.variables.push_back({"profile.knots[7].x_m", 0.39, 0.41});
  EXPECT_FALSE(LiftedDesignNlp::Qualifies(Build(positions), &why));
  EXPECT_NE(why.find("profile.knots[7].x_m"), std::string::npos) << why;
  // min_moi is a function of P: lifted too.
  DesignProblem moi = SolidAshKnotsAtBaseMass(16);
  moi.objective = DesignObjective::kMinMoi;
  EXPECT_TRUE(LiftedDesignNlp::Qualifies(Build(moi), &why)) << why;
}

// The gradient, the Jacobian and the Lagrangian's Hessian against central differences at a
// random interior point with random multipliers.
TEST(OptimizeLifted, DerivativesMatchCentralDifferences) {
  const DesignModel model = Build(SolidAshKnotsAtBaseMass(16));
  ScaledDesignNlp dense(model);
  LiftedDesignNlp nlp(dense);
  const int n = nlp.n(), m = nlp.m();
  std::vector<double> z;
  ASSERT_TRUE(nlp.Start(dense.ToScaled(model.BaseX()), &z));
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int j = 0; j < n; ++j) {
    // The knot radii in the middle of their range; q moved off P(x) (a point of the lifted
    // space, where the definitions are not met).
    z[static_cast<std::size_t>(j)] =
        j < nlp.design_variables() ? 0.5 + 0.3 * u(rng) : z[static_cast<std::size_t>(j)] + 0.01 * u(rng);
  }
  std::vector<double> lambda(static_cast<std::size_t>(m));
  for (double& l : lambda) l = u(rng);
  // Step 1e-6 on variables of order 1 (s in [0, 1], q ~ 1): truncation ~h^2 |f'''| ~ 1e-12 and
  // round-off ~1e-16 / 1e-6 = 1e-10 of the values (order 1): 1e-6 absolute is 1e4 times both,
  // and far below a wrong derivative (an entry off by a factor or a sign: >= 1e-3 here).
  nlp_derivative_check::ExpectDerivativesMatchCentralDifferences(nlp, z, lambda, 0.7, 1e-6, 1e-6,
                                                                 0.0);
}

// The lifted and the dense formulation (exact Hessian) reach the same optimum.
void ExpectSameOptimum(const DesignProblem& p) {
  DesignOptions lifted;
  lifted.hessian = HessianMode::kExact;
  DesignOptions dense = lifted;
  dense.lift = false;
  const DesignResult a = OptimizeDesign(p, lifted);
  const DesignResult b = OptimizeDesign(p, dense);
  ASSERT_EQ(a.summary.termination, Termination::kConverged) << a.summary.message;
  ASSERT_EQ(b.summary.termination, Termination::kConverged) << b.summary.message;
  const auto& used_a = a.summary.models_used;
  const auto& used_b = b.summary.models_used;
  EXPECT_NE(std::find(used_a.begin(), used_a.end(), "lifted_integrals"), used_a.end());
  EXPECT_EQ(std::find(used_b.begin(), used_b.end(), "lifted_integrals"), used_b.end());
  // Both converge to Ipopt's tol 1e-9 on the scaled problem (objective ~1): the objectives
  // agree to that, relative (22.8 m/s).
  EXPECT_NEAR(a.objective_value, b.objective_value, 1e-9 * std::abs(b.objective_value));
  // The KKT residual of each answer with its own multipliers (the lifted ones mapped back).
  EXPECT_LT(a.summary.error_estimate, 1e-7);
  EXPECT_LT(b.summary.error_estimate, 1e-7);
  // The mass constraint's multiplier (a sensitivity, m/s per kg) is the same to 1e-4
  // relative: a multiplier is one order less accurate than the objective at tol 1e-9 and the
  // mapped bound multipliers enter it.
  auto mass_multiplier = [](const DesignResult& r) {
    for (const auto& c : r.active_constraints) {
      if (c.name == "mass_kg") return c.multiplier;
    }
    return std::nan("");
  };
  EXPECT_NEAR(mass_multiplier(a), mass_multiplier(b), 1e-4 * std::abs(mass_multiplier(b)));
  // The same active constraints, except a taper constraint (r[k+1] >= r[k], named
  // "taper.knots[k]") that one answer reports active and the other leaves within 1e-8 m of its
  // limit: at 64 knots the lifted answer (monotone barrier) has taper.knots[35] and [38] at
  // 5e-10 and 5e-11 m with multipliers -0.07 and -0.16 m/s per unit, the dense one leaves
  // them 3.1e-9 and 1.4e-9 m open (objective 5.5e-10 relative lower). Ipopt's tol 1e-9 on the
  // scaled problem does not resolve the optimum that finely; 1e-8 m is 4e-7 of the radius.
  auto names = [](const DesignResult& r) {
    std::set<std::string> out;
    for (const auto& c : r.active_constraints) out.insert(c.name);
    return out;
  };
  const std::set<std::string> in_a = names(a), in_b = names(b);
  auto gap_elsewhere = [](const std::string& name, const DesignResult& other) {
    const std::string prefix = "taper.knots[";
    if (name.rfind(prefix, 0) != 0) return std::nan("");
    const auto k = static_cast<std::size_t>(std::stoi(name.substr(prefix.size())));
    return other.bat.knots[k + 1].radius_m - other.bat.knots[k].radius_m;
  };
  for (const std::string& name : in_a) {
    if (in_b.count(name) == 0) {
      EXPECT_LE(std::abs(gap_elsewhere(name, b)), 1e-8)
          << name << " active in the lifted answer only";
    }
  }
  for (const std::string& name : in_b) {
    if (in_a.count(name) == 0) {
      EXPECT_LE(std::abs(gap_elsewhere(name, a)), 1e-8)
          << name << " active in the dense answer only";
    }
  }
}

TEST(OptimizeLifted, SameOptimumAsDenseAtSixteenKnots) {
  ExpectSameOptimum(SolidAshKnotsAtBaseMass(16));
}
TEST(OptimizeLifted, SameOptimumAsDenseAtSixtyFourKnots) {
  ExpectSameOptimum(SolidAshKnotsAtBaseMass(64));
}

// A hollow aluminium profile of 69 stations (a knot every half inch of a 34-in bat) with a
// 3 mm wall: lifted too (the wall is fixed), the same optimum as the dense formulation.
TEST(OptimizeLifted, SameOptimumAsDenseForAHollowSixtyNineStationProfile) {
  DesignProblem p = SolidAshKnotsAtBaseMass(69);
  p.bat.material = *FindMaterial("aluminium-7050");
  p.bat.wall_thickness_m = 0.003;
  // The handle's smallest radius above the wall; the mass of the hollow base.
  for (auto& v : p.variables) v.min = 0.0115;
  p.constraints.mass_kg = DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg);
  ExpectSameOptimum(p);
}

// The Jacobian by sparse rows (DesignModel::EvaluateRows, ScaledDesignNlp::EvaluateRows: the
// merge's, the certificate's and the KKT residual's) has the dense Jacobian's nonzero entries,
// bit for bit (exact comparisons: the same sums in the same order), and no other entry, on the
// hollow 69-station profile (its wall guards' rows too) at the start and a point inside.
TEST(OptimizeLifted, JacobianRowsAreTheDenseJacobiansBits) {
  DesignProblem p = SolidAshKnotsAtBaseMass(69);
  p.bat.material = *FindMaterial("aluminium-7050");
  p.bat.wall_thickness_m = 0.003;
  for (auto& v : p.variables) v.min = 0.0115;
  p.constraints.mass_kg = DesignRange::Equal(ComputeMassProperties(p.bat).mass_kg);
  const DesignModel model = Build(p);
  std::vector<double> inside = model.BaseX();
  for (std::size_t j = 0; j < inside.size(); ++j) {
    const DesignVariableSpec& v = model.variables()[j];
    inside[j] = v.lower + (0.3 + 0.4 * static_cast<double>(j % 3) / 2.0) * (v.upper - v.lower);
  }
  ScaledDesignNlp dense_nlp(model), rows_nlp(model);
  for (const std::vector<double>& x : {model.BaseX(), inside}) {
    DesignPoint dense, rows;
    ASSERT_TRUE(model.Evaluate(x.data(), true, &dense));
    ASSERT_TRUE(model.EvaluateRows(x.data(), &rows));
    const std::vector<double> s = dense_nlp.ToScaled(x);
    ASSERT_TRUE(dense_nlp.Evaluate(s.data(), true));
    ASSERT_TRUE(rows_nlp.EvaluateRows(s.data()));
    ASSERT_EQ(rows.jacobian_rows.size(), static_cast<std::size_t>(model.m()));
    int nonzeros = 0, linear_rows = 0;
    for (int k = 0; k < model.m(); ++k) {
      const auto kk = static_cast<std::size_t>(k);
      EXPECT_EQ(rows.constraints[kk], dense.constraints[kk]) << k;
      EXPECT_EQ(rows_nlp.g()[kk], dense_nlp.g()[kk]) << k;
      const DesignGradientRow& r = rows.jacobian_rows[kk];
      const DesignGradientRow& rs = rows_nlp.jacobian_rows()[kk];
      ASSERT_EQ(r.size(), rs.size()) << k;
      std::size_t e = 0;
      for (int j = 0; j < model.n(); ++j) {
        if (dense.jacobian(k, j) == 0.0) continue;
        ++nonzeros;
        ASSERT_LT(e, r.size()) << k << ", " << j;
        EXPECT_EQ(r[e].first, j) << k;
        EXPECT_EQ(r[e].second, dense.jacobian(k, j)) << k << ", " << j;
        EXPECT_EQ(rs[e].first, j) << k;
        EXPECT_EQ(rs[e].second, dense_nlp.jacobian()(k, j)) << k << ", " << j;
        ++e;
      }
      EXPECT_EQ(e, r.size()) << k;
      if (model.constraints()[kk].f.function == DesignFunction::kLinear) {
        ++linear_rows;
        EXPECT_LE(r.size(), 2u) << k;  // a knot's limit, a taper step, a wall guard
      }
    }
    EXPECT_GT(linear_rows, 2 * model.n());  // the test covers the rows the merge scans
    EXPECT_GT(nonzeros, model.m());
    for (int j = 0; j < model.n(); ++j) {
      EXPECT_EQ(rows.objective_gradient(j), dense.objective_gradient(j));
      EXPECT_EQ(rows_nlp.grad_f()(j), dense_nlp.grad_f()(j));
    }
    EXPECT_EQ(rows_nlp.f(), dense_nlp.f());
  }
}

// The certificate above 32 variables factorises the active gradients sparsely: at the 64-knot
// answer it gives the dense path's multipliers (to 1e-9 of the largest: two QR factorisations
// of the same well-conditioned columns) and verdicts. With the flat barrel's knots moved onto
// the diameter limit, each knot's limit and the taper steps between them are active together
// (dependent columns: e_j, e_j+1 and e_j+1 - e_j): the sparse QR, as the dense one, says the
// multipliers are not unique.
TEST(OptimizeLifted, SparseCertificateIsTheDenseOne) {
  using design_detail::CertificateTolerances;
  using design_detail::Certify;
  const DesignProblem p = SolidAshKnotsAtBaseMass(64);
  const DesignResult r = OptimizeDesign(p);
  ASSERT_EQ(r.summary.termination, Termination::kConverged) << r.summary.message;
  const DesignModel model = Build(p);
  CertificateTolerances dense;
  dense.dense_max_variables = 1000;
  for (int dependent = 0; dependent < 2; ++dependent) {
    std::vector<double> x;
    for (const DesignValue& v : r.variables) {
      const double limit = 0.5 * InchesToMetres(2.61);
      x.push_back(dependent == 1 && v.value > 0.0324 ? limit : v.value);
    }
    const DesignCertificate a = Certify(model, x, CertificateTolerances{}, true);
    const DesignCertificate b = Certify(model, x, dense, true);
    ASSERT_TRUE(a.checked);
    ASSERT_TRUE(b.checked);
    EXPECT_EQ(a.active, b.active);
    EXPECT_EQ(a.certified, b.certified) << a.failed << " / " << b.failed;
    EXPECT_EQ(a.multipliers_unique, b.multipliers_unique);
    EXPECT_EQ(a.multipliers_unique, dependent == 0);
    if (dependent == 1) continue;  // not unique (and not optimal): no multipliers to compare
    EXPECT_LE(a.stationarity, 1e-8);
    EXPECT_LE(b.stationarity, 1e-8);
    double largest = 0.0;
    for (double v : b.lambda) largest = std::max(largest, std::abs(v));
    ASSERT_GT(largest, 0.0);
    for (std::size_t k = 0; k < a.lambda.size(); ++k) {
      EXPECT_NEAR(a.lambda[k], b.lambda[k], 1e-9 * largest) << "lambda " << k;
    }
  }
}

// The default request (the optimiser chooses): SLSQP at 14 variables, its certified answer the
// lifted Ipopt's optimum; Ipopt lifted at 62. SLSQP asked for by name above 32 variables is
// refused with the reason.
TEST(OptimizeLifted, TheChosenBackendIsCertifiedAndSlsqpIsRefusedAboveItsSize) {
  DesignOptions chosen;
  chosen.choose_backend = true;
  DesignOptions ipopt;
  const DesignResult small = OptimizeDesign(SolidAshKnotsAtBaseMass(16), chosen);
  const DesignResult small_ipopt = OptimizeDesign(SolidAshKnotsAtBaseMass(16), ipopt);
  ASSERT_EQ(small.summary.termination, Termination::kConverged) << small.summary.message;
  EXPECT_EQ(small.summary.backend, "nlopt:LD_SLSQP");
  EXPECT_LE(small.summary.error_estimate, 1e-6);
  // Both to their tolerance 1e-9 (scaled objective ~1): 1e-8 relative covers both.
  EXPECT_NEAR(small.objective_value, small_ipopt.objective_value,
              1e-8 * std::abs(small_ipopt.objective_value));
  const DesignResult large = OptimizeDesign(SolidAshKnotsAtBaseMass(64), chosen);
  ASSERT_EQ(large.summary.termination, Termination::kConverged) << large.summary.message;
  EXPECT_EQ(large.summary.backend, "ipopt");
  const auto& used = large.summary.models_used;
  EXPECT_NE(std::find(used.begin(), used.end(), "lifted_integrals"), used.end());

  DesignOptions slsqp;
  slsqp.backend = DesignBackend::kNloptSlsqp;
  const DesignResult refused = OptimizeDesign(SolidAshKnotsAtBaseMass(64), slsqp);
  EXPECT_EQ(refused.summary.termination, Termination::kInvalidInput);
  ASSERT_TRUE(refused.summary.refusal.has_value());
  EXPECT_EQ(refused.summary.refusal->field, "options.backend");
  EXPECT_NE(refused.summary.message.find("at most 32 variables (this problem has 62)"),
            std::string::npos)
      << refused.summary.message;
  EXPECT_EQ(OptimizeDesign(SolidAshKnotsAtBaseMass(32), slsqp).summary.termination,
            Termination::kConverged);
}

}  // namespace
}  // namespace optimize_lifted_test
}  // namespace sweetspot::core
