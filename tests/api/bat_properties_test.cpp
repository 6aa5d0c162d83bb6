// POST /v1/bat/properties through the router: the bat's three JSON forms, the
// numbers, and refusals that name the field, the value and the rule.
#include <gtest/gtest.h>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace bat_properties_test {
namespace {

Response Post(const std::string& path, const std::string& body) {
  return Dispatch({"POST", path, body}, Context{});
}

TEST(BatPropertiesTest, PaperWoodSlenderRodReproducesThePaperNotes) {
  const Response r = Post("/v1/bat/properties",
                          R"({"bat": {"preset": "paper-wood"}, "inertia_model": "slender_rod"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  // paper-notes.md gives 4 significant digits: 1e-4 relative covers the rounding.
  EXPECT_NEAR(r.body["mass_kg"].get<double>(), 1.0078, 1.0078 * 1e-4);
  EXPECT_NEAR(r.body["balance_point_m"].get<double>(), 0.6090, 0.6090 * 1e-4);
  EXPECT_NEAR(r.body["moi_knob_kg_m2"].get<double>(), 0.4122, 0.4122 * 1e-4);
  EXPECT_EQ(r.body["inertia_model"], "slender_rod");
  EXPECT_EQ(r.body["length_m"], 0.855);
  EXPECT_EQ(r.body["models_used"], nlohmann::json::array({"mass_properties"}));
  EXPECT_TRUE(r.body["timing_s"].is_number());
  EXPECT_FALSE(r.body.contains("moi_pivot_kg_m2"));
}

TEST(BatPropertiesTest, ThreeSegmentFormEqualsThePreset) {
  const Response preset = Post("/v1/bat/properties", R"({"bat": {"preset": "paper-wood"}})");
  const Response shape = Post("/v1/bat/properties", R"({"bat": {
      "three_segment": {"length_m": 0.855, "handle_radius_m": 0.0125, "barrel_radius_m": 0.035,
                        "taper_start_m": 0.3459, "taper_end_m": 0.6423},
      "material": {"density_kg_m3": 649, "youngs_modulus_pa": 1.814e10}}})");
  ASSERT_EQ(preset.status, 200);
  ASSERT_EQ(shape.status, 200) << shape.body.dump();
  for (const char* key : {"mass_kg", "balance_point_m", "moi_knob_kg_m2", "moi_six_inch_kg_m2",
                          "moi_centroid_kg_m2", "volume_m3"}) {
    // Same knots and density: identical arithmetic, so equal to rounding.
    EXPECT_NEAR(preset.body[key].get<double>(), shape.body[key].get<double>(),
                1e-14 * std::abs(preset.body[key].get<double>()))
        << key;
  }
}

TEST(BatPropertiesTest, PivotAddsMoiAboutThePivotByParallelAxes) {
  const Response r =
      Post("/v1/bat/properties", R"({"bat": {"preset": "paper-wood"}, "pivot_from_knob_m": -0.1})");
  ASSERT_EQ(r.status, 200);
  const double m = r.body["mass_kg"], c = r.body["balance_point_m"];
  const double icm = r.body["moi_centroid_kg_m2"];
  // Parallel axes, a sum of positive terms: equal to a few ulps.
  EXPECT_NEAR(r.body["moi_pivot_kg_m2"].get<double>(), icm + m * (c + 0.1) * (c + 0.1), 1e-12);
  EXPECT_EQ(r.body["pivot_from_knob_m"], -0.1);
}

TEST(BatPropertiesTest, ImperialBlockUsesInchesAndOunces) {
  const Response r = Post("/v1/bat/properties", R"({"bat": {"preset": "paper-wood"}})");
  ASSERT_EQ(r.status, 200);
  const auto& imperial = r.body["imperial"];
  EXPECT_NEAR(imperial["length_in"].get<double>(), 0.855 / 0.0254, 1e-12);
  EXPECT_NEAR(imperial["weight_oz"].get<double>(), r.body["mass_kg"].get<double>() / 0.028349523125,
              1e-12);
  EXPECT_NEAR(imperial["drop"].get<double>(),
              imperial["length_in"].get<double>() - imperial["weight_oz"].get<double>(), 1e-12);
}

TEST(BatPropertiesTest, ProfileFormAndOverridesBesideAPreset) {
  const Response cork = Post("/v1/bat/properties", R"({"bat": {"preset": "paper-wood",
      "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}}})");
  const Response plain = Post("/v1/bat/properties", R"({"bat": {"preset": "paper-wood"}})");
  ASSERT_EQ(cork.status, 200) << cork.body.dump();
  EXPECT_LT(cork.body["mass_kg"].get<double>(), plain.body["mass_kg"].get<double>());
  const Response profile = Post("/v1/bat/properties", R"({"bat": {"profile": {"knots": [
      {"x_m": 0, "radius_m": 0.02}, {"x_m": 1.0, "radius_m": 0.02}]}, "material": "ash"}})");
  ASSERT_EQ(profile.status, 200) << profile.body.dump();
  EXPECT_EQ(profile.body["length_m"], 1.0);
}

struct Refusal {
  const char* name;
  const char* body;
  int status;
  const char* code;
  const char* field;
  const char* message_start;
};

class BatRefusalTest : public ::testing::TestWithParam<Refusal> {};

TEST_P(BatRefusalTest, NamesFieldValueAndRule) {
  const Refusal& c = GetParam();
  const Response r = Post("/v1/bat/properties", c.body);
  EXPECT_EQ(r.status, c.status) << r.body.dump();
  EXPECT_EQ(r.body["code"], c.code) << r.body.dump();
  if (c.field == nullptr) {
    EXPECT_TRUE(r.body["field"].is_null()) << r.body.dump();
  } else {
    EXPECT_EQ(r.body["field"], c.field) << r.body.dump();
  }
  EXPECT_EQ(r.body["message"].get<std::string>().rfind(c.message_start, 0), 0u) << r.body.dump();
}

INSTANTIATE_TEST_SUITE_P(
    Cases, BatRefusalTest,
    ::testing::Values(
        Refusal{"missing_bat", "{}", 400, "MissingField", "bat", "bat is required"},
        Refusal{"not_object", "[1]", 400, "InvalidValue", nullptr,
                "body = [1]: must be a JSON object"},
        Refusal{"bad_json", "{\"bat\": ", 400, "InvalidJson", nullptr, "body is not valid JSON"},
        Refusal{"unknown_top", R"({"bat": {"preset": "paper-wood"}, "pivot": 1})", 400,
                "UnknownField", "pivot", "pivot is not a known field"},
        Refusal{"unknown_in_bat", R"({"bat": {"preset": "paper-wood", "colour": "red"}})", 400,
                "UnknownField", "bat.colour", "bat.colour is not a known field"},
        Refusal{"unknown_preset", R"({"bat": {"preset": "nope"}})", 400, "InvalidValue",
                "bat.preset", "bat.preset = \"nope\": is not a preset"},
        Refusal{"no_shape", R"({"bat": {"material": "ash"}})", 400, "MissingField", "bat",
                "bat needs a shape"},
        Refusal{"negative_length",
                R"({"bat": {"three_segment": {"length_m": -1, "handle_radius_m": 0.01,
                   "barrel_radius_m": 0.03, "taper_start_m": 0.2, "taper_end_m": 0.5}}})",
                400, "InvalidValue", "bat.three_segment.length_m",
                "bat.three_segment.length_m = -1: must be positive"},
        // The ranges are core's (Bat, ThreeSegmentShape, Material validators); the api names
        // the request's field, the value and core's rule.
        Refusal{"length_cap",
                R"({"bat": {"three_segment": {"length_m": 200, "handle_radius_m": 0.01,
                   "barrel_radius_m": 0.03, "taper_start_m": 0.2, "taper_end_m": 0.5}}})",
                400, "InvalidValue", "bat.three_segment.length_m",
                "bat.three_segment.length_m = 200: must be in (0, 100]"},
        Refusal{"radius_cap",
                R"({"bat": {"three_segment": {"length_m": 0.8, "handle_radius_m": 0.01,
                   "barrel_radius_m": 11, "taper_start_m": 0.2, "taper_end_m": 0.5}}})",
                400, "InvalidValue", "bat.three_segment.barrel_radius_m",
                "bat.three_segment.barrel_radius_m = 11: must be in (0, 10]"},
        Refusal{"negative_taper_start",
                R"({"bat": {"three_segment": {"length_m": 0.8, "handle_radius_m": 0.01,
                   "barrel_radius_m": 0.03, "taper_start_m": -0.1, "taper_end_m": 0.5}}})",
                400, "InvalidValue", "bat.three_segment.taper_start_m",
                "bat.three_segment.taper_start_m = -0.1: must be non-negative"},
        Refusal{"knot_position_cap",
                R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 0.02},
                   {"x_m": 150, "radius_m": 0.02}]}}})",
                400, "InvalidValue", "bat.profile.knots[1].x_m",
                "bat.profile.knots[1].x_m = 150: must be in [0, 100]"},
        Refusal{"knot_radius_cap",
                R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 0.02},
                   {"x_m": 0.8, "radius_m": 11}]}}})",
                400, "InvalidValue", "bat.profile.knots[1].radius_m",
                "bat.profile.knots[1].radius_m = 11: must be in (0, 10]"},
        // The wall is capped by the radii (it must be below the smallest).
        Refusal{"wall_cap", R"({"bat": {"preset": "paper-wood", "wall_thickness_m": 11}})", 400,
                "InvalidValue", "bat.wall_thickness_m",
                "bat.wall_thickness_m = 11: must be less than the smallest outer radius"},
        Refusal{"fill_diameter_cap", R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 10},
                   {"x_m": 0.8, "radius_m": 10}]}, "material": "ash",
                   "fill": {"material": "cork", "diameter_m": 15, "depth_m": 0.2}}})",
                400, "InvalidValue", "bat.fill.diameter_m",
                "bat.fill.diameter_m = 15: must be in [0, 10]"},
        Refusal{"fill_depth_cap", R"({"bat": {"preset": "paper-wood",
                   "fill": {"material": "cork", "diameter_m": 0.02, "depth_m": 101}}})",
                400, "InvalidValue", "bat.fill.depth_m",
                "bat.fill.depth_m = 101: must not exceed the bat's length"},
        Refusal{"density_cap", R"({"bat": {"preset": "paper-wood", "material":
                   {"density_kg_m3": 2e5, "youngs_modulus_pa": 1e10}}})",
                400, "InvalidValue", "bat.material.density_kg_m3",
                "bat.material.density_kg_m3 = 2e+05: must be in (0, 1e+05]"},
        Refusal{"youngs_modulus_cap", R"({"bat": {"preset": "paper-wood", "material":
                   {"density_kg_m3": 600, "youngs_modulus_pa": 2e13}}})",
                400, "InvalidValue", "bat.material.youngs_modulus_pa",
                "bat.material.youngs_modulus_pa = 2e+13: must be in (0, 1e+13]"},
        Refusal{"shear_modulus_cap", R"({"bat": {"preset": "paper-wood", "material":
                   {"density_kg_m3": 600, "youngs_modulus_pa": 1e10, "shear_modulus_pa": 2e13}}})",
                400, "InvalidValue", "bat.material.shear_modulus_pa",
                "bat.material.shear_modulus_pa = 2e+13: must be in [0, 1e+13]"},
        Refusal{"material_cor", R"({"bat": {"preset": "paper-wood", "material":
                   {"density_kg_m3": 600, "youngs_modulus_pa": 1e10, "cor": 1.5}}})",
                400, "InvalidValue", "bat.material.cor",
                "bat.material.cor = 1.5: must be between 0 and 1"},
        Refusal{"fill_material_density_cap", R"({"bat": {"preset": "paper-wood", "fill":
                   {"material": {"density_kg_m3": 2e5, "youngs_modulus_pa": 1e10},
                    "diameter_m": 0.02, "depth_m": 0.2}}})",
                400, "InvalidValue", "bat.fill.material.density_kg_m3",
                "bat.fill.material.density_kg_m3 = 2e+05: must be in (0, 1e+05]"},
        Refusal{"pivot_cap", R"({"bat": {"preset": "paper-wood"}, "pivot_from_knob_m": -150})", 400,
                "InvalidValue", "pivot_from_knob_m",
                "pivot_from_knob_m = -150: must be in [-100, 100]"},
        Refusal{"taper_order",
                R"({"bat": {"three_segment": {"length_m": 0.8, "handle_radius_m": 0.01,
                   "barrel_radius_m": 0.03, "taper_start_m": 0.6, "taper_end_m": 0.5}}})",
                400, "InvalidValue", "bat.three_segment.taper_start_m",
                "bat.three_segment.taper_start_m = 0.6"},
        Refusal{"knots_not_increasing",
                R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 0.02},
                   {"x_m": 0.5, "radius_m": 0.02}, {"x_m": 0.4, "radius_m": 0.03}]}}})",
                400, "InvalidValue", "bat.profile.knots[2].x_m", "bat.profile.knots[2].x_m = 0.4"},
        Refusal{"knot_string",
                R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": "wide"},
                   {"x_m": 0.5, "radius_m": 0.02}]}}})",
                400, "InvalidValue", "bat.profile.knots[0].radius_m",
                "bat.profile.knots[0].radius_m = \"wide\": must be a number"},
        Refusal{"one_knot", R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 0.02}]}}})",
                400, "InvalidValue", "bat.profile.knots", "bat.profile.knots = "},
        Refusal{"wall_too_thick", R"({"bat": {"preset": "paper-wood", "wall_thickness_m": 0.02}})",
                400, "InvalidValue", "bat.wall_thickness_m", "bat.wall_thickness_m = 0.02"},
        Refusal{"fill_too_deep", R"({"bat": {"preset": "paper-wood",
                   "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 2}}})",
                400, "InvalidValue", "bat.fill.depth_m", "bat.fill.depth_m = 2"},
        Refusal{"fill_too_wide", R"({"bat": {"preset": "paper-wood",
                   "fill": {"material": "cork", "diameter_m": 0.08, "depth_m": 0.2}}})",
                400, "InvalidValue", "bat.fill.diameter_m", "bat.fill.diameter_m = 0.08"},
        Refusal{"unknown_material", R"({"bat": {"preset": "paper-wood", "material": "oak"}})", 400,
                "InvalidValue", "bat.material",
                "bat.material = \"oak\": is not a catalogue material"},
        Refusal{"custom_material_incomplete",
                R"({"bat": {"preset": "paper-wood", "material": {"density_kg_m3": 600}}})", 400,
                "MissingField", "bat.material.youngs_modulus_pa",
                "bat.material.youngs_modulus_pa is required"},
        Refusal{"inertia_model", R"({"bat": {"preset": "paper-wood"}, "inertia_model": "disk"})",
                400, "InvalidValue", "inertia_model",
                "inertia_model = \"disk\": must be one of rigid_body, slender_rod"}),
    [](const ::testing::TestParamInfo<Refusal>& param_info) { return param_info.param.name; });

}  // namespace
}  // namespace bat_properties_test
}  // namespace sweetspot::api
