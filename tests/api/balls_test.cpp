// GET /v1/balls and ball.preset in scenes: the catalogue's content, preset + override
// precedence, cor_source in every case, the 400 for an unknown preset, and a sweep over a
// preset ball's fields giving the JSON path's bytes.
#include <gtest/gtest.h>

#include <string>

#include "api/router.hpp"
#include "core/ball/ball_catalogue.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace balls_test {
namespace {

using Json = nlohmann::json;

Response Post(const std::string& path, const std::string& body) {
  return Dispatch({"POST", path, body}, Context{});
}

TEST(BallsEndpointTest, ListsTheCatalogueWithSources) {
  const Response r = Dispatch({"GET", "/v1/balls", ""}, Context{});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& balls = r.body["balls"];
  ASSERT_EQ(balls.size(), core::BallCatalogue().size());
  for (std::size_t i = 0; i < balls.size(); ++i) {
    const Json& b = balls[i];
    const core::BallPreset& p = core::BallCatalogue()[i];
    EXPECT_EQ(b["name"], p.name);
    // The catalogue's own doubles, so exactly equal.
    EXPECT_EQ(b["mass_kg"].get<double>(), p.mass_kg);
    EXPECT_EQ(b["radius_m"].get<double>(), p.radius_m);
    EXPECT_EQ(b["cor"].get<double>(), p.cor_law.cor_at_reference);
    EXPECT_EQ(b["cor_law"]["slope_per_mps"].get<double>(), p.cor_law.slope_per_mps);
    EXPECT_EQ(b["stiffness_n_m_p"].get<double>(), p.stiffness);
    EXPECT_FALSE(b["source"].get<std::string>().empty());
    EXPECT_TRUE(b["dynamic_stiffness_n_m"].is_number());
  }
  EXPECT_EQ(balls[0]["name"], "mlb");
  EXPECT_EQ(balls[0]["cor"], 0.546);
  EXPECT_NEAR(balls[0]["cor_test_speed_mps"].get<double>(), 25.908, 1e-12);  // 85 ft/s
}

TEST(BallPresetTest, UnknownPresetIs400NamingFieldValueAndChoices) {
  const Response r =
      Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}, "ball": {"preset": "cricket"}})");
  ASSERT_EQ(r.status, 400) << r.body.dump();
  EXPECT_EQ(r.body["code"], "InvalidValue");
  EXPECT_EQ(r.body["field"], "ball.preset");
  const std::string message = r.body["message"];
  EXPECT_NE(message.find("cricket"), std::string::npos) << message;
  EXPECT_NE(message.find(core::BallPresetNames()), std::string::npos) << message;
  // Not a string.
  EXPECT_EQ(Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}, "ball": {"preset": 3}})")
                .body["field"],
            "ball.preset");
}

TEST(BallPresetTest, ExplicitFieldsOverrideThePresetAndCorSourceSaysWhichCor) {
  // The contact model reports the ball it used: the preset's stiffness, the request's mass.
  const Response r = Post("/v1/collision", R"({"bat": {"preset": "wood-34-ash"},
      "ball": {"preset": "softball-12-fastpitch", "mass_kg": 0.19, "speed_mps": 30},
      "impact_from_knob_m": 0.7, "model": "hertz"})");
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& p = r.body["hertz"]["parameters"];
  EXPECT_EQ(p["ball_mass_kg"], 0.19);
  EXPECT_EQ(p["ball_stiffness_n_m_p"].get<double>(),
            core::FindBallPreset("softball-12-fastpitch")->stiffness);
  EXPECT_EQ(r.body["cor"], 0.47);  // the softball's law is flat
  EXPECT_EQ(r.body["cor_source"], "ball:softball-12-fastpitch");
  EXPECT_EQ(r.body["cor_impact_speed_mps"], r.body["approach_speed_mps"]);
  // Field order does not matter: the preset is applied first, whatever its place.
  const Response later = Post("/v1/collision", R"({"bat": {"preset": "wood-34-ash"},
      "ball": {"mass_kg": 0.19, "speed_mps": 30, "preset": "softball-12-fastpitch"},
      "impact_from_knob_m": 0.7, "model": "hertz"})");
  EXPECT_EQ(later.body["hertz"]["parameters"]["ball_mass_kg"], 0.19);

  // sweet-spot: ball, request and material sources.
  Response s =
      Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}, "ball": {"preset": "mlb"}})");
  ASSERT_EQ(s.status, 200) << s.body.dump();
  EXPECT_EQ(s.body["cor_source"], "ball:mlb");
  const double v = 27.7 + 17.288 * (0.855 - 0.1524);  // 6 in from the tip
  EXPECT_NEAR(s.body["cor_impact_speed_mps"].get<double>(), v, 1e-12);
  EXPECT_NEAR(s.body["cor"].get<double>(), 0.546 - 0.0005 / 0.44704 * (v - 25.908), 1e-12);
  s = Post("/v1/sweet-spot",
           R"({"bat": {"preset": "paper-wood"}, "ball": {"preset": "mlb"}, "cor": 0.5})");
  EXPECT_EQ(s.body["cor_source"], "scene");
  EXPECT_FALSE(s.body.contains("cor_impact_speed_mps"));
  s = Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}})");
  EXPECT_EQ(s.body["cor_source"], "material:paper-wood");
  EXPECT_FALSE(s.body.contains("cor_impact_speed_mps"));
  s = Post("/v1/sweet-spot",
           R"({"bat": {"preset": "bbcor-33-aluminium"}, "ball": {"preset": "ncaa-nfhs"}})");
  ASSERT_EQ(s.status, 200) << s.body.dump();
  // A hollow bat: the trampoline's effective COR from the ball's law (issue 18 item 2).
  EXPECT_EQ(s.body["cor_source"], "barrel:ncaa-nfhs");
  EXPECT_FALSE(s.body.contains("warnings"));
}

TEST(BallPresetTest, CompareAndOptimizeAcceptAPreset) {
  const Response c = Post("/v1/compare", R"({"baseline": {"preset": "paper-wood"},
      "variants": [{"name": "ash", "bat": {"preset": "wood-34-ash"}}], "ball": {"preset": "mlb"}})");
  EXPECT_EQ(c.status, 200) << c.body.dump();
  const Response o = Post("/v1/optimize", R"({"bat": {"three_segment": {"length_m": 0.8636,
      "handle_radius_m": 0.0125, "barrel_radius_m": 0.033, "taper_start_m": 0.30,
      "taper_end_m": 0.55}, "material": "ash"},
      "variables": [{"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.4}],
      "ball": {"preset": "ncaa-nfhs"}, "options": {"max_time_s": 5, "starts": 1}})");
  EXPECT_EQ(o.status, 200) << o.body.dump();
  const Response bad = Post("/v1/optimize", R"({"bat": {"preset": "paper-wood"},
      "variables": [{"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.4}],
      "ball": {"preset": "nope"}})");
  EXPECT_EQ(bad.status, 400);
  EXPECT_EQ(bad.body["field"], "ball.preset");
}

TEST(BallPresetTest, ASweepOverAPresetBallMatchesTheJsonPath) {
  // The template's preset, its fields swept: the engine's bound rows equal the JSON path's
  // (each design's ball = preset, then the swept field), and the COR follows the swept speed.
  const Json body = Json::parse(R"({
    "bat": {"preset": "paper-wood"}, "ball": {"preset": "mlb"},
    "parameters": [{"path": "ball.speed_mps", "min": 20, "max": 40, "count": 3},
                   {"path": "ball.mass_kg", "min": 0.14, "max": 0.15, "count": 2}],
    "outputs": ["max_exit_speed"], "format": "json"})");
  const Response engine = Post("/v1/explore", body.dump());
  ASSERT_EQ(engine.status, 200) << engine.body.dump();
  const Json& rows = engine.body["rows"];
  ASSERT_EQ(rows.size(), 6u);
  for (const Json& row : rows) {
    Json one = Json::parse(R"({"bat": {"preset": "paper-wood"}, "ball": {"preset": "mlb"},
                                "outputs": ["max_exit_speed"]})");
    one["ball"]["speed_mps"] = row["parameters"]["ball.speed_mps"];
    one["ball"]["mass_kg"] = row["parameters"]["ball.mass_kg"];
    const Response single = Post("/v1/sweet-spot", one.dump());
    ASSERT_EQ(single.status, 200) << single.body.dump();
    EXPECT_EQ(row["max_exit_speed"]["exit_speed_mps"],
              single.body["max_exit_speed"]["exit_speed_mps"])
        << row.dump();
  }
  // A preset itself cannot be swept (a name): a 400 before the first design, with or without
  // one in the template.
  for (const char* ball : {R"({})", R"({"preset": "mlb"})"}) {
    const Response r = Post("/v1/explore", std::string(R"({"bat": {"preset": "paper-wood"},
        "ball": )") + ball + R"(, "parameters": [{"path": "ball.preset", "min": 0, "max": 1,
        "count": 2}], "outputs": ["max_exit_speed"]})");
    EXPECT_EQ(r.status, 400) << r.body.dump();
    EXPECT_EQ(r.body["field"], "parameters[0].path") << r.body.dump();
  }
  // Faster pitches, lower COR, so the exit speed rises by less than e * du per du.
  EXPECT_NE(rows[0]["max_exit_speed"]["exit_speed_mps"],
            rows[2]["max_exit_speed"]["exit_speed_mps"]);
}

}  // namespace
}  // namespace balls_test
}  // namespace sweetspot::api
