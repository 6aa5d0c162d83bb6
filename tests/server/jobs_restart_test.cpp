// Jobs survive the process: the real sweetspot-server with --jobs-db in a
// temporary directory, killed with SIGKILL in the middle of a job or stopped
// with SIGTERM while jobs run, then started again on the same database.
// Also: an HTTP request in flight when SIGTERM arrives is still answered.
#include <gtest/gtest.h>
#include <httplib.h>
#include <stdlib.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>

#include "tests/server/job_client.hpp"
#include "tests/server/server_process.hpp"

namespace sweetspot {
namespace {

namespace fs = std::filesystem;
using testing::jobs::Answer;
using testing::jobs::ClientOf;
using testing::jobs::Clock;
using testing::jobs::Get;
using testing::jobs::Json;
using testing::jobs::kMustHappen;
using testing::jobs::kQuick;
using testing::jobs::kSlowSweep;
using testing::jobs::kSlowSweepRows;
using testing::jobs::Parse;
using testing::jobs::PostJson;
using testing::jobs::SubmitJob;
using testing::jobs::WaitForState;
using testing::jobs::WithoutTimings;

using testing::jobs::TempDir;

std::vector<std::string> ServerArgs(const std::string& db, std::vector<std::string> more = {}) {
  std::vector<std::string> args{"--jobs-db", db, "--no-access-log"};
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

TEST(JobsRestartTest, SigkillMidJobThenRestartResumesItWithTheSameResult) {
  TempDir dir;
  const std::string db = dir.File("jobs.db");
  std::string id;
  std::string created_at;
  {
    testing::ServerProcess first;
    ASSERT_TRUE(first.Start(ServerArgs(db, {"--job-workers", "1"}))) << first.log();
    id = SubmitJob(first, "/v1/explore", kSlowSweep);
    ASSERT_FALSE(id.empty());
    const Json running = WaitForState(first, id, "running");
    created_at = running["created_at"];
    EXPECT_LT(running["progress"].get<double>(), 1.0);
    EXPECT_EQ(first.Stop(SIGKILL), -1);  // Killed: no clean-up of any kind ran.
  }
  testing::ServerProcess second;
  ASSERT_TRUE(second.Start(ServerArgs(db))) << second.log();
  EXPECT_NE(second.log().find("jobs are kept in \"" + db + "\""), std::string::npos)
      << second.log();
  const Answer resumed = Get(second, "/v1/jobs/" + id);
  ASSERT_EQ(resumed.status, 200);
  EXPECT_TRUE(resumed.body["state"] == "queued" || resumed.body["state"] == "running")
      << resumed.body.dump();
  EXPECT_EQ(resumed.body["resumes"], 1);
  EXPECT_EQ(resumed.body["created_at"], created_at);
  // The job's own times, not this process's (they were negative here: before its start).
  EXPECT_EQ(resumed.body["created_s"], 0.0);

  const Json done = WaitForState(second, id, "done");
  EXPECT_EQ(done["status"], 200);
  EXPECT_EQ(done["resumes"], 1);
  // Run again, from the start, by this process: started after the first process was killed,
  // so after the job's submit.
  EXPECT_GT(done["started_s"].get<double>(), 0.0);
  const Answer result = Get(second, "/v1/jobs/" + id + "/result");
  ASSERT_EQ(result.status, 200);
  ASSERT_EQ(result.body["rows"].size(), kSlowSweepRows);
  // The resumed run's rows are those of the same request sent directly.
  const Answer direct = PostJson(second, "/v1/explore", kSlowSweep);
  ASSERT_EQ(direct.status, 200);
  EXPECT_EQ(WithoutTimings(result.body["rows"]), WithoutTimings(direct.body["rows"]));
  EXPECT_EQ(second.Stop(SIGTERM), 0);
}

TEST(JobsRestartTest, SigkillMidJobBeyondMaxResumesMarksItFailedWithTheReason) {
  TempDir dir;
  const std::string db = dir.File("jobs.db");
  std::string id;
  {
    testing::ServerProcess first;
    ASSERT_TRUE(first.Start(ServerArgs(db, {"--job-max-resumes", "0"}))) << first.log();
    id = SubmitJob(first, "/v1/explore", kSlowSweep);
    ASSERT_FALSE(id.empty());
    WaitForState(first, id, "running");
    EXPECT_EQ(first.Stop(SIGKILL), -1);
  }
  testing::ServerProcess second;
  ASSERT_TRUE(second.Start(ServerArgs(db, {"--job-max-resumes", "0"}))) << second.log();
  const std::string reason =
      "interrupted by a server restart: the job was running when the server died, and it had "
      "already been resumed 0 times (limit max_resumes = 0)";
  const Answer status = Get(second, "/v1/jobs/" + id);
  ASSERT_EQ(status.status, 200);
  EXPECT_EQ(status.body["state"], "failed");
  EXPECT_EQ(status.body["error"],
            (Json{{"code", "Interrupted"}, {"message", reason}, {"field", nullptr}}));
  EXPECT_EQ(status.body["status"], 503);
  const Answer result = Get(second, "/v1/jobs/" + id + "/result");
  EXPECT_EQ(result.status, 503);
  EXPECT_EQ(result.body, (Json{{"code", "Interrupted"}, {"message", reason}, {"field", nullptr}}));
  EXPECT_EQ(second.Stop(SIGTERM), 0);
}

TEST(JobsRestartTest, FinishedJobAndItsResultSurviveACleanRestartAndSoDoesADelete) {
  TempDir dir;
  const std::string db = dir.File("jobs.db");
  std::string id;
  Json done_before;
  Answer result_before;
  {
    testing::ServerProcess first;
    ASSERT_TRUE(first.Start(ServerArgs(db))) << first.log();
    id = SubmitJob(first, "/v1/sweet-spot", kQuick);
    ASSERT_FALSE(id.empty());
    done_before = WaitForState(first, id, "done");
    result_before = Get(first, "/v1/jobs/" + id + "/result");
    ASSERT_EQ(result_before.status, 200);
    EXPECT_EQ(first.Stop(SIGTERM), 0);
  }
  {
    testing::ServerProcess second;
    ASSERT_TRUE(second.Start(ServerArgs(db))) << second.log();
    const Answer status = Get(second, "/v1/jobs/" + id);
    ASSERT_EQ(status.status, 200);
    for (const char* key : {"id", "state", "path", "created_at", "status", "error", "progress",
                            "cancel_requested", "resumes"}) {
      EXPECT_EQ(status.body[key], done_before[key]) << key;
    }
    // The stored answer, byte for byte (its timing_s included): not a re-run.
    const Answer result = Get(second, "/v1/jobs/" + id + "/result");
    EXPECT_EQ(result.status, 200);
    EXPECT_EQ(result.body, result_before.body);
    const Answer deleted = Parse(ClientOf(second).Delete(("/v1/jobs/" + id).c_str()));
    EXPECT_EQ(deleted.status, 200);
    EXPECT_EQ(deleted.body["deleted"], true);
    EXPECT_EQ(second.Stop(SIGTERM), 0);
  }
  testing::ServerProcess third;
  ASSERT_TRUE(third.Start(ServerArgs(db))) << third.log();
  EXPECT_EQ(Get(third, "/v1/jobs/" + id).status, 404);
  EXPECT_EQ(third.Stop(SIGTERM), 0);
}

// Job times are absolute (created_at, started_at, finished_at: ISO-8601 UTC) or relative to the
// job (created_s = 0, started_s and finished_s after its submit), never to a process's start:
// a restarted server shows a finished job's times as the first did. Before, *_s counted from
// the process's start, so after a restart they were negative, and started_at/finished_at did
// not exist.
TEST(JobsRestartTest, JobTimesReadTheSameAfterARestart) {
  TempDir dir;
  const std::string db = dir.File("jobs.db");
  std::string id;
  Json before;
  {
    testing::ServerProcess first;
    ASSERT_TRUE(first.Start(ServerArgs(db))) << first.log();
    id = SubmitJob(first, "/v1/sweet-spot", kQuick);
    ASSERT_FALSE(id.empty());
    before = WaitForState(first, id, "done");
    EXPECT_EQ(first.Stop(SIGTERM), 0);
  }
  // The second process starts later than the job ran: a time relative to a process's start
  // would differ (by at least this long).
  std::this_thread::sleep_for(std::chrono::milliseconds(1200));
  testing::ServerProcess second;
  ASSERT_TRUE(second.Start(ServerArgs(db))) << second.log();
  const Answer after = Get(second, "/v1/jobs/" + id);
  ASSERT_EQ(after.status, 200);
  for (const Json* job : {static_cast<const Json*>(&before), &after.body}) {
    EXPECT_EQ((*job)["created_s"], 0.0) << job->dump();
    // ISO-8601 UTC to the millisecond, "2026-11-28T05:17:05.317Z": 24 characters.
    for (const char* key : {"created_at", "started_at", "finished_at"}) {
      ASSERT_TRUE((*job)[key].is_string()) << key << " " << job->dump();
      const std::string text = (*job)[key];
      EXPECT_EQ(text.size(), 24u) << text;
      EXPECT_EQ(text.back(), 'Z') << text;
    }
    EXPECT_GE((*job)["started_s"].get<double>(), 0.0) << job->dump();
    EXPECT_GE((*job)["finished_s"].get<double>(), (*job)["started_s"].get<double>());
    // A quick job waits and runs well under a minute.
    EXPECT_LT((*job)["finished_s"].get<double>(), 60.0) << job->dump();
  }
  for (const char* key : {"created_at", "started_at", "finished_at"}) {
    EXPECT_EQ(after.body[key], before[key]) << key;
  }
  // Stored as seconds since the epoch (a double) and rounded to microseconds on each side:
  // equal within 2 us.
  for (const char* key : {"started_s", "finished_s"}) {
    EXPECT_NEAR(after.body[key].get<double>(), before[key].get<double>(), 2e-6) << key;
  }
  EXPECT_EQ(second.Stop(SIGTERM), 0);
}

TEST(JobsRestartTest, SigtermLetsARunningJobFinishWithinTheGrace) {
  TempDir dir;
  const std::string db = dir.File("jobs.db");
  std::string id;
  {
    testing::ServerProcess first;
    // A grace far longer than the sweep, so it always finishes (the default is 8 s).
    ASSERT_TRUE(first.Start(ServerArgs(db, {"--shutdown-grace-s", "100"}))) << first.log();
    id = SubmitJob(first, "/v1/explore", kSlowSweep);
    ASSERT_FALSE(id.empty());
    WaitForState(first, id, "running");
    EXPECT_EQ(first.Stop(SIGTERM), 0);
    const std::string log = first.log();
    EXPECT_NE(log.find("waiting up to 100 s for 1 running job(s) to finish"), std::string::npos)
        << log;
    EXPECT_EQ(log.find("unfinished job(s) kept"), std::string::npos) << log;  // None left.
  }
  testing::ServerProcess second;
  ASSERT_TRUE(second.Start(ServerArgs(db))) << second.log();
  const Answer status = Get(second, "/v1/jobs/" + id);
  ASSERT_EQ(status.status, 200);
  EXPECT_EQ(status.body["state"], "done");  // At once: it finished before the first exited.
  EXPECT_EQ(status.body["resumes"], 0);
  const Answer result = Get(second, "/v1/jobs/" + id + "/result");
  EXPECT_EQ(result.status, 200);
  EXPECT_EQ(result.body["rows"].size(), kSlowSweepRows);
  EXPECT_EQ(second.Stop(SIGTERM), 0);
}

TEST(JobsRestartTest, SigtermBeyondTheGraceKeepsRunningAndQueuedJobsForTheNextStart) {
  TempDir dir;
  const std::string db = dir.File("jobs.db");
  std::string running, queued;
  {
    testing::ServerProcess first;
    ASSERT_TRUE(first.Start(ServerArgs(db, {"--shutdown-grace-s", "0", "--job-workers", "1"})))
        << first.log();
    running = SubmitJob(first, "/v1/explore", kSlowSweep);
    ASSERT_FALSE(running.empty());
    WaitForState(first, running, "running");
    queued = SubmitJob(first, "/v1/sweet-spot", kQuick);
    ASSERT_FALSE(queued.empty());
    EXPECT_EQ(first.Stop(SIGTERM), 0);
    const std::string log = first.log();
    EXPECT_NE(log.find("2 unfinished job(s) kept in \"" + db + "\" for the next start"),
              std::string::npos)
        << log;
  }
  testing::ServerProcess second;
  ASSERT_TRUE(second.Start(ServerArgs(db))) << second.log();
  for (const std::string& id : {running, queued}) {
    const Json done = WaitForState(second, id, "done");
    EXPECT_EQ(done["resumes"], 0) << id;  // A clean stop is not a crash.
    EXPECT_EQ(Get(second, "/v1/jobs/" + id + "/result").status, 200) << id;
  }
  EXPECT_EQ(Get(second, "/v1/jobs/" + running + "/result").body["rows"].size(), kSlowSweepRows);
  EXPECT_EQ(second.Stop(SIGTERM), 0);
}

// The in-flight gauge of /metrics ("sweetspot_requests_in_flight N"), -1 if absent.
int InFlight(testing::ServerProcess& server) {
  const auto result = ClientOf(server).Get("/metrics");
  if (!result) return -1;
  const std::string name = "\nsweetspot_requests_in_flight ";
  const auto at = result->body.find(name);
  if (at == std::string::npos) return -1;
  return std::atoi(result->body.c_str() + at + name.size());
}

TEST(JobsRestartTest, RequestInFlightWhenSigtermArrivesIsAnswered) {
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start({"--no-access-log"})) << server.log();
  Answer answer;
  std::thread client([&] { answer = PostJson(server, "/v1/explore", kSlowSweep); });
  // The /metrics request counts itself: 2 means the sweep is being computed.
  const auto deadline = Clock::now() + kMustHappen;
  int in_flight = InFlight(server);
  while (in_flight < 2 && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    in_flight = InFlight(server);
  }
  EXPECT_GE(in_flight, 2);
  EXPECT_EQ(server.Stop(SIGTERM), 0);
  client.join();
  EXPECT_EQ(answer.status, 200);
  EXPECT_EQ(answer.body["rows"].size(), kSlowSweepRows);
  EXPECT_NE(server.log().find("received SIGTERM"), std::string::npos) << server.log();
}

}  // namespace
}  // namespace sweetspot
