// "format": "csv" for /v1/explore through every way in: streamed over real HTTP (chunked,
// text/csv), printed by the CLI, kept as a job's result, all the same bytes; and a sweep larger
// than a request may be (--max-samples) run by the CLI, whose batch limit is none by default.
#include <gtest/gtest.h>
#include <httplib.h>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <system_error>
#include <thread>
#include <vector>

#include "tests/refusal_text.hpp"
#include "tests/server/running_server.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace explore_csv_test {
namespace {

using Json = nlohmann::json;

struct CliOutput {
  int exit_code = -1;
  std::string out;
};

// Runs the CLI with `args` (stderr dropped; `env`, e.g. "NAME=value", set for it) and
// collects its stdout.
CliOutput RunSweetspot(const std::string& args, const std::string& env = "") {
  const std::string command = (env.empty() ? "" : "env " + env + " ") +
                              std::string(SWEETSPOT_BINARY_DIR) + "/server/sweetspot " + args +
                              " 2>/dev/null";
  CliOutput result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 65536> buffer{};
  std::size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// A file holding `text` in a new temporary folder, removed with the folder when it goes.
class TemporaryFile {
 public:
  TemporaryFile(const std::string& name, const std::string& text) {
    char folder[] = "/tmp/sweetspot-csv-XXXXXX";
    if (mkdtemp(folder) == nullptr) return;
    folder_ = folder;
    path_ = folder_ + "/" + name;
    std::ofstream(path_) << text;
  }
  ~TemporaryFile() {
    std::error_code ignored;
    if (!folder_.empty()) std::filesystem::remove_all(folder_, ignored);
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  /// The file's path ("" when the folder could not be made).
  const std::string& path() const { return path_; }

 private:
  std::string folder_;
  std::string path_;
};

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The HTTP answer, the CLI's output and a job's result of one CSV sweep are the same bytes
// (the CSV has no timing in it, so they are equal whole).

// Runs `sweep` as a /v1/explore job and returns GET /v1/jobs/{id}/result once the job is done
// (a null result when submitting fails, the job fails or is not done within 120 s; the
// failures are reported).
httplib::Result ExploreJobResult(httplib::Client* client, const Json& sweep) {
  const auto submitted = client->Post(
      "/v1/jobs", Json{{"path", "/v1/explore"}, {"body", sweep}}.dump(), "application/json");
  if (!submitted || submitted->status != 202) {
    ADD_FAILURE() << "submitting the job: " << (submitted ? submitted->body : "no answer");
    return httplib::Result{nullptr, httplib::Error::Unknown};
  }
  const std::string id = Json::parse(submitted->body)["id"].get<std::string>();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  std::string state;
  while (state != "done" && std::chrono::steady_clock::now() < deadline) {
    const auto status = client->Get("/v1/jobs/" + id);
    if (!status) break;
    state = Json::parse(status->body)["state"].get<std::string>();
    if (state == "failed") {
      ADD_FAILURE() << "the job failed: " << status->body;
      break;
    }
    if (state != "done") std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (state != "done") {
    ADD_FAILURE() << "the job is " << state << ", not done";
    return httplib::Result{nullptr, httplib::Error::Unknown};
  }
  return client->Get("/v1/jobs/" + id + "/result");
}
TEST(ExploreCsvEndToEndTest, HttpCliAndJobGiveTheSameBytes) {
  const Json sweep = Json::parse(R"({"bat": {"preset": "paper-wood",
      "fill": {"material": "cork", "diameter_m": 0.0254, "depth_m": 0.254}},
    "parameters": [{"path": "fill.depth_m", "min": 0.0, "max": 0.3, "count": 400},
                   {"path": "cor", "min": 0.4, "max": 1.2, "count": 3}],
    "outputs": ["max_exit_speed", "properties"], "format": "csv"})");
  ServerConfig config;
  config.threads = 4;
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  httplib::Client client = server.Client();
  client.set_read_timeout(std::chrono::seconds(120));

  std::string streamed;
  std::size_t chunks = 0;
  httplib::Request request;
  request.method = "POST";
  request.path = "/v1/explore";
  request.body = sweep.dump();
  request.set_header("Content-Type", "application/json");
  request.content_receiver = [&](const char* data, std::size_t length, std::uint64_t,
                                 std::uint64_t) {
    streamed.append(data, length);
    ++chunks;
    return true;
  };
  const auto http = client.send(request);
  ASSERT_TRUE(http) << httplib::to_string(http.error());
  ASSERT_EQ(http->status, 200);
  EXPECT_EQ(http->get_header_value("Content-Type"), "text/csv");
  EXPECT_EQ(http->get_header_value("Transfer-Encoding"), "chunked");
  EXPECT_GT(chunks, 3u);  // 1200 rows of ~330 bytes in chunks of about 16 KiB
  const std::vector<std::string> lines = Lines(streamed);
  ASSERT_EQ(lines.size(), 1201u);
  EXPECT_EQ(lines[0].rfind("index,parameters.fill.depth_m,parameters.cor,feasible,", 0), 0u)
      << lines[0];
  EXPECT_EQ(lines[3].substr(lines[3].rfind(',')), ",InvalidValue");  // cor 1.2 is refused

  const TemporaryFile request_file("sweep.json", sweep.dump());
  const std::string& file = request_file.path();
  const CliOutput cli = RunSweetspot("explore " + file);
  EXPECT_EQ(cli.exit_code, 0);
  EXPECT_TRUE(cli.out == streamed) << "the CLI's output differs from the HTTP answer";

  const auto result = ExploreJobResult(&client, sweep);
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status, 200);
  EXPECT_EQ(result->get_header_value("Content-Type"), "text/csv");
  EXPECT_TRUE(result->body == streamed) << "the job's result differs from the HTTP answer";
}

// 150,000 designs: over a request's limit (--max-samples, 100,000 by default), so the server
// answers 413 TooBig; the CLI has no limit by default and streams them all, and its
// --max-batch-samples refuses the same sweep when asked to.
TEST(ExploreCsvEndToEndTest, TheCliRunsASweepLargerThanARequestMayBe) {
  const Json sweep = Json::parse(R"({"bat": {"three_segment": {"length_m": 0.8636,
        "handle_radius_m": 0.0125, "barrel_radius_m": 0.033, "taper_start_m": 0.30,
        "taper_end_m": 0.55}, "material": "ash"},
    "parameters": [{"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.4, "count": 300},
                   {"path": "three_segment.taper_end_m", "min": 0.5, "max": 0.7, "count": 500}],
    "outputs": ["max_exit_speed"], "format": "csv",
    "columns": ["parameters.three_segment.taper_end_m", "max_exit_speed.exit_speed_mps"]})");
  {
    RunningServer server(ServerConfig{});
    ASSERT_TRUE(server.bound());
    const auto refused = server.Client().Post("/v1/explore", sweep.dump(), "application/json");
    ASSERT_TRUE(refused);
    EXPECT_EQ(refused->status, 413);
    const Json body = Json::parse(refused->body);
    EXPECT_EQ(body["code"], "TooBig");
    EXPECT_EQ(
        body["message"],
        "parameters describe 150000 designs, over the limit max_samples = 100000 (--max-samples)");
  }
  const TemporaryFile request_file("sweep.json", sweep.dump());
  const std::string& file = request_file.path();
  const CliOutput cli = RunSweetspot("explore " + file);
  ASSERT_EQ(cli.exit_code, 0);
  const std::vector<std::string> lines = Lines(cli.out);
  ASSERT_EQ(lines.size(), 150001u);
  EXPECT_EQ(lines[0], "parameters.three_segment.taper_end_m,max_exit_speed.exit_speed_mps");
  // Designs 0 and 499: taper_start_m 0.2 (the first of its 300 values) and taper_end_m the
  // first and last of its 500. Their exit speeds are the single request's, bit for bit.
  for (const std::size_t design : {std::size_t{0}, std::size_t{499}}) {
    const std::string& line = lines[design + 1];
    const std::size_t comma = line.find(',');
    ASSERT_NE(comma, std::string::npos) << line;
    const double taper_end_m = std::strtod(line.substr(0, comma).c_str(), nullptr);
    const double exit_speed_mps = std::strtod(line.substr(comma + 1).c_str(), nullptr);
    if (design == 0) {
      EXPECT_EQ(line.substr(0, comma), "0.5");
    }
    EXPECT_NEAR(taper_end_m, design == 0 ? 0.5 : 0.7, 1e-15);
    Json single = Json::parse(R"({"outputs": ["max_exit_speed"]})");
    single["bat"] = sweep["bat"];
    single["bat"]["three_segment"]["taper_start_m"] = 0.2;
    single["bat"]["three_segment"]["taper_end_m"] = taper_end_m;
    const TemporaryFile one_file("one.json", single.dump());
    const CliOutput one = RunSweetspot("sweet-spot " + one_file.path());
    ASSERT_EQ(one.exit_code, 0) << one.out;
    const double expected = Json::parse(one.out)["max_exit_speed"]["exit_speed_mps"].get<double>();
    EXPECT_EQ(std::memcmp(&exit_speed_mps, &expected, sizeof expected), 0)
        << "design " << design << ": " << line << " against " << expected;
  }
  const CliOutput limited = RunSweetspot("explore --max-batch-samples 149999 " + file);
  EXPECT_EQ(limited.exit_code, 2);
  EXPECT_EQ(Json::parse(limited.out)["message"],
            "parameters describe 150000 designs, over the limit max_batch_samples = 149999 "
            "(--max-batch-samples)");
}

// --explore-threads (flag or environment, CLI and server) changes the threads, never the
// bytes: row i is design i whatever the count; a count out of range is refused (exit 2).
TEST(ExploreCsvEndToEndTest, ExploreThreadsChangeNothingButTheThreads) {
  // 2000 designs: at least eight blocks (of at most 256), so that three threads interleave; some infeasible
  // (taper_start past taper_end), whose error rows must sit in their place too.
  const Json sweep = Json::parse(R"({"bat": {"three_segment": {"length_m": 0.8636,
        "handle_radius_m": 0.0125, "barrel_radius_m": 0.033, "taper_start_m": 0.30,
        "taper_end_m": 0.55}, "material": "ash"},
    "parameters": [{"path": "three_segment.taper_start_m", "min": 0.2, "max": 0.6, "count": 40},
                   {"path": "three_segment.taper_end_m", "min": 0.45, "max": 0.7, "count": 50}],
    "outputs": ["max_exit_speed", "properties"], "format": "csv",
    "columns": ["index", "max_exit_speed.exit_speed_mps", "properties.mass_kg", "error.code"]})");
  const TemporaryFile request_file("sweep.json", sweep.dump());
  const std::string& file = request_file.path();
  const CliOutput one = RunSweetspot("--explore-threads 1 explore " + file);
  ASSERT_EQ(one.exit_code, 0);
  ASSERT_EQ(Lines(one.out).size(), 2001u);
  EXPECT_NE(one.out.find(",InvalidValue\n"), std::string::npos);  // infeasible rows are in it
  EXPECT_EQ(RunSweetspot("--explore-threads 3 explore " + file).out, one.out);
  EXPECT_EQ(RunSweetspot("explore " + file).out, one.out);  // one per core
  EXPECT_EQ(RunSweetspot("explore " + file, "SWEETSPOT_EXPLORE_THREADS=2").out, one.out);
  EXPECT_EQ(RunSweetspot("explore " + file, "SWEETSPOT_EXPLORE_THREADS=0").exit_code, 2);
  EXPECT_EQ(RunSweetspot("--explore-threads 0 explore " + file).exit_code, 2);
  EXPECT_EQ(RunSweetspot("--explore-threads many explore " + file).exit_code, 2);
  // The server with three explore threads and one compute worker to borrow from: the same
  // bytes over HTTP.
  ServerConfig config;
  config.explore_threads = 3;
  config.compute_threads = 2;
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  const auto answer = server.Client().Post("/v1/explore", sweep.dump(), "application/json");
  ASSERT_TRUE(answer);
  EXPECT_EQ(answer->status, 200);
  EXPECT_EQ(answer->body, one.out);
  // Out of range in the server's configuration: refused with the rule.
  ServerConfig bad;
  bad.explore_threads = 2000;
  std::string why;
  EXPECT_FALSE(Validates(bad, &why));
  EXPECT_EQ(why, "explore_threads = 2000: must be in [0, 1024] (0 = one per core)");
}

// A job runs a sweep as a batch: over --max-samples but within --max-batch-samples, it is
// done while the same request is refused; over --max-batch-samples, POST /v1/jobs answers
// 413 at once and makes no job.
TEST(ExploreCsvEndToEndTest, AJobHasTheBatchLimit) {
  ServerConfig config;
  config.limits.max_samples = 10;
  config.limits.max_batch_samples = 20;
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  httplib::Client client = server.Client();
  const auto sweep = [](int count) {
    Json body = Json::parse(R"({"bat": {"preset": "paper-wood"}, "outputs": ["max_exit_speed"],
        "format": "csv", "columns": ["index"]})");
    body["parameters"] = {{{"path", "cor"}, {"min", 0.4}, {"max", 0.6}, {"count", count}}};
    return body;
  };
  const auto refused = client.Post("/v1/explore", sweep(15).dump(), "application/json");
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 413);
  const auto run_job = [&client](const Json& body) {
    const auto submitted = client.Post(
        "/v1/jobs", Json{{"path", "/v1/explore"}, {"body", body}}.dump(), "application/json");
    EXPECT_TRUE(submitted && submitted->status == 202);
    if (!submitted || submitted->status != 202) return Json();
    const std::string id = Json::parse(submitted->body)["id"].get<std::string>();
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    Json status;
    do {
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
      const auto answer = client.Get("/v1/jobs/" + id);
      if (!answer) break;
      status = Json::parse(answer->body);
    } while (status["state"] != "done" && status["state"] != "failed" &&
             std::chrono::steady_clock::now() < deadline);
    const auto result = client.Get("/v1/jobs/" + id + "/result");
    if (result) status["result"] = result->body;
    return status;
  };
  const Json done = run_job(sweep(15));
  EXPECT_EQ(done["state"], "done") << done.dump();
  EXPECT_EQ(Lines(done.value("result", "")).size(), 16u);
  // Over the batch limit: refused at submit, as the endpoint refuses it, and no job is made.
  const auto refused_job = client.Post(
      "/v1/jobs", Json{{"path", "/v1/explore"}, {"body", sweep(25)}}.dump(), "application/json");
  ASSERT_TRUE(refused_job);
  EXPECT_EQ(refused_job->status, 413);
  const Json refusal = Json::parse(refused_job->body);
  EXPECT_EQ(refusal["code"], "TooBig");
  EXPECT_EQ(refusal["message"],
            "parameters describe 25 designs, over the limit max_batch_samples = 20 "
            "(--max-batch-samples)");
  EXPECT_EQ(Json::parse(client.Get("/v1/jobs")->body)["total"], 1);  // Only the first job.
}

// Issue 19: an imperial sweep ("report_units": "imperial") in CSV (the default columns, the
// trade-unit fields among them) and in NDJSON is the same bytes over HTTP, from the CLI and as
// a job's result (NDJSON but the summary's timing_s); and its shards, run by the CLI and
// merged by explore-merge, are the unsharded sweep.
TEST(ExploreCsvEndToEndTest, ImperialSweepsAreTheSameBytesOverHttpCliAndJob) {
  Json sweep = Json::parse(R"({"bat": {"preset": "paper-wood",
      "fill": {"material": "cork", "diameter_in": 1, "depth_in": 10}},
    "parameters": [{"path": "fill.depth_in", "min": 0, "max": 12, "count": 40},
                   {"path": "ball.speed_mph", "min": 60, "max": 95, "count": 3}],
    "outputs": ["max_exit_speed", "center_of_percussion", "properties"],
    "report_units": "imperial"})");
  ServerConfig config;
  config.threads = 4;
  RunningServer server(config);
  ASSERT_TRUE(server.bound());
  httplib::Client client = server.Client();
  client.set_read_timeout(std::chrono::seconds(120));
  const auto without_timing = [](const std::string& ndjson) {
    const std::size_t at = ndjson.rfind("\"timing_s\":");
    if (at == std::string::npos) return ndjson;
    const std::size_t end = ndjson.find_first_of(",}", at);
    return ndjson.substr(0, at) + ndjson.substr(end);
  };
  for (const char* format : {"csv", "ndjson"}) {
    sweep["format"] = format;
    const auto http = client.Post("/v1/explore", sweep.dump(), "application/json");
    ASSERT_TRUE(http);
    ASSERT_EQ(http->status, 200) << http->body;
    const std::vector<std::string> lines = Lines(http->body);
    ASSERT_EQ(lines.size(), 121u) << format;  // 120 rows and the header or the summary
    if (std::string(format) == "csv") {
      EXPECT_NE(lines[0].find(",max_exit_speed.exit_speed_mph,"), std::string::npos) << lines[0];
      EXPECT_NE(lines[0].find(",center_of_percussion.position_from_tip_in,"), std::string::npos);
      EXPECT_NE(lines[0].find(",properties.mass_oz,"), std::string::npos);
    } else {
      EXPECT_EQ(Json::parse(lines.back())["summary"]["report_units"], "imperial");
      EXPECT_TRUE(Json::parse(lines[0])["max_exit_speed"].contains("position_from_tip_in"));
    }
    const TemporaryFile request_file("sweep.json", sweep.dump());
    const CliOutput cli = RunSweetspot("explore " + request_file.path());
    EXPECT_EQ(cli.exit_code, 0);
    EXPECT_TRUE(without_timing(cli.out) == without_timing(http->body))
        << format << ": the CLI's output differs from the HTTP answer";

    const auto result = ExploreJobResult(&client, sweep);
    ASSERT_TRUE(result);
    EXPECT_EQ(result->status, 200);
    EXPECT_TRUE(without_timing(result->body) == without_timing(http->body))
        << format << ": the job's result differs from the HTTP answer";

    if (std::string(format) != "ndjson") continue;
    // Three shards by the CLI, merged: the unsharded sweep (the summary but timing_s).
    std::vector<std::unique_ptr<TemporaryFile>> shard_files;
    std::string names;
    for (int i = 0; i < 3; ++i) {
      const CliOutput shard =
          RunSweetspot("explore --shard " + std::to_string(i) + "/3 " + request_file.path());
      ASSERT_EQ(shard.exit_code, 0) << shard.out;
      shard_files.push_back(
          std::make_unique<TemporaryFile>("shard-" + std::to_string(i) + ".ndjson", shard.out));
      names += " " + shard_files.back()->path();
    }
    const CliOutput merged = RunSweetspot("explore-merge" + names);
    ASSERT_EQ(merged.exit_code, 0) << merged.out;
    const std::vector<std::string> merged_lines = Lines(merged.out);
    ASSERT_EQ(merged_lines.size(), lines.size());
    for (std::size_t i = 0; i + 1 < lines.size(); ++i) EXPECT_EQ(merged_lines[i], lines[i]) << i;
    Json merged_summary = Json::parse(merged_lines.back())["summary"];
    Json whole_summary = Json::parse(lines.back())["summary"];
    merged_summary.erase("timing_s");
    whole_summary.erase("timing_s");
    EXPECT_EQ(merged_summary, whole_summary);
  }
}

}  // namespace
}  // namespace explore_csv_test
}  // namespace sweetspot::server
