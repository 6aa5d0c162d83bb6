// The `sweetspot` CLI: same handlers, no network; exit 0 for 2xx, 2 for 4xx.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <nlohmann/json.hpp>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace sweetspot {
namespace {

struct CliResult {
  int exit_code = -1;
  std::string out;
};

// Runs the CLI through the shell with `args`, feeding `stdin_text`.
CliResult RunCli(const std::string& args, const std::string& stdin_text = "") {
  const std::string binary = std::string(SWEETSPOT_BINARY_DIR) + "/server/sweetspot";
  const std::string command =
      "printf '%s' '" + stdin_text + "' | " + binary + " " + args + " 2>/dev/null";
  CliResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0)
    result.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

TEST(CliTest, HealthPrintsOkAndExitsZero) {
  const CliResult result = RunCli("health");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_EQ(nlohmann::json::parse(result.out), nlohmann::json({{"status", "ok"}}));
}

TEST(CliTest, UnknownPathExitsTwoWithErrorEnvelope) {
  const CliResult result = RunCli("no/such/path");
  EXPECT_EQ(result.exit_code, 2);
  const auto body = nlohmann::json::parse(result.out);
  EXPECT_EQ(body["code"], "NotFound");
  EXPECT_EQ(body["message"], "no endpoint at path /v1/no/such/path");
}

TEST(CliTest, HelpListsPathsAndExitsZero) {
  const CliResult result = RunCli("--help");
  EXPECT_EQ(result.exit_code, 0);
  EXPECT_NE(result.out.find("Usage: sweetspot"), std::string::npos);
  EXPECT_NE(result.out.find("GET health"), std::string::npos) << result.out;
}

TEST(CliTest, NoArgumentsIsAUsageError) { EXPECT_EQ(RunCli("").exit_code, 2); }

// A sweep run as three shards by `sweetspot explore --shard I/3` and merged by
// `sweetspot explore-merge` equals the unsharded sweep's NDJSON (but timing_s).
TEST(CliTest, ShardsMergeIntoTheUnshardedSweep) {
  char folder[] = "/tmp/sweetspot-cli-XXXXXX";
  ASSERT_NE(mkdtemp(folder), nullptr);
  const std::string dir = folder;
  {
    std::ofstream request(dir + "/sweep.json");
    request << R"({"bat": {"preset": "paper-wood", "fill": {"material": "cork",
      "diameter_m": 0.0254, "depth_m": 0.254}}, "outputs": ["max_exit_speed", "properties"],
      "parameters": [{"path": "fill.depth_m", "min": 0, "max": 0.3, "count": 7}],
      "format": "ndjson"})";
  }
  std::string shard_files;
  for (int i = 0; i < 3; ++i) {
    const std::string file = dir + "/shard-" + std::to_string(i) + ".ndjson";
    const CliResult shard =
        RunCli("explore --shard " + std::to_string(i) + "/3 " + dir + "/sweep.json");
    ASSERT_EQ(shard.exit_code, 0) << shard.out;
    std::ofstream(file) << shard.out;
    shard_files += " " + file;
  }
  const CliResult merged = RunCli("explore-merge" + shard_files);
  const CliResult whole = RunCli("explore " + dir + "/sweep.json");
  ASSERT_EQ(merged.exit_code, 0) << merged.out;
  ASSERT_EQ(whole.exit_code, 0) << whole.out;
  auto without_timing = [](const std::string& text) {
    std::vector<nlohmann::json> lines;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
      nlohmann::json value = nlohmann::json::parse(line);
      if (value.contains("summary")) value["summary"].erase("timing_s");
      lines.push_back(std::move(value));
    }
    return lines;
  };
  EXPECT_EQ(without_timing(merged.out), without_timing(whole.out));
  EXPECT_EQ(without_timing(whole.out).size(), 8u);  // 7 rows and the summary
  // Two shards of three: refused, exit 2, nothing on stdout.
  const CliResult incomplete =
      RunCli("explore-merge " + dir + "/shard-0.ndjson " + dir + "/shard-2.ndjson");
  EXPECT_EQ(incomplete.exit_code, 2);
  EXPECT_EQ(incomplete.out, "");
  EXPECT_EQ(RunCli("explore --shard 3/3 " + dir + "/sweep.json").exit_code, 2);
  EXPECT_EQ(RunCli("presets --shard 0/2").exit_code, 2);
  std::system(("rm -rf " + dir).c_str());
}

// `sweetspot flight`: the /v1/flight handler without a network (issue 34). Nathan's sheet case
// in mph: 422.18 ft converged (421.49 ft by the sheet's 0.01 s steps; docs/validation.md).
TEST(CliTest, FlightAnswersAndRefusesLikeTheEndpoint) {
  CliResult result = RunCli(
      "flight -", R"({"launch": {"exit_speed_mph": 103, "launch_angle_deg": 27.5,
      "backspin_rpm": 2500, "sidespin_rpm": 0}, "environment": {"elevation_ft": 15}})");
  ASSERT_EQ(result.exit_code, 0) << result.out;
  const auto body = nlohmann::json::parse(result.out);
  EXPECT_NEAR(body["distance_m"].get<double>() / 0.3048, 422.18, 0.01);
  EXPECT_EQ(body["spin_source"], "given");
  result = RunCli("flight -", R"({"launch": {"exit_speed_mph": 100, "launch_angle_deg": 120}})");
  EXPECT_EQ(result.exit_code, 2);
  EXPECT_EQ(nlohmann::json::parse(result.out)["field"], "launch.launch_angle_deg");
}

}  // namespace
}  // namespace sweetspot
