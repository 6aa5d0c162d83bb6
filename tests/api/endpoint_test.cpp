// The typed-endpoint driver (api/handlers/endpoint.hpp): a refused body or request never reaches
// the core call, a failure is answered before rendering, a 200 carries timing_s (and the
// summary and provenance the endpoint declares), unmet targets are a 422 with the answer as
// "closest", and an exception from a core call reaches the router's one catch (500).
#include "api/handlers/endpoint.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "api/router.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace endpoint_test {
namespace {

using Json = nlohmann::json;

// A toy endpoint: {"x": number >= 0, "options": any} -> x * 2, counting how often each step ran.
struct Calls {
  int parse = 0;
  int run = 0;
  int render = 0;
};

struct Doubled {
  double value = 0.0;
  core::Summary summary;
};

Endpoint<double, Doubled> Doubler(Calls* calls) {
  Endpoint<double, Doubled> e;
  e.parse = [calls](const Json& body, const Context&, ApiError* error) -> std::optional<double> {
    ++calls->parse;
    ObjectReader reader(body, "", error);
    double x = 0.0;
    reader.Number("x", NonNegative(), &x);
    reader.Skip("options");  // recorded by the provenance only
    if (!reader.Finish()) return std::nullopt;
    return x;
  };
  e.run = [calls](const double& x, const Context&) {
    ++calls->run;
    Doubled out;
    out.value = 2.0 * x;
    out.summary.termination = core::Termination::kConverged;
    out.summary.backend = "closed_form";
    return out;
  };
  e.render = [calls](const double&, const Doubled& result) {
    ++calls->render;
    return Json{{"value", result.value}};
  };
  return e;
}

Response Serve(const Endpoint<double, Doubled>& endpoint, const std::string& body) {
  return ServeEndpoint(endpoint, {"POST", "/test", body}, Context{});
}

TEST(EndpointTest, ARefusedBodyOrRequestNeverReachesTheCoreCall) {
  Calls calls;
  const auto endpoint = Doubler(&calls);
  const Response not_json = Serve(endpoint, "{\"x\": ");
  EXPECT_EQ(not_json.status, 400);
  EXPECT_EQ(not_json.body["code"], "InvalidJson");
  const Response not_object = Serve(endpoint, "[1]");
  EXPECT_EQ(not_object.status, 400);
  EXPECT_EQ(not_object.body["code"], "InvalidValue");
  EXPECT_EQ(calls.parse, 0);  // neither is an object: parse is not called

  const Response negative = Serve(endpoint, R"({"x": -1})");
  EXPECT_EQ(negative.status, 400);
  EXPECT_EQ(negative.body["code"], "InvalidValue");
  EXPECT_EQ(negative.body["field"], "x");
  const Response unknown = Serve(endpoint, R"({"x": 1, "y": 2})");
  EXPECT_EQ(unknown.status, 400);
  EXPECT_EQ(unknown.body["code"], "UnknownField");
  EXPECT_EQ(calls.parse, 2);
  EXPECT_EQ(calls.run, 0);
  EXPECT_EQ(calls.render, 0);
}

TEST(EndpointTest, A200CarriesTimingAndWhatTheEndpointDeclares) {
  Calls calls;
  auto endpoint = Doubler(&calls);
  const Response bare = Serve(endpoint, R"({"x": 1.5})");
  ASSERT_EQ(bare.status, 200) << bare.body.dump();
  EXPECT_EQ(bare.body["value"], 3.0);
  EXPECT_TRUE(bare.body["timing_s"].is_number());
  EXPECT_GE(bare.body["timing_s"].get<double>(), 0.0);
  EXPECT_FALSE(bare.body.contains("summary"));
  EXPECT_FALSE(bare.body.contains("provenance"));

  endpoint.summary = [](const Doubled& result) -> const core::Summary& { return result.summary; };
  endpoint.provenance = [](const double&, const Json& body) { return BodyOptions(body, 9); };
  const std::string text = R"({"x": 2})";
  const Response full = Serve(endpoint, text);
  ASSERT_EQ(full.status, 200) << full.body.dump();
  EXPECT_EQ(full.body["summary"]["termination"], "converged");
  EXPECT_EQ(full.body["summary"]["backend"], "closed_form");
  const Json& provenance = full.body.at("provenance");
  EXPECT_EQ(provenance, Provenance(Json::parse(text), Json::object(), 9));
  EXPECT_EQ(provenance["options"], Json::object());  // the body has no "options"
  EXPECT_EQ(provenance["seed"], 9);
  EXPECT_TRUE(full.body["timing_s"].is_number());
}

TEST(EndpointTest, AFailureIsAnsweredBeforeRendering) {
  Calls calls;
  auto endpoint = Doubler(&calls);
  endpoint.failure = [](const double& x, const Doubled&) -> std::optional<Response> {
    if (x < 10) return std::nullopt;
    return ErrorResponse(422, ErrorCode::kModelFailed, "too big for the toy", "x");
  };
  const Response failed = Serve(endpoint, R"({"x": 12})");
  EXPECT_EQ(failed.status, 422);
  EXPECT_EQ(failed.body,
            Json({{"code", "ModelFailed"}, {"message", "too big for the toy"}, {"field", "x"}}));
  EXPECT_EQ(calls.run, 1);
  EXPECT_EQ(calls.render, 0);
  EXPECT_EQ(Serve(endpoint, R"({"x": 1})").status, 200);
  EXPECT_EQ(calls.render, 1);
}

TEST(EndpointTest, UnmetTargetsAre422WithTheWholeAnswerAsClosest) {
  Calls calls;
  auto endpoint = Doubler(&calls);
  endpoint.provenance = [](const double&, const Json& body) { return BodyOptions(body); };
  endpoint.unmet = [](const double&, const Doubled& result) -> std::optional<Unmet> {
    if (result.value <= 4) return std::nullopt;
    return Unmet{ErrorCode::kInfeasible, "no value meets the target", "targets"};
  };
  const Response r = Serve(endpoint, R"({"x": 3, "options": {"budget": 1}})");
  ASSERT_EQ(r.status, 422) << r.body.dump();
  EXPECT_EQ(r.body["code"], "Infeasible");
  EXPECT_EQ(r.body["message"], "no value meets the target");
  EXPECT_EQ(r.body["field"], "targets");
  const Json& closest = r.body.at("closest");
  EXPECT_EQ(closest["value"], 6.0);
  EXPECT_EQ(closest["provenance"]["options"], Json({{"budget", 1}}));
  EXPECT_TRUE(closest["timing_s"].is_number());
  EXPECT_EQ(Serve(endpoint, R"({"x": 2})").status, 200);
}

TEST(EndpointTest, AnExceptionFromTheCoreCallBecomesA500AtTheRouter) {
  Calls calls;
  auto endpoint = Doubler(&calls);
  endpoint.run = [](const double&, const Context&) -> Doubled {
    throw std::runtime_error("core call exploded");
  };
  // The driver does not catch: the router's one catch (CallRoute, as Dispatch) does.
  EXPECT_THROW(Serve(endpoint, R"({"x": 1})"), std::runtime_error);
  Route route;
  route.method = "POST";
  route.path = "/test";
  route.handler = [&endpoint](const Request& request, const Context& context) {
    return ServeEndpoint(endpoint, request, context);
  };
  const Response r = CallRoute(route, {"POST", "/test", R"({"x": 1})"}, Context{});
  EXPECT_EQ(r.status, 500);
  EXPECT_EQ(r.body["code"], "InternalError");
  EXPECT_EQ(r.body["message"], "internal error");
  EXPECT_EQ(r.internal_error, "core call exploded");
  // A refused request still answers 400: the throwing core call is never reached.
  EXPECT_EQ(CallRoute(route, {"POST", "/test", R"({"x": -1})"}, Context{}).status, 400);
}

// Every typed POST endpoint through the router: its 200 has timing_s, and provenance
// unless it is the closed-form /v1/bat/properties (docs/api.md lists none there).
TEST(EndpointTest, EveryTypedEndpointsAnswerHasTimingAndProvenance) {
  const Json bat = {{"preset", "paper-wood"}};
  const Response properties =
      Dispatch({"POST", "/v1/bat/properties", Json{{"bat", bat}}.dump()}, Context{});
  ASSERT_EQ(properties.status, 200) << properties.body.dump();
  EXPECT_TRUE(properties.body["timing_s"].is_number());
  EXPECT_FALSE(properties.body.contains("provenance"));
  const double mass_kg = properties.body["mass_kg"].get<double>();

  struct Case {
    const char* path;
    Json body;
  };
  const Case cases[] = {
      {"/v1/sweet-spot", {{"bat", bat}}},
      {"/v1/collision", {{"bat", bat}, {"impact_from_knob_m", 0.7}}},
      {"/v1/compare", {{"baseline", bat}, {"variants", {{{"name", "same"}, {"bat", bat}}}}}},
      {"/v1/bat/modes", {{"bat", bat}, {"modes", 1}}},
      {"/v1/bat/fit", {{"bat", bat}, {"targets", {{"mass_kg", mass_kg}}}}},
      {"/v1/optimize",
       Json::parse(R"({"bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
            "variables": [{"path": "three_segment.barrel_radius_m", "min": 0.028,
                           "max": 0.0331}],
            "objective": "min_moi", "options": {"starts": 1, "seed": 3}})")},
  };
  for (const Case& c : cases) {
    const Response r = Dispatch({"POST", c.path, c.body.dump()}, Context{});
    ASSERT_EQ(r.status, 200) << c.path << ": " << r.body.dump().substr(0, 400);
    EXPECT_TRUE(r.body["timing_s"].is_number()) << c.path;
    ASSERT_TRUE(r.body.contains("provenance")) << c.path;
    EXPECT_EQ(r.body["provenance"]["input_hash"], InputHash(c.body)) << c.path;
  }
}

}  // namespace
}  // namespace endpoint_test
}  // namespace sweetspot::api
