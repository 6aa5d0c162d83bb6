// The shape fit's least-squares design problem (core/optimize/shape_fit_model.hpp): the design
// code's parametrisation, residuals against the public mass properties, and exact derivatives
// (the residuals' Jacobian and the constraints' gradients) against central differences.
#include "core/optimize/shape_fit_model.hpp"

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <cmath>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace shape_fit_model_test {
namespace {

using fit_detail::FitConstraint;
using fit_detail::ShapeFitModel;

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

// A point inside the bounds, away from every kink (the bore's bottom inside the barrel).
std::vector<double> InteriorPoint() {
  return {0.37, 0.61, 0.43, 0.52, 0.47, 0.33, 0.58, 0.41, 0.29, 0.66};
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
}

TEST(ShapeFitModelTest, ResidualsAreThePublicMassProperties) {
  const ShapeFitProblem problem = EveryUnknown();
  ShapeFitModel model(problem, ShapeFitOptions{});
  ASSERT_EQ(model.n(), 10);
  ASSERT_EQ(model.m(), 2);
  const std::vector<double> s = InteriorPoint();
  Eigen::VectorXd r;
  model.Residuals(s.data(), &r, nullptr);
  const std::vector<double> t = model.ToParameters(s.data());
  const auto value = [&t](DesignVariableKind v) { return fit_detail::FitValue(t, v); };
  ThreeSegmentShape shape{
      value(DesignVariableKind::kLength), value(DesignVariableKind::kHandleRadius),
      value(DesignVariableKind::kBarrelRadius), value(DesignVariableKind::kTaperStart),
      value(DesignVariableKind::kTaperEnd)};
  Material material = problem.material;
  material.density_kg_m3 = value(DesignVariableKind::kDensity);
  Bat bat = MakeThreeSegmentBat(shape, material);
  bat.wall_thickness_m = value(DesignVariableKind::kWallThickness);
  bat.fill = problem.fill;
  bat.fill->diameter_m = value(DesignVariableKind::kFillDiameter);
  bat.fill->depth_m = value(DesignVariableKind::kFillDepth);
  bat.fill->material.density_kg_m3 = value(DesignVariableKind::kFillDensity);
  std::string why;
  ASSERT_TRUE(Validates(bat, &why)) << why;
  const MassProperties p = ComputeMassProperties(bat);
  EXPECT_NEAR(r[0], (p.mass_kg - 0.9) / 0.9, 1e-14);
  EXPECT_NEAR(r[1], (p.balance_point_m - 0.55) / 0.55, 1e-14);
}

TEST(ShapeFitModelTest, JacobianMatchesCentralDifferences) {
  ShapeFitModel model(EveryUnknown(), ShapeFitOptions{});
  const std::vector<double> s = InteriorPoint();
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  model.Residuals(s.data(), &r, &jac);
  const double h = 1e-6;
  for (int j = 0; j < model.n(); ++j) {
    std::vector<double> up = s, down = s;
    up[static_cast<std::size_t>(j)] += h;
    down[static_cast<std::size_t>(j)] -= h;
    Eigen::VectorXd ru, rd;
    model.Residuals(up.data(), &ru, nullptr);
    model.Residuals(down.data(), &rd, nullptr);
    for (int i = 0; i < model.m(); ++i) {
      const double fd = (ru[i] - rd[i]) / (2.0 * h);
      // Central differences: error ~ h^2 |r'''| + eps / h, about 1e-9 here.
      EXPECT_NEAR(jac(i, j), fd, 1e-8 * (1.0 + std::abs(fd))) << "residual " << i << " s" << j;
    }
  }
  // The objective's gradient is 2 J^T r.
  std::vector<double> grad(static_cast<std::size_t>(model.n()));
  const double phi = model.Objective(s.data(), grad.data());
  EXPECT_NEAR(phi, r.squaredNorm(), 1e-15);
  const Eigen::VectorXd g = 2.0 * jac.transpose() * r;
  for (int j = 0; j < model.n(); ++j) EXPECT_NEAR(grad[static_cast<std::size_t>(j)], g[j], 1e-15);
}

TEST(ShapeFitModelTest, ConstraintGradientsMatchCentralDifferences) {
  ShapeFitModel model(EveryUnknown(), ShapeFitOptions{});
  ASSERT_EQ(model.constraints().size(), 8u);  // every constraint involves an unknown
  const std::vector<double> s = InteriorPoint();
  ASSERT_TRUE(model.Feasible(s.data()));
  const double h = 1e-6;
  for (FitConstraint kind : model.constraints()) {
    std::vector<double> grad(static_cast<std::size_t>(model.n()));
    const double value = model.Constraint(kind, s.data(), grad.data());
    EXPECT_EQ(value, model.Constraint(kind, s.data(), nullptr));
    for (int j = 0; j < model.n(); ++j) {
      std::vector<double> up = s, down = s;
      up[static_cast<std::size_t>(j)] += h;
      down[static_cast<std::size_t>(j)] -= h;
      const double fd = (model.Constraint(kind, up.data(), nullptr) -
                         model.Constraint(kind, down.data(), nullptr)) /
                        (2.0 * h);
      EXPECT_NEAR(grad[static_cast<std::size_t>(j)], fd, 1e-8)
          << "constraint " << static_cast<int>(kind) << " s" << j;
    }
  }
}

}  // namespace
}  // namespace shape_fit_model_test
}  // namespace sweetspot::core
