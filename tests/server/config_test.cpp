#include "server/config.hpp"

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <map>

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace config_test {
namespace {

ParsedCommandLine Parse(const std::vector<std::string>& args,
                        const std::map<std::string, std::string>& env = {}) {
  return ParseCommandLine(args, [&env](const std::string& name) -> std::optional<std::string> {
    const auto it = env.find(name);
    if (it == env.end()) return std::nullopt;
    return it->second;
  });
}

TEST(ConfigTest, DefaultsAreValidAndLoopback) {
  const ServerConfig config;
  std::string why;
  EXPECT_TRUE(Validates(config, &why)) << why;
  EXPECT_EQ(config.host, "127.0.0.1");
  EXPECT_EQ(config.port, 8080);
  EXPECT_EQ(config.threads, 8);
  EXPECT_EQ(config.max_body_bytes, 1u << 20);
}

TEST(ConfigTest, EnvironmentThenFlagsOverride) {
  const auto parsed = Parse({"--port", "9000", "--threads=3"},
                            {{"SWEETSPOT_HOST", "0.0.0.0"}, {"SWEETSPOT_PORT", "8500"}});
  ASSERT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.config.host, "0.0.0.0");
  EXPECT_EQ(parsed.config.port, 9000);
  EXPECT_EQ(parsed.config.threads, 3);
}

TEST(ConfigTest, SolverLimitsFromFlagsAndEnvironment) {
  const auto parsed = Parse({"--max-integration-steps", "5000", "--max-time-s", "2.5"},
                            {{"SWEETSPOT_MAX_ITERATIONS", "40"}});
  ASSERT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.config.limits.max_integration_steps, 5000);
  EXPECT_EQ(parsed.config.limits.max_time_s, 2.5);
  EXPECT_EQ(parsed.config.limits.max_iterations, 40);
  EXPECT_EQ(Parse({"--max-integration-steps", "9"}).error,
            "option --max-integration-steps = \"9\": must be an integer in [10, 1000000000]");
}

TEST(ConfigTest, RequestCapsFromFlagsAndEnvironment) {
  const auto parsed =
      Parse({"--max-curve-samples", "20000"}, {{"SWEETSPOT_MAX_DESIGN_VARIABLES", "12"}});
  ASSERT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.config.limits.max_curve_samples, 20000u);
  EXPECT_EQ(parsed.config.limits.max_design_variables, 12u);
  EXPECT_EQ(Parse({"--max-design-variables", "7"}).config.limits.max_design_variables, 7u);
  const std::string usage = Usage("sweetspot-server");
  EXPECT_NE(usage.find("--max-design-variables"), std::string::npos);
  EXPECT_NE(usage.find("SWEETSPOT_MAX_DESIGN_VARIABLES"), std::string::npos);
}

// A synchronous request's designs (--max-samples) and a job's (--max-batch-samples) are two
// limits.
TEST(ConfigTest, RequestAndBatchSampleLimitsAreSeparate) {
  EXPECT_EQ(ServerConfig{}.limits.max_samples, 100000u);
  EXPECT_EQ(ServerConfig{}.limits.max_batch_samples, 1000000u);
  const auto parsed = Parse({"--max-samples", "500"}, {{"SWEETSPOT_MAX_BATCH_SAMPLES", "5000000"}});
  ASSERT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.config.limits.max_samples, 500u);
  EXPECT_EQ(parsed.config.limits.max_batch_samples, 5000000u);
  EXPECT_EQ(Parse({"--max-batch-samples", "7"}).config.limits.max_batch_samples, 7u);
  EXPECT_EQ(Parse({"--max-batch-samples", "0"}).error,
            "option --max-batch-samples = \"0\": must be an integer in [1, 100000000]");
  EXPECT_NE(Usage("sweetspot-server").find("SWEETSPOT_MAX_BATCH_SAMPLES"), std::string::npos);
}

// Issue "Under attack, bounded", items 4 and 11a: the in-memory answer's estimated size and a
// job's estimated cost are limits with flags, environment variables and documented defaults.
TEST(ConfigTest, ResponseAndJobEstimateLimitsFromFlagsAndEnvironment) {
  const ServerConfig defaults;
  EXPECT_EQ(defaults.limits.max_response_bytes, 67108864u);
  EXPECT_EQ(defaults.limits.max_job_cpu_s, 3600.0);
  EXPECT_EQ(defaults.limits.max_job_time_s, 600.0);
  EXPECT_EQ(defaults.limits.max_job_result_bytes, 268435456u);
  const auto parsed =
      Parse({"--max-response-bytes", "1048576", "--max-job-cpu-s", "7200"},
            {{"SWEETSPOT_JOB_MAX_TIME_S", "30"}, {"SWEETSPOT_JOB_MAX_RESULT_BYTES", "2048"}});
  ASSERT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.config.limits.max_response_bytes, 1048576u);
  EXPECT_EQ(parsed.config.limits.max_job_cpu_s, 7200.0);
  // One flag per job limit: the check at submit takes the job runner's.
  EXPECT_EQ(parsed.config.jobs.max_time_s, 30.0);
  EXPECT_EQ(parsed.config.limits.max_job_time_s, 30.0);
  EXPECT_EQ(parsed.config.jobs.max_result_bytes, 2048u);
  EXPECT_EQ(parsed.config.limits.max_job_result_bytes, 2048u);
  EXPECT_EQ(Parse({"--job-max-result-bytes", "4096"}).config.limits.max_job_result_bytes, 4096u);
  EXPECT_EQ(Parse({}, {{"SWEETSPOT_MAX_RESPONSE_BYTES", "5000"}}).config.limits.max_response_bytes,
            5000u);
  EXPECT_EQ(Parse({"--max-response-bytes", "10"}).error,
            "option --max-response-bytes = \"10\": must be an integer in [1024, 1099511627776]");
  EXPECT_EQ(Parse({"--max-job-cpu-s", "0"}).error,
            "option --max-job-cpu-s = \"0\": must be a number of seconds in (0, 1e+07]");
  const std::string usage = Usage("sweetspot-server");
  for (const char* name :
       {"--max-response-bytes", "SWEETSPOT_MAX_RESPONSE_BYTES", "--max-job-cpu-s",
        "SWEETSPOT_MAX_JOB_CPU_S", "--job-max-time-s", "SWEETSPOT_JOB_MAX_TIME_S",
        "--job-max-result-bytes", "SWEETSPOT_JOB_MAX_RESULT_BYTES"}) {
    EXPECT_NE(usage.find(name), std::string::npos) << name;
  }
}

TEST(ConfigTest, BadValuesNameFlagValueAndRule) {
  EXPECT_EQ(Parse({"--port", "70000"}).error,
            "option --port = \"70000\": must be an integer in [0, 65535]");
  EXPECT_EQ(Parse({"--threads", "0"}).error,
            "option --threads = \"0\": must be an integer in [1, 1024]");
  EXPECT_EQ(Parse({"--read-timeout-s", "nan"}).error,
            "option --read-timeout-s = \"nan\": must be a number of seconds in (0, 3600]");
  EXPECT_EQ(Parse({}, {{"SWEETSPOT_PORT", "80x"}}).error,
            "environment SWEETSPOT_PORT = \"80x\": must be an integer in [0, 65535]");
  EXPECT_EQ(Parse({"--bogus"}).error, "unknown option --bogus (see --help)");
  EXPECT_EQ(Parse({"--port"}).error, "option --port needs a value");
}

TEST(ConfigTest, DrainSecondsFromFlagsAndEnvironment) {
  EXPECT_EQ(ServerConfig{}.drain_s, 0.0);  // stop accepting at once unless told otherwise
  EXPECT_EQ(Parse({}, {{"SWEETSPOT_DRAIN_S", "5"}}).config.drain_s, 5.0);
  EXPECT_EQ(Parse({"--drain-s", "1.5"}, {{"SWEETSPOT_DRAIN_S", "5"}}).config.drain_s, 1.5);
  EXPECT_EQ(Parse({"--drain-s", "0"}).config.drain_s, 0.0);
  EXPECT_EQ(Parse({"--drain-s", "-1"}).error,
            "option --drain-s = \"-1\": must be a number of seconds in [0, 3600]");
  EXPECT_EQ(Parse({"--drain-s", "3601"}).error,
            "option --drain-s = \"3601\": must be a number of seconds in [0, 3600]");
  ServerConfig config;
  config.drain_s = -0.5;
  std::string why;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "drain_s = -0.5: must be in [0, 3600]");
}

TEST(ConfigTest, IsValidRefusesOutOfRange) {
  ServerConfig config;
  config.threads = 0;
  std::string why;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "threads = 0: must be in [1, 1024]");
  config = ServerConfig{};
  config.read_timeout_s = -1;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "read_timeout_s = -1: must be in (0, 3600]");
  // The value as given, every digit (an ostream's 6 digits wrote "3600" here).
  config.read_timeout_s = 3600.0001;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "read_timeout_s = 3600.0001: must be in (0, 3600]");
}

TEST(ConfigTest, ServingLimitsFromFlagsAndEnvironment) {
  const ServerConfig defaults;
  EXPECT_EQ(defaults.header_timeout_s, 10.0);
  EXPECT_EQ(defaults.body_min_rate_bytes_per_s, 32768.0);
  EXPECT_EQ(defaults.max_head_bytes, 65536u);
  EXPECT_EQ(defaults.compute_threads, 0);  // one per core
  const auto parsed = Parse(
      {"--header-timeout-s", "2.5", "--body-min-rate-bytes-per-s=1000", "--compute-threads", "3"},
      {{"SWEETSPOT_MAX_HEAD_BYTES", "4096"}});
  ASSERT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.config.header_timeout_s, 2.5);
  EXPECT_EQ(parsed.config.body_min_rate_bytes_per_s, 1000.0);
  EXPECT_EQ(parsed.config.compute_threads, 3);
  EXPECT_EQ(parsed.config.max_head_bytes, 4096u);
  EXPECT_EQ(Parse({"--header-timeout-s", "0"}).error,
            "option --header-timeout-s = \"0\": must be a number of seconds in (0, 3600]");
  EXPECT_EQ(Parse({"--body-min-rate-bytes-per-s", "0"}).error,
            "option --body-min-rate-bytes-per-s = \"0\": must be an integer in [1, 17179869184]");
  EXPECT_EQ(Parse({"--max-head-bytes", "100"}).error,
            "option --max-head-bytes = \"100\": must be an integer in [256, 16777216]");
  EXPECT_EQ(Parse({"--compute-threads", "-1"}).error,
            "option --compute-threads = \"-1\": must be an integer in [0, 1024]");
  ServerConfig config;
  config.body_min_rate_bytes_per_s = 0.5;
  std::string why;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "body_min_rate_bytes_per_s = 0.5: must be at least 1");
}

TEST(ConfigTest, HelpListsEveryOptionAndEnvironmentVariable) {
  EXPECT_TRUE(Parse({"--help"}).show_help);
  const std::string usage = Usage("sweetspot-server");
  for (const char* name :
       {"--host", "SWEETSPOT_HOST", "--port", "SWEETSPOT_PORT", "--threads", "SWEETSPOT_THREADS",
        "--max-body-bytes", "--read-timeout-s", "--write-timeout-s", "--keep-alive-timeout-s",
        "--access-log", "--header-timeout-s", "SWEETSPOT_HEADER_TIMEOUT_S",
        "--body-min-rate-bytes-per-s", "--max-head-bytes", "--compute-threads",
        "SWEETSPOT_COMPUTE_THREADS"}) {
    EXPECT_NE(usage.find(name), std::string::npos) << name;
  }
}

}  // namespace
}  // namespace config_test
}  // namespace sweetspot::server
