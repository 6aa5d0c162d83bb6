// Every ranged integer field of the optimize, explore and jobs parsers against the served
// OpenAPI document: the document states minimum and maximum, and the parser accepts exactly
// that range (the minimum and maximum pass, one below and one above are refused with 400
// naming the field). Parsing only: Context::validate_only (POST /v1/jobs's check), so no
// solve or sweep runs. The maxima tied to a configured limit are the defaults (ApiLimits{}).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "api/job_service.hpp"
#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace openapi_ranges_test {
namespace {

using Json = nlohmann::json;

// The contract's optimisation (tests/api/optimize_test.cpp).
Json Optimisation() {
  return Json::parse(R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5}],
    "constraints": {"mass_kg": 0.88},
    "objective": "max_exit_speed", "cor": 0.5, "options": {}})");
}

// A small sweep with every ranged field present, so each can be set in place.
Json Sweep() {
  return Json::parse(R"({
    "bat": {"preset": "paper-wood"},
    "parameters": [{"path": "cor", "min": 0.4, "max": 0.6, "count": 3}],
    "shard": {"index": 0, "count": 1099511627776},
    "options": {"method": "nlopt", "nlopt": {}}})");
}

struct RangedField {
  std::string route;           // the endpoint
  std::string schema_pointer;  // the field's schema in the OpenAPI document
  std::string body_pointer;    // where the field is in the request body
  std::string field;           // the error's "field" for a refused value
};

const std::vector<RangedField>& Fields() {
  static const std::string optimize_options =
      "/paths/~1v1~1optimize/post/requestBody/content/application~1json/schema/properties/"
      "options/properties/";
  static const std::string explore =
      "/paths/~1v1~1explore/post/requestBody/content/application~1json/schema/properties/";
  static const std::vector<RangedField> fields = {
      {"/v1/optimize", optimize_options + "starts", "/options/starts", "options.starts"},
      {"/v1/optimize", optimize_options + "seed", "/options/seed", "options.seed"},
      {"/v1/optimize", optimize_options + "max_iterations", "/options/max_iterations",
       "options.max_iterations"},
      {"/v1/explore", explore + "samples", "/samples", "samples"},
      {"/v1/explore", explore + "seed", "/seed", "seed"},
      {"/v1/explore", explore + "parameters/items/properties/count", "/parameters/0/count",
       "parameters[0].count"},
      {"/v1/explore", explore + "shard/properties/index", "/shard/index", "shard.index"},
      {"/v1/explore", explore + "shard/properties/count", "/shard/count", "shard.count"},
      {"/v1/explore", explore + "options/properties/nlopt/properties/max_evaluations",
       "/options/nlopt/max_evaluations", "options.nlopt.max_evaluations"},
      {"/v1/explore", explore + "options/properties/nlopt/properties/seed", "/options/nlopt/seed",
       "options.nlopt.seed"},
      {"/v1/explore", explore + "options/properties/curve_samples", "/options/curve_samples",
       "options.curve_samples"},
      {"/v1/explore", "/components/schemas/HertzOptions/properties/max_steps",
       "/options/hertz/max_steps", "options.hertz.max_steps"},
  };
  return fields;
}

Json OpenApi() { return Dispatch({"GET", "/openapi.json", ""}, Context{}).body; }

// The endpoint's answer to `body` with the field at `pointer` set to `value`, parsing only.
Response Check(const RangedField& f, long long value, const ApiLimits& limits) {
  Json body = f.route == "/v1/optimize" ? Optimisation() : Sweep();
  if (f.body_pointer.rfind("/options/hertz", 0) == 0) body["options"]["model"] = "hertz";
  if (f.body_pointer == "/samples" || f.body_pointer == "/seed") {  // lhs: samples and a seed
    body["sampling"] = "lhs";
    body["samples"] = 4;
  }
  body[Json::json_pointer(f.body_pointer)] = value;
  Context context;
  context.validate_only = true;
  context.limits = limits;
  return Dispatch({"POST", f.route, body.dump()}, context);
}

TEST(OpenApiRangesTest, EveryRangedIntegerIsDocumentedAndIsTheParsersRange) {
  const Json document = OpenApi();
  ApiLimits limits;  // the defaults the document states
  // parameters[0].count's maximum is its own (1e9); the grid's total is capped by
  // --max-samples besides (documented), so that cap is lifted here to reach it.
  ApiLimits lifted = limits;
  lifted.max_samples = 1000000000;
  for (const RangedField& f : Fields()) {
    SCOPED_TRACE(f.field);
    const Json& schema = document[Json::json_pointer(f.schema_pointer)];
    ASSERT_EQ(schema.value("type", ""), "integer") << schema.dump();
    ASSERT_TRUE(schema.contains("minimum") && schema.contains("maximum")) << schema.dump();
    const long long min = schema["minimum"];
    const long long max = schema["maximum"];
    const ApiLimits& use = f.field == "parameters[0].count" ? lifted : limits;
    for (long long ok : {min, max}) {
      const Response r = Check(f, ok, use);
      EXPECT_EQ(r.status, 200) << ok << ": " << r.body.dump();
    }
    for (long long bad : {min - 1, max + 1}) {
      const Response r = Check(f, bad, use);
      EXPECT_EQ(r.status, 400) << bad << ": " << r.body.dump();
      EXPECT_EQ(r.body.value("field", Json()), f.field) << bad << ": " << r.body.dump();
    }
  }
}

// GET /v1/jobs's limit and offset: the document's parameters against the handler's range.
class NoJobs final : public JobService {
 public:
  Response Submit(const Request&) override { return {202, Json::object()}; }
  Response Status(const std::string&) const override { return {200, Json::object()}; }
  Response List(const JobListQuery&) const override { return {200, Json::object()}; }
  Response Result(const std::string&) const override { return {200, Json::object()}; }
  Response Cancel(const std::string&) override { return {200, Json::object()}; }
  std::map<std::string, int> CountsByState() const override { return {}; }
};

TEST(OpenApiRangesTest, JobListParametersAreTheHandlersRange) {
  const Json document = OpenApi();
  NoJobs jobs;
  Context context;
  context.jobs = &jobs;
  int checked = 0;
  for (const Json& parameter : document["paths"]["/v1/jobs"]["get"]["parameters"]) {
    if (parameter["schema"]["type"] != "integer") continue;
    const std::string name = parameter["name"];
    SCOPED_TRACE(name);
    const long long min = parameter["schema"]["minimum"];
    const long long max = parameter["schema"]["maximum"];
    for (long long ok : {min, max}) {
      EXPECT_EQ(Dispatch({"GET", "/v1/jobs", "", {{name, std::to_string(ok)}}}, context).status,
                200)
          << ok;
    }
    for (long long bad : {min - 1, max + 1}) {
      const Response r = Dispatch({"GET", "/v1/jobs", "", {{name, std::to_string(bad)}}}, context);
      EXPECT_EQ(r.status, 400) << bad;
      EXPECT_EQ(r.body["field"], name) << bad;
    }
    ++checked;
  }
  EXPECT_EQ(checked, 2);  // limit and offset
}

// The ranged numbers of the same parsers: the document's bounds, exclusive or not, against the
// parser's, to the last double (std::nextafter on each side of each bound).
TEST(OpenApiRangesTest, EveryRangedNumberIsDocumentedAndIsTheParsersRange) {
  const Json document = OpenApi();
  const std::string optimize_options =
      "/paths/~1v1~1optimize/post/requestBody/content/application~1json/schema/properties/"
      "options/properties/";
  const std::string explore =
      "/paths/~1v1~1explore/post/requestBody/content/application~1json/schema/properties/";
  const std::string nlopt = explore + "options/properties/nlopt/properties/";
  const std::vector<RangedField> fields = {
      {"/v1/optimize", optimize_options + "max_time_s", "/options/max_time_s",
       "options.max_time_s"},
      {"/v1/optimize", optimize_options + "max_cpu_time_s", "/options/max_cpu_time_s",
       "options.max_cpu_time_s"},
      {"/v1/optimize", optimize_options + "tolerance", "/options/tolerance", "options.tolerance"},
      {"/v1/optimize", optimize_options + "constraint_tolerance", "/options/constraint_tolerance",
       "options.constraint_tolerance"},
      {"/v1/explore", nlopt + "x_tolerance_m", "/options/nlopt/x_tolerance_m",
       "options.nlopt.x_tolerance_m"},
      {"/v1/explore", nlopt + "max_time_s", "/options/nlopt/max_time_s",
       "options.nlopt.max_time_s"},
      // The swept range's ends.
      {"/v1/explore", explore + "parameters/items/properties/min", "/parameters/0/min",
       "parameters[0].min"},
      {"/v1/explore", explore + "parameters/items/properties/max", "/parameters/0/max",
       "parameters[0].max"},
  };
  for (const RangedField& f : fields) {
    SCOPED_TRACE(f.field);
    const Json& schema = document[Json::json_pointer(f.schema_pointer)];
    ASSERT_EQ(schema.value("type", ""), "number") << schema.dump();
    ASSERT_TRUE(schema.contains("minimum") && schema.contains("maximum")) << schema.dump();
    const double min = schema["minimum"];
    const double max = schema["maximum"];
    const bool min_exclusive = schema.value("exclusiveMinimum", false);
    const bool max_exclusive = schema.value("exclusiveMaximum", false);
    const double inf = std::numeric_limits<double>::infinity();
    auto check = [&](double value, bool accepted) {
      Json body = f.route == "/v1/optimize" ? Optimisation() : Sweep();
      body[Json::json_pointer(f.body_pointer)] = value;
      // The other end of a swept range at its own bound, so that min <= max holds.
      if (f.body_pointer == "/parameters/0/min") body["parameters"][0]["max"] = max;
      if (f.body_pointer == "/parameters/0/max") body["parameters"][0]["min"] = min;
      Context context;
      context.validate_only = true;
      const Response r = Dispatch({"POST", f.route, body.dump()}, context);
      EXPECT_EQ(r.status, accepted ? 200 : 400) << value << ": " << r.body.dump();
      if (!accepted) {
        EXPECT_EQ(r.body.value("field", Json()), f.field) << value;
      }
    };
    check(min, !min_exclusive);
    check(std::nextafter(min, inf), true);
    check(std::nextafter(min, -inf), false);
    check(max, !max_exclusive);
    check(std::nextafter(max, -inf), true);
    check(std::nextafter(max, inf), false);
  }
}

}  // namespace
}  // namespace openapi_ranges_test
}  // namespace sweetspot::api
