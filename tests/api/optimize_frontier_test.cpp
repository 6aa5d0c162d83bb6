// POST /v1/optimize with "frontier" through the router: the rows in JSON, NDJSON and CSV, the
// trade unit of the constraint, shards, and the refusals.
#include <gtest/gtest.h>

#include <sstream>
#include <string>
#include <vector>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace optimize_frontier_test {
namespace {

using Json = nlohmann::json;

Response Post(const Json& body, Context context = Context{}) {
  return Dispatch({"POST", "/v1/optimize", body.dump()}, context);
}

// wood-34-ash with three barrel-side knots free, balance point at most 0.62 m, the mass from
// 31 to 32.5 oz.
Json Frontier(const Json& frontier) {
  return {{"bat", {{"preset", "wood-34-ash"}}},
          {"variables",
           Json::array({{{"path", "profile.knots[7].radius_m"}, {"min", 0.011}, {"max", 0.034}},
                        {{"path", "profile.knots[9].radius_m"}, {"min", 0.011}, {"max", 0.034}},
                        {{"path", "profile.knots[11].radius_m"}, {"min", 0.011}, {"max", 0.034}}})},
          {"constraints", {{"balance_point_m", {{"max", 0.62}}}}},
          {"frontier", frontier}};
}

Json MassOz() { return {{"constraint", "mass_oz"}, {"from", 31}, {"to", 32.5}, {"count", 4}}; }

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

TEST(FrontierApiTest, JsonRowsCarryTheValueAsWrittenAndEachDesignsAnswer) {
  const Response r = Post(Frontier(MassOz()));
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& rows = r.body["rows"];
  ASSERT_EQ(rows.size(), 4u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i]["index"], i);
    // The value in the unit the request wrote (0.5 oz steps), the design's mass equal to it
    // (Ipopt's and SLSQP's constraint tolerance, 1e-10 relative, is far inside 1e-9 oz).
    EXPECT_NEAR(rows[i]["mass_oz"].get<double>(), 31.0 + 0.5 * static_cast<double>(i), 1e-12);
    ASSERT_EQ(rows[i]["summary"]["termination"], "converged") << rows[i]["summary"].dump();
    EXPECT_NEAR(rows[i]["properties"]["mass_kg"].get<double>() / 0.028349523125,
                rows[i]["mass_oz"].get<double>(), 1e-9);
    EXPECT_TRUE(rows[i]["bat"].contains("preset"));  // the request's own form
    EXPECT_EQ(rows[i]["start"]["warm_started"], i > 0);
  }
  const Json& s = r.body["summary"];
  EXPECT_EQ(s["termination"], "converged");
  EXPECT_EQ(s["constraint"], "mass_oz");
  EXPECT_EQ(s["values"], 4);
  EXPECT_EQ(s["converged"], 4);
  EXPECT_EQ(s["continued"], 3);
  EXPECT_TRUE(s["pareto"].is_array());
  EXPECT_TRUE(s["provenance"]["input_hash"].is_string());
}

TEST(FrontierApiTest, NdjsonAndCsvStreamTheSameDesigns) {
  Json json_body = Frontier(MassOz());
  const Response json = Post(json_body);
  ASSERT_EQ(json.status, 200);
  Json nd_body = json_body;
  nd_body["format"] = "ndjson";
  const Response nd = Post(nd_body);
  ASSERT_EQ(nd.status, 200);
  EXPECT_EQ(nd.content_type, "application/x-ndjson");
  const std::vector<std::string> lines = Lines(nd.text);
  ASSERT_EQ(lines.size(), 5u);  // four rows, then the summary
  for (std::size_t i = 0; i < 4; ++i) {
    const Json row = Json::parse(lines[i]);
    // The same computation: the objective to the last bit.
    EXPECT_EQ(row["objective_value"], json.body["rows"][i]["objective_value"]);
  }
  EXPECT_EQ(Json::parse(lines[4])["summary"]["points"], 4);
  Json csv_body = json_body;
  csv_body["format"] = "csv";
  const Response csv = Post(csv_body);
  ASSERT_EQ(csv.status, 200);
  EXPECT_EQ(csv.content_type, "text/csv");
  const std::vector<std::string> csv_lines = Lines(csv.text);
  ASSERT_EQ(csv_lines.size(), 5u);  // header and four rows
  EXPECT_EQ(csv_lines[0].rfind("index,mass_oz,summary.termination,objective_value,", 0), 0u)
      << csv_lines[0];
  EXPECT_NE(csv_lines[0].find("variables.profile.knots[7].radius_m"), std::string::npos);
  EXPECT_EQ(csv_lines[2].rfind("1,31.5,converged,", 0), 0u) << csv_lines[2];
}

TEST(FrontierApiTest, ShardsAreContiguousBlocksWithTheirGlobalIndices) {
  Json body = Frontier(MassOz());
  body["shard"] = {{"index", 1}, {"count", 2}};
  const Response r = Post(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  ASSERT_EQ(r.body["rows"].size(), 2u);
  EXPECT_EQ(r.body["rows"][0]["index"], 2);
  EXPECT_DOUBLE_EQ(r.body["rows"][0]["mass_oz"].get<double>(), 32.0);
  EXPECT_EQ(r.body["summary"]["first_index"], 2);
  // Every shard carries the whole frontier's provenance (its identity: no shard, no format).
  const Response whole = Post(Frontier(MassOz()));
  EXPECT_EQ(r.body["summary"]["provenance"]["input_hash"],
            whole.body["summary"]["provenance"]["input_hash"]);
}

TEST(FrontierApiTest, RefusalsNameTheFieldAndTheRule) {
  const auto refused = [](const Json& body, int status = 400) {
    const Response r = Post(body);
    EXPECT_EQ(r.status, status) << r.body.dump();
    return r.body;
  };
  Json unknown = Frontier({{"constraint", "mass_lb"}, {"values", {1, 2}}});
  EXPECT_EQ(refused(unknown)["field"], "frontier.constraint");
  Json twice = Frontier(MassOz());
  twice["constraints"]["mass_oz"] = 31;
  const Json both = refused(twice);
  EXPECT_EQ(both["field"], "constraints.mass_oz");
  EXPECT_NE(both["message"].get<std::string>().find("frontier's constraint"), std::string::npos);
  Json repeated = Frontier({{"constraint", "mass_oz"}, {"values", {31, 32, 31}}});
  EXPECT_EQ(refused(repeated)["field"], "frontier.values[2]");
  Json no_count = Frontier({{"constraint", "mass_oz"}, {"from", 31}, {"to", 32}});
  EXPECT_EQ(refused(no_count)["field"], "frontier.count");
  Json mixed = Frontier({{"constraint", "mass_oz"}, {"values", {31}}, {"count", 3}});
  EXPECT_EQ(refused(mixed)["field"], "frontier.values");
  Json typo = Frontier({{"constraint", "mass_oz"}, {"values", {31}}, {"warmstart", false}});
  EXPECT_EQ(refused(typo)["field"], "frontier.warmstart");
  // More values than the configured limit: 413 naming the limit and its flag.
  Context small;
  small.limits.max_frontier_values = 3;
  const Response big = Post(Frontier({{"constraint", "mass_oz"}, {"values", {30, 31, 32, 33}}}),
                            small);
  EXPECT_EQ(big.status, 413) << big.body.dump();
  EXPECT_NE(big.body["message"].get<std::string>().find("--max-frontier-values"),
            std::string::npos);
  Json empty_shard = Frontier({{"constraint", "mass_oz"}, {"values", {31}}});
  empty_shard["shard"] = {{"index", 0}, {"count", 2}};  // one value: shard 0 of 2 gets none
  EXPECT_EQ(refused(empty_shard)["field"], "shard.count");
}

}  // namespace
}  // namespace optimize_frontier_test
}  // namespace sweetspot::api
