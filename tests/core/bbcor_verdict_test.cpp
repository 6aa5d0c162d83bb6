// Issue 35 item 1: one BBCOR everywhere. Over a sweep of hollow designs (the alloy preset's wall,
// length and material) no design changes verdict (legal: BBCOR <= 0.50) between the `bbcor`
// output, `rules: bbcor` (BbcorRuleHolds, the optimiser's check of its answers) and the
// `bbcor_scan` maximum. The fixed-point estimate is measured against the scan over the same
// sweep (docs/validation.md): its verdict differs for many of these designs, which is what makes
// the test able to fail (an output or rule that went back to the estimate would disagree).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/bat/material.hpp"
#include "core/bat/presets.hpp"
#include "core/collision/barrel.hpp"
#include "core/collision/bbcor_scan.hpp"
#include "core/flexible/modes.hpp"
#include "core/optimize/rules.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/scene/scene.hpp"
#include "core/scene/scene_barrel.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bbcor_verdict_test {
namespace {

constexpr double kInch = 0.0254;
constexpr double kLimit = 0.50;

// The preset's profile stretched to length_m (every knot's position scaled), with `wall_m` and
// `material`.
Bat AlloyDesign(double length_m, double wall_m, const Material& material) {
  Bat bat = FindPreset("bbcor-33-aluminium")->bat;
  const double scale = length_m / bat.LengthM();
  for (auto& k : bat.knots) k.x_m *= scale;
  bat.wall_thickness_m = wall_m;
  bat.material = material;
  return bat;
}

std::vector<Material> Materials() {
  std::vector<Material> out = {*FindMaterial("aluminium-7050"), *FindMaterial("aluminium-7046")};
  Material dense = *FindMaterial("aluminium-7050");  // as optimize_bbcor_test's dense alloy
  dense.name = "custom";
  dense.density_kg_m3 *= 1.2;
  out.push_back(dense);
  Material stiff = *FindMaterial("aluminium-7050");  // a 10 % stiffer alloy
  stiff.name = "custom";
  stiff.youngs_modulus_pa *= 1.1;
  out.push_back(stiff);
  return out;
}

// 7 walls (2.0 to 3.5 mm) x 4 lengths (31 to 34 in) x 4 alloys = 112 designs.
TEST(BbcorVerdict, NoDesignChangesVerdictBetweenOutputRuleAndScan) {
  int designs = 0, legal = 0, estimate_disagrees = 0;
  double worst_error = 0.0, sum_error = 0.0, min_error = 1.0;
  SceneEvaluator evaluator({});
  for (const Material& material : Materials()) {
    for (const double length_in : {31.0, 32.0, 33.0, 34.0}) {
      for (int w = 0; w <= 6; ++w) {
        const double wall_m = (2.0 + 0.25 * w) * 1e-3;
        Scene scene;
        scene.bat = AlloyDesign(length_in * kInch, wall_m, material);
        scene.length_m = scene.bat->LengthM();
        scene.outputs = {SceneOutput::kBbcor, SceneOutput::kBbcorScan};
        SceneResult r;
        evaluator.Evaluate(scene, &r);
        ASSERT_TRUE(r.summary.IsSolutionUsable()) << r.summary.message;
        ASSERT_TRUE(r.bbcor.has_value() && r.bbcor_scan.has_value());
        BbcorResult rule_bbcor;
        std::string why;
        const bool rule_legal = BbcorRuleHolds(*scene.bat, &rule_bbcor, &why);
        const bool output_legal = r.bbcor->value <= kLimit;
        const bool scan_legal = r.bbcor_scan->max_value <= kLimit;
        const std::string design = material.name + " " + std::to_string(length_in) + " in, " +
                                   std::to_string(wall_m * 1e3) + " mm";
        EXPECT_EQ(output_legal, scan_legal) << design;
        EXPECT_EQ(rule_legal, scan_legal) << design << ": " << why;
        // The same number, not only the same verdict (the same computation on the same bat).
        EXPECT_EQ(r.bbcor->value, r.bbcor_scan->max_value) << design;
        EXPECT_EQ(rule_bbcor.value, r.bbcor_scan->max_value) << design;
        const double error = r.bbcor->estimate_value - r.bbcor->value;
        worst_error = std::max(worst_error, std::abs(error));
        min_error = std::min(min_error, error);
        sum_error += error;
        estimate_disagrees += (r.bbcor->estimate_value <= kLimit) != scan_legal;
        legal += scan_legal;
        ++designs;
      }
    }
  }
  EXPECT_EQ(designs, 112);
  // The sweep straddles the limit (both verdicts occur) and the estimate disagrees with the
  // scan on many designs (measured: 38 of 112; estimate - scan 0.0030 to 0.0247, mean 0.0119), so a
  // verdict taken from the estimate would fail the checks above.
  EXPECT_GT(legal, 0);
  EXPECT_LT(legal, designs);
  EXPECT_GE(estimate_disagrees, 10);
  std::printf(
      "%d designs, %d legal by the scan; the estimate's verdict differs on %d; estimate - scan: "
      "mean %.4f, min %.4f, largest |.| %.4f\n",
      designs, legal, estimate_disagrees, sum_error / designs, min_error, worst_error);
  RecordProperty("estimate_disagrees", estimate_disagrees);
}

// THE BBCOR at one fixed location (m from the tip) of `bat`: a one-point scan.
double BbcorAtFromTip(const Bat& bat, double from_tip_m) {
  BbcorProtocol p;
  p.scan_first_from_tip_m = p.scan_last_from_tip_m = from_tip_m;
  const BatModes modes = ComputeBatModes(bat, FlexibleOptions{}.ImpactModes());
  const BbcorScan s = ComputeBbcorScan(bat, modes, p, FlexibleOptions{}.impact);
  EXPECT_TRUE(s.ok) << s.message;
  return s.ok ? s.points.front().value : std::nan("");
}

// The gradient the optimiser does NOT have (docs/optimization.md, "BBCOR"), measured: the
// envelope theorem says d/dθ max_x B(x, θ) = ∂B/∂θ at the arg-max x* (the max is interior and
// smooth here). Checked by central differences, wall and alloy density of the aluminium preset:
// the total derivative of THE BBCOR (the polished maximum, re-located at every step) against
// the partial at the fixed x*. Their agreement is limited by the polish's stopping rule (the
// vertex within 0.002 in: ~5e-8 of BBCOR, / 2h) and the impacts' tolerance (1e-8): 3 % holds
// both (measured: equal in the wall, where the maximum stays on the 6.0 in grid point; 0.3 %
// apart in the density). The estimate's gradient (the NLP's) beside them: not the same slope.
TEST(BbcorVerdict, EnvelopeTheoremGradientAgainstFiniteDifferencesAndTheEstimates) {
  const Bat base = FindPreset("bbcor-33-aluminium")->bat;
  BbcorScan scan;
  const BbcorResult c =
      ComputeCertifiedBbcor(base, FlexibleOptions{}, BarrelOptions{}, nullptr, nullptr, &scan);
  ASSERT_TRUE(c.ok) << c.message;
  const double at = c.impact_from_tip_m;
  struct Direction {
    const char* name;
    double step;
    void (*apply)(Bat*, double);
  };
  const Direction directions[] = {
      {"wall_thickness_m", 1e-5, [](Bat* b, double d) { b->wall_thickness_m += d; }},
      {"material.density_kg_m3", 20.0,
       [](Bat* b, double d) {
         b->material.density_kg_m3 += d;
         b->material.name = "custom";
       }},
  };
  for (const Direction& d : directions) {
    Bat plus = base, minus = base;
    d.apply(&plus, d.step);
    d.apply(&minus, -d.step);
    const double total =
        (ComputeCertifiedBbcor(plus).value - ComputeCertifiedBbcor(minus).value) / (2 * d.step);
    const double envelope = (BbcorAtFromTip(plus, at) - BbcorAtFromTip(minus, at)) / (2 * d.step);
    const double estimate = (ComputeBbcor(plus).value - ComputeBbcor(minus).value) / (2 * d.step);
    EXPECT_NEAR(envelope, total, 0.03 * std::abs(total)) << d.name;
    // Measured: the estimate's slope is 1.28x the scan's in the wall (-18.2 against -14.2 per
    // m) and of the OPPOSITE sign in the density (+2.9e-7 against -5.5e-6 per kg/m^3: a
    // heavier bat raises the rigid pivoted estimate's effective mass, while the flexible free
    // bat's maximum falls). Pinned loosely (10 %) so that a change of either model is seen.
    if (std::string(d.name) == "wall_thickness_m") {
      EXPECT_NEAR(estimate / envelope, 1.28, 0.13) << d.name;
    } else {
      EXPECT_LT(estimate * envelope, 0.0) << d.name;
    }
    std::printf(
        "d BBCOR / d %s: total (max re-located) %.6g, envelope (at x* = %.4f in) %.6g, "
        "estimate's %.6g (ratio %.3f)\n",
        d.name, total, at / kInch, envelope, estimate, estimate / envelope);
  }
}

}  // namespace
}  // namespace bbcor_verdict_test
}  // namespace sweetspot::core
