// /v1/sweet-spot, /v1/collision, /v1/compare and /v1/bat/fit through the
// router: contract names, the paper's numbers, models_used, and refusals.
#include <gtest/gtest.h>

#include <cmath>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace scene_endpoints_test {
namespace {

Response Post(const std::string& path, const std::string& body) {
  return Dispatch({"POST", path, body}, Context{});
}

// paper-notes.md §3 closed form: x* = wJ / (m (u + S)), S = sqrt(u² + w²J/m).
double ClosedFormSweetSpot(double j, double m, double u, double w) {
  const double s = std::sqrt(u * u + w * w * j / m);
  return w * j / (m * (u + s));
}

TEST(SweetSpotEndpointTest, PaperClaimsWithSlenderRodAndPivotAtKnob) {
  // paper-notes.md: 0.724 m for the M = 1.008 bat and 0.648 m for M = 0.885,
  // |v1| = 27.7, w = 17.288, m = 0.145, e = 0.5, pivot at the knob, slender rod.
  for (const auto& [preset, expected] :
       {std::pair{"paper-wood", 0.724}, std::pair{"paper-wood-m885", 0.648}}) {
    const Response r = Post("/v1/sweet-spot", std::string(R"({"bat": {"preset": ")") + preset +
                                                  R"("}, "inertia_model": "slender_rod"})");
    ASSERT_EQ(r.status, 200) << r.body.dump();
    // The notes round to the millimetre.
    EXPECT_NEAR(r.body["max_exit_speed"]["position_from_knob_m"].get<double>(), expected, 5e-4)
        << preset;
    const double j = r.body["properties"]["moi_knob_kg_m2"];
    EXPECT_NEAR(r.body["max_exit_speed"]["position_from_knob_m"].get<double>(),
                ClosedFormSweetSpot(j, 0.145, 27.7, 17.288), 1e-12);
  }
}

TEST(SweetSpotEndpointTest, OnlyTheNeededModelsRunAndAreListed) {
  const Response cop = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["center_of_percussion"]})");
  ASSERT_EQ(cop.status, 200) << cop.body.dump();
  EXPECT_EQ(cop.body["models_used"], nlohmann::json::array({"mass_properties"}));
  EXPECT_FALSE(cop.body.contains("max_exit_speed"));
  EXPECT_TRUE(cop.body["exit_speed_model"].is_null());
  const Response all = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["max_exit_speed", "sweet_zone", "exit_speed_curve"],
      "options": {"curve_samples": 5, "sweet_zone_tolerance_percent": 5}})");
  ASSERT_EQ(all.status, 200) << all.body.dump();
  EXPECT_EQ(all.body["models_used"], nlohmann::json::array({"mass_properties", "rigid_pivot"}));
  EXPECT_EQ(all.body["exit_speed_curve"].size(), 5u);
  EXPECT_EQ(all.body["exit_speed_curve"][4]["position_from_knob_m"], 0.855);
  const double max = all.body["max_exit_speed"]["exit_speed_mps"];
  EXPECT_NEAR(all.body["sweet_zone"]["tolerance_mps"].get<double>(), 0.05 * max, 1e-12);
  EXPECT_LE(all.body["sweet_zone"]["from_knob_m"].get<double>(),
            all.body["max_exit_speed"]["position_from_knob_m"].get<double>());
  EXPECT_TRUE(all.body["error_estimate"]["max_exit_speed"]["position_m"].is_number());
  EXPECT_TRUE(all.body["timing_s"].is_number());
  EXPECT_EQ(all.body["provenance"]["input_hash"].get<std::string>().rfind("fnv1a64:", 0), 0u);
}

TEST(SweetSpotEndpointTest, NloptPathAgreesWithClosedForm) {
  const Response closed = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}})");
  const Response nlopt = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "options": {"method": "nlopt", "nlopt": {"algorithm": "LN_BOBYQA", "seed": 7}}})");
  ASSERT_EQ(nlopt.status, 200) << nlopt.body.dump();
  // Core's tests bound the two paths to 1e-9 relative; the speed is flat at the optimum.
  EXPECT_NEAR(nlopt.body["max_exit_speed"]["exit_speed_mps"].get<double>(),
              closed.body["max_exit_speed"]["exit_speed_mps"].get<double>(), 1e-9 * 25);
  EXPECT_EQ(nlopt.body["max_exit_speed"]["method"], "nlopt:LN_BOBYQA");
  EXPECT_EQ(nlopt.body["provenance"]["seed"], 7);
}

TEST(SweetSpotEndpointTest, SameInputSameHash) {
  const std::string body = R"({"bat": {"preset": "paper-wood"}, "cor": 0.5})";
  const std::string reordered = R"({"cor": 0.5, "bat": {"preset": "paper-wood"}})";
  EXPECT_EQ(Post("/v1/sweet-spot", body).body["provenance"]["input_hash"],
            Post("/v1/sweet-spot", reordered).body["provenance"]["input_hash"]);
}

TEST(SweetSpotEndpointTest, VibrationNodeHasPositionAndFrequency) {
  const Response r =
      Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}, "outputs": ["vibration_node"]})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_TRUE(r.body.contains("vibration_node")) << r.body.dump();
  const double node = r.body["vibration_node"]["position_from_knob_m"];
  EXPECT_GT(node, 0.5 * 0.855);  // the barrel-side node
  EXPECT_LT(node, 0.855);
  EXPECT_GT(r.body["vibration_node"]["frequency_hz"].get<double>(), 0.0);
  EXPECT_EQ(r.body["models_used"], nlohmann::json::array({"mass_properties", "flexible_beam"}));
}

TEST(SweetSpotEndpointTest, OutputsWithoutAnImpactNeedNoCor) {
  // paper-wood's shape and material numbers as a custom material: it has no default COR.
  const std::string custom_bat = R"({"preset": "paper-wood", "material": {"density_kg_m3": 649, )"
                                 R"("youngs_modulus_pa": 1.814e10, "poissons_ratio": 0.25}})";
  const Response r = Post("/v1/sweet-spot", R"({"bat": )" + custom_bat +
                                                R"(, "outputs": ["center_of_percussion", )"
                                                R"("vibration_node"]})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  // No output used a COR: none is reported.
  EXPECT_FALSE(r.body.contains("cor")) << r.body.dump();
  EXPECT_FALSE(r.body.contains("cor_source")) << r.body.dump();
  // The preset's own material (COR 0.5) gives the same positions to the bit: neither output
  // depends on the COR and every other input is identical.
  const Response wood = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["center_of_percussion", "vibration_node"]})");
  ASSERT_EQ(wood.status, 200) << wood.body.dump();
  EXPECT_EQ(r.body["center_of_percussion"]["position_from_knob_m"],
            wood.body["center_of_percussion"]["position_from_knob_m"]);
  EXPECT_EQ(r.body["vibration_node"]["position_from_knob_m"],
            wood.body["vibration_node"]["position_from_knob_m"]);
  EXPECT_EQ(r.body["vibration_node"]["frequency_hz"], wood.body["vibration_node"]["frequency_hz"]);
  // The COP of this bat lies on the barrel, between the balance point and the tip (0.855 m).
  const double cop = r.body["center_of_percussion"]["position_from_knob_m"];
  EXPECT_GT(cop, r.body["properties"]["balance_point_m"].get<double>());
  EXPECT_LT(cop, 0.855);
  // Where a COR is used, it is reported with its source.
  EXPECT_EQ(Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}})").body["cor_source"],
            "material:paper-wood");
  // An exit-speed output still needs a COR: the same refusal as before.
  const Response refused = Post("/v1/sweet-spot", R"({"bat": )" + custom_bat +
                                                      R"(, "outputs": ["center_of_percussion", )"
                                                      R"("max_exit_speed"]})");
  EXPECT_EQ(refused.status, 400) << refused.body.dump();
  EXPECT_EQ(refused.body["code"], "InvalidValue");
  EXPECT_EQ(refused.body["message"], "cor: not given, and material 'custom' has no default COR");
}

// The calls of `model` in a response's timings (0 when it did not run).
int CallsOf(const nlohmann::json& body, const std::string& model) {
  for (const auto& t : body["timings"]) {
    if (t["model"] == model) return t["calls"].get<int>();
  }
  return 0;
}

TEST(SweetSpotEndpointTest, MassPropertiesAreComputedOncePerRequest) {
  // The api no longer computes them as a guard (ParseBat did, under both inertia models):
  // core's single computation is the only one, and it is what the timings count.
  for (const char* body :
       {R"({"bat": {"preset": "paper-wood"}})",
        R"({"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed", "sweet_zone",
            "exit_speed_curve", "center_of_percussion"], "inertia_model": "slender_rod"})"}) {
    const Response r = Post("/v1/sweet-spot", body);
    ASSERT_EQ(r.status, 200) << r.body.dump();
    EXPECT_EQ(CallsOf(r.body, "mass_properties"), 1) << body;
  }
  // A bat too small to compute with is still a 400 on the bat (fuzz/regressions/parse_bat/),
  // found on that one computation's result.
  const Response tiny = Post("/v1/sweet-spot", R"({"bat": {"profile": {"knots": [
      {"x_m": 0, "radius_m": 1e-200}, {"x_m": 1e-200, "radius_m": 1e-200}]}, "material": "ash"}})");
  EXPECT_EQ(tiny.status, 400) << tiny.body.dump();
  EXPECT_EQ(tiny.body["code"], "InvalidValue");
  EXPECT_EQ(tiny.body["field"], "bat");
  EXPECT_EQ(tiny.body["message"],
            "bat is too small or too light to compute with: its mass or moment of inertia is not "
            "a positive finite number (use SI units: metres, kg/m3)");
}

TEST(SweetSpotEndpointTest, RefusalsNameTheField) {
  struct Case {
    const char* body;
    const char* field;
    const char* message_start;
  };
  const Case cases[] = {
      {R"({"bat": {"preset": "paper-wood"}, "outputs": ["best"]})", "outputs",
       "outputs = [\"best\"]: outputs[0] = \"best\" is not one of"},
      {R"({"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0}})", "ball.mass_kg",
       "ball.mass_kg = 0: must be in [1e-06, 1000]"},
      // Ranges are core's; its names are mapped back to the request's.
      {R"({"bat": {"preset": "paper-wood"}, "ball": {"stiffness_n_m_p": 1e20}})",
       "ball.stiffness_n_m_p", "ball.stiffness_n_m_p = 1e+20: must be in (0, 1e+15]"},
      {R"({"bat": {"preset": "paper-wood"}, "swing": {"pivot_from_knob_m": -101}})",
       "swing.pivot_from_knob_m", "swing.pivot_from_knob_m = -101: must be in [-100, 100]"},
      {R"({"bat": {"preset": "paper-wood"}, "options": {"sweet_zone_tolerance_percent": 150}})",
       "options.sweet_zone_tolerance_percent",
       "options.sweet_zone_tolerance_percent = 150: must be in [0, 100]"},
      {R"({"bat": {"preset": "paper-wood"},
           "options": {"flexible": {"mode_frequency_tolerance": 0.5}}})",
       "options.flexible.mode_frequency_tolerance",
       "options.flexible.mode_frequency_tolerance = 0.5: must be in [1e-9, 0.1]"},
      {R"({"bat": {"preset": "paper-wood"}, "options": {"flexible": {"max_modes": 2.5}}})",
       "options.flexible.max_modes", "options.flexible.max_modes = 2.5: must be an integer"},
      {R"({"bat": {"preset": "paper-wood"}, "ball": {"speed": 3}})", "ball.speed",
       "ball.speed is not a known field"},
      {R"({"bat": {"preset": "paper-wood"}, "cor": 1.5})", "cor", "cor = 1.5: must be in [0, 1]"},
      {R"({"bat": {"preset": "paper-wood"}, "swing": {"angular_speed_rad_s": -1}})",
       "swing.angular_speed_rad_s", "swing.angular_speed_rad_s = -1"},
      {R"({"bat": {"preset": "paper-wood"}, "options": {"nlopt": {"algorithm": "LN_NEWUOA"}}})",
       "options.nlopt.algorithm", "options.nlopt.algorithm = \"LN_NEWUOA\": must be one of"},
      {R"({"bat": {"preset": "paper-wood"}, "options": {"curve_samples": 1}})",
       "options.curve_samples", "options.curve_samples = 1: must be an integer in [2, 10000]"},
  };
  for (const Case& c : cases) {
    const Response r = Post("/v1/sweet-spot", c.body);
    EXPECT_EQ(r.status, 400) << c.body;
    EXPECT_EQ(r.body["field"], c.field) << r.body.dump();
    EXPECT_EQ(r.body["message"].get<std::string>().rfind(c.message_start, 0), 0u) << r.body.dump();
  }
}

TEST(CollisionEndpointTest, RigidPivotMatchesTheClosedForm) {
  const Response r = Post("/v1/collision", R"({"bat": {"preset": "paper-wood"},
      "impact_from_knob_m": 0.7, "model": "rigid_pivot", "inertia_model": "slender_rod"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Response p = Post("/v1/bat/properties",
                          R"({"bat": {"preset": "paper-wood"}, "inertia_model": "slender_rod"})");
  const double j = p.body["moi_knob_kg_m2"], m = 0.145, u = 27.7, w = 17.288, x = 0.7, e = 0.5;
  // paper-notes.md §3: v2 = -u + J (1+e)(u + w x) / (J + m x²); a few ulps apart.
  EXPECT_NEAR(r.body["exit_speed_mps"].get<double>(),
              -u + j * (1 + e) * (u + w * x) / (j + m * x * x), 1e-12);
  EXPECT_EQ(r.body["model"], "rigid_pivot");
  EXPECT_TRUE(r.body["rigid_pivot"]["pivot_impulse_n_s"].is_number());
}

TEST(CollisionEndpointTest, HertzDefaultIsARealisticContact) {
  const Response r = Post("/v1/collision", R"({"bat": {"preset": "paper-wood"},
      "impact_from_knob_m": 0.7, "model": "hertz"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const double t = r.body["hertz"]["contact_time_s"];
  EXPECT_GT(t, 0.5e-3);  // a real baseball: 0.5-1 ms (issue 4)
  EXPECT_LT(t, 1.0e-3);
  EXPECT_EQ(r.body["hertz"]["parameters"]["law"], "ball_power_law");
  EXPECT_TRUE(r.body["hertz"]["peak_force_n"].is_number());
}

TEST(CollisionEndpointTest, AutoWithContactDetailsPicksHertz) {
  const Response r = Post("/v1/collision", R"({"bat": {"preset": "paper-wood"},
      "impact_from_knob_m": 0.7, "contact_details": true})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["model"], "hertz");
  EXPECT_FALSE(r.body["model_reason"].get<std::string>().empty());
}

TEST(CollisionEndpointTest, ImpactOffTheBatIsRefusedAndFlexibleRuns) {
  const Response off =
      Post("/v1/collision", R"({"bat": {"preset": "paper-wood"}, "impact_from_knob_m": 0.9})");
  EXPECT_EQ(off.status, 400);
  // The range is core's (Collide): the api reads the number, core refuses it by name.
  EXPECT_EQ(off.body["code"], "InvalidValue");
  EXPECT_EQ(off.body["field"], "impact_from_knob_m");
  EXPECT_EQ(off.body["message"],
            "impact_from_knob_m = 0.90000000000000002: must be within the bat [0, "
            "0.85499999999999998]");
  const Response behind =
      Post("/v1/collision", R"({"bat": {"preset": "paper-wood"}, "impact_from_knob_m": -0.1})");
  EXPECT_EQ(behind.status, 400);
  EXPECT_EQ(behind.body["field"], "impact_from_knob_m");
  const Response flexible = Post("/v1/collision", R"({"bat": {"preset": "paper-wood"},
      "impact_from_knob_m": 0.7, "model": "flexible"})");
  ASSERT_EQ(flexible.status, 200) << flexible.body.dump();
  EXPECT_EQ(flexible.body["model"], "flexible");
  EXPECT_TRUE(flexible.body["flexible"]["hands"]["vibration_energy_j"].is_number());
}

TEST(CompareEndpointTest, CorkLowersTheMassAndSweetSpotSpeed) {
  const Response r = Post("/v1/compare", R"({"baseline": {"preset": "paper-wood"},
      "variants": [
        {"name": "cork-320", "bat": {"preset": "paper-wood", "fill": {"material": {
           "density_kg_m3": 320, "youngs_modulus_pa": 2e7}, "diameter_m": 0.0254, "depth_m": 0.254}}},
        {"name": "cork-260", "bat": {"preset": "paper-wood", "fill": {"material": {
           "density_kg_m3": 260, "youngs_modulus_pa": 2e7}, "diameter_m": 0.0254, "depth_m": 0.254}}}],
      "inertia_model": "slender_rod"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 3u);
  EXPECT_EQ(r.body["rows"][0]["name"], "baseline");
  EXPECT_FALSE(r.body["rows"][0].contains("deltas"));
  // paper-notes.md Table 4: dM = -(rho - rho_s) V_s = -42.3 g / -50.1 g (to 0.1 g).
  EXPECT_NEAR(r.body["rows"][1]["deltas"]["mass_kg"].get<double>(), -0.0423, 1e-4);
  EXPECT_NEAR(r.body["rows"][2]["deltas"]["mass_kg"].get<double>(), -0.0501, 1e-4);
  // dJ_knob = -0.0227 / -0.0268 kg m² (slender rod, to 1e-4).
  EXPECT_NEAR(r.body["rows"][1]["deltas"]["moi_knob_kg_m2"].get<double>(), -0.0227, 1e-4);
  EXPECT_NEAR(r.body["rows"][2]["deltas"]["moi_knob_kg_m2"].get<double>(), -0.0268, 1e-4);
  EXPECT_LT(r.body["rows"][1]["deltas"]["max_exit_speed_mps"].get<double>(), 0.0);
}

TEST(SweetSpotEndpointTest, CoreRefusalsOfOptionsNameTheRequestField) {
  // Found by the hard-case suite: the field lacked its "options." prefix.
  const Response r = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["exit_speed_curve"], "options": {"curve_positions_from_knob_m": [-1e-300]}})");
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["field"], "options.curve_positions_from_knob_m[0]") << r.body.dump();
  // A scene field keeps its own name: hands beyond the balance point (0.6090 m)
  // leave no centre of percussion.
  const Response s = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["center_of_percussion"], "swing": {"hands_from_knob_m": 0.7}})");
  EXPECT_EQ(s.status, 400) << s.body.dump();
  EXPECT_EQ(s.body["field"], "swing.hands_from_knob_m") << s.body.dump();
}

TEST(SweetSpotEndpointTest, CoreChecksThePaperConstantsUnderTheRequestsNames) {
  // The range is core's (hertz.paper.k3); the request names the field paper_constants.k3.
  const Response r = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "options": {"hertz": {"paper_constants": {"k3": -1}}}})");
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["code"], "InvalidValue") << r.body.dump();
  EXPECT_EQ(r.body["field"], "options.hertz.paper_constants.k3") << r.body.dump();
  EXPECT_EQ(r.body["message"], "options.hertz.paper_constants.k3 = -1: must be in [0, 1e20]");
  // /v1/collision reads the contact options at the top level; core refuses them in Collide.
  const Response c = Post("/v1/collision", R"({"bat": {"preset": "paper-wood"},
      "impact_from_knob_m": 0.7, "model": "hertz", "hertz": {"paper_constants": {"k3": -1}}})");
  EXPECT_EQ(c.status, 400) << c.body.dump();
  EXPECT_EQ(c.body["field"], "hertz.paper_constants.k3") << c.body.dump();
  EXPECT_EQ(c.body["message"], "hertz.paper_constants.k3 = -1: must be in [0, 1e20]");
  // The integrator's tolerance likewise (core's ContactIntegrationValidate).
  const Response tol = Post("/v1/collision", R"({"bat": {"preset": "paper-wood"},
      "impact_from_knob_m": 0.7, "model": "hertz", "hertz": {"relative_tolerance": 1}})");
  EXPECT_EQ(tol.status, 400) << tol.body.dump();
  EXPECT_EQ(tol.body["field"], "hertz.relative_tolerance") << tol.body.dump();
  EXPECT_EQ(tol.body["message"], "hertz.relative_tolerance = 1: must be in [1e-13, 1e-2]");
  // A type error is still the api's.
  const Response t = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "options": {"hertz": {"paper_constants": {"k3": "big"}}}})");
  EXPECT_EQ(t.status, 400) << t.body.dump();
  EXPECT_EQ(t.body["field"], "options.hertz.paper_constants.k3") << t.body.dump();
}

TEST(CompareEndpointTest, TooManyVariantsIs413) {
  std::string variants;
  for (int i = 0; i < 65; ++i) {
    variants += (i ? "," : "") + std::string(R"({"name": "v", "bat": {"preset": "paper-wood"}})");
  }
  const Response r = Post(
      "/v1/compare", R"({"baseline": {"preset": "paper-wood"}, "variants": [)" + variants + "]}");
  EXPECT_EQ(r.status, 413);
  EXPECT_EQ(r.body["code"], "TooBig");
  EXPECT_EQ(r.body["field"], "variants");
}

TEST(FitEndpointTest, PaperTable2IsInfeasibleWithTheClosestBat) {
  const Response r = Post("/v1/bat/fit", R"({"bat": {"preset": "paper-wood"},
      "targets": {"mass_kg": 0.885, "balance_point_m": 0.564}})");
  ASSERT_EQ(r.status, 422) << r.body.dump();
  EXPECT_EQ(r.body["code"], "Infeasible");
  const auto& closest = r.body["closest"];
  // paper-notes.md: x1 = 0.1797, x2 = 0.855 (4 digits), M = 0.892, C = 0.583 (3 digits).
  EXPECT_NEAR(closest["bat"]["three_segment"]["taper_start_m"].get<double>(), 0.1797, 1e-4);
  EXPECT_NEAR(closest["bat"]["three_segment"]["taper_end_m"].get<double>(), 0.855, 1e-9);
  EXPECT_NEAR(closest["properties"]["mass_kg"].get<double>(), 0.892, 5e-4);
  EXPECT_NEAR(closest["properties"]["balance_point_m"].get<double>(), 0.583, 5e-4);
  EXPECT_EQ(closest["summary"]["termination"], "infeasible");
}

TEST(FitEndpointTest, AttainableTargetsConvergeAndTheBatRoundTrips) {
  const Response r = Post("/v1/bat/fit", R"({"bat": {"preset": "paper-wood"},
      "targets": {"mass_kg": 0.95, "balance_point_m": 0.60}})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  // Converged means every scaled residual <= 1e-9 (the default tolerance).
  EXPECT_LT(std::abs(r.body["residuals"]["mass_kg"].get<double>()), 1e-9 * 0.95);
  EXPECT_LT(std::abs(r.body["residuals"]["balance_point_m"].get<double>()), 1e-9 * 0.60);
  // The fitted bat, sent back to /v1/bat/properties, has the target properties.
  const Response again = Post("/v1/bat/properties", nlohmann::json{{"bat", r.body["bat"]}}.dump());
  ASSERT_EQ(again.status, 200) << again.body.dump();
  EXPECT_NEAR(again.body["mass_kg"].get<double>(), 0.95, 1e-8);
  EXPECT_NEAR(again.body["balance_point_m"].get<double>(), 0.60, 1e-8);
}

// The fit's ranges are core's (ShapeFitProblem / ShapeFitOptions validators); the api names
// the request's field, the value and core's rule.
TEST(FitEndpointTest, CoreRangesAreRefusedUnderTheRequestsField) {
  struct Case {
    const char* body;
    const char* field;
    const char* message;
  };
  const Case cases[] = {
      {R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 2e4}})", "targets.mass_kg",
       "targets.mass_kg = 20000: must be in [1e-06, 10000]"},
      {R"({"bat": {"preset": "paper-wood"}, "targets": {"balance_point_m": 150}})",
       "targets.balance_point_m", "targets.balance_point_m = 150: must be in [1e-06, 100]"},
      {R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.9},
           "unknowns": [{"name": "taper_start_m", "min": 0, "max": 2e5}]})",
       "unknowns[0].max", "unknowns[0].max = 2e+05: must be in [0, 1e+05]"},
      {R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.9},
           "options": {"mass_scale_kg": 2e4}})",
       "options.mass_scale_kg",
       "options.mass_scale_kg = 20000: must be in [0, 10000] (0 = the target)"},
      {R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.9},
           "options": {"balance_point_scale_m": 101}})",
       "options.balance_point_scale_m",
       "options.balance_point_scale_m = 101: must be in [0, 100] (0 = the target)"},
      {R"({"bat": {"preset": "paper-wood"}, "targets": {"mass_kg": 0.9},
           "options": {"tolerance": 0.5}})",
       "options.tolerance", "options.tolerance = 0.5: must be in [1e-15, 0.1]"},
  };
  for (const Case& c : cases) {
    const Response r = Post("/v1/bat/fit", c.body);
    EXPECT_EQ(r.status, 400) << c.body << " -> " << r.body.dump();
    EXPECT_EQ(r.body["code"], "InvalidValue") << c.body;
    EXPECT_EQ(r.body["field"], c.field) << r.body.dump();
    EXPECT_EQ(r.body["message"], c.message) << r.body.dump();
  }
}

TEST(FitEndpointTest, GeneralProfileIsRefused) {
  const Response r = Post("/v1/bat/fit", R"({"bat": {"profile": {"knots": [
      {"x_m": 0, "radius_m": 0.02}, {"x_m": 0.8, "radius_m": 0.03}]}},
      "targets": {"mass_kg": 0.9}})");
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "bat");
}

}  // namespace
}  // namespace scene_endpoints_test
}  // namespace sweetspot::api
