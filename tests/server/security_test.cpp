// Bearer token, CORS and the connection limit, over real HTTP on 127.0.0.1.
#include <httplib.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include "tests/server/running_server.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace security_test {
namespace {

TEST(SecurityTest, BearerTokenGuardsEverythingButHealth) {
  ServerConfig config;
  config.auth_token = "0123456789abcdef-secret";
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  const auto health = client.Get("/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  const auto anonymous = client.Get("/v1/materials");
  ASSERT_TRUE(anonymous);
  EXPECT_EQ(anonymous->status, 401);
  EXPECT_EQ(nlohmann::json::parse(anonymous->body)["code"], "Unauthorized");
  EXPECT_EQ(anonymous->get_header_value("WWW-Authenticate"), "Bearer");
  const auto wrong = client.Get("/v1/materials", {{"Authorization", "Bearer 0123456789abcdef-secreT"}});
  ASSERT_TRUE(wrong);
  EXPECT_EQ(wrong->status, 401);
  // A POST without the token is refused before its body is read.
  const auto post = client.Post("/v1/sweet-spot", R"({"bat": {"preset": "paper-wood"}})",
                                "application/json");
  ASSERT_TRUE(post);
  EXPECT_EQ(post->status, 401);
  client.set_bearer_token_auth("0123456789abcdef-secret");
  const auto allowed = client.Get("/v1/materials");
  ASSERT_TRUE(allowed);
  EXPECT_EQ(allowed->status, 200);
}

// GET /v1/jobs over real HTTP: the token guards it like every job route, the query string
// reaches the handler (filter, paging, a bad state named), and POST /v1/jobs refuses an invalid
// inner request at once without making a job.
TEST(SecurityTest, JobListIsGuardedAndTakesItsQueryOverHttp) {
  ServerConfig config;
  config.auth_token = "0123456789abcdef-secret";
  config.jobs_db = kNoJobsDb;  // in memory: a shared default file would couple tests
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  const auto anonymous = client.Get("/v1/jobs?state=running");
  ASSERT_TRUE(anonymous);
  EXPECT_EQ(anonymous->status, 401);
  client.set_bearer_token_auth("0123456789abcdef-secret");

  const auto refused = client.Post(
      "/v1/jobs",
      R"({"path": "/v1/optimize", "body": {"bat": {"preset": "paper-wood"},
          "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5}],
          "options": {"starts": 500}}})",
      "application/json");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 400);
  EXPECT_EQ(nlohmann::json::parse(refused->body)["field"], "options.starts") << refused->body;

  std::vector<std::string> ids;
  for (int i = 0; i < 3; ++i) {
    const auto submitted = client.Post(
        "/v1/jobs", R"({"path": "/v1/bat/properties", "body": {"bat": {"preset": "paper-wood"}}})",
        "application/json");
    ASSERT_TRUE(submitted);
    ASSERT_EQ(submitted->status, 202) << submitted->body;
    ids.push_back(nlohmann::json::parse(submitted->body)["id"]);
  }
  // Every job done (quick ones; bounded wait: 2000 x 5 ms).
  for (int i = 0; i < 2000; ++i) {
    const auto done = client.Get("/v1/jobs?state=done");
    ASSERT_TRUE(done);
    if (nlohmann::json::parse(done->body)["total"] == 3) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const auto page = client.Get("/v1/jobs?state=done&limit=2&offset=1");
  ASSERT_TRUE(page);
  ASSERT_EQ(page->status, 200) << page->body;
  const auto body = nlohmann::json::parse(page->body);
  EXPECT_EQ(body["total"], 3);  // the refused request made no job
  ASSERT_EQ(body["jobs"].size(), 2u) << page->body;
  EXPECT_EQ(body["jobs"][0]["id"], ids[1]);  // newest first, one skipped
  EXPECT_EQ(body["jobs"][1]["id"], ids[0]);
  EXPECT_TRUE(body["next_offset"].is_null());
  const auto bad = client.Get("/v1/jobs?state=sleeping");
  ASSERT_TRUE(bad);
  EXPECT_EQ(bad->status, 400);
  EXPECT_EQ(nlohmann::json::parse(bad->body)["field"], "state");
}

TEST(SecurityTest, NoCorsHeadersUnlessConfigured) {
  RunningServer plain{ServerConfig{}};
  ASSERT_TRUE(plain.bound());
  auto client = plain.Client();
  const auto res = client.Get("/health", {{"Origin", "https://example.org"}});
  ASSERT_TRUE(res);
  EXPECT_FALSE(res->has_header("Access-Control-Allow-Origin"));
  const auto preflight = client.Options("/v1/sweet-spot", {{"Origin", "https://example.org"},
                                                            {"Access-Control-Request-Method", "POST"}});
  ASSERT_TRUE(preflight);
  EXPECT_EQ(preflight->status, 405);  // OPTIONS is not an endpoint

  ServerConfig config;
  config.cors_origin = "https://example.org";
  RunningServer cors(config);
  ASSERT_TRUE(cors.bound());
  auto cors_client = cors.Client();
  const auto allowed = cors_client.Get("/health", {{"Origin", "https://example.org"}});
  ASSERT_TRUE(allowed);
  EXPECT_EQ(allowed->get_header_value("Access-Control-Allow-Origin"), "https://example.org");
  const auto other = cors_client.Get("/health", {{"Origin", "https://evil.example"}});
  ASSERT_TRUE(other);
  EXPECT_FALSE(other->has_header("Access-Control-Allow-Origin"));
  const auto pre = cors_client.Options(
      "/v1/sweet-spot",
      {{"Origin", "https://example.org"}, {"Access-Control-Request-Method", "POST"}});
  ASSERT_TRUE(pre);
  EXPECT_EQ(pre->status, 204);
  EXPECT_EQ(pre->get_header_value("Access-Control-Allow-Methods"), "GET, POST, DELETE, OPTIONS");
}

TEST(SecurityTest, ConnectionsOverTheLimitGet503AndAdmittedOnesAreServed) {
  ServerConfig config;
  config.threads = 2;
  config.max_connections = 2;
  config.keep_alive_timeout_s = 5;
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  // Two keep-alive connections stay open and hold both admitted slots.
  auto first = server.Client();
  auto second = server.Client();
  first.set_keep_alive(true);
  second.set_keep_alive(true);
  ASSERT_EQ(first.Get("/health")->status, 200);
  ASSERT_EQ(second.Get("/health")->status, 200);
  auto third = server.Client();
  const auto refused = third.Get("/health");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 503);
  EXPECT_EQ(nlohmann::json::parse(refused->body)["code"], "TooBusy");
  // The admitted connections are still served.
  EXPECT_EQ(first.Get("/v1/version")->status, 200);
  EXPECT_EQ(second.Get("/v1/version")->status, 200);
  // Once one closes, a new connection is admitted (bounded wait: 200 x 10 ms).
  first.stop();
  int status = 0;
  for (int i = 0; i < 200 && status != 200; ++i) {
    auto next = server.Client();
    const auto res = next.Get("/health");
    status = res ? res->status : 0;
    if (status != 200) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_EQ(status, 200);
}

TEST(SecurityTest, ErrorsCarryNoInternals) {
  RunningServer server{ServerConfig{}};
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  for (const char* body : {"{", "[[[[", "{\"bat\": 1}", "\x01\x02"}) {
    const auto res = client.Post("/v1/sweet-spot", body, "application/json");
    ASSERT_TRUE(res);
    EXPECT_EQ(res->status, 400);
    // No source paths, no exception class names.
    EXPECT_EQ(res->body.find("/work/"), std::string::npos) << res->body;
    EXPECT_EQ(res->body.find(".cpp"), std::string::npos) << res->body;
    EXPECT_EQ(res->body.find("json.exception"), std::string::npos) << res->body;
    EXPECT_EQ(res->body.find("what()"), std::string::npos) << res->body;
  }
}

}  // namespace
}  // namespace security_test
}  // namespace sweetspot::server
