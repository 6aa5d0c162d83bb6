// POST /v1/explore with "format": "ndjson" over real HTTP: the rows are
// streamed with chunked transfer encoding as they are evaluated (the first
// row arrives long before the last), the last line is the summary, the
// stream equals the collected JSON answer row for row, and a client that
// goes away mid-stream stops the sweep without harming the server.
#include <gtest/gtest.h>
#include <httplib.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "tests/server/running_server.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace explore_stream_test {
namespace {

using Json = nlohmann::json;

// Four handler threads: the streaming test and the health checks run side by side.
ServerConfig StreamConfig() {
  ServerConfig config;
  config.threads = 4;
  return config;
}

// A grid over the fill depth of the paper's bat with a cork fill.
Json Sweep(int count, const char* format) {
  Json body = Json::parse(R"({"bat": {"preset": "paper-wood",
      "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
    "outputs": ["max_exit_speed"]})");
  body["parameters"] = {{{"path", "fill.depth_m"}, {"min", 0.0}, {"max", 0.3}, {"count", count}}};
  body["format"] = format;
  return body;
}

TEST(ExploreStreamTest, RowsArriveChunkedAndEqualTheJsonAnswer) {
  RunningServer server(StreamConfig());
  ASSERT_TRUE(server.bound());
  httplib::Client client("127.0.0.1", server.port());
  const int count = 2000;
  std::string streamed;
  std::vector<std::size_t> chunk_sizes;
  httplib::Headers response_headers;
  int status = 0;
  httplib::Request request;
  request.method = "POST";
  request.path = "/v1/explore";
  request.body = Sweep(count, "ndjson").dump();
  request.set_header("Content-Type", "application/json");
  request.response_handler = [&](const httplib::Response& response) {
    status = response.status;
    response_headers = response.headers;
    return true;
  };
  request.content_receiver = [&](const char* data, std::size_t length, std::uint64_t,
                                 std::uint64_t) {
    streamed.append(data, length);
    chunk_sizes.push_back(length);
    return true;
  };
  const auto result = client.send(request);
  ASSERT_TRUE(result) << httplib::to_string(result.error());
  ASSERT_EQ(status, 200);
  EXPECT_EQ(result->get_header_value("Transfer-Encoding"), "chunked");
  EXPECT_EQ(result->get_header_value("Content-Type"), "application/x-ndjson");
  // 2000 rows of ~250 bytes are ~0.5 MB: at 16 KiB per chunk that is many chunks.
  EXPECT_GT(chunk_sizes.size(), 5u);

  std::istringstream lines(streamed);
  std::string line;
  std::vector<Json> rows;
  Json summary;
  while (std::getline(lines, line)) {
    const Json value = Json::parse(line);
    if (value.contains("summary")) {
      summary = value["summary"];
    } else {
      rows.push_back(value);
    }
  }
  ASSERT_EQ(rows.size(), static_cast<std::size_t>(count));
  ASSERT_TRUE(summary.is_object()) << "the last line must be the summary";
  EXPECT_EQ(summary["designs_in_shard"], count);

  const auto collected =
      client.Post("/v1/explore", Sweep(count, "json").dump(), "application/json");
  ASSERT_TRUE(collected);
  ASSERT_EQ(collected->status, 200);
  const Json body = Json::parse(collected->body);
  ASSERT_EQ(body["rows"].size(), rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i], body["rows"][i]) << "row " << i;  // same designs, same numbers, bit for bit
  }
}

TEST(ExploreStreamTest, ClientGoingAwayMidStreamStopsTheSweepAndTheServerKeepsServing) {
  RunningServer server(StreamConfig());
  ASSERT_TRUE(server.bound());
  {
    httplib::Client client("127.0.0.1", server.port());
    std::size_t received = 0;
    httplib::Request request;
    request.method = "POST";
    request.path = "/v1/explore";
    request.body = Sweep(100000, "ndjson").dump();  // ~1 s of designs if it ran to the end
    request.set_header("Content-Type", "application/json");
    request.content_receiver = [&](const char*, std::size_t length, std::uint64_t, std::uint64_t) {
      received += length;
      return received < 64 * 1024;  // hang up after the first few chunks
    };
    const auto result = client.send(request);
    EXPECT_FALSE(result);  // the client cancelled the read
    EXPECT_GE(received, 64u * 1024u);
  }
  // The worker that streamed is free again and the server answers at once.
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(std::chrono::seconds(5));
  for (int i = 0; i < 8; ++i) {
    const auto health = client.Get("/health");
    ASSERT_TRUE(health);
    EXPECT_EQ(health->status, 200);
  }
}

// A streamed sweep the server stops (here --max-request-time-s; a shutdown alike) never looks
// complete: the 200 and some rows are already sent, so the NDJSON ends with an {"error"} line in
// place of its summary and, in every format, the chunked body gets no last chunk: the client
// reports the body incomplete. Before, a CSV cut short ended as a complete chunked body (curl
// exited 0 on a truncated CSV) and an NDJSON one too, after its error line. A JSON answer is
// not streamed: it is the 503 Timeout.
TEST(ExploreStreamTest, AStreamStoppedByTheDeadlineEndsIncomplete) {
  ServerConfig config = StreamConfig();
  config.max_request_time_s = 0.5;
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  // 10,000 Hertz designs (~1.5 ms each in Release: ~15 s, far past the 0.5 s budget).
  Json sweep = Json::parse(R"({"bat": {"preset": "paper-wood",
      "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
    "outputs": ["max_exit_speed"], "options": {"model": "hertz"}})");
  sweep["parameters"] = {
      {{"path", "fill.depth_m"}, {"min", 0.0}, {"max", 0.3}, {"count", 100}},
      {{"path", "fill.diameter_m"}, {"min", 0.01}, {"max", 0.03}, {"count", 100}}};
  for (const char* format : {"csv", "ndjson"}) {
    SCOPED_TRACE(format);
    sweep["format"] = format;
    httplib::Client client("127.0.0.1", server.port());
    client.set_read_timeout(std::chrono::seconds(60));
    std::string streamed;
    int status = 0;
    httplib::Request request;
    request.method = "POST";
    request.path = "/v1/explore";
    request.body = sweep.dump();
    request.set_header("Content-Type", "application/json");
    request.response_handler = [&](const httplib::Response& response) {
      status = response.status;
      return true;
    };
    request.content_receiver = [&](const char* data, std::size_t length, std::uint64_t,
                                   std::uint64_t) {
      streamed.append(data, length);
      return true;
    };
    const auto result = client.send(request);
    EXPECT_EQ(status, 200);  // sent with the first rows
    EXPECT_FALSE(streamed.empty());
    EXPECT_FALSE(result) << "a body cut short must not end as a complete chunked body";
    if (std::string(format) == "ndjson") {
      const std::size_t last = streamed.rfind('\n', streamed.size() - 2);
      const Json tail = Json::parse(streamed.substr(last + 1), nullptr, false);
      EXPECT_TRUE(tail.contains("error")) << streamed.substr(last + 1);
      EXPECT_FALSE(tail.contains("summary"));
    }
  }
  sweep["format"] = "json";
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(std::chrono::seconds(60));
  const auto json = client.Post("/v1/explore", sweep.dump(), "application/json");
  ASSERT_TRUE(json);
  EXPECT_EQ(json->status, 503);
  EXPECT_EQ(Json::parse(json->body)["code"], "Timeout");
}

}  // namespace
}  // namespace explore_stream_test
}  // namespace sweetspot::server
