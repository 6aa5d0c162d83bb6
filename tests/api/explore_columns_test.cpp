// POST /v1/explore with "format": "csv" and "columns": RFC 4180 quoting, the
// default columns, numbers that read back bit for bit, flat column rows in
// json/ndjson, columns refused before the first design, the batch limit.
#include <gtest/gtest.h>

#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "api/explore/columns.hpp"
#include "api/explore/shards.hpp"
#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace explore_columns_test {
namespace {

using Json = nlohmann::json;

Response Explore(const Json& body, const Context& context = {}) {
  return Dispatch({"POST", "/v1/explore", body.dump()}, context);
}

Json CorkSweep() {
  return Json::parse(R"({
    "bat": {"preset": "paper-wood",
            "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
    "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 31}],
    "outputs": ["max_exit_speed", "properties"]})");
}

// A strict RFC 4180 reader: records of fields, LF line ends (what the writer promises).
std::vector<std::vector<std::string>> ReadCsv(const std::string& text) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  std::size_t i = 0;
  while (i < text.size()) {
    if (text[i] == '"') {  // a quoted field: up to the closing quote, "" is a quote
      for (++i; i < text.size(); ++i) {
        if (text[i] == '"') {
          if (i + 1 < text.size() && text[i + 1] == '"') {
            field.push_back('"');
            ++i;
          } else {
            ++i;
            break;
          }
        } else {
          field.push_back(text[i]);
        }
      }
    } else {
      while (i < text.size() && text[i] != ',' && text[i] != '\n') field.push_back(text[i++]);
    }
    EXPECT_TRUE(i < text.size()) << "the last record must end with LF";
    if (i >= text.size()) break;
    record.push_back(std::move(field));
    field.clear();
    if (text[i++] == '\n') records.push_back(std::move(record)), record.clear();
  }
  return records;
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST(ExploreCsvTest, FieldsAreQuotedAsRfc4180Says) {
  const auto field = [](const std::string& text) {
    std::string out;
    AppendCsvField(text, &out);
    return out;
  };
  EXPECT_EQ(field("plain_text 1.5"), "plain_text 1.5");
  EXPECT_EQ(field(""), "");
  EXPECT_EQ(field("a,b"), "\"a,b\"");
  EXPECT_EQ(field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(field("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(field("cr\rhere"), "\"cr\rhere\"");
  EXPECT_EQ(ReadCsv("a,\"b,\"\"c\"\"\nd\",e\n"),
            (std::vector<std::vector<std::string>>{{"a", "b,\"c\"\nd", "e"}}));
}

TEST(ExploreCsvTest, NumbersAreShortestAndReadBackBitForBit) {
  const auto number = [](double value) {
    std::string out;
    AppendCsvNumber(value, &out);
    return out;
  };
  EXPECT_EQ(number(0.1), "0.1");
  EXPECT_EQ(number(0.0), "0");
  EXPECT_EQ(number(-2.5), "-2.5");
  EXPECT_EQ(number(1e-300), "1e-300");
  EXPECT_EQ(number(23.23759724121471), "23.23759724121471");
  EXPECT_EQ(number(std::nan("")), "");  // rows never hold one; an empty cell if one came
  for (const double value : {0.1 + 0.2, 1.0 / 3.0, 6.02214076e23, 5e-324, -0.0, 1e308}) {
    EXPECT_TRUE(SameBits(std::strtod(number(value).c_str(), nullptr), value)) << number(value);
  }
}

// The CSV answer with its default columns carries the values of the JSON answer's rows, every
// number bit for bit (strtod of the cell against the row's double), and nothing else.
TEST(ExploreCsvTest, DefaultColumnsHoldTheJsonRowsValuesBitForBit) {
  Json body = CorkSweep();
  const Response json = Explore(body);
  ASSERT_EQ(json.status, 200) << json.body.dump();
  body["format"] = "csv";
  const Response csv = Explore(body);
  ASSERT_EQ(csv.status, 200) << csv.body.dump();
  EXPECT_EQ(csv.content_type, "text/csv");
  const auto records = ReadCsv(csv.text);
  ASSERT_EQ(records.size(), 32u);  // the header and 31 designs
  const std::vector<std::string> header{"index",
                                        "parameters.fill.depth_m",
                                        "feasible",
                                        "max_exit_speed.exit_speed_mps",
                                        "max_exit_speed.method",
                                        "max_exit_speed.model",
                                        "max_exit_speed.placement",
                                        "max_exit_speed.position_from_knob_m",
                                        "max_exit_speed.unconstrained_position_from_knob_m",
                                        "properties.balance_point_m",
                                        "properties.inertia_model",
                                        "properties.length_m",
                                        "properties.mass_kg",
                                        "properties.moi_centroid_kg_m2",
                                        "properties.moi_knob_kg_m2",
                                        "properties.moi_six_inch_kg_m2",
                                        "properties.volume_m3",
                                        "error.code"};
  ASSERT_EQ(records[0], header);
  std::size_t numbers = 0;
  for (std::size_t r = 1; r < records.size(); ++r) {
    const Json& row = json.body["rows"][r - 1];
    ASSERT_EQ(records[r].size(), header.size());
    for (std::size_t c = 0; c < header.size(); ++c) {
      const std::string& cell = records[r][c];
      const Json* value = FindAt(row, MakeColumn(header[c]).tokens);
      if (value == nullptr) {
        EXPECT_EQ(cell, "") << header[c];
      } else if (value->is_number_float()) {
        char* end = nullptr;
        const double parsed = std::strtod(cell.c_str(), &end);
        EXPECT_EQ(*end, '\0') << cell;
        EXPECT_TRUE(SameBits(parsed, value->get<double>()))
            << header[c] << " row " << r << ": " << cell << " against " << value->dump();
        ++numbers;
      } else if (value->is_string()) {
        EXPECT_EQ(cell, value->get<std::string>());
      } else {
        EXPECT_EQ(cell, value->dump()) << header[c];  // index, true/false
      }
    }
  }
  EXPECT_EQ(numbers, 31u * 11u);  // the parameter and 10 output numbers per row
}

// A failed design is a row with its error.code (and its message quoted, when asked for) and
// empty output cells.
TEST(ExploreCsvTest, FailedDesignsHaveAnErrorCodeAndEmptyOutputs) {
  Json body = CorkSweep();
  // A COR above 1 is refused: "cor = 1.5: must be a number in [0, 1]", a message with a comma.
  body["parameters"] = {{{"path", "cor"}, {"min", 0.0}, {"max", 1.5}, {"count", 4}}};
  body["format"] = "csv";
  body["columns"] = {"index",       "max_exit_speed.exit_speed_mps",
                     "error.code",  "error.message",
                     "error.field", "feasible"};
  const Response csv = Explore(body);
  ASSERT_EQ(csv.status, 200) << csv.body.dump();
  body.erase("format");
  body.erase("columns");
  const Json bad = Explore(body).body["rows"][3];
  ASSERT_FALSE(bad["feasible"].get<bool>());
  const std::string message = bad["error"]["message"].get<std::string>();
  ASSERT_NE(message.find(','), std::string::npos) << "the test needs a message to quote";
  const auto records = ReadCsv(csv.text);
  ASSERT_EQ(records.size(), 5u);
  EXPECT_EQ(records[4], (std::vector<std::string>{"3", "", bad["error"]["code"].get<std::string>(),
                                                  message, "cor", "false"}));
  EXPECT_EQ(records[1][2], "");
  EXPECT_EQ(records[1][5], "true");
  // The quoted field as written: in quotes, its quotes doubled.
  std::string quoted;
  AppendCsvField(message, &quoted);
  EXPECT_EQ(quoted.front(), '"');
  EXPECT_NE(csv.text.find(quoted), std::string::npos);
}

// With "columns", json and ndjson rows are flat objects keyed by the columns' paths (null where
// a row has no value), equal to the full rows' values; the summary is unchanged (but its time),
// and so is the provenance: format and columns are not part of the sweep's identity.
TEST(ExploreCsvTest, ColumnsGiveFlatRowsInJsonAndNdjson) {
  Json body = CorkSweep();
  body["parameters"] = {{{"path", "fill.diameter_m"}, {"min", 0.02}, {"max", 0.08}, {"count", 4}}};
  const Response full = Explore(body);
  ASSERT_EQ(full.status, 200);
  body["columns"] = {"index", "parameters.fill.diameter_m", "max_exit_speed.exit_speed_mps",
                     "error.code"};
  const Response json = Explore(body);
  ASSERT_EQ(json.status, 200) << json.body.dump();
  ASSERT_EQ(json.body["rows"].size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const Json& row = full.body["rows"][i];
    const Json expected{{"index", i},
                        {"parameters.fill.diameter_m", row["parameters"]["fill.diameter_m"]},
                        {"max_exit_speed.exit_speed_mps",
                         i < 3 ? row["max_exit_speed"]["exit_speed_mps"] : Json(nullptr)},
                        {"error.code", i < 3 ? Json(nullptr) : row["error"]["code"]}};
    EXPECT_EQ(json.body["rows"][i], expected) << i;
  }
  Json summary = json.body["summary"], full_summary = full.body["summary"];
  summary.erase("timing_s");
  full_summary.erase("timing_s");
  EXPECT_EQ(summary, full_summary);

  body["format"] = "ndjson";
  const Response ndjson = Explore(body);
  ASSERT_EQ(ndjson.status, 200);
  std::string expected_text;
  for (const Json& row : json.body["rows"]) expected_text += row.dump() + "\n";
  ASSERT_GT(ndjson.text.size(), expected_text.size());
  EXPECT_EQ(ndjson.text.substr(0, expected_text.size()), expected_text);
  const Json last = Json::parse(ndjson.text.substr(expected_text.size()));
  EXPECT_EQ(last["summary"]["provenance"], full.body["summary"]["provenance"]);
}

// A column no row of the sweep can have is refused before the first design: 400 InvalidValue
// naming columns[i], its value and the rule.
TEST(ExploreCsvTest, ColumnsNoRowCanHaveAreRefusedBeforeTheFirstDesign) {
  const auto refusal = [](const Json& columns, const char* format) {
    Json body = CorkSweep();
    body["columns"] = columns;
    body["format"] = format;
    return Explore(body);
  };
  Response r = refusal({"index", "max_exit_speed.exit_speed_mp"}, "csv");
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["code"], "InvalidValue");
  EXPECT_EQ(r.body["field"], "columns[1]");
  EXPECT_EQ(r.body["message"],
            "columns[1] = \"max_exit_speed.exit_speed_mp\": max_exit_speed has no field "
            "\"exit_speed_mp\" (known: exit_speed_mps, method, model, placement, "
            "position_from_knob_m, summary, unconstrained_position_from_knob_m)");

  r = refusal({"vibration_node.frequency_hz"}, "json");  // not a requested output
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "columns[0]");
  EXPECT_EQ(r.body["message"],
            "columns[0] = \"vibration_node.frequency_hz\": a row has no field "
            "\"vibration_node\" (known: error, feasible, index, max_exit_speed, parameters, "
            "properties); outputs and parameters name what a row has");

  r = refusal({"index", "parameters.fill.diameter_m"}, "ndjson");  // not a swept parameter
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["message"],
            "columns[1] = \"parameters.fill.diameter_m\": parameters has no field "
            "\"fill.diameter_m\" (known: fill.depth_m)");

  r = refusal({"properties.mass_kg.value"}, "csv");
  EXPECT_EQ(r.body["message"],
            "columns[0] = \"properties.mass_kg.value\": properties.mass_kg is a number: it has "
            "no field \"value\"");

  r = refusal({"index", "feasible", "index"}, "csv");
  EXPECT_EQ(r.body["field"], "columns[2]");
  EXPECT_EQ(r.body["message"], "columns[2] = \"index\": repeats columns[0]: each column once");

  r = refusal({"index", 3}, "csv");
  EXPECT_EQ(r.body["field"], "columns[1]");
  r = refusal(Json::array(), "csv");
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body["field"], "columns");
  r = refusal("index", "csv");
  EXPECT_EQ(r.body["field"], "columns");

  // Nested parts of an output and array elements are columns too.
  Json body = CorkSweep();
  body["outputs"] = {"exit_speed_curve"};
  body["options"] = {{"curve_samples", 3}};
  body["columns"] = {"index", "exit_speed_curve.2.exit_speed_mps",
                     "exit_speed_curve.9.exit_speed_mps"};
  body["format"] = "csv";
  r = Explore(body);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const auto records = ReadCsv(r.text);
  ASSERT_EQ(records.size(), 32u);
  EXPECT_NE(records[1][1], "");
  EXPECT_EQ(records[1][2], "");  // past the curve's end: an empty cell
  body["columns"] = {"exit_speed_curve.last.exit_speed_mps"};
  r = Explore(body);
  EXPECT_EQ(r.body["message"],
            "columns[0] = \"exit_speed_curve.last.exit_speed_mps\": exit_speed_curve is an "
            "array: the next part must be an index (0, 1, ...), not \"last\"");
}

// A batch (a job, the CLI) has its own limit, max_batch_samples; a request keeps max_samples.
TEST(ExploreCsvTest, BatchesHaveTheirOwnLimit) {
  Context context;
  context.limits.max_samples = 100;
  context.limits.max_batch_samples = 200;
  Json body = CorkSweep();
  body["parameters"][0]["count"] = 150;
  body["format"] = "csv";
  body["columns"] = {"index"};
  Response r = Explore(body, context);
  EXPECT_EQ(r.status, 413);
  EXPECT_EQ(r.body["message"],
            "parameters describe 150 designs, over the limit max_samples = 100 (--max-samples)");
  context.batch = true;
  r = Explore(body, context);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(ReadCsv(r.text).size(), 151u);
  body["parameters"][0]["count"] = 201;
  r = Explore(body, context);
  EXPECT_EQ(r.status, 413);
  EXPECT_EQ(r.body["message"],
            "parameters describe 201 designs, over the limit max_batch_samples = 200 "
            "(--max-batch-samples)");
}

}  // namespace
}  // namespace explore_columns_test
}  // namespace sweetspot::api
