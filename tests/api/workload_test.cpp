// ClassifyWorkload: which worker pool the server answers a request in.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <memory>
#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace workload_test {
namespace {

Workload Classify(const std::string& method, const std::string& path, const std::string& body) {
  return ClassifyWorkload(method, path, body, Context{});
}

TEST(WorkloadTest, RoutesThatAlwaysRunModelsAreCompute) {
  EXPECT_EQ(Classify("POST", "/v1/explore", "{}"), Workload::kCompute);
  EXPECT_EQ(Classify("POST", "/v1/optimize", "{}"), Workload::kCompute);
  EXPECT_EQ(Classify("POST", "/v1/bat/fit", "{}"), Workload::kCompute);
  EXPECT_EQ(Classify("POST", "/v1/bat/modes", "{}"), Workload::kCompute);
}

TEST(WorkloadTest, CatalogueJobsHealthAndUnknownPathsAreLight) {
  EXPECT_EQ(Classify("GET", "/health", ""), Workload::kLight);
  EXPECT_EQ(Classify("GET", "/metrics", ""), Workload::kLight);
  EXPECT_EQ(Classify("GET", "/v1/presets", ""), Workload::kLight);
  EXPECT_EQ(Classify("POST", "/v1/bat/properties", "{}"), Workload::kLight);
  // Jobs run on the job workers: submitting one is cheap.
  EXPECT_EQ(Classify("POST", "/v1/jobs", R"({"path": "/v1/explore", "body": {}})"),
            Workload::kLight);
  EXPECT_EQ(Classify("GET", "/v1/jobs/abc", ""), Workload::kLight);
  EXPECT_EQ(Classify("GET", "/v1/nowhere", ""), Workload::kLight);
  // A known path with another method is refused at once.
  EXPECT_EQ(Classify("GET", "/v1/explore", ""), Workload::kLight);
}

// A closed-form curve is light up to 10,000 points over all the bats of a body; a compare
// of 65 bats x 10,000 points (57 MB of JSON, six times that while built) is compute work.
TEST(WorkloadTest, LongCurvesOverManyBatsAreCompute) {
  const std::string curve = R"("outputs": ["exit_speed_curve"], "options": {"curve_samples": )";
  EXPECT_EQ(Classify("POST", "/v1/sweet-spot",
                     R"({"bat": {"preset": "paper-wood"}, )" + curve + "10000}}"),
            Workload::kLight);
  EXPECT_EQ(Classify("POST", "/v1/sweet-spot",
                     R"({"bat": {"preset": "paper-wood"}, "outputs": ["exit_speed_curve"]})"),
            Workload::kLight);
  const std::string compare = R"({"baseline": {"preset": "paper-wood"}, "variants": [)"
                              R"({"name": "a", "bat": {"preset": "paper-wood"}}], )";
  EXPECT_EQ(Classify("POST", "/v1/compare", compare + curve + "5000}}"), Workload::kLight);
  EXPECT_EQ(Classify("POST", "/v1/compare", compare + curve + "5001}}"), Workload::kCompute);
  // Explicit positions count like samples: 4000 positions x 3 bats.
  std::string positions = "0.1";
  for (int i = 1; i < 4000; ++i) positions += ", 0.1";
  const std::string three = R"({"baseline": {"preset": "paper-wood"}, "variants": [)"
                            R"({"name": "a", "bat": {"preset": "paper-wood"}},)"
                            R"({"name": "b", "bat": {"preset": "paper-wood"}}], )";
  EXPECT_EQ(Classify("POST", "/v1/compare",
                     three + R"("outputs": ["exit_speed_curve"], "options": )"
                             R"({"curve_positions_from_knob_m": [)" + positions + "]}}"),
            Workload::kCompute);
}

TEST(WorkloadTest, ScenesAreComputeExactlyWhenAnOutputOrModelIsIterative) {
  const std::string bat = R"("bat": {"preset": "paper-wood"})";
  // Closed forms: light.
  EXPECT_EQ(Classify("POST", "/v1/sweet-spot", "{" + bat + "}"), Workload::kLight);
  EXPECT_EQ(Classify("POST", "/v1/sweet-spot",
                     "{" + bat + R"(, "outputs": ["max_exit_speed", "center_of_percussion",
                     "sweet_zone", "exit_speed_curve"], "options": {"model": "free_bat"}})"),
            Workload::kLight);
  EXPECT_EQ(Classify("POST", "/v1/collision", "{" + bat + R"(, "model": "rigid_pivot"})"),
            Workload::kLight);
  // The flexible beam (vibration node, least sting) and the ODE models: compute.
  EXPECT_EQ(Classify("POST", "/v1/sweet-spot", "{" + bat + R"(, "outputs": ["vibration_node"]})"),
            Workload::kCompute);
  EXPECT_EQ(Classify("POST", "/v1/sweet-spot", "{" + bat + R"(, "outputs": ["least_sting_zone"]})"),
            Workload::kCompute);
  EXPECT_EQ(Classify("POST", "/v1/sweet-spot", "{" + bat + R"(, "options": {"model": "hertz"}})"),
            Workload::kCompute);
  EXPECT_EQ(Classify("POST", "/v1/compare",
                     R"({"baseline": {"preset": "paper-wood"}, "variants": [],
                         "options": {"model": "flexible"}})"),
            Workload::kCompute);
  EXPECT_EQ(Classify("POST", "/v1/collision", "{" + bat + R"(, "model": "flexible"})"),
            Workload::kCompute);
  // A name in another field does not count: the body is parsed.
  EXPECT_EQ(
      Classify("POST", "/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}, "note_hertz": 1})"),
      Workload::kLight);
  // A name behind a JSON escape is still seen.
  EXPECT_EQ(
      Classify("POST", "/v1/sweet-spot", "{" + bat + R"(, "outputs": ["vibration_nod\u0065"]})"),
      Workload::kCompute);
  // A body that does not parse is refused at once: light.
  EXPECT_EQ(Classify("POST", "/v1/sweet-spot", R"({"outputs": ["vibration_node")"),
            Workload::kLight);
}

// A scene body parsed to choose the pool is handed on: ClassifyWorkload gives the parsed
// object, and the handler takes it instead of parsing the body (issue 33, item 4).
TEST(WorkloadTest, AParsedSceneBodyIsHandedOnAndTheHandlerDoesNotParseItAgain) {
  const std::string body =
      R"({"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed"],
          "options": {"model": "hertz"}})";
  std::shared_ptr<nlohmann::json> parsed;
  EXPECT_EQ(ClassifyWorkload("POST", "/v1/sweet-spot", body, Context{}, &parsed),
            Workload::kCompute);
  ASSERT_TRUE(parsed);
  EXPECT_EQ(*parsed, nlohmann::json::parse(body));

  // Bodies that were not parsed to decide leave it null: closed-form scenes (the name scan
  // decides), routes that never look at the body, bodies that do not parse.
  std::shared_ptr<nlohmann::json> none;
  EXPECT_EQ(ClassifyWorkload("POST", "/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}})",
                             Context{}, &none),
            Workload::kLight);
  EXPECT_FALSE(none);
  EXPECT_EQ(ClassifyWorkload("POST", "/v1/explore", body, Context{}, &none), Workload::kCompute);
  EXPECT_FALSE(none);
  EXPECT_EQ(ClassifyWorkload("POST", "/v1/sweet-spot", R"({"outputs": ["hertz")", Context{},
                             &none),
            Workload::kLight);
  EXPECT_FALSE(none);

  // The handler answers from the parsed object: its body text here is not JSON at all, so an
  // answer of 200 shows it was not parsed. The object is taken (moved out) once.
  Request request{"POST", "/v1/sweet-spot", "not JSON: the parsed body is used instead"};
  request.parsed_body = std::make_shared<nlohmann::json>(
      nlohmann::json::parse(R"({"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed"]})"));
  const Response answered = Dispatch(request, Context{});
  EXPECT_EQ(answered.status, 200) << answered.body.dump();
  EXPECT_TRUE(answered.body.contains("max_exit_speed")) << answered.body.dump();
  EXPECT_TRUE(request.parsed_body->is_null());
  // A second answer of the same request has nothing to take: it parses the text, and refuses it.
  const Response again = Dispatch(request, Context{});
  EXPECT_EQ(again.status, 400) << again.body.dump();
  EXPECT_EQ(again.body["code"], "InvalidJson") << again.body.dump();

  // The same answer as from the text: the hand-over changes nothing but the parse.
  Request from_text{"POST", "/v1/sweet-spot", body};
  Request from_parsed{"POST", "/v1/sweet-spot", body};
  from_parsed.parsed_body = parsed;
  Response a = Dispatch(from_text, Context{});
  Response b = Dispatch(from_parsed, Context{});
  ASSERT_EQ(a.status, 200) << a.body.dump();
  EXPECT_EQ(a.status, b.status);
  // Timings differ between two answers; the result is the same.
  a.body["max_exit_speed"]["summary"].erase("solve_time_s");
  b.body["max_exit_speed"]["summary"].erase("solve_time_s");
  EXPECT_EQ(a.body["max_exit_speed"], b.body["max_exit_speed"]);
  EXPECT_EQ(a.body["exit_speed_model"], b.body["exit_speed_model"]);
}

}  // namespace
}  // namespace workload_test
}  // namespace sweetspot::api

namespace sweetspot::api {
namespace workload_test_outputs {
namespace {

// The class comes from each output's declaration (core/scene/output_registry.hpp): bbcor_scan
// runs flexible impacts (compute, also when the body is not parsed; it was light then), and so
// does bbcor (THE BBCOR is the scan's maximum, issue 35); barrel is a fixed point of
// microseconds (light, also when the body is parsed).
TEST(WorkloadTest, EachOutputsClassIsItsDeclarations) {
  const std::string bat = R"("bat": {"preset": "paper-wood"})";
  auto classify = [](const std::string& body) {
    return ClassifyWorkload("POST", "/v1/sweet-spot", body, Context{}, nullptr);
  };
  EXPECT_EQ(classify("{" + bat + R"(, "outputs": ["bbcor_scan"]})"), Workload::kCompute);
  EXPECT_EQ(classify("{" + bat + R"(, "outputs": ["barrel", "bbcor"]})"), Workload::kCompute);
  EXPECT_EQ(classify("{" + bat + R"(, "outputs": ["barrel"]})"), Workload::kLight);
  // Parsed (an escape in the body): the same classes.
  EXPECT_EQ(classify("{" + bat + R"(, "outputs": ["barre\u006c", "bbcor"]})"), Workload::kCompute);
  EXPECT_EQ(classify("{" + bat + R"(, "outputs": ["barre\u006c"]})"), Workload::kLight);
  EXPECT_EQ(classify("{" + bat + R"(, "outputs": ["bbcor_sca\u006e"]})"), Workload::kCompute);
}

}  // namespace
}  // namespace workload_test_outputs
}  // namespace sweetspot::api
