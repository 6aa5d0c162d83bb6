// The sweep engine (api/explore/engine.hpp): its rows are the JSON path's, byte for byte, in
// every format, for every path it binds and every column it reads directly, for feasible and
// failing designs alike; and they do not depend on the number of threads.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "api/explore/engine.hpp"
#include "api/outputs/scene_outputs.hpp"
#include "api/router.hpp"
#include "api/thread_budget.hpp"
#include "core/explore/sampling.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace explore_engine_test {
namespace {

using Json = nlohmann::json;

ExploreRequest Parse(const Json& body) {
  ApiError error;
  Context context;
  auto request = ParseExploreRequest(body, context, &error);
  EXPECT_TRUE(request.has_value()) << error.message;
  return request ? std::move(*request) : ExploreRequest{};
}

// The whole answer of a run as text: the rows (ndjson or csv lines, or each JSON row dumped
// on a line) and the summary without its timing.
std::string RunText(const Sweep& sweep, RowFormat format,
                    const std::vector<ExploreColumn>& columns) {
  std::string text;
  const SweepOutcome outcome = RunSweep(sweep, format, columns, nullptr, [&](BlockRows& rows) {
    text += rows.text;
    for (const Json& row : rows.rows) text += row.dump() + "\n";
    return true;
  });
  Json summary = outcome.summary;
  summary.erase("timing_s");
  return text + summary.dump() + "\n";
}

// Runs `body` through the engine (bound, 1 and 3 threads) and through the JSON path (the
// binder dropped) in json, ndjson and csv, with and without `columns`; all must agree.
// Returns the engine's ndjson rows. `expect_bound`: the engine binds every swept path.
std::string ExpectSameRows(Json body, bool expect_bound, const Json& columns = nullptr) {
  std::string ndjson;
  for (const char* format : {"json", "ndjson", "csv"}) {
    for (const bool with_columns : {false, true}) {
      if (with_columns && columns.is_null()) continue;
      body["format"] = format;
      if (with_columns) {
        body["columns"] = columns;
      } else {
        body.erase("columns");
      }
      const ExploreRequest request = Parse(body);
      if (request.sweep == nullptr) return "";
      EXPECT_EQ(request.sweep->binder.has_value(), expect_bound) << body.dump();
      const RowFormat f = request.format == "csv"      ? RowFormat::kCsv
                          : request.format == "ndjson" ? RowFormat::kNdjson
                                                       : RowFormat::kJson;
      Sweep engine = *request.sweep;
      engine.threads = 1;
      const std::string one = RunText(engine, f, request.columns);
      engine.threads = 3;
      ThreadBudget budget(8);
      engine.budget = &budget;
      const std::string three = RunText(engine, f, request.columns);
      EXPECT_EQ(budget.taken(), 0);  // every borrowed thread given back
      Sweep json_path = *request.sweep;
      json_path.binder.reset();
      const std::string reference = RunText(json_path, f, request.columns);
      EXPECT_EQ(one, reference) << format << (with_columns ? " with columns" : "");
      EXPECT_EQ(three, one) << format << (with_columns ? " with columns" : "");
      if (request.format == "ndjson" && !with_columns) ndjson = one;
    }
  }
  return ndjson;
}

TEST(ExploreEngineTest, ThreeSegmentSweepWithInfeasibleDesignsMatchesTheJsonPath) {
  // taper_start past taper_end in part of the grid: those designs fail the shape's check, and
  // their error rows must be the JSON path's. 600 designs: at least three blocks (of at
  // most 256), so threads interleave.
  const Json body = Json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "cor": 0.5,
    "parameters": [{"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.6, "count": 30},
                   {"path": "three_segment.taper_end_m", "min": 0.45, "max": 0.7, "count": 20}],
    "outputs": ["max_exit_speed", "properties", "center_of_percussion", "collision_efficiency"],
    "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                              {"output": "properties.mass_kg", "sense": "min"}]}})");
  const Json columns = {"index",
                        "feasible",
                        "parameters.three_segment.taper_start_m",
                        "max_exit_speed.exit_speed_mps",
                        "max_exit_speed.position_from_knob_m",
                        "max_exit_speed.unconstrained_position_from_knob_m",
                        "max_exit_speed.placement",
                        "max_exit_speed.model",
                        "max_exit_speed.method",
                        "center_of_percussion.position_from_knob_m",
                        "center_of_percussion.hands_from_knob_m",
                        "center_of_percussion.moi_hands_kg_m2",
                        "center_of_percussion.placement",
                        "properties.mass_kg",
                        "properties.balance_point_m",
                        "properties.moi_knob_kg_m2",
                        "properties.moi_six_inch_kg_m2",
                        "properties.moi_centroid_kg_m2",
                        "properties.volume_m3",
                        "properties.length_m",
                        "properties.inertia_model",
                        "properties.imperial.length_in",
                        "properties.imperial.weight_oz",
                        "properties.imperial.drop",
                        "properties.imperial.balance_point_in",
                        "properties.imperial.moi_knob_oz_in2",
                        "properties.imperial.moi_six_inch_oz_in2",
                        "properties.imperial.moi_centroid_oz_in2",
                        "collision_efficiency",
                        "error.code",
                        "error.field"};
  const std::string rows = ExpectSameRows(body, /*expect_bound=*/true, columns);
  // The sweep holds both kinds of row (else the comparison proves less than it says).
  EXPECT_NE(rows.find("\"feasible\":false"), std::string::npos);
  EXPECT_NE(rows.find("\"feasible\":true"), std::string::npos);
}

TEST(ExploreEngineTest, SceneAndMaterialAndFillPathsMatchTheJsonPath) {
  // The bat unswept (its mass properties computed once) with ball, swing and cor swept, some
  // designs out of range (a cor above 1, hands past the tip); then material, wall and fill.
  Json scene = Json::parse(R"({
    "bat": {"preset": "paper-wood"},
    "parameters": [{"path": "ball.speed_mps", "min": 20, "max": 40, "count": 3},
                   {"path": "swing.hands_from_knob_m", "min": 0.1, "max": 0.9, "count": 3},
                   {"path": "cor", "min": 0.4, "max": 1.2, "count": 5}],
    "outputs": ["max_exit_speed", "center_of_percussion", "properties"]})");
  ExpectSameRows(scene, true, {"index", "max_exit_speed.exit_speed_mps", "error.code"});
  Json bat = Json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.84, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": {"density_kg_m3": 700, "youngs_modulus_pa": 1.2e10, "cor": 0.5},
            "fill": {"material": "cork", "diameter_m": 0.02, "depth_m": 0.2}},
    "parameters": [{"path": "material.density_kg_m3", "min": -100, "max": 900, "count": 3},
                   {"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 3},
                   {"path": "fill.diameter_m", "min": 0.01, "max": 0.07, "count": 2},
                   {"path": "material.cor", "min": 0.4, "max": 0.6, "count": 2}],
    "outputs": ["max_exit_speed", "properties"]})");
  ExpectSameRows(bat, true, {"parameters.fill.depth_m", "properties.mass_kg", "error.message"});
  // A hollow profile bat: knots and the wall swept, a properties-only row.
  Json profile = Json::parse(R"({
    "bat": {"profile": {"knots": [{"x_m": 0, "radius_m": 0.012}, {"x_m": 0.3, "radius_m": 0.013},
                                  {"x_m": 0.55, "radius_m": 0.03}, {"x_m": 0.8, "radius_m": 0.032}]},
            "material": "aluminium-7046", "wall_thickness_m": 0.003},
    "parameters": [{"path": "profile.knots[2].x_m", "min": 0.2, "max": 0.6, "count": 3},
                   {"path": "profile.knots[1].radius_m", "min": 0.01, "max": 0.02, "count": 2},
                   {"path": "wall_thickness_m", "min": 0.001, "max": 0.02, "count": 2}],
    "outputs": ["properties"]})");
  ExpectSameRows(profile, true, {"properties.mass_kg", "feasible"});
}

TEST(ExploreEngineTest, APresetBallsSweptFieldsMatchTheJsonPath) {
  // ball.preset in the template: each design's ball is the preset's with the swept fields
  // over it, and its COR the preset's law at the design's own speeds, in both paths.
  Json scene = Json::parse(R"({
    "bat": {"preset": "paper-wood"}, "ball": {"preset": "mlb"},
    "parameters": [{"path": "ball.speed_mps", "min": 20, "max": 40, "count": 3},
                   {"path": "ball.mass_kg", "min": 0.14, "max": 0.15, "count": 2},
                   {"path": "swing.angular_speed_rad_s", "min": 10, "max": 50, "count": 2}],
    "outputs": ["max_exit_speed", "center_of_percussion"]})");
  ExpectSameRows(scene, true, {"index", "max_exit_speed.exit_speed_mps", "error.code"});
}

TEST(ExploreEngineTest, OutputsAndPathsTheEngineDoesNotReadDirectlyMatchTheJsonPath) {
  // A sweet zone and a curve are rendered from the JSON row (not direct columns); the swept
  // path is bound.
  Json body = Json::parse(R"({
    "bat": {"preset": "paper-wood"},
    "parameters": [{"path": "ball.mass_kg", "min": 0.1, "max": 0.2, "count": 4}],
    "outputs": ["sweet_zone", "exit_speed_curve"], "options": {"curve_samples": 5}})");
  ExpectSameRows(body, true, {"sweet_zone.from_knob_m", "exit_speed_curve.2.exit_speed_mps"});
  // A fill's own material is not a path the engine binds: the whole sweep takes the JSON path.
  body["bat"]["fill"] = {{"material", {{"density_kg_m3", 100}, {"youngs_modulus_pa", 1e7}}},
                         {"diameter_m", 0.02},
                         {"depth_m", 0.2}};
  body["parameters"] = {
      {{"path", "fill.material.density_kg_m3"}, {"min", 50}, {"max", 400}, {"count", 3}}};
  body["outputs"] = {"max_exit_speed"};
  ExpectSameRows(body, false, {"max_exit_speed.exit_speed_mps"});
}

TEST(ExploreEngineTest, ThreadsBeyondTheSweepsOwnComeFromTheBudget) {
  ThreadBudget budget(2);
  EXPECT_EQ(budget.TryTake(5), 2);  // no more than there are
  EXPECT_EQ(budget.TryTake(1), 0);  // never waits
  budget.Give(1);
  EXPECT_EQ(budget.taken(), 1);
  budget.TakeOne();
  EXPECT_EQ(budget.taken(), 2);
  budget.Give(2);
  EXPECT_EQ(budget.taken(), 0);
  // A sweep with no thread free runs on its own thread alone, with the same rows.
  const Json body = Json::parse(R"({
    "bat": {"preset": "paper-wood"},
    "parameters": [{"path": "ball.speed_mps", "min": 20, "max": 40, "count": 700}],
    "outputs": ["max_exit_speed"], "format": "ndjson"})");
  const ExploreRequest request = Parse(body);
  ASSERT_NE(request.sweep, nullptr);
  Sweep sweep = *request.sweep;
  sweep.threads = 4;
  const std::string free_threads = RunText(sweep, RowFormat::kNdjson, {});
  EXPECT_EQ(budget.TryTake(2), 2);
  sweep.budget = &budget;
  const std::string none_free = RunText(sweep, RowFormat::kNdjson, {});
  EXPECT_EQ(budget.taken(), 2);  // the sweep took none and gave none back
  EXPECT_EQ(none_free, free_threads);
}

// The Pareto front is cut as the values grow (here from 500 values, then at each 8-fold
// growth, instead of 65,536): over 12,000 designs, on one thread and on three, it equals the
// front of all the rows computed at once, and the answer without cuts.
TEST(ExploreEngineTest, ParetoFrontCutAsItGrowsEqualsTheFrontOfAllTheRows) {
  const Json body = Json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "cor": 0.5, "options": {"model": "rigid_pivot"},
    "parameters": [{"path": "three_segment.taper_start_m", "min": 0.20, "max": 0.40, "count": 120},
                   {"path": "three_segment.barrel_radius_m", "min": 0.029, "max": 0.033,
                    "count": 100}],
    "outputs": ["properties", "max_exit_speed"],
    "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                              {"output": "properties.moi_six_inch_kg_m2", "sense": "min"}]}})");
  const ExploreRequest request = Parse(body);
  ASSERT_NE(request.sweep, nullptr);
  const std::vector<ExploreColumn> columns = {MakeColumn("index"),
                                              MakeColumn("max_exit_speed.exit_speed_mps"),
                                              MakeColumn("properties.moi_six_inch_kg_m2")};
  Sweep sweep = *request.sweep;
  std::vector<std::vector<double>> points;
  std::vector<std::uint64_t> index;
  sweep.pareto_cut_min = 1u << 30;  // no cut before the end
  const SweepOutcome whole =
      RunSweep(sweep, RowFormat::kCsv, columns, nullptr, [&](BlockRows& rows) {
        std::size_t pos = 0;
        while (pos < rows.text.size()) {
          const std::size_t end = rows.text.find('\n', pos);
          unsigned long long i = 0;
          double v = 0.0, m = 0.0;
          EXPECT_EQ(std::sscanf(rows.text.c_str() + pos, "%llu,%lf,%lf", &i, &v, &m), 3);
          points.push_back({v, m});  // %lf reads the shortest round-trip text back exactly
          index.push_back(i);
          pos = end + 1;
        }
        return true;
      });
  ASSERT_EQ(points.size(), 12000u);
  Json expected = Json::array();
  for (const std::size_t k :
       core::ParetoFront(points, {core::Sense::kMaximize, core::Sense::kMinimize})) {
    expected.push_back(index[k]);
  }
  EXPECT_EQ(whole.summary["pareto_front"], expected);
  // 832 of the 12,000 designs: cuts drop designs, and keep a front of many.
  EXPECT_GT(expected.size(), 100u);
  EXPECT_LT(expected.size(), 4000u);
  sweep.pareto_cut_min = 500;
  for (const int threads : {1, 3}) {
    sweep.threads = threads;
    const SweepOutcome cut =
        RunSweep(sweep, RowFormat::kCsv, columns, nullptr, [](BlockRows&) { return true; });
    EXPECT_EQ(cut.summary["pareto_front"], expected) << "threads " << threads;
  }
}

// Issue 19: one parameter setting several fields ("paths": one barrel diameter is two knots)
// or scaling a group ("scale_paths"): the engine's rows are the JSON path's, and each design
// is the bat with those fields set, as a single request computes it.
TEST(ExploreEngineTest, LinkedAndScaledPathsSetEveryFieldAndMatchTheJsonPath) {
  const Json bat = Json::parse(R"({"profile": {"knots": [
      {"x_m": 0.0, "radius_m": 0.0125}, {"x_m": 0.3, "radius_m": 0.0125},
      {"x_m": 0.6, "radius_m": 0.032}, {"x_m": 0.8636, "radius_m": 0.032}]},
      "material": "ash"})");
  Json body{{"bat", bat},
            {"cor", 0.5},
            {"parameters",
             {{{"paths", {"profile.knots[2].radius_m", "profile.knots[3].radius_m"}},
               {"min", 0.030},
               {"max", 0.034},
               {"count", 3}},
              {{"scale_paths", {"profile.knots[0].radius_m", "profile.knots[1].radius_m"}},
               {"name", "handle_scale"},
               {"min", 0.9},
               {"max", 1.1},
               {"count", 2}}}},
            {"outputs", {"properties", "max_exit_speed"}}};
  const std::string rows =
      ExpectSameRows(body, true, Json{"parameters.handle_scale", "properties.mass_kg"});
  ASSERT_FALSE(rows.empty());
  // Design 0: barrel radius 0.030 m on both knots, the handle scaled by 0.9.
  const Json row = Json::parse(rows.substr(0, rows.find('\n')));
  EXPECT_EQ(row["parameters"]["profile.knots[2].radius_m+profile.knots[3].radius_m"], 0.030);
  EXPECT_EQ(row["parameters"]["handle_scale"], 0.9);
  Json single = bat;
  single["profile"]["knots"][2]["radius_m"] = 0.030;
  single["profile"]["knots"][3]["radius_m"] = 0.030;
  single["profile"]["knots"][0]["radius_m"] = 0.0125 * 0.9;
  single["profile"]["knots"][1]["radius_m"] = 0.0125 * 0.9;
  const Response one =
      Dispatch({"POST", "/v1/bat/properties", Json{{"bat", single}}.dump()}, Context{});
  ASSERT_EQ(one.status, 200) << one.body.dump();
  EXPECT_EQ(row["properties"]["mass_kg"], one.body["mass_kg"]);  // the same bat, bit for bit

  // Refusals name the field: two forms, a scaled field the template lacks, a bad list.
  Json both = body;
  both["parameters"][0]["path"] = "profile.knots[2].radius_m";
  ApiError error;
  EXPECT_FALSE(ParseExploreRequest(both, Context{}, &error).has_value());
  EXPECT_EQ(error.field, "parameters[0].paths") << error.message;
  Json missing = body;
  missing["bat"]["material"] = "ash";
  missing["parameters"][1]["scale_paths"] = {"material.density_kg_m3"};
  error = ApiError{};
  EXPECT_FALSE(ParseExploreRequest(missing, Context{}, &error).has_value());
  EXPECT_EQ(error.field, "parameters[1].scale_paths[0]") << error.message;
  EXPECT_NE(error.message.find("multiplies the template's value"), std::string::npos)
      << error.message;
  Json empty = body;
  empty["parameters"][0]["paths"] = Json::array();
  error = ApiError{};
  EXPECT_FALSE(ParseExploreRequest(empty, Context{}, &error).has_value());
  EXPECT_EQ(error.field, "parameters[0].paths") << error.message;
}

// Issue 19: a swept field is set in SI; a template that gives the same quantity in a trade
// unit (ball.speed_mph beside a swept ball.speed_mps) has it replaced, so the engine and the
// JSON path give the same rows (the JSON path used to refuse every design: two forms). A path
// may be written in a trade unit too: its values are in that unit, its field the SI one.
TEST(ExploreEngineTest, TradeUnitsInTheTemplateAndInSweptPathsMatchTheJsonPath) {
  Json body = Json::parse(R"({
    "bat": {"three_segment": {"length_in": 34, "handle_diameter_in": 0.98,
            "barrel_diameter_in": 2.6, "taper_start_in": 12, "taper_end_in": 21.6},
            "material": "ash"},
    "ball": {"speed_mph": 60, "mass_oz": 5.1},
    "parameters": [{"path": "ball.speed_mps", "min": 20, "max": 40, "count": 3},
                   {"path": "three_segment.barrel_radius_m", "min": 0.03, "max": 0.034,
                    "count": 2}],
    "outputs": ["max_exit_speed", "properties"]})");
  const std::string rows =
      ExpectSameRows(body, /*expect_bound=*/true, Json{"index", "max_exit_speed.exit_speed_mps"});
  ASSERT_FALSE(rows.empty());
  EXPECT_EQ(rows.find("\"feasible\":false"), std::string::npos) << rows;
  // Design 5 (speed 40 m/s, barrel radius 0.034 m) is the single request with those SI
  // fields in place of the template's trade forms, bit for bit.
  const auto row_of = [](const std::string& ndjson, std::size_t index) {
    std::size_t at = 0;
    for (std::size_t k = 0; k < index; ++k) at = ndjson.find('\n', at) + 1;
    return Json::parse(ndjson.substr(at, ndjson.find('\n', at) - at));
  };
  const Json row = row_of(rows, 5);
  EXPECT_EQ(row["parameters"]["ball.speed_mps"], 40.0);
  EXPECT_EQ(row["parameters"]["three_segment.barrel_radius_m"], 0.034);
  Json single{{"bat", body["bat"]}, {"ball", body["ball"]}, {"outputs", {"max_exit_speed"}}};
  single["ball"].erase("speed_mph");
  single["ball"]["speed_mps"] = 40.0;
  single["bat"]["three_segment"].erase("barrel_diameter_in");
  single["bat"]["three_segment"]["barrel_radius_m"] = 0.034;
  const Response one = Dispatch({"POST", "/v1/sweet-spot", single.dump()}, Context{});
  ASSERT_EQ(one.status, 200) << one.body.dump();
  EXPECT_EQ(row["max_exit_speed"]["exit_speed_mps"], one.body["max_exit_speed"]["exit_speed_mps"]);

  // The same sweep with its paths in trade units: the values as written (mph, diameter in
  // inches) in the rows, the designs those values make. Bound, and the JSON path's rows.
  Json trade = body;
  trade["parameters"] = Json::parse(R"([
      {"path": "ball.speed_mph", "min": 50, "max": 90, "count": 3},
      {"path": "three_segment.barrel_diameter_in", "min": 2.4, "max": 2.7, "count": 2}])");
  const std::string trade_rows = ExpectSameRows(
      trade, true, Json{"parameters.ball.speed_mph", "max_exit_speed.exit_speed_mps"});
  ASSERT_FALSE(trade_rows.empty());
  const Json trade_row = row_of(trade_rows, 5);
  EXPECT_EQ(trade_row["parameters"]["ball.speed_mph"], 90.0);
  EXPECT_EQ(trade_row["parameters"]["three_segment.barrel_diameter_in"], 2.7);
  Json single_trade = single;
  single_trade["ball"].erase("speed_mps");
  single_trade["ball"]["speed_mph"] = 90.0;
  single_trade["bat"]["three_segment"].erase("barrel_radius_m");
  single_trade["bat"]["three_segment"]["barrel_diameter_in"] = 2.7;
  const Response two = Dispatch({"POST", "/v1/sweet-spot", single_trade.dump()}, Context{});
  ASSERT_EQ(two.status, 200) << two.body.dump();
  EXPECT_EQ(trade_row["max_exit_speed"]["exit_speed_mps"],
            two.body["max_exit_speed"]["exit_speed_mps"]);

  // A scaled field the template gives in a trade unit scales its SI value.
  Json scaled = body;
  scaled["parameters"] = Json::parse(
      R"([{"scale_paths": ["ball.speed_mps"], "name": "speed_scale", "min": 1, "max": 1.5,
           "count": 2}])");
  const std::string scaled_rows =
      ExpectSameRows(scaled, true, Json{"max_exit_speed.exit_speed_mps"});
  ASSERT_FALSE(scaled_rows.empty());
  EXPECT_EQ(scaled_rows.find("\"feasible\":false"), std::string::npos) << scaled_rows;

  // A fill's own diameter_m stays the field it is (it is not a trade form of a radius there).
  Json fill = Json::parse(R"({
    "bat": {"preset": "paper-wood", "fill": {"material": "cork", "diameter_in": 1, "depth_m": 0.2}},
    "parameters": [{"path": "fill.diameter_m", "min": 0.02, "max": 0.03, "count": 2}],
    "outputs": ["properties"]})");
  const std::string fill_rows = ExpectSameRows(fill, true, Json{"properties.mass_kg"});
  EXPECT_NE(fill_rows.find("\"fill.diameter_m\":0.03"), std::string::npos) << fill_rows;
  EXPECT_EQ(fill_rows.find("\"feasible\":false"), std::string::npos) << fill_rows;
}

// Issue 19: "report_units": "imperial" rows, and columns that name trade-unit fields (read by
// the engine as the SI value and a conversion), are the JSON path's, byte for byte, for
// feasible and failing designs; a column's value does not depend on report_units.
TEST(ExploreEngineTest, ImperialRowsAndTradeUnitColumnsMatchTheJsonPath) {
  Json body = Json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "cor": 0.5, "report_units": "imperial",
    "parameters": [{"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.6, "count": 12},
                   {"path": "three_segment.taper_end_in", "min": 18, "max": 27, "count": 25}],
    "outputs": ["max_exit_speed", "properties", "center_of_percussion", "collision_efficiency"],
    "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mph", "sense": "max"},
                              {"output": "properties.mass_oz", "sense": "min"}]}})");
  const Json columns = {"index",
                        "parameters.three_segment.taper_end_in",
                        "max_exit_speed.exit_speed_mph",
                        "max_exit_speed.position_from_knob_in",
                        "max_exit_speed.position_from_tip_in",
                        "max_exit_speed.unconstrained_position_from_tip_in",
                        "center_of_percussion.position_from_tip_in",
                        "center_of_percussion.hands_from_knob_in",
                        "center_of_percussion.moi_hands_oz_in2",
                        "properties.mass_oz",
                        "properties.balance_point_in",
                        "properties.moi_knob_oz_in2",
                        "properties.moi_six_inch_oz_in2",
                        "properties.moi_centroid_oz_in2",
                        "properties.length_in",
                        "properties.imperial.weight_oz",
                        "max_exit_speed.exit_speed_mps",
                        "error.code"};
  const std::string rows = ExpectSameRows(body, /*expect_bound=*/true, columns);
  EXPECT_NE(rows.find("\"feasible\":false"), std::string::npos);
  EXPECT_NE(rows.find("\"exit_speed_mph\":"), std::string::npos);
  EXPECT_NE(rows.find("\"position_from_tip_in\":"), std::string::npos);
  EXPECT_NE(rows.find("\"report_units\":\"imperial\""), std::string::npos);  // the summary
  // The named columns are the same values without report_units.
  Json si = body;
  si.erase("report_units");
  si.erase("pareto");
  body.erase("pareto");
  for (Json* b : {&body, &si}) {
    (*b)["format"] = "csv";
    (*b)["columns"] = columns;
  }
  const ExploreRequest imperial_request = Parse(body), si_request = Parse(si);
  ASSERT_NE(imperial_request.sweep, nullptr);
  ASSERT_NE(si_request.sweep, nullptr);
  // RunText's last line is the summary, which says report_units in the imperial sweep only.
  const auto csv_rows = [](const ExploreRequest& request) {
    std::string text = RunText(*request.sweep, RowFormat::kCsv, request.columns);
    text.pop_back();
    return text.substr(0, text.rfind('\n') + 1);
  };
  const std::string imperial_csv = csv_rows(imperial_request);
  EXPECT_EQ(std::count(imperial_csv.begin(), imperial_csv.end(), '\n'), 300);
  EXPECT_EQ(imperial_csv, csv_rows(si_request));
}

// The lean path (core::ClosedFormDesigns: max_exit_speed by a closed form, direct columns):
// its rows are the JSON path's in every format, for designs that change the shape, the swing,
// the COR, the ball, the wall and the material, the failing ones among them (each check the
// lean path runs again per design is failed by some design). A sweep of the shape alone skips
// the knots' own checks, not the wall's or the fill's: a hollow and a filled bat check them.
TEST(ExploreEngineTest, LeanPathRowsMatchTheJsonPath) {
  const Json columns = {"index",
                        "feasible",
                        "max_exit_speed.exit_speed_mps",
                        "max_exit_speed.position_from_knob_m",
                        "max_exit_speed.unconstrained_position_from_knob_m",
                        "max_exit_speed.placement",
                        "max_exit_speed.model",
                        "max_exit_speed.method",
                        "max_exit_speed.exit_speed_mph",
                        "max_exit_speed.position_from_tip_in",
                        "properties.mass_kg",
                        "properties.moi_six_inch_kg_m2",
                        "properties.volume_m3",
                        "properties.length_m",
                        "properties.inertia_model",
                        "properties.imperial.weight_oz",
                        "error.code",
                        "error.message"};
  const Json bat = Json::parse(R"({"three_segment": {"length_m": 0.8636,
      "handle_radius_m": 0.0125, "barrel_radius_m": 0.033, "taper_start_m": 0.30,
      "taper_end_m": 0.55}, "material": {"density_kg_m3": 700, "youngs_modulus_pa": 1.2e10,
      "cor": 0.5}})");
  const std::vector<Json> sweeps = {
      // The shape (taper_start past taper_end fails the shape's check).
      Json::parse(R"([{"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.6, "count": 9},
                      {"path": "three_segment.taper_end_m", "min": 0.45, "max": 0.7, "count": 7}])"),
      // The hands (past the tip), the pivot (the maximum off the bat), the COR (above 1).
      Json::parse(R"([{"path": "swing.hands_from_knob_m", "min": 0.0, "max": 1.0, "count": 5},
                      {"path": "swing.pivot_from_knob_m", "min": -1.0, "max": 2.0, "count": 7},
                      {"path": "cor", "min": 0.2, "max": 1.2, "count": 3}])"),
      // The ball (a zero mass) and the swing's speed (zero: a maximum at an end).
      Json::parse(R"([{"path": "ball.mass_kg", "min": 0.0, "max": 0.3, "count": 4},
                      {"path": "ball.speed_mps", "min": 0.0, "max": 40, "count": 3},
                      {"path": "swing.angular_speed_rad_s", "min": 0, "max": 30, "count": 3}])"),
      // The wall (at or above the handle's radius) and the handle's radius.
      Json::parse(R"([{"path": "wall_thickness_m", "min": 0.0, "max": 0.02, "count": 5},
                      {"path": "three_segment.handle_radius_m", "min": 0.005, "max": 0.02,
                       "count": 4}])"),
      // The shape of a hollow bat (its handle within the wall in some; steps in some).
      Json::parse(R"([{"path": "three_segment.handle_radius_m", "min": 0.005, "max": 0.02,
                       "count": 4},
                      {"path": "three_segment.taper_end_m", "min": 0.3, "max": 0.55, "count": 3}])"),
      // The shape of a filled bat (its barrel around the bore or not).
      Json::parse(R"([{"path": "three_segment.barrel_radius_m", "min": 0.015, "max": 0.035,
                       "count": 5},
                      {"path": "three_segment.taper_end_m", "min": 0.45, "max": 0.8636,
                       "count": 4}])"),
      // The material (a negative density, a COR above 1), the template's cor not given.
      Json::parse(R"([{"path": "material.density_kg_m3", "min": -100, "max": 900, "count": 6},
                      {"path": "material.cor", "min": 0.3, "max": 1.3, "count": 3}])")};
  for (const char* model : {"rigid_pivot", "free_bat"}) {
    for (std::size_t k = 0; k < sweeps.size(); ++k) {
      Json design_bat = bat;
      if (k == 4) design_bat["wall_thickness_m"] = 0.008;
      if (k == 5) {
        design_bat["fill"] = {{"material", "cork"}, {"diameter_m", 0.04}, {"depth_m", 0.3}};
      }
      Json body{{"bat", design_bat},
                {"parameters", sweeps[k]},
                {"outputs", {"max_exit_speed", "properties"}},
                {"options", {{"model", model}}}};
      if (k + 1 < sweeps.size()) body["cor"] = 0.5;
      if (k == 0) {  // Pareto objectives read from the lean path's rows too (the summary's front)
        body["pareto"] = Json::parse(R"({"objectives": [
            {"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
            {"output": "properties.mass_kg", "sense": "min"}]})");
      }
      const ExploreRequest request = Parse(body);
      ASSERT_NE(request.sweep, nullptr);
      ASSERT_TRUE(request.sweep->binder.has_value());
      // The lean path applies (else this test proves nothing about it).
      EXPECT_TRUE(core::ClosedFormDesigns::Applies(request.sweep->options,
                                                   request.sweep->binder->base_scene()))
          << model << " sweep " << k;
      const std::string rows = ExpectSameRows(body, /*expect_bound=*/true, columns);
      EXPECT_NE(rows.find("\"feasible\":false"), std::string::npos) << model << " sweep " << k;
      EXPECT_NE(rows.find("\"feasible\":true"), std::string::npos) << model << " sweep " << k;
    }
  }
}

// Every field an output's api declaration reads directly (api/outputs/: DirectField), as a column
// of a sweep asking for that output alone (max_exit_speed alone goes the lean path), is the
// JSON path's: a new output's direct fields are checked without listing them here.
TEST(ExploreEngineTest, EveryDirectFieldOfEveryOutputMatchesTheJsonPath) {
  int checked = 0;
  for (const ApiOutputDecl* output : ApiOutputTable()) {
    if (output->direct_begin == output->direct_end) continue;
    const std::string name = core::SceneOutputName(output->id);
    Json body = Json::parse(R"({
      "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
              "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
              "material": "ash"},
      "cor": 0.5,
      "parameters": [{"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.6,
                      "count": 12}]})");
    body["outputs"] = Json::array({name});
    Json columns = Json::array({"index"});
    for (const DirectField* f = output->direct_begin; f != output->direct_end; ++f) {
      columns.push_back(name + "." + f->name);
      ++checked;
    }
    ExpectSameRows(body, /*expect_bound=*/true, columns);
  }
  EXPECT_GT(checked, 0);
}

}  // namespace
}  // namespace explore_engine_test
}  // namespace sweetspot::api
