// Issue 19 for /v1/explore: "report_units": "imperial" gives each row's output blocks the fields
// a single /v1/sweet-spot request with report_units imperial gives for that design (the same
// numbers, bit for bit); columns may name those fields whatever report_units says; shards of an
// imperial sweep merge into the unsharded sweep and not with SI shards.
#include <gtest/gtest.h>

#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "api/explore/shards.hpp"
#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace explore_imperial_test {
namespace {

using Json = nlohmann::json;

Response Explore(const Json& body) {
  return Dispatch({"POST", "/v1/explore", body.dump()}, Context{});
}

std::vector<Json> NdjsonLines(const std::string& text) {
  std::vector<Json> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty()) lines.push_back(Json::parse(line));
  }
  return lines;
}

// A three-segment ash bat swept in its taper's end and the pitch's speed (a path written in
// mph), with every output the engine reads directly and two it renders.
Json ImperialSweep() {
  return Json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "cor": 0.5,
    "parameters": [{"path": "three_segment.taper_end_m", "min": 0.5, "max": 0.6, "count": 2},
                   {"path": "ball.speed_mph", "min": 60, "max": 90, "count": 2}],
    "outputs": ["max_exit_speed", "center_of_percussion", "sweet_zone", "exit_speed_curve",
                "properties"],
    "options": {"curve_samples": 5},
    "report_units": "imperial"})");
}

// Every name AddImperial adds in `block` (the numbers whose key is a trade unit's), recursively,
// as dotted paths.
void TradeFields(const Json& block, const std::string& at, std::set<std::string>* out) {
  if (block.is_array()) {
    for (std::size_t i = 0; i < block.size(); ++i) {
      TradeFields(block[i], at + "." + std::to_string(i), out);
    }
    return;
  }
  if (!block.is_object()) return;
  for (const auto& [key, value] : block.items()) {
    if (value.is_structured()) {
      if (key != "imperial")
        TradeFields(value, at + "." + key, out);  // properties.imperial: SI-era names
      continue;
    }
    for (const char* suffix : {"_in", "_oz", "_mph", "_oz_in2"}) {
      const std::string s(suffix);
      if (key.size() > s.size() && key.compare(key.size() - s.size(), s.size(), s) == 0) {
        out->insert(at + "." + key);
      }
    }
  }
}

const Json& At(const Json& root, const std::string& dotted) {
  const Json* node = &root;
  std::istringstream in(dotted);
  for (std::string token; std::getline(in, token, '.');) {
    if (token.empty()) continue;
    node = node->is_array() ? &(*node)[std::stoul(token)] : &(*node)[token];
  }
  return *node;
}

TEST(ExploreImperialTest, ARowsBlocksAreTheSingleRequestsFieldByField) {
  const Response r = Explore(ImperialSweep());
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 4u);
  EXPECT_EQ(r.body["summary"]["report_units"], "imperial");
  for (const Json& row : r.body["rows"]) {
    ASSERT_TRUE(row["feasible"].get<bool>()) << row.dump();
    // The design as a single request, in the units the sweep wrote it.
    Json single{
        {"bat", ImperialSweep()["bat"]},
        {"cor", 0.5},
        {"ball", {{"speed_mph", row["parameters"]["ball.speed_mph"]}}},
        {"outputs", {"max_exit_speed", "center_of_percussion", "sweet_zone", "exit_speed_curve"}},
        {"options", {{"curve_samples", 5}}},
        {"report_units", "imperial"}};
    single["bat"]["three_segment"]["taper_end_m"] = row["parameters"]["three_segment.taper_end_m"];
    const Response one = Dispatch({"POST", "/v1/sweet-spot", single.dump()}, Context{});
    ASSERT_EQ(one.status, 200) << one.body.dump();
    // The parameters are the swept values as written: no trade-unit twins there.
    EXPECT_EQ(row["parameters"].size(), 2u);
    std::size_t compared = 0;
    for (const char* block : {"max_exit_speed", "center_of_percussion", "sweet_zone",
                              "exit_speed_curve", "properties"}) {
      std::set<std::string> in_row, in_single;
      TradeFields(row[block], "", &in_row);
      TradeFields(one.body[block], "", &in_single);
      EXPECT_EQ(in_row, in_single) << block;  // the same fields
      for (const std::string& field : in_row) {
        // The same numbers, bit for bit (the same conversion of the same SI number).
        EXPECT_EQ(At(row[block], field), At(one.body[block], field)) << block << field;
        ++compared;
      }
    }
    // The positions from the tip among them, and enough fields that the loop proves something.
    EXPECT_TRUE(row["max_exit_speed"].contains("position_from_tip_in"));
    EXPECT_TRUE(row["center_of_percussion"].contains("position_from_tip_in"));
    EXPECT_TRUE(row["sweet_zone"].contains("to_knob_in"));
    EXPECT_GE(compared, 20u);
    // And what they mean: 1 mph = 0.44704 m/s, 1 in = 0.0254 m (exact), positions from the tip.
    const Json& max = row["max_exit_speed"];
    EXPECT_EQ(max["exit_speed_mph"].get<double>(), max["exit_speed_mps"].get<double>() / 0.44704);
    EXPECT_EQ(max["position_from_tip_in"].get<double>(),
              (0.8636 - max["position_from_knob_m"].get<double>()) / 0.0254);
  }
  // Without report_units the rows are as before: SI only.
  Json si = ImperialSweep();
  si.erase("report_units");
  const Response s = Explore(si);
  ASSERT_EQ(s.status, 200);
  EXPECT_FALSE(s.body["rows"][0]["max_exit_speed"].contains("exit_speed_mph"));
  EXPECT_FALSE(s.body["summary"].contains("report_units"));
  // The provenance does not depend on report_units (a form of the rows, as format is).
  EXPECT_EQ(s.body["summary"]["provenance"], r.body["summary"]["provenance"]);
}

TEST(ExploreImperialTest, ColumnsNameTradeUnitFieldsAndGetTheRowsValues) {
  const Json full = Explore(ImperialSweep()).body;
  ASSERT_EQ(full["rows"].size(), 4u);
  const std::vector<std::string> names = {"index",
                                          "max_exit_speed.exit_speed_mph",
                                          "max_exit_speed.position_from_tip_in",
                                          "max_exit_speed.position_from_knob_in",
                                          "center_of_percussion.moi_hands_oz_in2",
                                          "sweet_zone.to_knob_in",
                                          "exit_speed_curve.2.position_from_tip_in",
                                          "properties.mass_oz",
                                          "properties.moi_six_inch_oz_in2",
                                          "properties.length_in",
                                          "max_exit_speed.exit_speed_mps"};
  // Only the named columns are written, with report_units imperial or without it.
  for (const bool imperial : {true, false}) {
    Json body = ImperialSweep();
    if (!imperial) body.erase("report_units");
    body["columns"] = names;
    const Response r = Explore(body);
    ASSERT_EQ(r.status, 200) << r.body.dump();
    for (std::size_t i = 0; i < 4; ++i) {
      const Json& flat = r.body["rows"][i];
      EXPECT_EQ(flat.size(), names.size());
      for (const std::string& name : names) {
        EXPECT_EQ(flat[name], At(full["rows"][i], name)) << name << " imperial " << imperial;
      }
    }
  }
  // A misspelt one is refused with the fields known in SI.
  Json bad = ImperialSweep();
  bad["columns"] = {"max_exit_speed.exit_speed_mhp"};
  const Response refused = Explore(bad);
  EXPECT_EQ(refused.status, 400);
  EXPECT_EQ(refused.body["field"], "columns[0]");
  // Parameters are not converted: "parameters.ball.speed_mps" is no column of this sweep.
  bad["columns"] = {"parameters.ball.speed_mps"};
  EXPECT_EQ(Explore(bad).status, 400);
}

TEST(ExploreImperialTest, TheDefaultCsvColumnsAreTheImperialRowsFields) {
  Json body = ImperialSweep();
  body["outputs"] = {"max_exit_speed"};
  body["format"] = "csv";
  const Response r = Explore(body);
  ASSERT_EQ(r.status, 200);
  const std::string header = r.text.substr(0, r.text.find('\n'));
  EXPECT_EQ(header,
            "index,parameters.three_segment.taper_end_m,parameters.ball.speed_mph,feasible,"
            "max_exit_speed.exit_speed_mph,max_exit_speed.exit_speed_mps,max_exit_speed.method,"
            "max_exit_speed.model,max_exit_speed.placement,max_exit_speed.position_from_knob_in,"
            "max_exit_speed.position_from_knob_m,max_exit_speed.position_from_tip_in,"
            "max_exit_speed.unconstrained_position_from_knob_in,"
            "max_exit_speed.unconstrained_position_from_knob_m,"
            "max_exit_speed.unconstrained_position_from_tip_in,error.code");
  body.erase("report_units");
  const Response si = Explore(body);
  ASSERT_EQ(si.status, 200);
  EXPECT_EQ(si.text.substr(0, si.text.find('\n')),
            "index,parameters.three_segment.taper_end_m,parameters.ball.speed_mph,feasible,"
            "max_exit_speed.exit_speed_mps,max_exit_speed.method,max_exit_speed.model,"
            "max_exit_speed.placement,max_exit_speed.position_from_knob_m,"
            "max_exit_speed.unconstrained_position_from_knob_m,error.code");
}

TEST(ExploreImperialTest, ImperialShardsMergeIntoTheUnshardedSweepAndNotWithSiShards) {
  Json body = ImperialSweep();
  body["format"] = "ndjson";
  body["parameters"][0]["count"] = 5;  // 10 designs
  const std::vector<Json> whole = NdjsonLines(Explore(body).text);
  ASSERT_EQ(whole.size(), 11u);
  std::vector<ShardOutput> shards;
  for (int index = 0; index < 3; ++index) {
    body["shard"] = {{"index", index}, {"count", 3}};
    const Response part = Explore(body);
    ASSERT_EQ(part.status, 200) << part.body.dump();
    shards.push_back({"shard-" + std::to_string(index), part.text});
  }
  const MergedSweep merged = MergeExploreShards(shards);
  ASSERT_TRUE(merged.ok) << merged.error;
  std::vector<Json> lines = NdjsonLines(merged.ndjson);
  ASSERT_EQ(lines.size(), whole.size());
  for (std::size_t i = 0; i + 1 < lines.size(); ++i) EXPECT_EQ(lines[i], whole[i]) << i;
  Json merged_summary = lines.back()["summary"], whole_summary = whole.back()["summary"];
  merged_summary.erase("timing_s");
  whole_summary.erase("timing_s");
  EXPECT_EQ(merged_summary, whole_summary);
  EXPECT_EQ(merged_summary["report_units"], "imperial");
  // An SI run of shard 1 is of the same sweep (same provenance) but not the same rows.
  body.erase("report_units");
  body["shard"] = {{"index", 1}, {"count", 3}};
  shards[1] = {"si-shard-1", Explore(body).text};
  const MergedSweep mixed = MergeExploreShards(shards);
  EXPECT_FALSE(mixed.ok);
  EXPECT_EQ(mixed.error,
            "si-shard-1: has report_units \"si\", shard-0 has \"imperial\": run every shard "
            "with the same");
}

}  // namespace
}  // namespace explore_imperial_test
}  // namespace sweetspot::api
