// What the job tests share: a slow and a quick jobbable request, and a small
// HTTP client for the real sweetspot-server (submit, poll, read results).
#pragma once

#include <gtest/gtest.h>
#include <httplib.h>
#include <stdlib.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <string>
#include <thread>

#include "tests/sanitizers.hpp"
#include "tests/server/server_process.hpp"

namespace sweetspot::testing::jobs {

using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// How long a test waits for something that must happen (a job to reach a
// state, a request to be in flight). Only reached when the code is broken: the
// slowest step, the sweep below under ASan on a loaded 2-core machine, takes a
// few seconds; a passing Release run needs about one.
inline constexpr auto kMustHappen = std::chrono::seconds(120);

// The sweeps below are sized to the build: a test needs a job that is still running when it
// acts (kills, cancels, stops the database), not a given number of designs. Under a sanitizer
// each design costs about 9 times what it costs in Release (a 400-design Hertz sweep through
// the CLI: 0.43 s Release, 3.8 s ASan, 4.8 s TSan), so there the sweeps have a quarter of the
// designs and still run about twice as long as in Release. They were the slowest tests of
// both sanitizer passes (PostgresJobsTest.EveryJobIsVisible... 35 s under TSan, 5.6 s Release).
#if SWEETSPOT_UNDER_ASAN || SWEETSPOT_UNDER_TSAN
#define SWEETSPOT_SLOW_SWEEP_COUNT "10"
#define SWEETSPOT_LONG_SWEEP_COUNT "20"
inline constexpr std::size_t kSlowSweepRows = 100;
inline constexpr std::size_t kLongSweepRows = 400;
#else
#define SWEETSPOT_SLOW_SWEEP_COUNT "20"
#define SWEETSPOT_LONG_SWEEP_COUNT "40"
inline constexpr std::size_t kSlowSweepRows = 400;
inline constexpr std::size_t kLongSweepRows = 1600;
#endif

// A slow request with a small answer: kSlowSweepRows designs (400 in Release), each a
// Hertz-contact exit speed maximised by NLopt (~1.5 ms each in Release, so ~0.6 s), checking
// its cancel flag between designs. Its numbers are deterministic, so running it again gives
// the same rows.
inline const char* const kSlowSweep = R"({
  "bat": {"preset": "paper-wood",
          "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
  "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": )" SWEETSPOT_SLOW_SWEEP_COUNT
                                      R"(},
                 {"path": "fill.diameter_m", "min": 0.01, "max": 0.03, "count": )" SWEETSPOT_SLOW_SWEEP_COUNT
                                      R"(}],
  "outputs": ["max_exit_speed"],
  "options": {"model": "hertz"}})";

// A longer sweep than kSlowSweep (kLongSweepRows designs, 1600 and ~2.5 s in Release): long
// enough to be killed or cancelled while it runs, and to report progress.
inline const char* const kLongSweep = R"({
  "bat": {"preset": "paper-wood",
          "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
  "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": )" SWEETSPOT_LONG_SWEEP_COUNT
                                      R"(},
                 {"path": "fill.diameter_m", "min": 0.01, "max": 0.03, "count": )" SWEETSPOT_LONG_SWEEP_COUNT
                                      R"(}],
  "outputs": ["max_exit_speed"],
  "options": {"model": "hertz"}})";
#undef SWEETSPOT_SLOW_SWEEP_COUNT
#undef SWEETSPOT_LONG_SWEEP_COUNT

// A quick job's inner request.
inline const char* const kQuick = R"({"bat": {"preset": "paper-wood"}})";

// A client with time-outs far above the slowest answer here (the sweep).
inline httplib::Client ClientOf(ServerProcess& server) {
  httplib::Client client("127.0.0.1", server.port());
  client.set_read_timeout(std::chrono::seconds(120));
  client.set_write_timeout(std::chrono::seconds(120));
  return client;
}

struct Answer {
  int status = 0;  // 0: no answer (connection failed).
  Json body;
};

inline Answer Parse(const httplib::Result& result) {
  if (!result) return {};
  return {result->status, Json::parse(result->body, nullptr, false)};
}

inline Answer Get(ServerProcess& server, const std::string& path) {
  return Parse(ClientOf(server).Get(path.c_str()));
}

inline Answer Delete(ServerProcess& server, const std::string& path) {
  return Parse(ClientOf(server).Delete(path.c_str()));
}

inline Answer PostJson(ServerProcess& server, const std::string& path, const std::string& body) {
  return Parse(ClientOf(server).Post(path.c_str(), body, "application/json"));
}

// Submits `inner` (JSON text) to `path` as a job; returns its id ("" on failure).
inline std::string SubmitJob(ServerProcess& server, const std::string& path,
                             const std::string& inner) {
  const Answer answer =
      PostJson(server, "/v1/jobs", R"({"path": ")" + path + R"(", "body": )" + inner + "}");
  EXPECT_EQ(answer.status, 202) << answer.body.dump();
  return answer.body.value("id", "");
}

// Polls GET /v1/jobs/{id} until its state is `state` (at most kMustHappen).
inline Json WaitForState(ServerProcess& server, const std::string& id, const std::string& state) {
  const auto deadline = Clock::now() + kMustHappen;
  Answer answer = Get(server, "/v1/jobs/" + id);
  while (answer.status == 200 && answer.body["state"] != state && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    answer = Get(server, "/v1/jobs/" + id);
  }
  EXPECT_EQ(answer.status, 200) << answer.body.dump();
  EXPECT_EQ(answer.body["state"], state) << answer.body.dump();
  return answer.body;
}

// Removes the keys that measure time ("timing_s", "solve_time_s") at any depth.
inline Json WithoutTimings(Json json) {
  if (json.is_object()) {
    json.erase("timing_s");
    json.erase("solve_time_s");
    for (auto& [key, value] : json.items()) value = WithoutTimings(value);
  } else if (json.is_array()) {
    for (Json& value : json) value = WithoutTimings(value);
  }
  return json;
}

/// A fresh directory under the test temp dir (named `prefix`-XXXXXX), removed with its files
/// at the end.
class TempDir {
 public:
  explicit TempDir(const std::string& prefix = "sweetspot-jobs") {
    std::string pattern =
        (std::filesystem::path(::testing::TempDir()) / (prefix + "-XXXXXX")).string();
    if (mkdtemp(pattern.data()) != nullptr) path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    if (!path_.empty()) std::filesystem::remove_all(path_, ignored);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  /// The path of `name` in the directory.
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  std::filesystem::path path_;
};

}  // namespace sweetspot::testing::jobs
