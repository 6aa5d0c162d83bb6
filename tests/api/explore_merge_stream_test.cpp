// MergeShardStreams (api/explore/merge_stream.hpp): the shards of a sweep, NDJSON or CSV,
// merged as streams into the unsharded sweep's bytes (NDJSON: but the summary's timing_s, a
// measured time); shards that do not make one sweep refused before a byte is written, the
// missing ones named.
#include "api/explore/merge_stream.hpp"

#include <gtest/gtest.h>

#include <memory>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace explore_merge_stream_test {
namespace {

using Json = nlohmann::json;

// The text of /v1/explore for `body` in `format`, as one shard (count 1: the whole sweep).
std::string Explore(Json body, const std::string& format, int index = 0, int count = 1) {
  body["format"] = format;
  if (count > 1) body["shard"] = {{"index", index}, {"count", count}};
  const Response r = Dispatch({"POST", "/v1/explore", body.dump()}, Context{});
  EXPECT_EQ(r.status, 200) << r.text << r.body.dump();
  return r.text;
}

// 23 Sobol designs over the cork fill's depth and the COR, whose last values (over 1) are
// refused: failed designs' rows (with an "error" field) among the rows, and a Pareto front.
Json Sweep() {
  return Json::parse(R"({
    "bat": {"preset": "paper-wood",
            "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
    "sampling": "sobol", "samples": 23, "seed": 3,
    "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3},
                   {"path": "cor", "min": 0.3, "max": 1.2}],
    "outputs": ["max_exit_speed", "properties"],
    "pareto": {"objectives": [{"output": "max_exit_speed.exit_speed_mps", "sense": "max"},
                              {"output": "properties.mass_kg", "sense": "min"}]}})");
}

struct Merged {
  StreamedMerge result;
  std::string text;
  int writes = 0;
};

Merged Merge(const std::vector<std::string>& names, const std::vector<std::string>& texts,
             std::size_t chunk = 1u << 20) {
  Merged m;
  MergeStreamOptions options;
  options.sink_chunk_bytes = chunk;
  m.result = MergeShardStreams(
      names,
      [&texts](std::size_t k) -> std::unique_ptr<std::istream> {
        return std::make_unique<std::istringstream>(texts[k]);
      },
      [&m](std::string_view bytes) {
        m.text.append(bytes.data(), bytes.size());
        ++m.writes;
        return true;
      },
      {}, options);
  return m;
}

// The shards' texts in the order given by `order` (shard indices), and their names.
void Shards(const Json& sweep, const std::string& format, int count, const std::vector<int>& order,
            std::vector<std::string>* names, std::vector<std::string>* texts) {
  for (const int i : order) {
    names->push_back("shard-" + std::to_string(i) + "." + format);
    texts->push_back(Explore(sweep, format, i, count));
  }
}

std::string Untimed(const std::string& ndjson) {
  return std::regex_replace(ndjson, std::regex("\"timing_s\":[-0-9.e+]+"), "\"timing_s\":T");
}

TEST(ExploreMergeStreamTest, NdjsonShardsMergeIntoTheUnshardedBytesButTimingS) {
  const std::string whole = Explore(Sweep(), "ndjson");
  ASSERT_NE(whole.find("\"feasible\":false"), std::string::npos);  // failed rows are merged too
  for (const int count : {1, 2, 4, 23, 30}) {  // 30 > 23 designs: shards without rows
    std::vector<int> order;
    for (int i = count - 1; i >= 0; --i) order.push_back(i);  // any order
    std::vector<std::string> names, texts;
    Shards(Sweep(), "ndjson", count, order, &names, &texts);
    const Merged m = Merge(names, texts, /*chunk=*/1000);  // several writes
    ASSERT_TRUE(m.result.ok()) << m.result.error;
    EXPECT_EQ(m.result.format, "ndjson");
    EXPECT_EQ(m.result.rows, 23u);
    EXPECT_EQ(m.result.shards, static_cast<std::uint64_t>(count));
    EXPECT_EQ(Untimed(m.text), Untimed(whole)) << count;
    EXPECT_GT(m.writes, 1);
  }
  // The front is the whole sweep's: it is not empty and it is not any shard's.
  const Json summary = Json::parse(whole.substr(whole.rfind("{\"summary\"")))["summary"];
  EXPECT_GE(summary["pareto_front"].size(), 2u);
  EXPECT_GT(summary["failed"].get<int>(), 0);
}

TEST(ExploreMergeStreamTest, CsvShardsMergeIntoTheUnshardedBytes) {
  Json sweep = Sweep();
  const std::string whole = Explore(sweep, "csv");
  std::vector<std::string> names, texts;
  Shards(sweep, "csv", 4, {2, 0, 3, 1}, &names, &texts);
  Merged m = Merge(names, texts);
  ASSERT_TRUE(m.result.ok()) << m.result.error;
  EXPECT_EQ(m.result.format, "csv");
  EXPECT_EQ(m.text, whole);
  // With columns, a quoted field holding a comma (a refusal's message), index not first.
  sweep["columns"] = {"error.message", "index", "max_exit_speed.exit_speed_mps"};
  const std::string flat = Explore(sweep, "csv");
  ASSERT_NE(flat.find("\"cor = "), std::string::npos) << flat;
  names.clear();
  texts.clear();
  Shards(sweep, "csv", 3, {0, 1, 2}, &names, &texts);
  m = Merge(names, texts);
  ASSERT_TRUE(m.result.ok()) << m.result.error;
  EXPECT_EQ(m.text, flat);
}

TEST(ExploreMergeStreamTest, MissingShardsAreNamedAndNothingIsWritten) {
  for (const std::string format : {"ndjson", "csv"}) {
    std::vector<std::string> names, texts;
    Shards(Sweep(), format, 5, {0, 2, 4}, &names, &texts);
    const Merged m = Merge(names, texts);
    EXPECT_EQ(m.result.status, MergeStatus::kRefused);
    EXPECT_EQ(m.result.error, "the shards are incomplete: shards 1 and 3 of 5 missing (3 of 5 given)")
        << format;
    EXPECT_EQ(m.writes, 0);
    EXPECT_EQ(m.text, "");
  }
  EXPECT_EQ(MissingShardsMessage({2}, 4), "shard 2 of 4 missing");
  EXPECT_EQ(MissingShardsMessage({0, 1, 3}, 4), "shards 0, 1 and 3 of 4 missing");
  std::vector<std::uint64_t> many;
  for (std::uint64_t i = 0; i < 25; ++i) many.push_back(i);
  EXPECT_EQ(MissingShardsMessage(many, 100),
            "shards 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19 and 5 "
            "more of 100 missing");
}

TEST(ExploreMergeStreamTest, RepeatedAndOverlappingShardsAreRefused) {
  std::vector<std::string> names, texts;
  Shards(Sweep(), "ndjson", 3, {0, 1, 1, 2}, &names, &texts);
  Merged m = Merge(names, texts);
  EXPECT_EQ(m.result.error, "shard-1.ndjson: repeats shard 1 of 3");
  EXPECT_EQ(m.writes, 0);
  // Shards of one sweep split in 2 and in 4: shard 1 of 2 overlaps shards 1 and 3 of 4.
  names = {"a.ndjson", "b.ndjson"};
  texts = {Explore(Sweep(), "ndjson", 0, 2), Explore(Sweep(), "ndjson", 1, 4)};
  m = Merge(names, texts);
  EXPECT_EQ(m.result.error, "b.ndjson: has shard count 4 and 23 designs, a.ndjson has 2 and 23");
  // The same in CSV, where the count is the rows' step.
  names.clear();
  texts.clear();
  Shards(Sweep(), "csv", 3, {0, 1, 1, 2}, &names, &texts);
  m = Merge(names, texts);
  EXPECT_EQ(m.result.error, "shard-1.csv: repeats shard 1 of 3 (shard-1.csv is shard 1 too)");
  names = {"a.csv", "b.csv", "c.csv"};
  texts = {Explore(Sweep(), "csv", 0, 2), Explore(Sweep(), "csv", 1, 2), Explore(Sweep(), "csv", 1, 4)};
  m = Merge(names, texts);
  EXPECT_EQ(m.result.error,
            "c.csv: its rows step by 4, a.csv's by 2: shards of sweeps split in different counts");
  EXPECT_EQ(m.writes, 0);
}

TEST(ExploreMergeStreamTest, ShardsCutShortOrOutOfOrderAreRefused) {
  std::vector<std::string> names, texts;
  Shards(Sweep(), "csv", 2, {0, 1}, &names, &texts);
  std::vector<std::string> cut = texts;
  cut[1].pop_back();  // the last row without its line end: the shard did not finish
  Merged m = Merge(names, cut);
  EXPECT_NE(m.result.error.find("shard-1.csv: line 12 is cut short"), std::string::npos)
      << m.result.error;
  cut = texts;
  cut[1] = cut[1].substr(0, cut[1].rfind('\n', cut[1].size() - 2) + 1);  // its last row gone
  m = Merge(names, cut);
  EXPECT_EQ(m.result.error,
            "shard-1.csv: has 10 rows and shard-0.csv (shard 0) has 12: shard 1 of 2 has as many "
            "or one fewer, and no more than shard 0 (a shard cut short?)");
  // NDJSON: two rows swapped.
  names.clear();
  texts.clear();
  Shards(Sweep(), "ndjson", 2, {0, 1}, &names, &texts);
  std::istringstream in(texts[1]);
  std::string a, b, rest;
  std::getline(in, a);
  std::getline(in, b);
  rest.assign(std::istreambuf_iterator<char>(in), {});
  texts[1] = b + "\n" + a + "\n" + rest;
  m = Merge(names, texts);
  EXPECT_EQ(m.result.error,
            "shard-1.ndjson: line 2: row index 1 comes after 3: the rows are not in index order");
  EXPECT_EQ(Merge({}, {}).result.error, "no shards given");
}

}  // namespace
}  // namespace explore_merge_stream_test
}  // namespace sweetspot::api
