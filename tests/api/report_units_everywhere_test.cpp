// Issue 33, item 2 ("trade units everywhere"): answers that ignored the trade's units the
// request asked for. "report_units": "imperial" gives every SI number its trade twin at every
// endpoint, arrays of numbers too (a mode's nodes), a number whose unit a sibling names
// (/v1/optimize's objective_value in objective_unit), and a preset's design written in the
// units its variables were written in.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace report_units_everywhere_test {
namespace {

using Json = nlohmann::json;

constexpr double kInch = 0.0254;      // m, exact
constexpr double kMph = 0.44704;      // m/s, exact
constexpr double kFoot = 12 * kInch;  // m, exact

Response Post(const std::string& path, const Json& body) {
  return Dispatch({"POST", path, body.dump()}, Context{});
}

// A CSV answer's lines split at commas (these rows quote nothing: no field has a comma).
std::vector<std::vector<std::string>> CsvRows(const std::string& text) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> fields;
    std::istringstream cells(line);
    for (std::string cell; std::getline(cells, cell, ',');) fields.push_back(cell);
    rows.push_back(std::move(fields));
  }
  return rows;
}

// The bat's length as /v1/bat/properties states it.
double LengthOf(const Json& bat) {
  const Response r = Post("/v1/bat/properties", Json{{"bat", bat}});
  EXPECT_EQ(r.status, 200) << r.body.dump();
  return r.body["length_m"].get<double>();
}

// The twins are AddImperial's own arithmetic (x / 0.0254, (L - x) / 0.0254), so each is
// compared with EXPECT_EQ: the same operation on the same doubles gives the same bits.
TEST(ReportUnitsEverywhereTest, ModesNodesHaveInchTwinsFromKnobAndTip) {
  const Json bat{{"preset", "wood-34-ash"}};
  const Response r = Post("/v1/bat/modes", Json{{"bat", bat}, {"report_units", "imperial"}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const double length = LengthOf(bat);
  ASSERT_EQ(r.body["modes"].size(), 4u);
  for (const Json& mode : r.body["modes"]) {
    const Json& nodes = mode["nodes_from_knob_m"];
    ASSERT_FALSE(nodes.empty());
    ASSERT_TRUE(mode.contains("nodes_from_knob_in")) << mode.dump();
    ASSERT_TRUE(mode.contains("nodes_from_tip_in")) << mode.dump();
    ASSERT_EQ(mode["nodes_from_knob_in"].size(), nodes.size());
    ASSERT_EQ(mode["nodes_from_tip_in"].size(), nodes.size());
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const double x = nodes[i].get<double>();
      EXPECT_EQ(mode["nodes_from_knob_in"][i].get<double>(), x / kInch);
      EXPECT_EQ(mode["nodes_from_tip_in"][i].get<double>(), (length - x) / kInch);
    }
    EXPECT_EQ(mode["nodes_error_estimate_in"].get<double>(),
              mode["nodes_error_estimate_m"].get<double>() / kInch);
    const Json& last = mode["shape"].back();
    EXPECT_EQ(last["position_from_knob_in"].get<double>(),
              last["position_from_knob_m"].get<double>() / kInch);
    EXPECT_EQ(last["position_from_tip_in"].get<double>(),
              (length - last["position_from_knob_m"].get<double>()) / kInch);
  }
  const Json& node = r.body["vibration_node"];
  EXPECT_EQ(node["position_from_tip_in"].get<double>(),
            (length - node["position_from_knob_m"].get<double>()) / kInch);
  EXPECT_EQ(node["other_node_from_tip_in"].get<double>(),
            (length - node["other_node_from_knob_m"].get<double>()) / kInch);
  // SI only without report_units: no twin, and the answer states no length of its own.
  const Response si = Post("/v1/bat/modes", Json{{"bat", bat}});
  ASSERT_EQ(si.status, 200);
  EXPECT_FALSE(si.body["modes"][0].contains("nodes_from_knob_in"));
  EXPECT_FALSE(si.body["vibration_node"].contains("position_from_tip_in"));
}

// /v1/sweet-spot's vibration node: its second mode's nodes are an array too.
TEST(ReportUnitsEverywhereTest, SweetSpotSecondModeNodesHaveTwins) {
  const Json bat{{"preset", "paper-wood"}};
  const Response r =
      Post("/v1/sweet-spot",
           Json{{"bat", bat}, {"outputs", {"vibration_node"}}, {"report_units", "imperial"}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const double length = r.body["properties"]["length_m"].get<double>();
  const Json& second = r.body["vibration_node"]["second_mode"];
  const Json& nodes = second["nodes_from_knob_m"];
  ASSERT_FALSE(nodes.empty());
  ASSERT_EQ(second["nodes_from_knob_in"].size(), nodes.size()) << second.dump();
  ASSERT_EQ(second["nodes_from_tip_in"].size(), nodes.size()) << second.dump();
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    EXPECT_EQ(second["nodes_from_knob_in"][i].get<double>(), nodes[i].get<double>() / kInch);
    EXPECT_EQ(second["nodes_from_tip_in"][i].get<double>(),
              (length - nodes[i].get<double>()) / kInch);
  }
}

// /v1/collision states no length of its own: its positions from the knob get their distances
// from the tip as /v1/sweet-spot gives them (swing.hands_from_tip_in) all the same.
TEST(ReportUnitsEverywhereTest, CollisionPositionsAreAlsoFromTheTip) {
  const Json bat{{"preset", "wood-34-ash"}};
  const Response r = Post("/v1/collision", Json{{"bat", bat},
                                                {"impact_from_knob_m", 0.70},
                                                {"model", "free_bat"},
                                                {"report_units", "imperial"}});
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const double length = LengthOf(bat);
  EXPECT_EQ(r.body["impact_from_knob_in"].get<double>(), 0.70 / kInch);
  ASSERT_TRUE(r.body.contains("impact_from_tip_in")) << r.body.dump();
  EXPECT_EQ(r.body["impact_from_tip_in"].get<double>(), (length - 0.70) / kInch);
  const Json& swing = r.body["swing"];
  ASSERT_TRUE(swing.contains("hands_from_tip_in")) << swing.dump();
  EXPECT_EQ(swing["hands_from_tip_in"].get<double>(),
            (length - swing["hands_from_knob_m"].get<double>()) / kInch);
}

// A carry map's undercuts and carries: arrays with nulls (a grid point whose ball misses),
// which stay null in the twins; a carry is a flight length, so in feet too.
TEST(ReportUnitsEverywhereTest, CarryMapArraysHaveTwinsAndKeepTheirNulls) {
  const Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"},
      "ball": {"preset": "mlb", "speed_mph": 90, "descent_angle_deg": 6},
      "swing": {"bat_speed_mph": 70, "attack_angle_deg": 10},
      "options": {"model": "free_bat", "distance": {"map_positions": 3, "map_undercuts": 3,
                  "undercut_min_m": 0, "undercut_max_m": 0.03}},
      "outputs": ["carry_map"], "report_units": "imperial"})");
  const Response r = Post("/v1/sweet-spot", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& map = r.body["carry_map"];
  ASSERT_EQ(map["undercuts_in"].size(), map["undercuts_m"].size()) << map.dump();
  for (std::size_t j = 0; j < map["undercuts_m"].size(); ++j) {
    EXPECT_EQ(map["undercuts_in"][j].get<double>(), map["undercuts_m"][j].get<double>() / kInch);
  }
  for (const Json& row : map["positions"]) {
    ASSERT_EQ(row["distance_ft"].size(), row["distance_m"].size()) << row.dump();
    for (std::size_t j = 0; j < row["distance_m"].size(); ++j) {
      if (row["distance_m"][j].is_null()) {
        EXPECT_TRUE(row["distance_ft"][j].is_null());
      } else {
        EXPECT_EQ(row["distance_ft"][j].get<double>(), row["distance_m"][j].get<double>() / kFoot);
      }
    }
  }
}

// /v1/explore's rows: the array twins as a single /v1/sweet-spot answer has them, in full rows
// with report_units and in a column that names one element (read from the row's twins).
TEST(ReportUnitsEverywhereTest, ExploreRowsAndColumnsHaveTheArrayTwins) {
  Json body{{"bat", {{"preset", "paper-wood"}}},
            {"outputs", {"vibration_node"}},
            {"parameters", {{{"path", "cor"}, {"min", 0.45}, {"max", 0.5}, {"count", 2}}}},
            {"report_units", "imperial"}};
  const Response full = Post("/v1/explore", body);
  ASSERT_EQ(full.status, 200) << full.body.dump();
  const Json single = Post("/v1/sweet-spot", Json{{"bat", {{"preset", "paper-wood"}}},
                                                  {"outputs", {"vibration_node"}},
                                                  {"cor", 0.45},
                                                  {"report_units", "imperial"}})
                          .body;
  const Json& second = full.body["rows"][0]["vibration_node"]["second_mode"];
  ASSERT_TRUE(second.contains("nodes_from_tip_in")) << second.dump();
  EXPECT_EQ(second["nodes_from_tip_in"],
            single["vibration_node"]["second_mode"]["nodes_from_tip_in"]);
  body.erase("report_units");
  body["columns"] = {"vibration_node.second_mode.nodes_from_knob_m.0",
                     "vibration_node.second_mode.nodes_from_tip_in.0"};
  const Response columns = Post("/v1/explore", body);
  ASSERT_EQ(columns.status, 200) << columns.body.dump();
  const Json& row = columns.body["rows"][0];
  EXPECT_EQ(row["vibration_node.second_mode.nodes_from_tip_in.0"], second["nodes_from_tip_in"][0])
      << row.dump();
}

// The contract's three-segment ash bat, the taper's start free, at most 0.95 kg.
Json OptimizeRequest() {
  return Json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5}],
    "constraints": {"mass_kg": {"max": 0.95}},
    "objective": "max_exit_speed", "cor": 0.5, "options": {"backend": "nlopt_slsqp"}})");
}

TEST(ReportUnitsEverywhereTest, OptimizeObjectiveValueHasItsMphTwin) {
  Json body = OptimizeRequest();
  body["report_units"] = "imperial";
  const Response r = Post("/v1/optimize", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["objective_unit"], "mps");
  EXPECT_EQ(r.body["objective_value_mph"].get<double>(),
            r.body["objective_value"].get<double>() / kMph)
      << r.body.dump();
  EXPECT_FALSE(r.body.contains("objective_value_ft"));  // a speed, not a carry
  // The bat stays the request's own form, SI as it was given.
  EXPECT_TRUE(r.body["bat"]["three_segment"].contains("taper_start_m"));
  EXPECT_FALSE(r.body["bat"]["three_segment"].contains("taper_start_in"));
  const Response si = Post("/v1/optimize", OptimizeRequest());
  ASSERT_EQ(si.status, 200);
  EXPECT_FALSE(si.body.contains("objective_value_mph"));
}

// The summary's numbers in the objective's unit (the spread, each run) and in an active
// constraint's unit (its value, bound, tolerance) get their twins too; the multiplier, a unit
// of the objective per unit of the constraint, is left.
TEST(ReportUnitsEverywhereTest, OptimizeSpreadAndActiveConstraintsHaveTwins) {
  Json body = OptimizeRequest();
  body["report_units"] = "imperial";
  const Response r = Post("/v1/optimize", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& spread = r.body["summary"]["spread"];
  for (const char* key : {"objective_min", "objective_max", "objective_median"}) {
    EXPECT_EQ(spread[std::string(key) + "_mph"].get<double>(), spread[key].get<double>() / kMph)
        << key;
  }
  ASSERT_FALSE(spread["runs"].empty());
  for (const Json& run : spread["runs"]) {
    EXPECT_EQ(run["objective_mph"].get<double>(), run["objective"].get<double>() / kMph);
  }
  const Json& active = r.body["summary"]["active_constraints"];
  ASSERT_FALSE(active.empty()) << r.body.dump();  // the mass bound holds the optimum
  bool saw_mass = false;
  for (const Json& a : active) {
    if (a["unit"] != "kg") continue;
    saw_mass = true;
    constexpr double kOunce = 0.028349523125;  // kg, exact
    for (const char* key : {"value", "bound", "tolerance"}) {
      EXPECT_EQ(a[std::string(key) + "_oz"].get<double>(), a[key].get<double>() / kOunce) << key;
    }
    EXPECT_FALSE(a.contains("multiplier_oz"));
  }
  EXPECT_TRUE(saw_mass) << active.dump();
}

// A material choice: each material's objective_value in the answer's objective_unit.
TEST(ReportUnitsEverywhereTest, MaterialChoiceRowsHaveObjectiveTwins) {
  Json body = OptimizeRequest();
  body["variables"].push_back({{"path", "material"}, {"choices", {"ash", "hard-maple"}}});
  body["report_units"] = "imperial";
  const Response r = Post("/v1/optimize", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["materials"].size(), 2u);
  for (const Json& m : r.body["materials"]) {
    EXPECT_EQ(m["objective_value_mph"].get<double>(), m["objective_value"].get<double>() / kMph)
        << m.dump();
  }
}

// The frontier in CSV with "report_units": "imperial": each SI column is followed by its twins
// (the objective's in its unit, the properties', the sweet spot's from the knob and the tip),
// with AddImperial's values.
TEST(ReportUnitsEverywhereTest, FrontierCsvHasImperialColumns) {
  Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"},
      "variables": [{"path": "profile.knots[9].radius_m", "min": 0.011, "max": 0.034}],
      "constraints": {"balance_point_m": {"max": 0.62}},
      "frontier": {"constraint": "mass_oz", "from": 31, "to": 32, "count": 2},
      "format": "csv", "report_units": "imperial"})");
  const std::string csv = Post("/v1/optimize", body).text;
  const std::vector<std::vector<std::string>> rows = CsvRows(csv);
  ASSERT_EQ(rows.size(), 3u) << csv;
  const std::vector<std::string>& header = rows[0];
  const auto column = [&](const std::string& name) {
    const auto it = std::find(header.begin(), header.end(), name);
    EXPECT_NE(it, header.end()) << name << " in " << csv;
    return static_cast<std::size_t>(it - header.begin());
  };
  const std::size_t value = column("objective_value"), mph = column("objective_value_mph");
  EXPECT_EQ(mph, value + 1);  // the twin right after its SI column
  const std::size_t kg = column("properties.mass_kg"), oz = column("properties.mass_oz");
  const std::size_t knob = column("sweet_spot.position_from_knob_m");
  const std::size_t knob_in = column("sweet_spot.position_from_knob_in");
  const std::size_t tip_in = column("sweet_spot.position_from_tip_in");
  const std::size_t length = column("properties.length_m");
  for (std::size_t i = 1; i < rows.size(); ++i) {
    const auto at = [&](std::size_t c) { return std::stod(rows[i].at(c)); };
    // CSV writes each double round-trip exactly, so AddImperial's arithmetic on the SI
    // column's number gives the twin's bits.
    EXPECT_EQ(at(mph), at(value) / kMph);
    EXPECT_EQ(at(oz), at(kg) / 0.028349523125);
    EXPECT_EQ(at(knob_in), at(knob) / kInch);
    EXPECT_EQ(at(tip_in), (at(length) - at(knob)) / kInch);
  }
  body["report_units"] = "si";
  const std::vector<std::vector<std::string>> si = CsvRows(Post("/v1/optimize", body).text);
  ASSERT_FALSE(si.empty());
  EXPECT_EQ(std::find(si[0].begin(), si[0].end(), "objective_value_mph"), si[0].end());
}

// /v1/bat/fit answers its bat as the request wrote it: a three_segment given in inches (the
// barrel as a diameter) comes back in those forms, the fitted unknown included, and sent
// again it has the fitted properties.
TEST(ReportUnitsEverywhereTest, FitAnswersTheBatInTheFormsTheRequestWrote) {
  const Json body = Json::parse(R"({"bat": {"three_segment": {"length_in": 34,
      "handle_diameter_in": 0.98, "barrel_diameter_in": 2.6, "taper_start_in": 11,
      "taper_end_m": 0.55}, "material": "ash"},
      "targets": {"mass_oz": 38}, "unknowns": [{"name": "taper_start_m", "min": 0.1,
      "max": 0.5}]})");
  const Response r = Post("/v1/bat/fit", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& shape = r.body["bat"]["three_segment"];
  EXPECT_EQ(shape["length_in"], 34.0);
  EXPECT_EQ(shape["handle_diameter_in"], 0.98);
  EXPECT_EQ(shape["barrel_diameter_in"], 2.6);
  EXPECT_EQ(shape["taper_end_m"], 0.55);
  // The unknown's value, fitted in SI, in the inches the bat gave it in.
  EXPECT_EQ(shape["taper_start_in"].get<double>(),
            r.body["unknowns"]["taper_start_m"].get<double>() / kInch);
  EXPECT_FALSE(shape.contains("taper_start_m"));
  EXPECT_FALSE(shape.contains("length_m"));
  const Response again = Post("/v1/bat/properties", Json{{"bat", r.body["bat"]}});
  ASSERT_EQ(again.status, 200) << again.body.dump();
  // Inches back to metres round the taper's start by an ulp or so; the mass moves with it by
  // far less than 1e-9 relative.
  EXPECT_NEAR(again.body["mass_kg"].get<double>(), r.body["properties"]["mass_kg"].get<double>(),
              1e-9 * r.body["properties"]["mass_kg"].get<double>());
}

// max_distance: the objective is a carry in metres, so in feet (and inches) too.
TEST(ReportUnitsEverywhereTest, OptimizeMaxDistanceObjectiveHasItsFeetTwin) {
  Json body = Json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "ball": {"descent_angle_deg": 6}, "swing": {"attack_angle_deg": 10},
    "variables": [{"path": "three_segment.barrel_radius_m", "min": 0.030, "max": 0.0345}],
    "constraints": {"mass_kg": {"max": 1.1}},
    "objective": "max_distance", "cor": 0.5, "options": {"model": "free_bat"},
    "report_units": "imperial"})");
  const Response r = Post("/v1/optimize", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["objective_unit"], "m");
  const double carry = r.body["objective_value"].get<double>();
  EXPECT_EQ(r.body["objective_value_ft"].get<double>(), carry / kFoot) << r.body.dump();
  EXPECT_EQ(r.body["objective_value_in"].get<double>(), carry / kInch);
  EXPECT_EQ(r.body["distance_sweet_spot"]["distance_ft"].get<double>(), carry / kFoot);
}

// The frontier's rows are ResultToJson's answers too.
TEST(ReportUnitsEverywhereTest, FrontierRowsObjectiveValueHasItsMphTwin) {
  Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"},
      "variables": [{"path": "profile.knots[9].radius_m", "min": 0.011, "max": 0.034},
                    {"path": "profile.knots[11].radius_m", "min": 0.011, "max": 0.034}],
      "constraints": {"balance_point_m": {"max": 0.62}},
      "frontier": {"constraint": "mass_oz", "from": 31, "to": 32, "count": 2},
      "report_units": "imperial"})");
  const Response r = Post("/v1/optimize", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 2u);
  for (const Json& row : r.body["rows"]) {
    EXPECT_EQ(row["objective_value_mph"].get<double>(), row["objective_value"].get<double>() / kMph)
        << row.dump();
  }
}

// A preset's design with its variables written as diameters in inches: the variables come
// back under the names written, in inches, and the profile the answer writes out whole (the
// preset's request has none) is in inches too, each radius as a diameter, so the answer's bat
// is in the form and units the request used and can be sent again as it stands.
TEST(ReportUnitsEverywhereTest, PresetDesignInDiametersAnswersInDiameters) {
  const Json body = Json::parse(R"({"bat": {"preset": "wood-34-ash"},
      "variables": [{"path": "profile.knots[9].diameter_in", "min": 1.0, "max": 2.65},
                    {"path": "profile.knots[11].diameter_in", "min": 1.0, "max": 2.65}],
      "constraints": {"mass_oz": {"max": 32}},
      "objective": "max_exit_speed", "cor": 0.5})");
  const Response r = Post("/v1/optimize", body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& variables = r.body["variables"];
  ASSERT_TRUE(variables.contains("profile.knots[9].diameter_in")) << variables.dump();
  ASSERT_TRUE(variables.contains("profile.knots[11].diameter_in")) << variables.dump();
  EXPECT_FALSE(variables.contains("profile.knots[9].radius_m"));
  const Json& bat = r.body["bat"];
  EXPECT_EQ(bat["preset"], "wood-34-ash");
  ASSERT_TRUE(bat.contains("profile")) << bat.dump();
  for (const Json& knot : bat["profile"]["knots"]) {
    EXPECT_TRUE(knot.contains("x_in") && knot.contains("diameter_in")) << knot.dump();
    EXPECT_FALSE(knot.contains("x_m") || knot.contains("radius_m")) << knot.dump();
  }
  for (const int k : {9, 11}) {
    const double d = variables["profile.knots[" + std::to_string(k) + "].diameter_in"];
    EXPECT_GE(d, 1.0);
    EXPECT_LE(d, 2.65);
    // Both are the design's radius / 0.0127; 1e-12 relative covers a rounding on the way.
    EXPECT_NEAR(bat["profile"]["knots"][k]["diameter_in"].get<double>(), d, 1e-12 * d);
  }
  // Sent again as it stands: the same bat. A bat in inches has the SI bat's mass to 1e-12
  // relative (trade_units_test); 1e-11 relative allows the twelve knots' round trips.
  const Response again = Post("/v1/bat/properties", Json{{"bat", bat}});
  ASSERT_EQ(again.status, 200) << again.body.dump();
  const double mass = r.body["properties"]["mass_kg"].get<double>();
  EXPECT_NEAR(again.body["mass_kg"].get<double>(), mass, 1e-11 * mass);
}

}  // namespace
}  // namespace report_units_everywhere_test
}  // namespace sweetspot::api
