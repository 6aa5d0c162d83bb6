// Exact gradients of the mass properties against central finite differences.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace mass_properties_gradient_test {
namespace {

struct NamedBat {
  std::string name;
  Bat bat;
};

std::vector<NamedBat> GradientBats() {
  std::vector<NamedBat> out;
  for (const char* name : {"paper-wood", "wood-34-ash", "bbcor-33-aluminium"}) {
    out.push_back({name, FindPreset(name)->bat});
  }
  Bat corked = FindPreset("paper-wood")->bat;
  corked.fill = Fill{*FindMaterial("cork"), 0.0254, 0.254};
  out.push_back({"paper-wood+cork", corked});
  Bat cupped = FindPreset("wood-34-ash")->bat;
  cupped.fill = Fill{EmptyFillMaterial(), 0.03, 0.025};
  out.push_back({"wood-34-ash+cup", cupped});
  Bat hollow_fill = FindPreset("bbcor-33-aluminium")->bat;
  hollow_fill.fill = Fill{*FindMaterial("rubber"), 0.04, 0.2};
  out.push_back({"bbcor+rubber", hollow_fill});
  // Issue 35: an end cap and a knob (their centres and radii move with the tip's and knob's
  // knots and the wall).
  Bat capped = FindPreset("bbcor-33-aluminium")->bat;
  capped.end_cap = BatPart{0.030, 0.012, "rubber"};
  capped.knob = BatPart{0.025, 0.02, "aluminium-7050"};
  out.push_back({"bbcor+cap+knob", capped});
  Bat weighted = FindPreset("wood-34-ash")->bat;
  weighted.knob = BatPart{0.05, 0.03, ""};
  out.push_back({"wood-34-ash+knob", weighted});
  // Walls per knot (the bat's wall entry moves the knots without their own).
  Bat walled = FindPreset("bbcor-33-aluminium")->bat;
  walled.knots[0].wall_thickness_m = 0.004;
  walled.knots[5].wall_thickness_m = 0.0035;
  walled.knots[11].wall_thickness_m = 0.0022;
  walled.end_cap = BatPart{0.02, 0.01, ""};
  out.push_back({"bbcor+knot-walls", walled});
  // A short (1e-6 m) segment: the finite-difference step on its positions
  // must stay below its length, so it is not 1e-12 here.
  Bat short_step;
  short_step.knots = {{0.0, 0.015}, {0.5, 0.015}, {0.5 + 1e-6, 0.033}, {0.86, 0.03}};
  short_step.material = *FindMaterial("ash");
  out.push_back({"short-step", short_step});
  return out;
}

// Finite-difference step for parameter i: small against the parameter's own
// scale (and, for positions, against the shortest adjacent segment).
double Step(const Bat& bat, const DesignParameterLayout& lay, const Eigen::VectorXd& theta, int i) {
  if (i >= lay.KnotPosition(0) && i < lay.Density()) {
    const int k = i - lay.KnotPosition(0);
    double shortest = bat.LengthM();
    if (k > 0) shortest = std::min(shortest, theta[i] - theta[i - 1]);
    if (k + 1 < lay.num_knots) shortest = std::min(shortest, theta[i + 1] - theta[i]);
    return std::min(1e-6 * bat.LengthM(), 0.1 * shortest);
  }
  if (i < lay.KnotPosition(0)) return 1e-6 * theta[i];
  if (i == lay.WallThickness()) return theta[i] > 0 ? 1e-6 * theta[i] : 0.0;
  // An empty bore (density 0) cannot be perturbed downwards: see EmptyBoreFillDensity.
  if (i == lay.FillDensity()) return bat.fill && !bat.fill->IsEmpty() ? 1e-6 * theta[i] : 0.0;
  if (i == lay.FillDiameter() || i == lay.FillDepth()) return bat.fill ? 1e-6 * theta[i] : 0.0;
  return 1e-6 * theta[i];  // density
}

TEST(MassPropertiesGradient, MatchesCentralDifferences) {
  for (const NamedBat& nb : GradientBats()) {
    for (InertiaModel model : {InertiaModel::kRigidBody, InertiaModel::kSlenderRod}) {
      const Bat& bat = nb.bat;
      ASSERT_TRUE(bat.Validate(nullptr)) << nb.name;
      const MassPropertiesWithGradient g = ComputeMassPropertiesWithGradient(bat, model);
      const DesignParameterLayout& lay = g.layout;
      ASSERT_EQ(g.mass_gradient.size(), lay.Size());
      const Eigen::VectorXd theta = DesignParameters(bat);
      const double pivot = -0.1;
      for (int i = 0; i < lay.Size(); ++i) {
        const double h = Step(bat, lay, theta, i);
        if (i == lay.KnotPosition(0)) continue;  // x_0 = 0 must stay 0 for a valid bat
        if (h == 0.0) continue;                  // checked in ZeroEntries below
        Eigen::VectorXd plus = theta, minus = theta;
        plus[i] += h;
        minus[i] -= h;
        const Bat bp = WithDesignParameters(bat, plus);
        const Bat bm = WithDesignParameters(bat, minus);
        ASSERT_TRUE(bp.Validate(nullptr)) << nb.name << " " << lay.Name(i);
        ASSERT_TRUE(bm.Validate(nullptr)) << nb.name << " " << lay.Name(i);
        const MassProperties pp = ComputeMassProperties(bp, model);
        const MassProperties pm = ComputeMassProperties(bm, model);
        struct Item {
          const char* what;
          double vp, vm, grad, value;
        } items[] = {
            {"volume", pp.volume_m3, pm.volume_m3, g.volume_gradient[i], g.properties.volume_m3},
            {"mass", pp.mass_kg, pm.mass_kg, g.mass_gradient[i], g.properties.mass_kg},
            {"balance", pp.balance_point_m, pm.balance_point_m, g.balance_point_gradient[i],
             g.properties.balance_point_m},
            {"moi_knob", pp.moi_knob_kg_m2, pm.moi_knob_kg_m2, g.moi_knob_gradient[i],
             g.properties.moi_knob_kg_m2},
            {"moi_centroid", pp.moi_centroid_kg_m2, pm.moi_centroid_kg_m2,
             g.moi_centroid_gradient[i], g.properties.moi_centroid_kg_m2},
            {"moi_six_inch", pp.MoiSixInchKgM2(), pm.MoiSixInchKgM2(), g.MoiSixInchGradient()[i],
             g.properties.MoiSixInchKgM2()},
            {"moi_pivot", pp.MoiAboutKgM2(pivot), pm.MoiAboutKgM2(pivot),
             g.MoiAboutGradient(pivot)[i], g.properties.MoiAboutKgM2(pivot)},
        };
        for (const Item& it : items) {
          const double fd = (it.vp - it.vm) / (2 * h);
          // Central differences: truncation ~h^2 |P'''| (relative ~1e-12 with
          // h ~ 1e-6 of the scale) and round-off ~1e-16 |P| / h. Tolerance:
          // 1e-6 of the gradient plus 1e-8 |P| / scale_i, where scale_i = h / 1e-6.
          const double scale = h / 1e-6;
          const double tol = 1e-6 * std::abs(it.grad) + 1e-8 * std::abs(it.value) / scale;
          EXPECT_NEAR(it.grad, fd, tol)
              << nb.name << " " << it.what << " d/d" << lay.Name(i)
              << (model == InertiaModel::kRigidBody ? " rigid" : " slender");
        }
      }
    }
  }
}

TEST(MassPropertiesGradient, ZeroEntries) {
  // Solid bat without fill: the wall and fill entries are exactly 0.
  const MassPropertiesWithGradient g =
      ComputeMassPropertiesWithGradient(FindPreset("paper-wood")->bat);
  const DesignParameterLayout& lay = g.layout;
  for (int i : {lay.WallThickness(), lay.FillDiameter(), lay.FillDepth(), lay.FillDensity()}) {
    EXPECT_EQ(g.mass_gradient[i], 0.0) << lay.Name(i);
    EXPECT_EQ(g.moi_knob_gradient[i], 0.0) << lay.Name(i);
    EXPECT_EQ(g.balance_point_gradient[i], 0.0) << lay.Name(i);
  }
  // The balance point does not depend on the density of a homogeneous bat.
  EXPECT_NEAR(g.balance_point_gradient[lay.Density()], 0.0, 1e-18);
  // The centroidal moment is stationary in the pivot: d/dp [I_cm + M (p-C)^2] at p = C
  // equals dI_cm (the pivot gradient at the centroid is the centroidal gradient).
  const Eigen::VectorXd at_c = g.MoiAboutGradient(g.properties.balance_point_m);
  EXPECT_LT((at_c - g.moi_centroid_gradient).cwiseAbs().maxCoeff(),
            1e-12 * g.moi_centroid_gradient.cwiseAbs().maxCoeff());
}

TEST(MassPropertiesGradient, EmptyBoreFillDensity) {
  // Filling an empty bore: the mass grows by the bore's volume per kg/m^3.
  Bat bat = FindPreset("wood-34-ash")->bat;
  bat.fill = Fill{EmptyFillMaterial(), 0.03, 0.025};
  const MassPropertiesWithGradient g = ComputeMassPropertiesWithGradient(bat);
  const double bore = M_PI * 0.015 * 0.015 * 0.025;
  EXPECT_NEAR(g.mass_gradient[g.layout.FillDensity()], bore, 1e-14 * bore);  // a few roundings
  // Its moment about the knob grows by the bore's own slender + disk moment.
  const double L = bat.LengthM();
  const double own = bore * ((L - 0.0125) * (L - 0.0125) + 0.025 * 0.025 / 12 + 0.015 * 0.015 / 4);
  EXPECT_NEAR(g.moi_knob_gradient[g.layout.FillDensity()], own, 1e-13 * own);
}

TEST(MassPropertiesGradient, ClosedFormForACylinder) {
  // M = rho pi r^2 L: dM/dr_i = rho pi r L (each of the two knots carries half),
  // dM/dL = rho pi r^2, dM/drho = pi r^2 L.
  Bat bat;
  bat.knots = {{0.0, 0.03}, {0.9, 0.03}};
  bat.material = *FindMaterial("ash");
  const double rho = bat.material.density_kg_m3;
  const MassPropertiesWithGradient g = ComputeMassPropertiesWithGradient(bat);
  const DesignParameterLayout& lay = g.layout;
  // Exact polynomial derivatives vs their closed forms: a few ulp.
  EXPECT_NEAR(g.mass_gradient[lay.KnotRadius(0)], rho * M_PI * 0.03 * 0.9, 1e-12);
  EXPECT_NEAR(g.mass_gradient[lay.KnotRadius(1)], rho * M_PI * 0.03 * 0.9, 1e-12);
  EXPECT_NEAR(g.mass_gradient[lay.KnotPosition(1)], rho * M_PI * 0.03 * 0.03, 1e-12);
  EXPECT_NEAR(g.mass_gradient[lay.KnotPosition(0)], -rho * M_PI * 0.03 * 0.03, 1e-12);
  EXPECT_NEAR(g.mass_gradient[lay.Density()], M_PI * 0.03 * 0.03 * 0.9, 1e-15);
  EXPECT_NEAR(g.balance_point_gradient[lay.KnotPosition(1)], 0.5, 1e-14);  // C = L / 2
}

TEST(MassPropertiesGradient, LayoutNamesAndRoundTrip) {
  DesignParameterLayout lay{4};
  EXPECT_EQ(lay.Size(), 13);
  EXPECT_EQ(lay.Name(0), "knots[0].radius_m");
  EXPECT_EQ(lay.Name(3), "knots[3].radius_m");
  EXPECT_EQ(lay.Name(4), "knots[0].x_m");
  EXPECT_EQ(lay.Name(7), "knots[3].x_m");
  EXPECT_EQ(lay.Name(8), "density_kg_m3");
  EXPECT_EQ(lay.Name(9), "wall_thickness_m");
  EXPECT_EQ(lay.Name(10), "fill.diameter_m");
  EXPECT_EQ(lay.Name(11), "fill.depth_m");
  EXPECT_EQ(lay.Name(12), "fill.density_kg_m3");
  EXPECT_EQ(lay.Name(13), "");
  EXPECT_EQ(lay.Name(-1), "");

  Bat bat = FindPreset("bbcor-33-aluminium")->bat;
  bat.fill = Fill{*FindMaterial("rubber"), 0.04, 0.2};
  const Eigen::VectorXd theta = DesignParameters(bat);
  const DesignParameterLayout l2{static_cast<int>(bat.knots.size())};
  EXPECT_EQ(theta[l2.WallThickness()], bat.wall_thickness_m);
  EXPECT_EQ(theta[l2.FillDepth()], 0.2);
  EXPECT_EQ(theta[l2.FillDensity()], 1100.0);
  Eigen::VectorXd changed = theta;
  changed[l2.KnotRadius(2)] = 0.02;
  changed[l2.FillDiameter()] = 0.03;
  const Bat b2 = WithDesignParameters(bat, changed);
  EXPECT_EQ(b2.knots[2].radius_m, 0.02);
  EXPECT_EQ(b2.fill->diameter_m, 0.03);
  EXPECT_EQ(DesignParameters(b2), changed);
  // A wrong size leaves the bat unchanged.
  EXPECT_EQ(DesignParameters(WithDesignParameters(bat, Eigen::VectorXd::Zero(3))), theta);
}

TEST(MassPropertiesGradient, InvalidBatGivesNaN) {
  Bat bat = FindPreset("paper-wood")->bat;
  bat.wall_thickness_m = 1.0;
  const MassPropertiesWithGradient g = ComputeMassPropertiesWithGradient(bat);
  EXPECT_TRUE(std::isnan(g.properties.mass_kg));
  ASSERT_EQ(g.mass_gradient.size(), 2 * static_cast<int>(bat.knots.size()) + 5);
  EXPECT_TRUE(g.mass_gradient.array().isNaN().all());
  EXPECT_TRUE(g.moi_centroid_gradient.array().isNaN().all());
}

TEST(MassPropertiesGradient, ValuesIdenticalToComputeMassProperties) {
  for (const NamedBat& nb : GradientBats()) {
    const MassProperties a = ComputeMassProperties(nb.bat, InertiaModel::kSlenderRod);
    const MassProperties b =
        ComputeMassPropertiesWithGradient(nb.bat, InertiaModel::kSlenderRod).properties;
    EXPECT_EQ(a.mass_kg, b.mass_kg) << nb.name;
    EXPECT_EQ(a.moi_knob_kg_m2, b.moi_knob_kg_m2) << nb.name;
  }
}

}  // namespace
}  // namespace mass_properties_gradient_test
}  // namespace sweetspot::core
