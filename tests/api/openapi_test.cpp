// The served OpenAPI document and the router describe the same endpoints,
// compared both ways.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "api/openapi_document.hpp"
#include "api/router.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace openapi_test {
namespace {

std::string Lower(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

// Records every object's keys as the document is read, and the first key given twice in one
// object (a JSON reader silently keeps one of the two: a merge once left two
// "feasibility_tolerance" schemas with different ranges).
class DuplicateKeyFinder : public nlohmann::json_sax<nlohmann::json> {
 public:
  std::string duplicate;  // "" = none

  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override {
    keys_.emplace_back();
    return true;
  }
  bool key(string_t& k) override {
    if (!keys_.back().insert(k).second && duplicate.empty()) duplicate = k;
    return true;
  }
  bool end_object() override {
    keys_.pop_back();
    return true;
  }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;
  }

 private:
  std::vector<std::set<std::string>> keys_;
};

TEST(OpenApiTest, NoObjectGivesAKeyTwice) {
  DuplicateKeyFinder finder;
  ASSERT_TRUE(nlohmann::json::sax_parse(std::string(OpenApiDocumentText()), &finder));
  EXPECT_EQ(finder.duplicate, "");
}

TEST(OpenApiTest, DocumentIsOpenApi3) {
  const Response r = Dispatch({"GET", "/openapi.json", ""}, Context{});
  ASSERT_EQ(r.status, 200);
  EXPECT_EQ(r.body["openapi"].get<std::string>().rfind("3.", 0), 0u);
  EXPECT_TRUE(r.body["info"]["title"].is_string());
  EXPECT_TRUE(r.body["paths"].is_object());
}

TEST(OpenApiTest, PathsMatchTheRouterBothWays) {
  const Response r = Dispatch({"GET", "/openapi.json", ""}, Context{});
  std::set<std::pair<std::string, std::string>> documented;
  for (const auto& [path, operations] : r.body["paths"].items()) {
    for (const auto& [method, operation] : operations.items()) {
      documented.insert({Lower(method), path});
      EXPECT_TRUE(operation.contains("responses")) << method << " " << path;
    }
  }
  std::set<std::pair<std::string, std::string>> routed;
  for (const Route& route : Routes()) routed.insert({Lower(route.method), route.path});
  for (const auto& entry : routed) {
    EXPECT_TRUE(documented.count(entry)) << "not in openapi.json: " << entry.first << " "
                                          << entry.second;
  }
  for (const auto& entry : documented) {
    EXPECT_TRUE(routed.count(entry)) << "not routed: " << entry.first << " " << entry.second;
  }
}

// The outputs an endpoint's schema lists are the ones its parser takes: every registered scene
// output (core's table, core/scene/output_registry.hpp) for
// /v1/sweet-spot and /v1/compare, and with properties and collision_efficiency for /v1/explore.
// The explore and compare lists had fallen behind the parser (least_sting_zone; barrel, bbcor,
// bbcor_scan).
TEST(OpenApiTest, OutputEnumsAreTheOutputsTheParsersTake) {
  const Response r = Dispatch({"GET", "/openapi.json", ""}, Context{});
  ASSERT_EQ(r.status, 200);
  std::set<std::string> scene;
  for (const core::SceneOutputDecl* output : core::SceneOutputTable()) {
    const std::string name = output->name;
    EXPECT_EQ(core::ParseSceneOutput(name), output->id) << name;
    scene.insert(name);
  }
  std::set<std::string> explore = scene;
  explore.insert({"properties", "collision_efficiency"});
  for (const auto& [path, expected] : {std::pair{"/v1/sweet-spot", scene},
                                       std::pair{"/v1/compare", scene},
                                       std::pair{"/v1/explore", explore}}) {
    const auto& enumerated = r.body["paths"][path]["post"]["requestBody"]["content"]
                                    ["application/json"]["schema"]["properties"]["outputs"]
                                    ["items"]["enum"];
    ASSERT_TRUE(enumerated.is_array()) << path;
    std::set<std::string> listed;
    for (const auto& name : enumerated) listed.insert(name.get<std::string>());
    EXPECT_EQ(listed, expected) << path;
  }
}

TEST(OpenApiTest, EveryReferenceResolves) {
  const Response r = Dispatch({"GET", "/openapi.json", ""}, Context{});
  const nlohmann::json& schemas = r.body["components"]["schemas"];
  std::function<void(const nlohmann::json&)> visit = [&](const nlohmann::json& node) {
    if (node.is_object()) {
      if (node.contains("$ref")) {
        const std::string ref = node["$ref"];
        const std::string prefix = "#/components/schemas/";
        ASSERT_EQ(ref.rfind(prefix, 0), 0u) << ref;
        EXPECT_TRUE(schemas.contains(ref.substr(prefix.size()))) << ref;
      }
      for (const auto& item : node.items()) visit(item.value());
    } else if (node.is_array()) {
      for (const auto& item : node) visit(item);
    }
  };
  visit(r.body);
}

}  // namespace
}  // namespace openapi_test
}  // namespace sweetspot::api
