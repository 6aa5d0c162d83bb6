#include "api/router.hpp"

#include <gtest/gtest.h>

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace router_test {
namespace {

TEST(RouterTest, HealthAnswersOk) {
  std::string route;
  const Response response = Dispatch({"GET", "/health", ""}, Context{}, &route);
  EXPECT_EQ(response.status, 200);
  EXPECT_EQ(response.body, nlohmann::json({{"status", "ok"}}));
  EXPECT_EQ(route, "/health");
}

TEST(RouterTest, ReadyAnswersReadyAnd503WhileDraining) {
  std::string route;
  const Response ready = Dispatch({"GET", "/ready", ""}, Context{}, &route);
  EXPECT_EQ(ready.status, 200);
  EXPECT_EQ(ready.body, nlohmann::json({{"status", "ready"}}));
  EXPECT_EQ(route, "/ready");
  Context draining;
  draining.draining = [] { return true; };
  const Response refused = Dispatch({"GET", "/ready", ""}, draining);
  EXPECT_EQ(refused.status, 503);
  EXPECT_EQ(refused.body["code"], "Unavailable");
  EXPECT_EQ(refused.body["message"],
            "draining: the server is stopping; it still answers until its drain period "
            "(--drain-s) ends, then stops accepting connections");
  draining.draining = [] { return false; };
  EXPECT_EQ(Dispatch({"GET", "/ready", ""}, draining).status, 200);
}

TEST(RouterTest, UnknownPathIs404WithEnvelope) {
  std::string route;
  const Response response = Dispatch({"GET", "/nope", ""}, Context{}, &route);
  EXPECT_EQ(response.status, 404);
  EXPECT_EQ(response.body["code"], "NotFound");
  EXPECT_EQ(response.body["message"], "no endpoint at path /nope");
  EXPECT_TRUE(response.body["field"].is_null());
  EXPECT_EQ(route, "unmatched");
}

TEST(RouterTest, WrongMethodIs405) {
  const Response response = Dispatch({"POST", "/health", "{}"}, Context{});
  EXPECT_EQ(response.status, 405);
  EXPECT_EQ(response.body["code"], "MethodNotAllowed");
  EXPECT_EQ(response.body["message"], "method POST is not allowed on /health (allowed: GET)");
}

TEST(RouterTest, TrailingSlashAndPrefixesDoNotMatch) {
  EXPECT_EQ(Dispatch({"GET", "/health/", ""}, Context{}).status, 404);
  EXPECT_EQ(Dispatch({"GET", "/healthz", ""}, Context{}).status, 404);
  EXPECT_EQ(Dispatch({"GET", "", ""}, Context{}).status, 404);
}

TEST(RouterTest, RoutesAreUniqueByMethodAndPath) {
  const auto& routes = Routes();
  for (std::size_t i = 0; i < routes.size(); ++i) {
    for (std::size_t j = i + 1; j < routes.size(); ++j) {
      EXPECT_FALSE(routes[i].method == routes[j].method && routes[i].path == routes[j].path)
          << routes[i].method << " " << routes[i].path;
    }
  }
}

}  // namespace
}  // namespace router_test
}  // namespace sweetspot::api
