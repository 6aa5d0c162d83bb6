// Issue 19, "Swing by bat speed": swing.bat_speed_mps at swing.bat_speed_from_tip_m sets the
// angular speed about the pivot; the answers echo the swing they resolved.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace swing_bat_speed_test {
namespace {

using Json = nlohmann::json;

Response Post(const std::string& path, const Json& body) {
  return Dispatch({"POST", path, body.dump()}, Context{});
}

// paper-wood's length, m (api-contract.md).
constexpr double kPaperLengthM = 0.855;

TEST(SwingBatSpeedTest, OmegaFromBatSpeedAtTheDefaultPoint) {
  // 70 mph = 31.2928 m/s at 6 in from the tip, pivot 0.05 m from the knob.
  const double v = 31.2928, pivot = 0.05;
  const Response r = Post("/v1/sweet-spot", {{"bat", {{"preset", "paper-wood"}}},
                                             {"swing", {{"bat_speed_mps", v},
                                                        {"pivot_from_knob_m", pivot}}}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& swing = r.body["swing"];
  const double expected = v / (kPaperLengthM - 0.1524 - pivot);
  // One division and two subtractions: a few ulps; 1e-12 relative as the brief asks.
  EXPECT_NEAR(swing["angular_speed_rad_s"].get<double>(), expected, 1e-12 * expected);
  EXPECT_EQ(swing["bat_speed_mps"], v);
  EXPECT_EQ(swing["bat_speed_from_tip_m"], 0.1524);
  EXPECT_EQ(swing["pivot_from_knob_m"], pivot);
  EXPECT_EQ(swing["hands_from_knob_m"], 0.1524);
}

TEST(SwingBatSpeedTest, ExplicitPointAndEchoWithoutBatSpeed) {
  const double v = 30.0, from_tip = 0.2;
  const Response r = Post("/v1/collision", {{"bat", {{"preset", "paper-wood"}}},
                                            {"impact_from_knob_m", 0.7},
                                            {"swing", {{"bat_speed_mps", v},
                                                       {"bat_speed_from_tip_m", from_tip}}}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const double expected = v / (kPaperLengthM - from_tip);  // pivot at the knob (default)
  EXPECT_NEAR(r.body["swing"]["angular_speed_rad_s"].get<double>(), expected, 1e-12 * expected);
  EXPECT_EQ(r.body["swing"]["bat_speed_from_tip_m"], from_tip);
  // Without a bat speed the echo is the swing as given, compact (no bat-speed fields).
  const Response plain = Post("/v1/collision", {{"bat", {{"preset", "paper-wood"}}},
                                                {"impact_from_knob_m", 0.7}});
  ASSERT_EQ(plain.status, 200) << plain.body.dump();
  EXPECT_EQ(plain.body["swing"], Json({{"angular_speed_rad_s", 17.288},
                                       {"pivot_from_knob_m", 0.0},
                                       {"hands_from_knob_m", 0.1524}}));
}

TEST(SwingBatSpeedTest, SameExitSpeedAsTheEquivalentOmega) {
  const double v = 31.2928;
  for (const char* model : {"rigid_pivot", "free_bat"}) {
    const Response by_speed =
        Post("/v1/sweet-spot", {{"bat", {{"preset", "wood-34-ash"}}},
                                {"swing", {{"bat_speed_mps", v}}},
                                {"options", {{"model", model}}}});
    ASSERT_EQ(by_speed.status, 200) << by_speed.body.dump();
    const double omega = by_speed.body["swing"]["angular_speed_rad_s"];
    const Response by_omega =
        Post("/v1/sweet-spot", {{"bat", {{"preset", "wood-34-ash"}}},
                                {"swing", {{"angular_speed_rad_s", omega}}},
                                {"options", {{"model", model}}}});
    ASSERT_EQ(by_omega.status, 200) << by_omega.body.dump();
    // The same omega reaches the same closed form: bit-identical.
    EXPECT_EQ(by_speed.body["max_exit_speed"], by_omega.body["max_exit_speed"]) << model;
  }
}

TEST(SwingBatSpeedTest, CompareRowsEachResolveTheirOwnOmega) {
  const Response r = Post(
      "/v1/compare",
      {{"baseline", {{"preset", "paper-wood"}}},
       {"variants", {{{"name", "ash"}, {"bat", {{"preset", "wood-34-ash"}}}}}},
       {"swing", {{"bat_speed_mps", 30.0}}}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  for (const Json& row : r.body["rows"]) {
    const double length = row["properties"]["length_m"];
    const double expected = 30.0 / (length - 0.1524);
    EXPECT_NEAR(row["swing"]["angular_speed_rad_s"].get<double>(), expected, 1e-12 * expected);
  }
}

TEST(SwingBatSpeedTest, ExploreRowsResolveEachDesignsOmega) {
  const Json body = {
      {"bat", {{"three_segment", {{"length_m", 0.8636}, {"handle_radius_m", 0.0125},
                                  {"barrel_radius_m", 0.033}, {"taper_start_m", 0.30},
                                  {"taper_end_m", 0.55}}},
               {"material", "ash"}}},
      {"swing", {{"bat_speed_mps", 30.0}}},
      {"parameters", {{{"path", "three_segment.length_m"}, {"min", 0.80}, {"max", 0.86},
                       {"count", 2}}}}};
  const Response r = Post("/v1/explore", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 2u);
  for (const Json& row : r.body["rows"]) {
    const double length = row["parameters"]["three_segment.length_m"];
    const double expected = 30.0 / (length - 0.1524);  // one division: 1e-12 relative is ample
    EXPECT_NEAR(row["swing"]["angular_speed_rad_s"].get<double>(), expected, 1e-12 * expected);
  }
  // Sweeping the angular speed beside a bat speed would be overridden in every design: a 400.
  Json both = body;
  both["parameters"] = {{{"path", "swing.angular_speed_rad_s"}, {"min", 10}, {"max", 20},
                         {"count", 2}}};
  const Response refused = Post("/v1/explore", both);
  EXPECT_EQ(refused.status, 400) << refused.body.dump();
  EXPECT_EQ(refused.body["field"], "parameters[0].path");
  EXPECT_NE(refused.body["message"].get<std::string>().find("exactly one"), std::string::npos)
      << refused.body.dump();
  // Without a bat speed the rows are as before: no swing block.
  Json plain = body;
  plain["swing"] = {{"angular_speed_rad_s", 40.0}};
  const Response p = Post("/v1/explore", plain);
  ASSERT_EQ(p.status, 200) << p.body.dump();
  EXPECT_FALSE(p.body["rows"][0].contains("swing"));
}

TEST(SwingBatSpeedTest, BatSpeedInMphThroughTheUnitsMechanism) {
  // No swing code reads *_mph: api/json_reader's central units turn it into bat_speed_mps.
  const Response r = Post("/v1/sweet-spot", {{"bat", {{"preset", "paper-wood"}}},
                                             {"swing", {{"bat_speed_mph", 70.0}}}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const double v = 70.0 * 0.44704;  // mph -> m/s, exact by definition
  EXPECT_NEAR(r.body["swing"]["bat_speed_mps"].get<double>(), v, 1e-15 * v);  // one product
  const double expected = v / (kPaperLengthM - 0.1524);
  EXPECT_NEAR(r.body["swing"]["angular_speed_rad_s"].get<double>(), expected, 1e-12 * expected);
  const Response both = Post("/v1/sweet-spot", {{"bat", {{"preset", "paper-wood"}}},
                                                {"swing", {{"bat_speed_mph", 70.0},
                                                           {"angular_speed_rad_s", 17.0}}}});
  EXPECT_EQ(both.status, 400);
  // Named as written (issue 33, item 2), the SI field after it.
  EXPECT_EQ(both.body["field"], "swing.bat_speed_mph");
  EXPECT_NE(both.body["message"].get<std::string>().find(
                "exactly one of swing.bat_speed_mph and swing.angular_speed_rad_s"),
            std::string::npos)
      << both.body.dump();
}

TEST(SwingBatSpeedTest, BothGivenIsRefused) {
  const Response r = Post("/v1/sweet-spot", {{"bat", {{"preset", "paper-wood"}}},
                                             {"swing", {{"bat_speed_mps", 30.0},
                                                        {"angular_speed_rad_s", 17.0}}}});
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["code"], "InvalidValue");
  EXPECT_EQ(r.body["field"], "swing.bat_speed_mps");
  EXPECT_NE(r.body["message"].get<std::string>().find("exactly one"), std::string::npos)
      << r.body.dump();
}

TEST(SwingBatSpeedTest, PointNotBeyondThePivotIsRefused) {
  // 0.855 - 0.1524 = 0.7026 m from the knob, behind a pivot at 0.75 m.
  const Response behind = Post("/v1/sweet-spot", {{"bat", {{"preset", "paper-wood"}}},
                                                  {"swing", {{"bat_speed_mps", 30.0},
                                                             {"pivot_from_knob_m", 0.75}}}});
  EXPECT_EQ(behind.status, 400) << behind.body.dump();
  EXPECT_EQ(behind.body["field"], "swing.bat_speed_from_tip_m");
  EXPECT_NE(behind.body["message"].get<std::string>().find("must lie beyond the pivot"),
            std::string::npos)
      << behind.body.dump();
  // Off the bat (more than its length from the tip).
  const Response off = Post("/v1/collision", {{"bat", {{"preset", "paper-wood"}}},
                                              {"impact_from_knob_m", 0.7},
                                              {"swing", {{"bat_speed_mps", 30.0},
                                                         {"bat_speed_from_tip_m", 0.9}}}});
  EXPECT_EQ(off.status, 400) << off.body.dump();
  EXPECT_EQ(off.body["field"], "swing.bat_speed_from_tip_m");
}

// /v1/optimize resolves a bat speed per design: with the length fixed, once (the base bat's);
// with the length a variable, from each design's own length. The answer's
// sweet_spot.angular_speed_rad_s is the final design's omega: times its arm it is the bat speed.
TEST(SwingBatSpeedTest, OptimizeResolvesBatSpeedForEachDesignsLength) {
  const double v = 31.2928;  // 70 mph
  // paper-wood's shape and wood in the three_segment form (its length a variable below).
  const Json bat = {{"three_segment",
                     {{"length_m", kPaperLengthM},
                      {"handle_radius_m", 0.0125},
                      {"barrel_radius_m", 0.035},
                      {"taper_start_m", 0.3459},
                      {"taper_end_m", 0.6423}}},
                    {"material", "paper-wood"}};
  Json body = {
      {"bat", bat},
      {"swing", {{"bat_speed_mps", v}, {"pivot_from_knob_m", 0.05}}},
      {"cor", 0.5},
      {"variables", {{{"path", "three_segment.taper_start_m"}, {"min", 0.1}, {"max", 0.3}}}}};
  const Response fixed = Post("/v1/optimize", body);
  ASSERT_EQ(fixed.status, 200) << fixed.body.dump();
  const double fixed_omega = fixed.body["sweet_spot"]["angular_speed_rad_s"];
  // The base bat's length: one division, as the scenes resolve it (1e-12 relative).
  EXPECT_NEAR(fixed_omega, v / (kPaperLengthM - 0.1524 - 0.05), 1e-12 * fixed_omega);
  // The length a variable, in mph as the scenes accept it: the longest bat has the longest arm.
  body["swing"] = {{"bat_speed_mph", 70.0}, {"pivot_from_knob_m", 0.05}};
  body["variables"].push_back({{"path", "three_segment.length_m"}, {"min", 0.80}, {"max", 0.90}});
  body["constraints"] = {{"mass_kg", {{"max", 0.95}}}};
  const Response varied = Post("/v1/optimize", body);
  ASSERT_EQ(varied.status, 200) << varied.body.dump();
  EXPECT_EQ(varied.body["summary"]["termination"], "converged") << varied.body.dump();
  const double length = varied.body["bat"]["three_segment"]["length_m"];
  EXPECT_GT(std::abs(length - kPaperLengthM), 1e-3);  // the length moved: omega0 is its own
  const double omega = varied.body["sweet_spot"]["angular_speed_rad_s"];
  // omega = v / (L - 0.1524 - 0.05): their product is v to a few ulps (1e-12 relative).
  EXPECT_NEAR(omega * (length - 0.1524 - 0.05), v, 1e-12 * v) << varied.body.dump();
  // A bat-speed point behind the pivot for the shortest bat the bounds allow: 400 naming it.
  body["swing"]["pivot_from_knob_m"] = 0.7;  // 0.80 - 0.1524 = 0.6476 m from the knob
  const Response behind = Post("/v1/optimize", body);
  EXPECT_EQ(behind.status, 400) << behind.body.dump();
  EXPECT_EQ(behind.body["field"], "swing.bat_speed_from_tip_m");
  EXPECT_NE(behind.body["message"].get<std::string>().find("the shortest bat the variables allow"),
            std::string::npos)
      << behind.body.dump();
}

// docs/models.md, "Bat speed at the impact point": with V = omega x fixed at the impact point,
// rigid_pivot's v2 = -u + (1+e)(u+V) J/(J + m x^2) still depends on the bat through J/x^2.
TEST(SwingBatSpeedTest, FixedBatSpeedAtImpactExitSpeedDependsOnEffectiveMass) {
  const double v = 31.2928, u = 27.7, m = 0.145, e = 0.5;
  double exits[2];
  int i = 0;
  for (const char* preset : {"paper-wood", "paper-wood-m885"}) {
    const Response props = Post("/v1/bat/properties", {{"bat", {{"preset", preset}}}});
    ASSERT_EQ(props.status, 200) << props.body.dump();
    const double length = props.body["length_m"];
    const double x = length - 0.1524;  // impact at the bat-speed point, pivot at the knob
    const Response r = Post("/v1/collision", {{"bat", {{"preset", preset}}},
                                              {"model", "rigid_pivot"},
                                              {"cor", e},
                                              {"impact_from_knob_m", x},
                                              {"swing", {{"bat_speed_mps", v}}}});
    ASSERT_EQ(r.status, 200) << r.body.dump();
    const double j = props.body["moi_knob_kg_m2"];
    const double expected = -u + (1.0 + e) * (u + v) * j / (j + m * x * x);
    // A handful of roundings on numbers of order 50 m/s.
    EXPECT_NEAR(r.body["exit_speed_mps"].get<double>(), expected, 1e-12 * 50.0) << preset;
    EXPECT_NEAR(r.body["rigid_pivot"]["bat_speed_at_impact_mps"].get<double>(), v, 1e-12 * v);
    exits[i++] = r.body["exit_speed_mps"];
  }
  // The lighter bat (smaller J/x^2) gives less: by ~1.5 m/s here, far beyond rounding.
  EXPECT_GT(exits[0] - exits[1], 0.5);
}

}  // namespace
}  // namespace swing_bat_speed_test
}  // namespace sweetspot::api
