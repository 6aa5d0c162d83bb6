// The design explorer's static files: lookup rules without HTTP, then GET /
// and the bundle's files over real HTTP on 127.0.0.1 (content types, cache
// headers, no way out of the web root, no token needed, 404 when missing).
#include "server/static_files.hpp"

#include <gtest/gtest.h>
#include <httplib.h>
#include <unistd.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <thread>

#include "server/config.hpp"
#include "server/server.hpp"
#include "tests/server/running_server.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace static_files_test {
namespace {

namespace fs = std::filesystem;

constexpr const char* kIndexHtml = "<!doctype html><title>explorer</title>";
constexpr const char* kAppJs = "console.log('explorer');";
constexpr const char* kSecret = "secret outside the web root";

void WriteFile(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

// A temporary folder holding web/ (the root: index.html, assets/app-HASH.js,
// a hidden file, a link out of the root) and secret.txt beside it.
class WebFolder {
 public:
  WebFolder() {
    base_ = fs::temp_directory_path() /
            ("sweetspot-static-" + std::to_string(getpid()) + "-" + std::to_string(counter_++));
    fs::remove_all(base_);
    WriteFile(root() / "index.html", kIndexHtml);
    WriteFile(root() / "assets" / "app-ABCD1234.js", kAppJs);
    WriteFile(root() / "assets" / "app-ABCD1234.css", "body{}");
    WriteFile(root() / "notes.txt", "plain");
    WriteFile(root() / ".hidden", "HIDDEN-CONTENT");
    WriteFile(root() / "health", "a file shadowed by the API's /health");
    WriteFile(root() / "v1" / "presets.js", "never served: /v1/ is the API's");
    WriteFile(base_ / "secret.txt", kSecret);
    fs::create_symlink(base_ / "secret.txt", root() / "link-out.txt");
  }
  ~WebFolder() { fs::remove_all(base_); }
  fs::path root() const { return base_ / "web"; }
  fs::path base() const { return base_; }

 private:
  static inline int counter_ = 0;
  fs::path base_;
};

TEST(StaticFilesTest, FindsIndexAndFilesInsideTheRoot) {
  WebFolder folder;
  const StaticFiles files(folder.root().string());
  EXPECT_TRUE(files.Installed());
  const auto index = files.Find("/");
  ASSERT_TRUE(index);
  EXPECT_EQ(*index, fs::canonical(folder.root() / "index.html").string());
  EXPECT_TRUE(files.Find("/index.html"));
  EXPECT_TRUE(files.Find("/assets/app-ABCD1234.js"));
  EXPECT_FALSE(files.Find("/assets"));  // A folder is not a file.
  EXPECT_FALSE(files.Find("/missing.js"));
}

TEST(StaticFilesTest, RefusesEveryWayOutOfTheRoot) {
  WebFolder folder;
  const StaticFiles files(folder.root().string());
  for (const char* path : {"/../secret.txt", "/assets/../../secret.txt", "/assets/../index.html",
                           "/./index.html", "//index.html", "/assets/", "/.hidden", "/link-out.txt",
                           "/assets\\..\\..\\secret.txt", "index.html", ""}) {
    EXPECT_FALSE(files.Find(path)) << path;
  }
  EXPECT_FALSE(files.Find(std::string_view("/index.html\0.js", 15)));
}

TEST(StaticFilesTest, MissingRootIsNotInstalled) {
  const StaticFiles files("/nonexistent/sweetspot/web");
  EXPECT_FALSE(files.Installed());
  EXPECT_FALSE(files.Find("/"));
  EXPECT_FALSE(StaticFiles("").Installed());
}

TEST(StaticFilesTest, ContentTypesAndCachePolicy) {
  EXPECT_EQ(ContentTypeFor("index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(ContentTypeFor("app-X.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(ContentTypeFor("app-X.css"), "text/css; charset=utf-8");
  EXPECT_EQ(ContentTypeFor("logo.svg"), "image/svg+xml");
  EXPECT_EQ(ContentTypeFor("data.bin"), "application/octet-stream");
  WebFolder folder;
  const StaticFiles files(folder.root().string());
  const auto index = files.Read(*files.Find("/"));
  ASSERT_TRUE(index);
  EXPECT_EQ(index->body, kIndexHtml);
  EXPECT_EQ(index->cache_control, "no-cache");
  EXPECT_FALSE(index->etag.empty());
  const auto app = files.Read(*files.Find("/assets/app-ABCD1234.js"));
  ASSERT_TRUE(app);
  EXPECT_EQ(app->body, kAppJs);
  EXPECT_EQ(app->cache_control, "public, max-age=31536000, immutable");
}

TEST(StaticFilesTest, DefaultRootIsWebNextToTheExecutable) {
  const std::string root = DefaultWebRoot();
  ASSERT_FALSE(root.empty());
  EXPECT_EQ(fs::path(root).filename(), "web");
  EXPECT_EQ(fs::path(root).parent_path(), fs::canonical("/proc/self/exe").parent_path());
}

TEST(StaticFilesTest, WebRootFromFlagAndEnvironment) {
  const auto no_env = [](const std::string&) -> std::optional<std::string> { return std::nullopt; };
  EXPECT_EQ(ParseCommandLine({}, no_env).config.web_root, "");
  EXPECT_EQ(ParseCommandLine({"--web-root", "/srv/web"}, no_env).config.web_root, "/srv/web");
  const auto env = [](const std::string& name) -> std::optional<std::string> {
    if (name == "SWEETSPOT_WEB_ROOT") return "/env/web";
    return std::nullopt;
  };
  EXPECT_EQ(ParseCommandLine({}, env).config.web_root, "/env/web");
  EXPECT_EQ(ParseCommandLine({"--web-root=/flag/web"}, env).config.web_root, "/flag/web");
  EXPECT_EQ(ParseCommandLine({"--web-root", ""}, no_env).error,
            "option --web-root = \"\": must be a folder path");
  EXPECT_NE(Usage("sweetspot-server").find("--web-root VALUE"), std::string::npos);
  EXPECT_NE(Usage("sweetspot-server").find("SWEETSPOT_WEB_ROOT"), std::string::npos);
}

ServerConfig WithRoot(const fs::path& root) {
  ServerConfig config;
  config.threads = 2;
  config.web_root = root.string();
  return config;
}

TEST(StaticServingTest, RootIsTheExplorerPage) {
  WebFolder folder;
  RunningServer server(WithRoot(folder.root()));
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  const auto res = client.Get("/");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_EQ(res->body, kIndexHtml);
  EXPECT_EQ(res->get_header_value("Content-Type"), "text/html; charset=utf-8");
  EXPECT_EQ(res->get_header_value("Cache-Control"), "no-cache");
  EXPECT_EQ(res->get_header_value("X-Content-Type-Options"), "nosniff");
  EXPECT_NE(res->get_header_value("Content-Security-Policy").find("default-src 'self'"),
            std::string::npos);
  // Revalidation: the ETag gives 304 without a body.
  const std::string etag = res->get_header_value("ETag");
  ASSERT_FALSE(etag.empty());
  const auto again = client.Get("/", {{"If-None-Match", etag}});
  ASSERT_TRUE(again);
  EXPECT_EQ(again->status, 304);
  EXPECT_TRUE(again->body.empty());
  const auto head = client.Head("/");
  ASSERT_TRUE(head);
  EXPECT_EQ(head->status, 200);
  EXPECT_TRUE(head->body.empty());
}

TEST(StaticServingTest, BundleFilesHaveTheirContentType) {
  WebFolder folder;
  RunningServer server(WithRoot(folder.root()));
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  const auto js = client.Get("/assets/app-ABCD1234.js");
  ASSERT_TRUE(js);
  EXPECT_EQ(js->status, 200);
  EXPECT_EQ(js->body, kAppJs);
  EXPECT_EQ(js->get_header_value("Content-Type"), "text/javascript; charset=utf-8");
  EXPECT_EQ(js->get_header_value("Cache-Control"), "public, max-age=31536000, immutable");
  const auto css = client.Get("/assets/app-ABCD1234.css");
  ASSERT_TRUE(css);
  EXPECT_EQ(css->get_header_value("Content-Type"), "text/css; charset=utf-8");
  const auto txt = client.Get("/notes.txt");
  ASSERT_TRUE(txt);
  EXPECT_EQ(txt->get_header_value("Content-Type"), "text/plain; charset=utf-8");
}

TEST(StaticServingTest, TraversalIsRefused) {
  WebFolder folder;
  RunningServer server(WithRoot(folder.root()));
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  // Raw and percent-encoded dot segments (the server decodes the path first),
  // a hidden file and a symbolic link out of the root.
  for (const char* path : {"/../secret.txt", "/assets/../../secret.txt", "/%2e%2e/secret.txt",
                           "/assets/%2e%2e%2f%2e%2e%2fsecret.txt", "/..%2fsecret.txt", "/.hidden",
                           "/link-out.txt", "/assets/..%5c..%5csecret.txt"}) {
    const auto res = client.Get(path);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 404) << path;
    EXPECT_EQ(res->body.find(kSecret), std::string::npos) << path;
    EXPECT_EQ(res->body.find("HIDDEN-CONTENT"), std::string::npos) << path;
    EXPECT_EQ(res->get_header_value("Content-Type"), "application/json") << path;
    EXPECT_EQ(nlohmann::json::parse(res->body)["code"], "NotFound") << path;
  }
}

TEST(StaticServingTest, TheApiWinsOverFilesAndOwnsV1) {
  WebFolder folder;
  RunningServer server(WithRoot(folder.root()));
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  const auto health = client.Get("/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(nlohmann::json::parse(health->body)["status"], "ok");
  const auto v1 = client.Get("/v1/presets.js");
  ASSERT_TRUE(v1);
  EXPECT_EQ(v1->status, 404);
  EXPECT_EQ(nlohmann::json::parse(v1->body)["code"], "NotFound");
  // A POST to / is the API's (no such endpoint), not a file.
  const auto post = client.Post("/", "{}", "application/json");
  ASSERT_TRUE(post);
  EXPECT_EQ(post->status, 404);
}

TEST(StaticServingTest, MissingWebRootAnswers404EnvelopeAndTheApiWorks) {
  RunningServer server(WithRoot("/nonexistent/sweetspot/web"));
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  const auto res = client.Get("/");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 404);
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/json");
  const auto body = nlohmann::json::parse(res->body);
  EXPECT_EQ(body["code"], "NotFound");
  EXPECT_TRUE(body["field"].is_null());
  EXPECT_NE(body["message"].get<std::string>().find("design explorer is not installed"),
            std::string::npos);
  const auto presets = client.Get("/v1/presets");
  ASSERT_TRUE(presets);
  EXPECT_EQ(presets->status, 200);
  EXPECT_TRUE(nlohmann::json::parse(presets->body)["presets"].is_array());
}

TEST(StaticServingTest, StaticFilesNeedNoTokenTheApiStillDoes) {
  WebFolder folder;
  ServerConfig config = WithRoot(folder.root());
  config.auth_token = "0123456789abcdef-secret";
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  const auto page = client.Get("/");
  ASSERT_TRUE(page);
  EXPECT_EQ(page->status, 200);
  const auto js = client.Get("/assets/app-ABCD1234.js");
  ASSERT_TRUE(js);
  EXPECT_EQ(js->status, 200);
  // Not a file: the token is asked for first, as before.
  for (const char* path : {"/v1/presets", "/missing.js", "/../secret.txt", "/metrics"}) {
    const auto res = client.Get(path);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 401) << path;
  }
  client.set_bearer_token_auth("0123456789abcdef-secret");
  const auto presets = client.Get("/v1/presets");
  ASSERT_TRUE(presets);
  EXPECT_EQ(presets->status, 200);
}

TEST(StaticServingTest, MetricsCountStaticFilesUnderOneRoute) {
  WebFolder folder;
  RunningServer server(WithRoot(folder.root()));
  ASSERT_TRUE(server.bound());
  auto client = server.Client();
  ASSERT_EQ(client.Get("/")->status, 200);
  ASSERT_EQ(client.Get("/assets/app-ABCD1234.js")->status, 200);
  const auto metrics = client.Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find(
                "sweetspot_requests_total{route=\"static\",method=\"GET\",status=\"200\"} 2"),
            std::string::npos)
      << metrics->body;
}

}  // namespace
}  // namespace static_files_test
}  // namespace sweetspot::server
