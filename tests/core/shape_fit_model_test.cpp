// The shape fit as a design problem (core/optimize/shape_fit_checks.hpp, FitDesignProblem): the
// fit's unknowns are the design variables of the same fields, its residuals the public mass
// properties', and the design model's derivatives of what the fit uses (the residuals'
// Jacobian, the validity constraints' gradients with the exact bore rule, the Lagrangian's
// Hessian) match central differences. There is no second model: these are the design model's.
#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/shape_fit_checks.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace shape_fit_model_test {
namespace {

// Every variable of the family unknown: a hollow bat with a fill (every constraint applies).
ShapeFitProblem EveryUnknown() {
  ShapeFitProblem problem;
  problem.shape = {0.84, 0.012, 0.032, 0.28, 0.52};
  problem.material = *FindMaterial("aluminium-7050");
  problem.wall_thickness_m = 0.002;
  problem.fill = Fill{*FindMaterial("cork"), 0.02, 0.1};
  problem.unknowns = {{DesignVariableKind::kTaperStart, 0.1, 0.4},
                      {DesignVariableKind::kTaperEnd, 0.42, 0.7},
                      {DesignVariableKind::kLength, 0.8, 0.9},
                      {DesignVariableKind::kHandleRadius, 0.011, 0.014},
                      {DesignVariableKind::kBarrelRadius, 0.03, 0.034},
                      {DesignVariableKind::kDensity, 2000.0, 3000.0},
                      {DesignVariableKind::kWallThickness, 0.001, 0.003},
                      {DesignVariableKind::kFillDiameter, 0.01, 0.03},
                      {DesignVariableKind::kFillDepth, 0.05, 0.2},
                      {DesignVariableKind::kFillDensity, 100.0, 400.0}};
  problem.targets.mass_kg = 0.9;
  problem.targets.balance_point_m = 0.55;
  return problem;
}

// A point inside the bounds (in s), away from every kink: the bore's bottom inside the barrel
// (depth 0.0935 m, L = 0.843 m: the bottom at 0.75 m beyond x2 = 0.59 m), and with the bore's
// bottom in the taper (depth 0.2 m, x2 = 0.7 m: the bottom at 0.64 m).
const std::vector<double> kInteriorS = {0.37, 0.61, 0.43, 0.52, 0.47, 0.33, 0.58, 0.41, 0.29, 0.66};
const std::vector<double> kTaperBottomS = {0.37, 1.0,  0.43, 0.52, 0.47,
                                           0.33, 0.58, 0.41, 0.97, 0.66};

DesignModel FitModel(const ShapeFitProblem& problem) {
  DesignModel model;
  Refusal why;
  EXPECT_TRUE(DesignModel::Build(fit_detail::FitDesignProblem(problem, ShapeFitOptions{},
                                                              fit_detail::StartParameters(problem)),
                                 DesignOptions{}, &model, &why))
      << why.Message();
  return model;
}

std::vector<double> AtS(const DesignModel& model, const std::vector<double>& s) {
  std::vector<double> x;
  for (std::size_t j = 0; j < s.size(); ++j) {
    const DesignVariableSpec& v = model.variables()[j];
    x.push_back(v.lower + (v.upper - v.lower) * s[j]);
  }
  return x;
}

TEST(ShapeFitModelTest, UnknownsAreTheDesignVariablesOfTheSameFields) {
  EXPECT_EQ(DesignVariablePath(fit_detail::DesignVariableOf(DesignVariableKind::kTaperStart)),
            "three_segment.taper_start_m");
  EXPECT_EQ(DesignVariablePath(fit_detail::DesignVariableOf(DesignVariableKind::kBarrelRadius)),
            "three_segment.barrel_radius_m");
  EXPECT_EQ(DesignVariablePath(fit_detail::DesignVariableOf(DesignVariableKind::kDensity)),
            "material.density_kg_m3");
  EXPECT_EQ(DesignVariablePath(fit_detail::DesignVariableOf(DesignVariableKind::kFillDensity)),
            "fill.material.density_kg_m3");
  const DesignProblem design = fit_detail::FitDesignProblem(
      EveryUnknown(), ShapeFitOptions{}, fit_detail::StartParameters(EveryUnknown()));
  ASSERT_EQ(design.variables.size(), 10u);
  EXPECT_EQ(design.variables[9].path, "fill.material.density_kg_m3");
  EXPECT_EQ(design.objective, DesignObjective::kLeastSquares);
  ASSERT_TRUE(design.least_squares.has_value());
  EXPECT_EQ(design.least_squares->mass_scale_kg, 0.9);  // s_M = M* by default
  EXPECT_EQ(design.least_squares->balance_point_scale_m, 0.55);
}

TEST(ShapeFitModelTest, ResidualsAreThePublicMassProperties) {
  const DesignModel model = FitModel(EveryUnknown());
  ASSERT_EQ(model.n(), 10);
  const std::vector<double> x = AtS(model, kInteriorS);
  Eigen::VectorXd r;
  ASSERT_TRUE(model.LeastSquaresResiduals(x.data(), &r, nullptr));
  ASSERT_EQ(r.size(), 2);
  const Bat bat = model.BatAt(x.data());
  std::string why;
  ASSERT_TRUE(Validates(bat, &why)) << why;
  const MassProperties p = ComputeMassProperties(bat);
  // The design model's integrals about c0 and the public ones about the knob: 1e-14.
  EXPECT_NEAR(r[0], (p.mass_kg - 0.9) / 0.9, 1e-14);
  EXPECT_NEAR(r[1], (p.balance_point_m - 0.55) / 0.55, 1e-14);
  DesignPoint point;
  ASSERT_TRUE(model.Evaluate(x.data(), false, &point));
  EXPECT_NEAR(point.objective, r.squaredNorm(), 1e-15);
}

TEST(ShapeFitModelTest, JacobianMatchesCentralDifferences) {
  const DesignModel model = FitModel(EveryUnknown());
  const std::vector<double> x = AtS(model, kInteriorS);
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  ASSERT_TRUE(model.LeastSquaresResiduals(x.data(), &r, &jac));
  DesignPoint point;
  ASSERT_TRUE(model.Evaluate(x.data(), true, &point));
  for (int j = 0; j < model.n(); ++j) {
    const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
    const double h = 1e-6 * (v.upper - v.lower);
    std::vector<double> up = x, down = x;
    up[static_cast<std::size_t>(j)] += h;
    down[static_cast<std::size_t>(j)] -= h;
    Eigen::VectorXd ru, rd;
    ASSERT_TRUE(model.LeastSquaresResiduals(up.data(), &ru, nullptr));
    ASSERT_TRUE(model.LeastSquaresResiduals(down.data(), &rd, nullptr));
    for (int i = 0; i < 2; ++i) {
      // Per unit of s (the variable's range): error ~ h_s^2 |r'''| + eps / h_s, ~1e-9 here.
      const double fd = (ru[i] - rd[i]) / (2.0 * h) * (v.upper - v.lower);
      EXPECT_NEAR(jac(i, j) * (v.upper - v.lower), fd, 1e-8 * (1.0 + std::abs(fd)))
          << "residual " << i << " d/d " << v.path;
    }
    // The objective's gradient is 2 J^T r.
    const double g = 2.0 * jac.col(j).dot(r);
    EXPECT_NEAR(point.objective_gradient[j], g, 1e-14 * (1.0 + std::abs(g)) / (v.upper - v.lower));
  }
}

TEST(ShapeFitModelTest, ConstraintGradientsAndHessianMatchCentralDifferences) {
  const DesignModel model = FitModel(EveryUnknown());
  // The fit's rules that an unknown can break: the taper's order and end, the wall against
  // both radii, the fill's depth, and the bore at the tip and (exactly) at its bottom.
  const auto& cs = model.constraints();
  const auto named = [&cs](const char* name) {
    return std::any_of(cs.begin(), cs.end(),
                       [name](const DesignConstraintSpec& c) { return c.name == name; });
  };
  EXPECT_TRUE(named("validity.three_segment.taper_order"));
  EXPECT_TRUE(named("validity.three_segment.taper_end"));
  EXPECT_TRUE(named("validity.fill.depth_m"));
  EXPECT_TRUE(named("validity.fill.diameter_m.tip"));
  EXPECT_TRUE(named("validity.fill.diameter_m.bottom"));
  for (const std::vector<double>* s : {&kInteriorS, &kTaperBottomS}) {
    const std::vector<double> x = AtS(model, *s);
    DesignPoint point;
    ASSERT_TRUE(model.Evaluate(x.data(), true, &point));
    std::vector<double> weights(static_cast<std::size_t>(model.m()), 0.0);
    for (int k = 0; k < model.m(); ++k) weights[static_cast<std::size_t>(k)] = 0.3 + 0.1 * k;
    Eigen::MatrixXd hess;
    ASSERT_TRUE(model.Hessian(x.data(), 0.7, weights.data(), &hess));
    for (int j = 0; j < model.n(); ++j) {
      const DesignVariableSpec& v = model.variables()[static_cast<std::size_t>(j)];
      const double h = 1e-6 * (v.upper - v.lower);
      std::vector<double> up = x, down = x;
      up[static_cast<std::size_t>(j)] += h;
      down[static_cast<std::size_t>(j)] -= h;
      DesignPoint pu, pd;
      ASSERT_TRUE(model.Evaluate(up.data(), true, &pu));
      ASSERT_TRUE(model.Evaluate(down.data(), true, &pd));
      for (int k = 0; k < model.m(); ++k) {
        // Per unit of s (the variable's range), in metres, values < 1 m: rounding eps / 1e-6
        // ~ 2e-10 and the bore's quotient's truncation below that (smooth away from kinks).
        const double w = v.upper - v.lower;
        const double fd = (pu.constraints[static_cast<std::size_t>(k)] -
                           pd.constraints[static_cast<std::size_t>(k)]) /
                          (2.0 * h) * w;
        EXPECT_NEAR(point.jacobian(k, j) * w, fd, 1e-8)
            << cs[static_cast<std::size_t>(k)].name << " d/d " << v.path;
      }
      Eigen::VectorXd gu = 0.7 * pu.objective_gradient, gd = 0.7 * pd.objective_gradient;
      for (int k = 0; k < model.m(); ++k) {
        gu += weights[static_cast<std::size_t>(k)] * pu.jacobian.row(k).transpose();
        gd += weights[static_cast<std::size_t>(k)] * pd.jacobian.row(k).transpose();
      }
      const Eigen::VectorXd column = (gu - gd) / (2.0 * h);
      for (int i = 0; i < model.n(); ++i) {
        const double scale =
            std::abs(hess(i, j)) + std::abs(column[i]) + hess.col(j).lpNorm<Eigen::Infinity>();
        // Central differences of exact gradients: truncation and rounding below 1e-5 of the
        // column's scale (as OptimizeModel's test of the same Hessian).
        EXPECT_NEAR(hess(i, j), column[i], 1e-5 * scale + 1e-12) << "H(" << i << ", " << j << ")";
      }
    }
  }
}

}  // namespace
}  // namespace shape_fit_model_test
}  // namespace sweetspot::core
