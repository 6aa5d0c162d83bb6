// The `sweetspot` CLI: same handlers, no network; exit 0 for 2xx, 2 for 4xx.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

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
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) result.out.append(buffer.data(), n);
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

TEST(CliTest, NoArgumentsIsAUsageError) {
  EXPECT_EQ(RunCli("").exit_code, 2);
}

}  // namespace
}  // namespace sweetspot
