// The flexible beam through the API: HandleBatModes (called directly: its route is added by
// the router's owner), vibration_node and least_sting_zone in /v1/sweet-spot, model flexible
// in /v1/collision, the "flexible" options, and refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "api/handlers/modes.hpp"
#include "api/router.hpp"
#include "core/flexible/modes_cache.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace flexible_api_test {
namespace {

Response Post(const std::string& path, const std::string& body) {
  return Dispatch({"POST", path, body}, Context{});
}

Response Modes(const std::string& body, const Context& context = Context{}) {
  return HandleBatModes({"POST", "/v1/bat/modes", body}, context);
}

TEST(BatModesHandlerTest, DefaultsGiveFourTimoshenkoModesWithShapesAndNodes) {
  const Response r = Modes(R"({"bat": {"preset": "paper-wood"}})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["theory"], "timoshenko");
  EXPECT_EQ(r.body["boundary_conditions"], "free-free");
  ASSERT_EQ(r.body["frequencies_hz"].size(), 4u);
  ASSERT_EQ(r.body["modes"].size(), 4u);
  // paper-wood's fundamental (core tests pin it: 176.90 Hz, node 0.68905 m); 1e-4 relative is
  // the default tolerance.
  EXPECT_NEAR(r.body["frequencies_hz"][0].get<double>(), 176.90, 176.90 * 1e-4);
  double previous = 0.0;
  for (std::size_t k = 0; k < 4; ++k) {
    const auto& mode = r.body["modes"][k];
    EXPECT_EQ(mode["mode"], k + 1);
    EXPECT_GT(mode["frequency_hz"].get<double>(), previous);
    previous = mode["frequency_hz"].get<double>();
    EXPECT_EQ(mode["nodes_from_knob_m"].size(), k + 2);  // bending mode n has n + 1 nodes
    ASSERT_EQ(mode["shape"].size(), 41u);
    double peak = 0.0;
    for (const auto& p : mode["shape"])
      peak = std::max(peak, std::abs(p["displacement"].get<double>()));
    EXPECT_LE(peak, 1.0);
    EXPECT_GT(peak, 0.9);  // 41 samples catch the maximum to within 10 %
    EXPECT_GT(mode["shape"][40]["displacement"].get<double>(), 0.0);  // the tip moves positive
    EXPECT_LE(mode["error_estimate_hz"].get<double>(), 1e-4 * mode["frequency_hz"].get<double>());
  }
  EXPECT_NEAR(r.body["vibration_node"]["position_from_knob_m"].get<double>(), 0.68905, 1e-4);
  EXPECT_LE(r.body["error_estimate"]["frequency_relative"].get<double>(), 1e-4);
  EXPECT_EQ(r.body["summary"]["termination"], "converged");
  EXPECT_EQ(r.body["models_used"], nlohmann::json::array({"flexible_beam"}));
  EXPECT_GT(r.body["elements"].get<int>(), 8);
  EXPECT_TRUE(r.body.contains("timing_s"));
  EXPECT_FALSE(r.body["cache_hit"].get<bool>());
}

TEST(BatModesHandlerTest, OptionsAreReadStrictly) {
  const Response eb = Modes(R"({"bat": {"preset": "bbcor-33-aluminium"}, "theory":
      "euler_bernoulli", "modes": 2, "tolerance": 1e-3, "shape_samples": 3, "max_elements": 64})");
  ASSERT_EQ(eb.status, 200) << eb.body.dump();
  EXPECT_EQ(eb.body["theory"], "euler_bernoulli");
  EXPECT_EQ(eb.body["modes"].size(), 2u);
  EXPECT_EQ(eb.body["modes"][0]["shape"].size(), 3u);
  EXPECT_EQ(eb.body["modes"][0]["shape"][2]["position_from_knob_m"], 0.8382);

  struct Case {
    const char* body;
    int status;
    const char* code;
    const char* field;
  };
  for (const Case& c : {
           Case{R"({})", 400, "MissingField", "bat"},
           Case{R"({"bat": {"preset": "paper-wood"}, "modes": 21})", 400, "InvalidValue", "modes"},
           Case{R"({"bat": {"preset": "paper-wood"}, "modes": 2.5})", 400, "InvalidValue", "modes"},
           Case{R"({"bat": {"preset": "paper-wood"}, "theory": "rayleigh"})", 400, "InvalidValue",
                "theory"},
           Case{R"({"bat": {"preset": "paper-wood"}, "tolerance": 0})", 400, "InvalidValue",
                "tolerance"},
           Case{R"({"bat": {"preset": "paper-wood"}, "shape_samples": 1})", 400, "InvalidValue",
                "shape_samples"},
           // Core's ranges (BeamModesOptions::Validate) under the request's names.
           Case{R"({"bat": {"preset": "paper-wood"}, "tolerance": 0.5})", 400, "InvalidValue",
                "tolerance"},
           Case{R"({"bat": {"preset": "paper-wood"}, "max_elements": 1})", 400, "InvalidValue",
                "max_elements"},
           Case{R"({"bat": {"preset": "paper-wood"}, "max_elements": 4097})", 400, "InvalidValue",
                "max_elements"},
           Case{R"({"bat": {"preset": "paper-wood"}, "mode": 2})", 400, "UnknownField", "mode"},
       }) {
    const Response r = Modes(c.body);
    EXPECT_EQ(r.status, c.status) << c.body << " -> " << r.body.dump();
    EXPECT_EQ(r.body["code"], c.code) << c.body;
    EXPECT_EQ(r.body["field"], c.field) << c.body;
  }
}

TEST(BatModesHandlerTest, CoreRangesAreRefusedUnderTheRequestsNames) {
  // core's relative_tolerance is the request's tolerance.
  Response r = Modes(R"({"bat": {"preset": "paper-wood"}, "tolerance": 0.5})");
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["message"], "tolerance = 0.5: must be in [1e-9, 0.1]");
  r = Modes(R"({"bat": {"preset": "paper-wood"}, "max_elements": 1})");
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["message"], "max_elements = 1: must be in [2, 4096]");
}

TEST(BatModesHandlerTest, ABatThatIsNoBeamIsRefusedNamingTheField) {
  const Response r = Modes(R"({"bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 0.035},
      {"x_m": 0.001, "radius_m": 0.035}]}, "material": "ash"}})");
  EXPECT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["code"], "InvalidValue");
  EXPECT_EQ(r.body["field"], "bat.length_m");
  EXPECT_EQ(r.body["message"],
            "bat.length_m = 0.001: the beam model needs a slender bat (length at least 4 x the "
            "largest radius 0.035000000000000003 m)");
}

TEST(BatModesHandlerTest, TooSmallAMeshBoundIsNoConvergenceNotAnError) {
  const Response r = Modes(R"({"bat": {"preset": "paper-wood"}, "tolerance": 1e-9,
      "max_elements": 30})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["termination"], "no_convergence");
  EXPECT_GT(r.body["error_estimate"]["frequency_relative"].get<double>(), 1e-9);
}

TEST(BatModesHandlerTest, TheContextsCacheServesTheSecondRequest) {
  core::ModesCache cache(4);
  Context context;
  context.modes_cache = &cache;
  const std::string body = R"({"bat": {"preset": "paper-wood"}, "modes": 2})";
  const Response first = Modes(body, context);
  const Response second = Modes(body, context);
  ASSERT_EQ(first.status, 200);
  EXPECT_FALSE(first.body["cache_hit"].get<bool>());
  EXPECT_TRUE(second.body["cache_hit"].get<bool>());
  EXPECT_EQ(first.body["frequencies_hz"], second.body["frequencies_hz"]);
  EXPECT_EQ(cache.Stats().hits, 1);
}

TEST(BatModesHandlerTest, TheRouteDispatchesToTheHandler) {
  const Response r = Post("/v1/bat/modes", R"({"bat": {"preset": "paper-wood"}, "modes": 1})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["frequencies_hz"].size(), 1u);
}

TEST(FlexibleSweetSpotEndpointTest, VibrationNodeHasThePositionAndTheFrequency) {
  const Response r =
      Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}, "outputs": ["vibration_node"]})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& v = r.body["vibration_node"];
  EXPECT_NEAR(v["position_from_knob_m"].get<double>(), 0.68905, 1e-4);
  EXPECT_NEAR(v["frequency_hz"].get<double>(), 176.90, 176.90 * 1e-4);
  EXPECT_NEAR(v["other_node_from_knob_m"].get<double>(), 0.21233, 1e-4);
  EXPECT_EQ(v["second_mode"]["nodes_from_knob_m"].size(), 3u);
  EXPECT_EQ(v["theory"], "timoshenko");
  EXPECT_LT(r.body["error_estimate"]["vibration_node"]["position_m"].get<double>(), 1e-5);
  EXPECT_LT(r.body["error_estimate"]["vibration_node"]["frequency_hz"].get<double>(), 0.02);
  EXPECT_EQ(r.body["models_used"], nlohmann::json::array({"mass_properties", "flexible_beam"}));
}

TEST(FlexibleSweetSpotEndpointTest, FlexibleOptionsAreReadStrictly) {
  const Response eb = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["vibration_node"], "options": {"flexible": {"theory": "euler_bernoulli",
      "frequency_tolerance": 1e-5}}})");
  ASSERT_EQ(eb.status, 200) << eb.body.dump();
  EXPECT_EQ(eb.body["vibration_node"]["theory"], "euler_bernoulli");
  EXPECT_EQ(eb.body["vibration_node"]["relative_tolerance"], 1e-5);
  const Response typo = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["vibration_node"], "options": {"flexible": {"theroy": "timoshenko"}}})");
  EXPECT_EQ(typo.status, 400);
  EXPECT_EQ(typo.body["code"], "UnknownField");
  EXPECT_EQ(typo.body["field"], "options.flexible.theroy");
  const Response range = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["vibration_node"], "options": {"flexible": {"max_modes": 0}}})");
  EXPECT_EQ(range.status, 400);
  EXPECT_EQ(range.body["field"], "options.flexible.max_modes");
}

TEST(FlexibleSweetSpotEndpointTest, LeastStingZoneAndTheFlexibleCurve) {
  const Response r = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"},
      "outputs": ["least_sting_zone"], "options": {"flexible": {"sting_samples": 5,
      "refine_check": false}}})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto& z = r.body["least_sting_zone"];
  EXPECT_LT(z["from_knob_m"].get<double>(), z["min_position_from_knob_m"].get<double>());
  EXPECT_GT(z["to_knob_m"].get<double>(), z["min_position_from_knob_m"].get<double>());
  ASSERT_EQ(z["curve"].size(), 5u);
  for (const auto& p : z["curve"]) {
    for (const char* key :
         {"position_from_knob_m", "exit_speed_mps", "rigid_exit_speed_mps", "vibration_energy_j",
          "hands_vibration_energy_j", "hands_peak_shear_force_n", "hands_peak_bending_moment_n_m",
          "contact_time_s"}) {
      EXPECT_TRUE(p[key].is_number()) << key;
    }
  }
  EXPECT_TRUE(r.body["error_estimate"]["least_sting_zone"]["ends_m"].is_number());
  const Response unknown =
      Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}, "outputs": ["sting"]})");
  EXPECT_EQ(unknown.status, 400);
  EXPECT_NE(unknown.body["message"].get<std::string>().find("least_sting_zone"), std::string::npos);
}

TEST(FlexibleCollisionEndpointTest, ModelFlexibleReportsVibrationsStingAndErrors) {
  const Response r = Post("/v1/collision", R"({"bat": {"preset": "paper-wood"},
      "impact_from_knob_m": 0.7, "model": "flexible"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["model"], "flexible");
  const auto& f = r.body["flexible"];
  EXPECT_EQ(r.body["exit_speed_mps"], f["exit_speed_mps"]);
  EXPECT_LT(f["exit_speed_mps"].get<double>(), f["rigid_exit_speed_mps"].get<double>());
  EXPECT_GT(f["vibration_energy_j"].get<double>(), 1.0);
  EXPECT_GT(f["hands"]["vibration_energy_j"].get<double>(), 0.0);
  EXPECT_GT(f["hands"]["peak_shear_force_n"].get<double>(), 0.0);
  EXPECT_GT(f["hands"]["peak_bending_moment_n_m"].get<double>(), 0.0);
  EXPECT_GT(f["contact_time_s"].get<double>(), 0.6e-3);
  EXPECT_LT(f["contact_time_s"].get<double>(), 1.0e-3);
  EXPECT_GT(f["peak_force_n"].get<double>(), 2e4);
  EXPECT_GT(f["modes_used"].get<int>(), 0);
  EXPECT_EQ(f["modes"].size(), f["modes_used"].get<std::size_t>());
  // The energy block balances (core tests: 1e-6 of the initial energy).
  const auto& e = f["energy"];
  EXPECT_NEAR(e["balance_error_j"].get<double>() / e["initial_j"].get<double>(), 0.0, 1e-6);
  EXPECT_LT(f["error_estimate"]["exit_speed_mps"].get<double>(), 0.01);
  EXPECT_EQ(r.body["models_used"],
            nlohmann::json::array({"mass_properties", "flexible_beam", "flexible"}));
}

}  // namespace
}  // namespace flexible_api_test
}  // namespace sweetspot::api
