// GET /v1/speed-vs-error serves the committed report (docs/speed-vs-error.json), the report is
// well formed (one auto row per model, finite errors, positive times), and the Markdown and SVG
// written by the same run name every model.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace speed_vs_error_test {
namespace {

std::string ReadDoc(const std::string& name) {
  std::ifstream in(std::string(SWEETSPOT_SOURCE_DIR) + "/docs/" + name, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

nlohmann::json Served() {
  const Response r = Dispatch({"GET", "/v1/speed-vs-error", ""}, Context{});
  EXPECT_EQ(r.status, 200);
  return r.body;
}

TEST(SpeedVsErrorTest, AnswersTheCommittedReport) {
  const nlohmann::json body = Served();
  ASSERT_TRUE(body.is_object());
  ASSERT_TRUE(body["metadata"].is_object());
  EXPECT_TRUE(body["metadata"]["generated"].is_string());
  EXPECT_TRUE(body["metadata"]["command"].is_string());
  EXPECT_TRUE(body["metadata"]["sweetspot_version"].is_string());
  ASSERT_TRUE(body["models"].is_array());
  ASSERT_TRUE(body["rows"].is_array());
  EXPECT_FALSE(body["models"].empty());
  EXPECT_FALSE(body["rows"].empty());
  const nlohmann::json committed =
      nlohmann::json::parse(ReadDoc("speed-vs-error.json"), nullptr, false);
  ASSERT_FALSE(committed.is_discarded()) << "docs/speed-vs-error.json does not parse";
  EXPECT_EQ(body, committed) << "rebuild: the embedded report differs from the file";
}

TEST(SpeedVsErrorTest, EveryModelHasExactlyOneAutoRow) {
  const nlohmann::json body = Served();
  std::map<std::string, int> autos;
  for (const auto& model : body["models"]) autos[model["name"].get<std::string>()] = 0;
  for (const auto& row : body["rows"]) {
    const std::string model = row["model"].get<std::string>();
    ASSERT_TRUE(autos.count(model)) << "row of an undeclared model " << model;
    ASSERT_TRUE(row["is_auto"].is_boolean()) << model;
    if (row["is_auto"].get<bool>()) ++autos[model];
  }
  for (const auto& [model, count] : autos) EXPECT_EQ(count, 1) << model;
}

TEST(SpeedVsErrorTest, ErrorsAreFiniteAndTimesPositive) {
  const nlohmann::json body = Served();
  for (const auto& row : body["rows"]) {
    const std::string what =
        row["model"].get<std::string>() + ": " + row["setting"].get<std::string>();
    ASSERT_TRUE(row["time_per_eval_s"].is_number()) << what;
    ASSERT_TRUE(row["error"].is_number()) << what;
    ASSERT_TRUE(row["relative_error"].is_number()) << what;
    const double time = row["time_per_eval_s"].get<double>();
    const double error = row["error"].get<double>();
    const double relative = row["relative_error"].get<double>();
    EXPECT_TRUE(std::isfinite(time) && time > 0.0) << what;
    EXPECT_TRUE(std::isfinite(error) && error >= 0.0) << what;
    EXPECT_TRUE(std::isfinite(relative) && relative >= 0.0) << what;
    EXPECT_TRUE(row["error_unit"].is_string()) << what;
    EXPECT_TRUE(row["parameters"].is_object()) << what;
    ASSERT_TRUE(row["errors"].is_object()) << what;
    for (const auto& [quantity, e] : row["errors"].items()) {
      ASSERT_TRUE(e["error"].is_number()) << what << " " << quantity;
      EXPECT_GE(e["error"].get<double>(), 0.0) << what << " " << quantity;
      EXPECT_LE(e["relative_error"].get<double>(), relative) << what << " " << quantity;
    }
  }
}

TEST(SpeedVsErrorTest, MarkdownAndPlotNameEveryModelOfTheSameRun) {
  const nlohmann::json body = Served();
  const std::string md = ReadDoc("speed-vs-error.md");
  const std::string svg = ReadDoc("speed-vs-error.svg");
  ASSERT_FALSE(md.empty()) << "docs/speed-vs-error.md is missing";
  ASSERT_FALSE(svg.empty()) << "docs/speed-vs-error.svg is missing";
  for (const auto& model : body["models"]) {
    const std::string name = model["name"].get<std::string>();
    EXPECT_NE(md.find("`" + name + "`"), std::string::npos) << name << " not in the Markdown";
    EXPECT_NE(svg.find(">" + name + "<"), std::string::npos) << name << " not in the plot";
  }
  const std::string generated = body["metadata"]["generated"].get<std::string>();
  EXPECT_NE(md.find(generated), std::string::npos)
      << "docs/speed-vs-error.md is not from the run that wrote the JSON (" << generated << ")";
}

TEST(SpeedVsErrorTest, VersionNamesTheReportsDate) {
  const Response r = Dispatch({"GET", "/v1/version", ""}, Context{});
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.body["speed_vs_error_generated"], Served()["metadata"]["generated"]);
}

}  // namespace
}  // namespace speed_vs_error_test
}  // namespace sweetspot::api
