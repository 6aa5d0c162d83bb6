// The raw bytes of the server's answers (status line, headers in their order, body) to a
// fixed set of requests across routes, against the copy kept in
// tests/server/data/wire_bytes.txt: the request path may change how it answers, never what.
// SWEETSPOT_WRITE_WIRE_BYTES=1 rewrites the kept copy (from the server as it is).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "running_server.hpp"
#include "wire.hpp"

namespace sweetspot::server {
namespace {

using testing::Connect;
using testing::ReadFor;
using testing::SendAll;

const std::string kScene =
    R"({"bat": {"preset": "paper-wood"}, "ball": {"mass_kg": 0.145, "radius_m": 0.0366, )"
    R"("speed_mps": 27.7}, "swing": {"angular_speed_rad_s": 17.288, "pivot_from_knob_m": 0.0, )"
    R"("hands_from_knob_m": 0.1524}, "cor": 0.5, "outputs": ["max_exit_speed"]})";

std::string Post(const std::string& path, const std::string& body, const std::string& extra = "") {
  return "POST " + path + " HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n" + extra +
         "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body;
}

// The answers in `got` with what differs from run to run replaced: the compute times in a
// JSON body ("timing_s", "solve_time_s", "time_s"), and then a Content-Length that matches
// its body's bytes (checked here) by "(matches)". Date headers are removed.
std::string Normalised(const std::string& got, bool head_only) {
  static const std::regex times("\"(timing_s|solve_time_s|time_s)\":[-0-9.e+]+");
  std::string out;
  std::size_t at = 0;
  while (at < got.size()) {
    const std::size_t end = got.find("\r\n\r\n", at);
    if (end == std::string::npos) {
      out += got.substr(at);
      break;
    }
    std::string head = got.substr(at, end + 4 - at);
    at = end + 4;
    if (head.rfind("HTTP/1.1 100", 0) == 0) {
      out += head;
      continue;
    }
    std::size_t length = 0;
    const std::size_t cl = head.find("Content-Length: ");
    if (cl != std::string::npos) length = std::stoul(head.substr(cl + 16));
    if (head_only) length = 0;
    std::string body = got.substr(at, length);
    at += body.size();
    const std::string timeless = std::regex_replace(body, times, "\"$1\":T");
    if (timeless != body && cl != std::string::npos && length == body.size()) {
      head.replace(cl, head.find("\r\n", cl) - cl, "Content-Length: (matches)");
    }
    const std::size_t date = head.find("\r\nDate: ");
    if (date != std::string::npos) head.erase(date, head.find("\r\n", date + 2) - date);
    out += head + timeless;
  }
  return out;
}

// Every answer's bytes to `requests`, sent one after another on one connection (each
// waited for: until the server closes, or 0.5 s of quiet).
std::string Exchange(int port, const std::vector<std::string>& requests) {
  const int fd = Connect(port);
  if (fd < 0) return "(no connection)";
  std::string out;
  for (const std::string& request : requests) {
    if (!SendAll(fd, request)) {
      out += "(send failed)\n";
      break;
    }
    const bool head_only = request.rfind("HEAD ", 0) == 0;
    // Complete: the last head (past a 100 Continue) and its Content-Length's bytes.
    const auto complete = [&](const std::string& b) {
      std::size_t start = 0;
      while (b.compare(start, 12, "HTTP/1.1 100") == 0) {
        const std::size_t e = b.find("\r\n\r\n", start);
        if (e == std::string::npos) return false;
        start = e + 4;
      }
      const std::size_t end = b.find("\r\n\r\n", start);
      if (end == std::string::npos) return false;
      if (head_only) return true;
      const std::size_t at = b.find("Content-Length: ", start);
      if (at == std::string::npos || at > end) return false;
      return b.size() >= end + 4 + std::stoul(b.substr(at + 16));
    };
    testing::ReadResult r = ReadFor(fd, 5.0, complete);
    std::string got = r.bytes;
    bool closed = r.closed;
    if (!closed && got.find("Connection: close\r\n") != std::string::npos) {
      const testing::ReadResult rest = ReadFor(fd, 5.0, [](const std::string&) { return false; });
      got += rest.bytes;
      closed = rest.closed;
    }
    out += Normalised(got, head_only);
    out += closed ? "\n(closed)\n" : "\n(open)\n";
    if (closed) break;
  }
  close(fd);
  return out;
}

std::string AllExchanges() {
  namespace fs = std::filesystem;
  const fs::path web = fs::temp_directory_path() / ("wire-bytes-web-" + std::to_string(getpid()));
  fs::create_directories(web);
  std::ofstream(web / "index.html") << "<!doctype html><title>x</title>\n";
  std::ofstream(web / "app.js") << "console.log(1);\n";
  // The ETag is the file's size and time: a fixed time.
  for (const char* name : {"index.html", "app.js"}) {
    fs::last_write_time(web / name, fs::file_time_type(std::chrono::seconds(1700000000)));
  }

  std::string all;
  {
    ServerConfig config;
    config.cors_origin = "https://app.example";
    config.web_root = web.string();
    config.max_body_bytes = 64 * 1024;
    RunningServer server(config);
    if (!server.bound()) return "(not bound)";
    const int port = server.port();
    const std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
        {"keep-alive GET /health twice, then the example POST",
         {"GET /health HTTP/1.1\r\nHost: x\r\n\r\n", "GET /health HTTP/1.1\r\nHost: x\r\n\r\n",
          Post("/v1/sweet-spot", kScene)}},
        {"POST /v1/sweet-spot, Connection: close", {Post("/v1/sweet-spot", kScene, "Connection: close\r\n")}},
        {"POST /v1/sweet-spot over HTTP/1.0",
         {"POST /v1/sweet-spot HTTP/1.0\r\nContent-Type: application/json\r\nContent-Length: " +
          std::to_string(kScene.size()) + "\r\n\r\n" + kScene}},
        {"POST /v1/sweet-spot with a query and a percent-encoded path",
         {Post("/v1/sweet%2Dspot?x=1&y=a+b", kScene)}},
        {"400: not JSON", {Post("/v1/sweet-spot", "{not json")}},
        {"400: invalid value", {Post("/v1/sweet-spot", R"({"bat": {"preset": "nope"}})")}},
        {"404", {"GET /nope HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"404 under /v1", {Post("/v1/nope", "{}")}},
        {"405?", {"DELETE /v1/sweet-spot HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"413 from the head", {"POST /v1/sweet-spot HTTP/1.1\r\nHost: x\r\nContent-Length: 1000000\r\n\r\n"}},
        {"411 chunked", {"POST /v1/sweet-spot HTTP/1.1\r\nHost: x\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n"}},
        {"400 unknown method", {"FOO / HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"static /", {"GET / HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"static /app.js", {"GET /app.js HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"HEAD /", {"HEAD / HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"HEAD /health", {"HEAD /health HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"OPTIONS preflight",
         {"OPTIONS /v1/sweet-spot HTTP/1.1\r\nHost: x\r\nOrigin: https://app.example\r\n"
          "Access-Control-Request-Method: POST\r\n\r\n"}},
        {"OPTIONS without preflight", {"OPTIONS /v1/sweet-spot HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"CORS POST", {Post("/v1/sweet-spot", kScene, "Origin: https://app.example\r\n")}},
        {"CORS POST other origin", {Post("/v1/sweet-spot", kScene, "Origin: https://other.example\r\n")}},
        {"gzip asked of a 400", {Post("/v1/sweet-spot", "[]", "Accept-Encoding: gzip\r\n")}},
        {"gzip asked of a file", {"GET /app.js HTTP/1.1\r\nHost: x\r\nAccept-Encoding: gzip, br\r\n\r\n"}},
        {"304", {"GET /app.js HTTP/1.1\r\nHost: x\r\nIf-None-Match: \"10-70eeca4af57c0000\"\r\n\r\n"}},
        {"Range dropped", {"GET /app.js HTTP/1.1\r\nHost: x\r\nRange: bytes=0-3\r\n\r\n"}},
        {"Expect 100-continue", {Post("/v1/sweet-spot", kScene, "Expect: 100-continue\r\n")}},
        {"GET /ready", {"GET /ready HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"GET /v1/jobs/none", {"GET /v1/jobs/none HTTP/1.1\r\nHost: x\r\n\r\n"}},
        {"odd header lines", {"GET /health HTTP/1.1\r\nHost: x\r\nNoColon\r\nEmpty:\r\nX-A:  v%41 \r\n\r\n"}},
    };
    for (const auto& [name, requests] : cases) {
      all += "=== " + name + "\n" + Exchange(port, requests);
    }
  }
  {
    ServerConfig config;
    config.auth_token = "secret";
    config.web_root = web.string();
    RunningServer server(config);
    if (!server.bound()) return all + "(not bound)";
    all += "=== 401\n" + Exchange(server.port(), {Post("/v1/sweet-spot", kScene)});
    all += "=== token\n" +
           Exchange(server.port(), {Post("/v1/sweet-spot", kScene, "Authorization: Bearer secret\r\n")});
  }
  fs::remove_all(web);
  return all;
}

TEST(WireBytesTest, AnswersAreByteForByteTheKeptOnes) {
  const std::string path = std::string(SWEETSPOT_SOURCE_DIR) + "/tests/server/data/wire_bytes.txt";
  const std::string now = AllExchanges();
  if (std::getenv("SWEETSPOT_WRITE_WIRE_BYTES") != nullptr) {
    std::ofstream(path, std::ios::binary) << now;
    GTEST_SKIP() << "wrote " << path;
  }
  std::ifstream in(path, std::ios::binary);
  ASSERT_TRUE(in) << path;
  std::stringstream kept;
  kept << in.rdbuf();
  EXPECT_EQ(now, kept.str());
}

}  // namespace
}  // namespace sweetspot::server
