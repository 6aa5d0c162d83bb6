// MergeExploreShards: the NDJSON outputs of a sweep's shards merge into the
// unsharded sweep's NDJSON, row for row and in the summary (but timing_s);
// shards that do not make one complete sweep are refused with the reason.
#include "api/explore/shards.hpp"

#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace explore_shards_test {
namespace {

using Json = nlohmann::json;

// The NDJSON output of /v1/explore for `body` (format ndjson).
std::string Ndjson(Json body) {
  body["format"] = "ndjson";
  const Response r = Dispatch({"POST", "/v1/explore", body.dump()}, Context{});
  EXPECT_EQ(r.status, 200) << r.text << r.body.dump();
  return r.text;
}

std::vector<Json> Lines(const std::string& ndjson) {
  std::vector<Json> lines;
  std::istringstream in(ndjson);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty()) lines.push_back(Json::parse(line));
  }
  return lines;
}

// A sweep over the cork fill's depth and the ball's speed, with a Pareto front
// (exit speed up, mass down: a real trade-off along the depth).
Json Sweep(const char* sampling) {
  Json body = Json::parse(R"({
    "bat": {"preset": "paper-wood",
            "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
    "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 11},
                   {"path": "ball.speed_mps", "min": 20, "max": 40, "count": 3}],
    "outputs": ["max_exit_speed", "properties"],
    "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                              {"output": "properties.mass_kg", "sense": "min"}]}})");
  body["sampling"] = sampling;
  if (std::string(sampling) != "grid") {
    body["samples"] = 25;
    body["seed"] = 7;
  }
  return body;
}

std::vector<ShardOutput> Shards(Json body, int count) {
  std::vector<ShardOutput> shards;
  for (int index = count - 1; index >= 0; --index) {  // any order
    body["shard"] = {{"index", index}, {"count", count}};
    shards.push_back({"shard-" + std::to_string(index) + ".ndjson", Ndjson(body)});
  }
  return shards;
}

TEST(ExploreShardsTest, MergeOfTheShardsEqualsTheUnshardedSweepRowForRowAndInItsSummary) {
  for (const char* sampling : {"grid", "lhs"}) {
    const std::vector<Json> whole = Lines(Ndjson(Sweep(sampling)));
    const MergedSweep merged = MergeExploreShards(Shards(Sweep(sampling), 4));
    ASSERT_TRUE(merged.ok) << merged.error;
    const std::vector<Json> lines = Lines(merged.ndjson);
    ASSERT_EQ(lines.size(), whole.size()) << sampling;
    for (std::size_t i = 0; i + 1 < lines.size(); ++i) EXPECT_EQ(lines[i], whole[i]) << i;
    Json merged_summary = lines.back()["summary"];
    Json whole_summary = whole.back()["summary"];
    EXPECT_GT(merged_summary["timing_s"].get<double>(), 0.0);
    merged_summary.erase("timing_s");  // the shards' sum, not the whole sweep's wall time
    whole_summary.erase("timing_s");
    EXPECT_EQ(merged_summary, whole_summary) << sampling;
    // The front is over all rows: not empty, and not the union of the shards' fronts' sizes.
    EXPECT_FALSE(whole_summary["pareto_front"].empty());
  }
}

// Shards whose rows are flat "columns" rows merge too: the same rows, and the same summary
// (the Pareto front found from the objectives' flat keys).
TEST(ExploreShardsTest, ShardsOfColumnRowsMergeWithTheSameFront) {
  Json sweep = Sweep("grid");
  sweep["columns"] = {"index", "parameters.fill.depth_m", "max_exit_speed.exit_speed_mps",
                      "properties.mass_kg"};
  const std::vector<Json> whole = Lines(Ndjson(sweep));
  const MergedSweep merged = MergeExploreShards(Shards(sweep, 3));
  ASSERT_TRUE(merged.ok) << merged.error;
  const std::vector<Json> lines = Lines(merged.ndjson);
  ASSERT_EQ(lines.size(), whole.size());
  for (std::size_t i = 0; i + 1 < lines.size(); ++i) EXPECT_EQ(lines[i], whole[i]) << i;
  Json merged_summary = lines.back()["summary"];
  Json whole_summary = whole.back()["summary"];
  merged_summary.erase("timing_s");
  whole_summary.erase("timing_s");
  EXPECT_EQ(merged_summary, whole_summary);
  EXPECT_FALSE(whole_summary["pareto_front"].empty());
}

TEST(ExploreShardsTest, EveryShardCarriesTheSweepsProvenance) {
  const std::vector<ShardOutput> shards = Shards(Sweep("grid"), 3);
  const Json whole = Lines(Ndjson(Sweep("grid"))).back()["summary"]["provenance"];
  for (const ShardOutput& shard : shards) {
    EXPECT_EQ(Lines(shard.text).back()["summary"]["provenance"], whole) << shard.name;
  }
}

TEST(ExploreShardsTest, ShardsThatDoNotMakeOneCompleteSweepAreRefusedWithTheReason) {
  std::vector<ShardOutput> shards = Shards(Sweep("grid"), 3);  // shard-2, shard-1, shard-0

  std::vector<ShardOutput> missing = {shards[0], shards[2]};
  MergedSweep r = MergeExploreShards(missing);
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "the shards are incomplete: shard 1 of 3 missing (2 of 3 given)");

  std::vector<ShardOutput> repeated = {shards[0], shards[1], shards[1]};
  r = MergeExploreShards(repeated);
  EXPECT_EQ(r.error, "shard-1.ndjson: repeats shard 1 of 3");

  Json other = Sweep("grid");
  other["parameters"][0]["max"] = 0.2;
  other["shard"] = {{"index", 1}, {"count", 3}};
  std::vector<ShardOutput> foreign = {shards[0], {"other-1.ndjson", Ndjson(other)}, shards[2]};
  r = MergeExploreShards(foreign);
  EXPECT_NE(r.error.find("other-1.ndjson: belongs to another sweep"), std::string::npos) << r.error;

  // A shard cut short: its summary line is missing, or a row is.
  std::vector<ShardOutput> cut = shards;
  cut[1].text = cut[1].text.substr(0, cut[1].text.rfind("{\"summary\""));
  r = MergeExploreShards(cut);
  EXPECT_NE(r.error.find("shard-1.ndjson: has no summary line"), std::string::npos) << r.error;
  cut = shards;
  cut[1].text = cut[1].text.substr(cut[1].text.find('\n') + 1);
  r = MergeExploreShards(cut);
  EXPECT_EQ(r.error, "shard-1.ndjson: has 10 rows; shard 1 of 3 has 11");

  // A cancelled shard ends with an error line.
  cut = shards;
  cut[1].text = R"({"error": {"code": "Cancelled", "message": "cancelled", "field": null}})";
  r = MergeExploreShards(cut);
  EXPECT_NE(r.error.find("shard-1.ndjson: line 1 is an error"), std::string::npos) << r.error;

  // Not NDJSON at all.
  cut = shards;
  cut[2].text = "<html>";
  r = MergeExploreShards(cut);
  EXPECT_EQ(r.error, "shard-0.ndjson: line 1 is not a JSON object");  // shards[2] is shard 0

  EXPECT_EQ(MergeExploreShards({}).error, "no shards given");
}

}  // namespace
}  // namespace explore_shards_test
}  // namespace sweetspot::api
