// Refusals as data (core/refusal.hpp): each validator's Validate names core's field, the value
// and the rule, and its Message() is the "field = value: rule" text users see.
#include "core/refusal.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/bat/bat.hpp"
#include "core/bat/material.hpp"
#include "core/collision/hertz_contact.hpp"
#include "core/explore/sampling.hpp"
#include "core/geometry_format.hpp"
#include "core/optimize/design_model.hpp"
#include "core/optimize/design_problem.hpp"
#include "core/scene/evaluate_scene.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::core {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace refusal_test {
namespace {

// A valid hollow bat: two knots of radius 0.0125 and 0.033 m, ash, a wall of 3 mm.
Bat HollowBat() {
  Bat bat;
  bat.knots = {{0.0, 0.0125}, {0.86, 0.033}};
  bat.material = *FindMaterial("ash");
  bat.wall_thickness_m = 0.003;
  return bat;
}

// Validate's refusal (and the same verdict without one).
template <typename T>
Refusal RefusalOf(const T& value) {
  Refusal refusal;
  EXPECT_FALSE(value.Validate(&refusal));
  EXPECT_FALSE(value.Validate(nullptr));
  return refusal;
}

TEST(RefusalTest, ABatRefusalNamesFieldValueAndRule) {
  Bat bat = HollowBat();
  ASSERT_TRUE(bat.Validate(nullptr));
  bat.wall_thickness_m = -0.001;
  const Refusal r = RefusalOf(bat);
  EXPECT_EQ(r.field, "wall_thickness_m");
  EXPECT_EQ(r.value, -0.001);
  EXPECT_EQ(r.shown, "-0.001");
  EXPECT_EQ(r.rule, "must be non-negative (0 = solid)");
  EXPECT_EQ(r.Message(), "wall_thickness_m = -0.001: must be non-negative (0 = solid)");
}

TEST(RefusalTest, NestedFieldsKeepTheirPath) {
  Bat bat = HollowBat();
  bat.material.density_kg_m3 = -5.0;
  Refusal r = RefusalOf(bat);
  EXPECT_EQ(r.field, "material.density_kg_m3");
  EXPECT_EQ(r.value, -5.0);
  EXPECT_EQ(r.rule, "must be positive");

  bat = HollowBat();
  bat.knots[1].x_m = 0.0;
  r = RefusalOf(bat);
  EXPECT_EQ(r.field, "knots[1].x_m");
  EXPECT_EQ(r.rule, "must be greater than knots[0].x_m = 0");

  ThreeSegmentShape shape{0.86, 0.0125, 0.033, 0.6, 0.5};
  r = RefusalOf(shape);
  EXPECT_EQ(r.field, "taper_start_m");
  EXPECT_EQ(r.value, 0.6);
  EXPECT_EQ(r.rule, "must not exceed taper_end_m = 0.5");
}

TEST(RefusalTest, SceneRefusalsKeepTheirNumberFormats) {
  Scene scene;
  scene.bat = HollowBat();
  scene.ball.speed_mps = -0.1;  // written with 17 significant digits, as before
  Refusal r = RefusalOf(scene);
  EXPECT_EQ(r.field, "ball.speed_mps");
  EXPECT_EQ(r.value, -0.1);
  EXPECT_EQ(r.Message(), "ball.speed_mps = -0.10000000000000001: must be in [0, 1000]");

  scene = Scene{};
  r = RefusalOf(scene);  // no bat: a refusal that quotes no value
  EXPECT_EQ(r.field, "bat");
  EXPECT_FALSE(r.QuotesValue());
  EXPECT_TRUE(std::isnan(r.value));
  EXPECT_EQ(r.Message(), "bat: missing (give a bat or precomputed mass_properties)");

  SceneOptions options;
  options.flexible.max_elements = 1;  // integers are written as integers
  r = RefusalOf(options);
  EXPECT_EQ(r.field, "flexible.max_elements");
  EXPECT_EQ(r.value, 1.0);
  EXPECT_EQ(r.Message(), "flexible.max_elements = 1: must be in [2, 4096]");
}

TEST(RefusalTest, SamplingAndDesignOptions) {
  Shard shard{3, 2};
  Refusal r = RefusalOf(shard);
  EXPECT_EQ(r.field, "shard.index");
  EXPECT_EQ(r.value, 3.0);
  EXPECT_EQ(r.rule, "must be below shard.count = 2");

  DesignOptions options;
  options.max_variables = 0;
  r = RefusalOf(options);
  EXPECT_EQ(r.field, "max_variables");
  EXPECT_EQ(r.Message(), "max_variables = 0: must be >= 1");
  options = DesignOptions{};
  EXPECT_EQ(options.max_variables, 1000);
  options.backend = DesignBackend::kNloptCobyla;
  options.derivative_check = DerivativeCheck::kFirstOrder;
  r = RefusalOf(options);
  EXPECT_EQ(r.field, "derivative_check");
  EXPECT_EQ(r.Message(), "derivative_check: Ipopt's checker needs backend = ipopt");
}

TEST(RefusalTest, TheDesignModelEnforcesTheConfiguredVariableCap) {
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.86, 0.0125, 0.033, 0.30, 0.55};
  p.bat.material = *FindMaterial("ash");
  p.variables = {{"three_segment.length_m", 0.84, 0.88},
                 {"three_segment.handle_radius_m", 0.011, 0.014},
                 {"three_segment.barrel_radius_m", 0.030, 0.034},
                 {"three_segment.taper_start_m", 0.2, 0.4}};
  p.swing.pivot_from_knob_m = 0.1;
  p.objective = DesignObjective::kMinMoi;
  DesignModel model;
  Refusal why;
  ASSERT_TRUE(DesignModel::Build(p, DesignOptions{}, &model, &why)) << why.Message();
  DesignOptions three;
  three.max_variables = 3;
  EXPECT_FALSE(DesignModel::Build(p, three, &model, &why));
  EXPECT_EQ(why.Message(), "variables.size() = 4: must be between 1 and 3");
}

TEST(RefusalTest, TheDesignModelHandsOverItsRefusalAsData) {
  DesignProblem p;
  p.three_segment = ThreeSegmentShape{0.86, 0.0125, 0.033, 0.30, 0.55};
  p.bat.material = *FindMaterial("ash");
  p.variables = {{"three_segment.length_m", 0.84, 0.88}, {"three_segment.length_m", 0.84, 0.88}};
  p.swing.pivot_from_knob_m = 0.1;
  p.objective = DesignObjective::kMinMoi;
  Refusal refusal;
  ASSERT_FALSE(p.Validate(&refusal));
  // A value that is no number is quoted as written.
  EXPECT_EQ(refusal.field, "variables[1].path");
  EXPECT_EQ(refusal.shown, "three_segment.length_m");
  EXPECT_TRUE(std::isnan(refusal.value));
  EXPECT_EQ(refusal.rule, "appears more than once");
  // A nested check (the ball's) keeps its own field.
  p.variables.pop_back();
  p.ball.mass_kg = 0.0;
  ASSERT_FALSE(p.Validate(&refusal));
  EXPECT_EQ(refusal.field, "ball.mass_kg");
  EXPECT_EQ(refusal.value, 0.0);
}

TEST(RefusalTest, SummariesCarryTheRefusalTheirMessageStates) {
  // Refused for an option nested in the scene's options (nlopt), then for the scene itself.
  SceneOptions options;
  options.nlopt.max_evaluations = 5;
  const Summary by_options = EvaluateScene(Scene{}, options).summary;
  EXPECT_EQ(by_options.termination, Termination::kInvalidInput);
  ASSERT_TRUE(by_options.refusal.has_value());
  EXPECT_EQ(by_options.refusal->field, "nlopt.max_evaluations");
  EXPECT_EQ(by_options.refusal->value, 5.0);
  EXPECT_EQ(by_options.message, "nlopt.max_evaluations = 5: must be >= 10");
  EXPECT_EQ(by_options.message, by_options.refusal->Message());

  const Summary by_scene = EvaluateScene(Scene{}, SceneOptions{}).summary;
  EXPECT_EQ(by_scene.termination, Termination::kInvalidInput);
  ASSERT_TRUE(by_scene.refusal.has_value());
  EXPECT_EQ(by_scene.refusal->field, "bat");
  EXPECT_EQ(by_scene.message, by_scene.refusal->Message());

  // A converged solve carries none.
  Summary done;
  done.termination = Termination::kConverged;
  EXPECT_FALSE(done.refusal.has_value());
  done.SetRefusal(TextRefusal("cor", "not given"));
  EXPECT_EQ(done.termination, Termination::kInvalidInput);
  EXPECT_EQ(done.message, "cor: not given");
}

TEST(RefusalTest, TheContactOptionsOwnTheRangesARequestGets) {
  // The ranges the api checked before (now only core does): the paper's constants in
  // [0, 1e20] (K1 > 0) whatever the law, the hands' stiffness and damping finite, >= 0 and at
  // most 1e12.
  HertzOptions h;
  Refusal refusal;
  EXPECT_TRUE(h.Validate(&refusal));
  h.paper.k3 = -1.0;
  ASSERT_FALSE(h.Validate(&refusal));
  EXPECT_EQ(refusal.field, "hertz.paper.k3");
  EXPECT_EQ(refusal.Message(), "hertz.paper.k3 = -1: must be in [0, 1e20]");
  h.paper.k3 = 2e20;
  EXPECT_FALSE(h.Validate(nullptr));
  h.paper.k3 = 1e20;
  EXPECT_TRUE(h.Validate(nullptr));
  h.paper.k1 = 0.0;
  ASSERT_FALSE(h.Validate(&refusal));
  EXPECT_EQ(refusal.field, "hertz.paper.k1");
  h = HertzOptions{};
  h.hands_stiffness_n_m = 1e12;  // the bound itself is accepted
  EXPECT_TRUE(h.Validate(nullptr));
  h.hands_damping_n_s_m = 2e12;
  ASSERT_FALSE(h.Validate(&refusal));
  EXPECT_EQ(refusal.Message(), "hertz.hands_damping_n_s_m = 2000000000000: must be at most 1e12");
}

TEST(RefusalTest, NotedAppendsToTheRule) {
  const Refusal r = Noted(NumberRefusal("bat.length_m", 0.1, "too short"), " (model = flexible)");
  EXPECT_EQ(r.field, "bat.length_m");
  EXPECT_EQ(r.Message(), "bat.length_m = 0.1: too short (model = flexible)");
  EXPECT_EQ(QuotedRefusal("objective", "min_sting", "r").Message(), "objective = min_sting: r");
}

TEST(RefusalTest, RefusalMessageIsNumberRefusalsMessage) {
  EXPECT_EQ(RefusalMessage("knots.size()", 1.0, "must be at least 2"),
            NumberRefusal("knots.size()", 1.0, "must be at least 2").Message());
  EXPECT_EQ(Prefixed("fill.", NumberRefusal("depth_m", 2.0, "r")).Message(), "fill.depth_m = 2: r");
}

TEST(RefusalTest, RangesAreWrittenFromTheirBounds) {
  EXPECT_EQ(RangeRule(0.0, 100.0), "must be in [0, 100]");
  EXPECT_EQ(RangeRule(0.0, 1e5, /*lo_open=*/true), "must be in (0, 1e+05]");
  Refusal r;
  EXPECT_TRUE(CheckInRange(&r, "x_m", 100.0, 0.0, 100.0));  // the bounds themselves pass
  EXPECT_TRUE(CheckInRange(&r, "x_m", 0.0, 0.0, 100.0));
  EXPECT_FALSE(CheckInRange(&r, "x_m", 0.0, 0.0, 100.0, /*lo_open=*/true));
  EXPECT_EQ(r.Message(), "x_m = 0: must be in (0, 100]");
  EXPECT_FALSE(CheckInRange(&r, "wall_m", 11.0, 0.0, 10.0, false, " (0 = solid)"));
  EXPECT_EQ(r.Message(), "wall_m = 11: must be in [0, 10] (0 = solid)");
  EXPECT_EQ(r.value, 11.0);
  EXPECT_FALSE(CheckInRange(nullptr, "x_m", std::nan(""), -1.0, 1.0));  // NaN is refused
  EXPECT_FALSE(CheckIntegerInRange(&r, "modes", 21, 1, 20));
  EXPECT_EQ(r.Message(), "modes = 21: must be in [1, 20]");
  EXPECT_TRUE(CheckIntegerInRange(&r, "modes", 20, 1, 20));
}

}  // namespace
}  // namespace refusal_test
}  // namespace sweetspot::core
