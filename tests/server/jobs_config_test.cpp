// The job persistence and shutdown options: defaults, flags, environment,
// Validate's messages, --help, and a server whose jobs database is unusable.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <map>
#include <string>
#include <thread>

#include "server/config.hpp"
#include "server/server.hpp"
#include "tests/refusal_text.hpp"
#include "tests/server/server_process.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace jobs_config_test {
namespace {

ParsedCommandLine Parse(const std::vector<std::string>& args,
                        const std::map<std::string, std::string>& env = {}) {
  return ParseCommandLine(args, [&env](const std::string& name) -> std::optional<std::string> {
    const auto it = env.find(name);
    if (it == env.end()) return std::nullopt;
    return it->second;
  });
}

TEST(JobsConfigTest, Defaults) {
  const ServerConfig config;
  EXPECT_EQ(config.jobs_db, "sweetspot-jobs.db");
  EXPECT_EQ(config.shutdown_grace_s, 8.0);
  EXPECT_EQ(config.jobs.max_resumes, 2);
  EXPECT_STREQ(kNoJobsDb, "none");
  std::string why;
  EXPECT_TRUE(Validates(config, &why)) << why;
}

TEST(JobsConfigTest, FlagsAndEnvironment) {
  const auto parsed = Parse(
      {"--jobs-db", "/var/lib/sweetspot/jobs.db", "--shutdown-grace-s=0", "--job-max-resumes", "0"},
      {{"SWEETSPOT_JOBS_DB", "none"}, {"SWEETSPOT_SHUTDOWN_GRACE_S", "30"}});
  ASSERT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.config.jobs_db, "/var/lib/sweetspot/jobs.db");
  EXPECT_EQ(parsed.config.shutdown_grace_s, 0.0);
  EXPECT_EQ(parsed.config.jobs.max_resumes, 0);
  const auto from_env = Parse({}, {{"SWEETSPOT_JOBS_DB", "none"},
                                   {"SWEETSPOT_SHUTDOWN_GRACE_S", "2.5"},
                                   {"SWEETSPOT_JOB_MAX_RESUMES", "100"}});
  ASSERT_EQ(from_env.error, "");
  EXPECT_EQ(from_env.config.jobs_db, "none");
  EXPECT_EQ(from_env.config.shutdown_grace_s, 2.5);
  EXPECT_EQ(from_env.config.jobs.max_resumes, 100);
  // A PostgreSQL URI is kept as given; the lease and the result limit are PostgreSQL's.
  const auto postgres = Parse({"--jobs-db", "postgresql://sweetspot@db.example:5432/jobs",
                               "--job-lease-s", "4"},
                              {{"SWEETSPOT_JOB_MAX_RESULT_BYTES", "1048576"}});
  ASSERT_EQ(postgres.error, "");
  EXPECT_EQ(postgres.config.jobs_db, "postgresql://sweetspot@db.example:5432/jobs");
  EXPECT_EQ(postgres.config.jobs.lease_s, 4.0);
  EXPECT_EQ(postgres.config.jobs.max_result_bytes, 1048576u);
  EXPECT_EQ(ServerConfig{}.jobs.lease_s, 10.0);
  EXPECT_EQ(ServerConfig{}.jobs.max_result_bytes, 256u << 20);
}

TEST(JobsConfigTest, BadValuesNameFlagValueAndRule) {
  EXPECT_EQ(Parse({"--jobs-db", ""}).error,
            "option --jobs-db = \"\": must be a file path, a postgresql:// URI, or none for no "
            "persistence");
  EXPECT_EQ(Parse({"--job-lease-s", "0.5"}).error,
            "option --job-lease-s = \"0.5\": must be in [1, 3600] s");
  EXPECT_EQ(Parse({"--job-max-result-bytes", "100"}).error,
            "option --job-max-result-bytes = \"100\": must be an integer in [1024, 1000000000000]");
  EXPECT_EQ(Parse({"--shutdown-grace-s", "-1"}).error,
            "option --shutdown-grace-s = \"-1\": must be a number of seconds in [0, 3600]");
  EXPECT_EQ(Parse({"--shutdown-grace-s", "nan"}).error,
            "option --shutdown-grace-s = \"nan\": must be a number of seconds in [0, 3600]");
  EXPECT_EQ(Parse({}, {{"SWEETSPOT_SHUTDOWN_GRACE_S", "3601"}}).error,
            "environment SWEETSPOT_SHUTDOWN_GRACE_S = \"3601\": must be a number of seconds in "
            "[0, 3600]");
  EXPECT_EQ(Parse({"--job-max-resumes", "101"}).error,
            "option --job-max-resumes = \"101\": must be an integer in [0, 100]");
}

TEST(JobsConfigTest, IsValidRefusesOutOfRange) {
  std::string why;
  ServerConfig config;
  config.jobs_db = "";
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why,
            "jobs_db = \"\": must be a file path, a postgresql:// URI, or \"none\" for no "
            "persistence");
  config = ServerConfig{};
  config.jobs.lease_s = 0.0;
  EXPECT_FALSE(Validates(config.jobs, &why));
  EXPECT_EQ(why, "lease_s = 0: must be in [1, 3600]");
  config.jobs.lease_s = 10.0;
  config.jobs.max_result_bytes = 10;
  EXPECT_FALSE(Validates(config.jobs, &why));
  EXPECT_EQ(why, "max_result_bytes = 10: must be in [1024, 1000000000000]");
  config = ServerConfig{};
  config.shutdown_grace_s = -0.5;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "shutdown_grace_s = -0.5: must be in [0, 3600]");
  config.shutdown_grace_s = std::nan("");
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "shutdown_grace_s = nan: must be in [0, 3600]");
  config = ServerConfig{};
  config.jobs.max_resumes = -1;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "jobs.max_resumes = -1: must be in [0, 100]");
}

TEST(JobsConfigTest, HelpListsTheOptions) {
  const std::string usage = Usage("sweetspot-server");
  for (const char* name :
       {"--jobs-db", "SWEETSPOT_JOBS_DB", "--shutdown-grace-s", "SWEETSPOT_SHUTDOWN_GRACE_S",
        "--job-max-resumes", "SWEETSPOT_JOB_MAX_RESUMES"}) {
    EXPECT_NE(usage.find(name), std::string::npos) << name;
  }
}

// The limits of "Under attack, bounded": a job's time, its results in memory, the database's
// size.
TEST(JobsConfigTest, JobLimitsFlagsEnvironmentAndRules) {
  const ServerConfig defaults;
  EXPECT_EQ(defaults.jobs.max_time_s, 600.0);
  EXPECT_EQ(defaults.jobs.max_results_memory_bytes, 256u << 20);
  EXPECT_EQ(defaults.jobs_db_max_bytes, 4294967296u);  // 4 GiB: a disk is never filled by default
  const auto parsed = Parse(
      {"--job-max-time-s", "0.5", "--jobs-db-max-bytes=131072"},
      {{"SWEETSPOT_JOB_RESULTS_MEMORY_BYTES", "2500000"}, {"SWEETSPOT_JOB_MAX_TIME_S", "30"}});
  ASSERT_EQ(parsed.error, "");
  EXPECT_EQ(parsed.config.jobs.max_time_s, 0.5);
  EXPECT_EQ(parsed.config.jobs.max_results_memory_bytes, 2500000u);
  EXPECT_EQ(parsed.config.jobs_db_max_bytes, 131072u);
  EXPECT_EQ(Parse({}, {{"SWEETSPOT_JOBS_DB_MAX_BYTES", "0"}}).config.jobs_db_max_bytes, 0u);
  EXPECT_EQ(Parse({"--job-max-time-s", "0"}).error,
            "option --job-max-time-s = \"0\": must be a number of seconds in (0, 1000000]");
  EXPECT_EQ(Parse({}, {{"SWEETSPOT_JOB_MAX_TIME_S", "inf"}}).error,
            "environment SWEETSPOT_JOB_MAX_TIME_S = \"inf\": must be a number of seconds in "
            "(0, 1000000]");
  EXPECT_EQ(Parse({"--job-results-memory-bytes", "1000"}).error,
            "option --job-results-memory-bytes = \"1000\": must be an integer in [1024, "
            "1000000000000]");
  EXPECT_EQ(Parse({"--jobs-db-max-bytes", "4096"}).error,
            "option --jobs-db-max-bytes = \"4096\": must be 0 (no limit) or at least 65536");
  ServerConfig config;
  std::string why;
  config.jobs_db_max_bytes = 1000;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "jobs_db_max_bytes = 1000: must be 0 (no limit) or in [65536, 1e15]");
  config = ServerConfig{};
  config.jobs.max_time_s = -1;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "jobs.max_time_s = -1: must be in (0, 1e+06]");
  const std::string usage = Usage("sweetspot-server");
  for (const char* name : {"--job-max-time-s", "SWEETSPOT_JOB_MAX_TIME_S", "(default 600)",
                           "--job-results-memory-bytes", "SWEETSPOT_JOB_RESULTS_MEMORY_BYTES",
                           "--jobs-db-max-bytes", "SWEETSPOT_JOBS_DB_MAX_BYTES"}) {
    EXPECT_NE(usage.find(name), std::string::npos) << name;
  }
}

TEST(JobsConfigTest, AnUnusableJobsDatabaseStopsTheServerWithTheReason) {
  const std::string path = ::testing::TempDir() + "sweetspot-no-such-dir/sub/jobs.db";
  const std::string reason = "jobs database \"" + path +
                             "\": cannot open or create it: unable to open database file (code 14)";
  ServerConfig config;
  config.port = 0;
  config.access_log = false;
  config.jobs_db = path;
  Server server(config);
  std::string error;
  EXPECT_FALSE(server.Bind(&error));
  EXPECT_EQ(error, reason);

  testing::ServerProcess process;  // The executable exits 1 and says why.
  EXPECT_FALSE(process.Start({"--jobs-db", path}));
  // Start() sees the exit; the pipe's last bytes may still be on their way to
  // the log reader: wait for them (bounded; they come within milliseconds).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (process.log().find(reason) == std::string::npos &&
         std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_NE(process.log().find("sweetspot-server: " + reason), std::string::npos) << process.log();
}

}  // namespace
}  // namespace jobs_config_test
}  // namespace sweetspot::server
