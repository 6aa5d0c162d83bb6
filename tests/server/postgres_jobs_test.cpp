// Jobs shared by replicas through a real PostgreSQL (Debian's postgresql, a
// throw-away cluster per test: tests/server/postgres_cluster.hpp) and real
// sweetspot-server processes started with --jobs-db postgresql://...:
// every job visible from every replica, the queue shared, a replica killed with
// SIGKILL mid-job and its job finished by another, cancel across replicas, two
// replicas migrating one database at once, the database stopped and restarted
// under load, and results larger than the limit refused whole.
#include <gtest/gtest.h>
#include <httplib.h>
#include <signal.h>

#include <atomic>
#include <chrono>
#include <iostream>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "tests/sanitizers.hpp"
#include "tests/server/attack_client.hpp"
#include "tests/server/job_client.hpp"
#include "tests/server/postgres_cluster.hpp"
#include "tests/server/server_process.hpp"

namespace sweetspot {
namespace {

using testing::PostgresCluster;
using testing::ServerProcess;
using testing::jobs::Answer;
using testing::jobs::ClientOf;
using testing::jobs::Clock;
using testing::jobs::Delete;
using testing::jobs::Get;
using testing::jobs::Json;
using testing::jobs::kLongSweep;
using testing::jobs::kLongSweepRows;
using testing::jobs::kMustHappen;
using testing::jobs::kQuick;
using testing::jobs::kSlowSweep;
using testing::jobs::kSlowSweepRows;
using testing::jobs::PostJson;
using testing::jobs::SubmitJob;
using testing::jobs::WaitForState;
using testing::jobs::WithoutTimings;

// The issue's "within a second" as asserted. Under AddressSanitizer or
// ThreadSanitizer the instrumented server runs the sweep (and everything else)
// about 10 times slower, so the bound there is 5 times the issue's.
#if SWEETSPOT_UNDER_ASAN || SWEETSPOT_UNDER_TSAN
constexpr double kSlowdown = 5.0;
#else
constexpr double kSlowdown = 1.0;
#endif

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

class PostgresJobsTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(cluster_.Start()) << cluster_.why(); }

  // Starts a replica on database `db` with `more` flags (one job worker each,
  // unless `more` says otherwise).
  std::unique_ptr<ServerProcess> Replica(std::vector<std::string> more = {},
                                         const std::string& db = "postgres") {
    auto server = std::make_unique<ServerProcess>();
    std::vector<std::string> args{"--jobs-db", cluster_.Uri(db), "--no-access-log"};
    args.insert(args.end(), more.begin(), more.end());
    EXPECT_TRUE(server->Start(args)) << server->log();
    return server;
  }

  PostgresCluster cluster_;
};

TEST_F(PostgresJobsTest, EveryJobIsVisibleFromEveryReplicaAndTheQueueIsShared) {
  std::vector<std::unique_ptr<ServerProcess>> replicas;
  for (int i = 0; i < 3; ++i) replicas.push_back(Replica({"--job-workers", "1"}));
  EXPECT_NE(replicas[0]->log().find("are kept in PostgreSQL"), std::string::npos)
      << replicas[0]->log();

  // The issue's round robin: a job posted to one replica, then read six times
  // through the replicas in turn; every read is 200 (it was 404 200 404 ...).
  const std::string quick = SubmitJob(*replicas[0], "/v1/bat/properties", kQuick);
  WaitForState(*replicas[1], quick, "done");
  for (int i = 0; i < 6; ++i) {
    const Answer answer = Get(*replicas[i % 3], "/v1/jobs/" + quick);
    EXPECT_EQ(answer.status, 200) << "read " << i << ": " << answer.body.dump();
  }
  // The job's times are its own, the same through every replica (issue 35: they counted from
  // each replica's start, so they differed from replica to replica and went negative on one
  // started after the job): absolute (*_at) or after its submit (*_s).
  const Answer first_view = Get(*replicas[0], "/v1/jobs/" + quick);
  for (auto& replica : replicas) {
    const Answer view = Get(*replica, "/v1/jobs/" + quick);
    ASSERT_EQ(view.status, 200);
    EXPECT_EQ(view.body["created_s"], 0.0) << view.body.dump();
    EXPECT_GE(view.body["started_s"].get<double>(), 0.0) << view.body.dump();
    for (const char* key : {"created_at", "started_at", "finished_at", "started_s", "finished_s"}) {
      EXPECT_EQ(view.body[key], first_view.body[key]) << key;
    }
  }
  const Answer direct = PostJson(*replicas[0], "/v1/bat/properties", kQuick);
  for (auto& replica : replicas) {
    const Answer result = Get(*replica, "/v1/jobs/" + quick + "/result");
    ASSERT_EQ(result.status, 200);
    EXPECT_EQ(WithoutTimings(result.body), WithoutTimings(direct.body));
  }

  // Three slow jobs posted to one replica run at once on the three replicas
  // (one worker each): the queue is shared.
  std::vector<std::string> slow;
  for (int i = 0; i < 3; ++i) slow.push_back(SubmitJob(*replicas[0], "/v1/explore", kLongSweep));
  int most_running = 0;
  const auto deadline = Clock::now() + kMustHappen;
  while (most_running < 3 && Clock::now() < deadline) {
    int running = 0;
    for (const std::string& id : slow) {
      running += Get(*replicas[2], "/v1/jobs/" + id).body["state"] == "running" ? 1 : 0;
    }
    most_running = std::max(most_running, running);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(most_running, 3) << "the replicas did not share the queue";

  // The list is the same from every replica: the four jobs, newest first.
  for (auto& replica : replicas) {
    const Answer list = Get(*replica, "/v1/jobs");
    ASSERT_EQ(list.status, 200);
    ASSERT_EQ(list.body["jobs"].size(), 4u) << list.body.dump();
    EXPECT_EQ(list.body["jobs"][0]["id"], slow[2]);
    EXPECT_EQ(list.body["jobs"][3]["id"], quick);
  }
  for (const std::string& id : slow) {
    WaitForState(*replicas[1], id, "done");
    EXPECT_EQ(Get(*replicas[0], "/v1/jobs/" + id + "/result").body["rows"].size(), kLongSweepRows);
  }
}

TEST_F(PostgresJobsTest, JobOfAReplicaKilledWithSigkillIsFinishedByAnother) {
  // Only the first replica runs at first, so the job is surely its.
  auto first = Replica({"--job-lease-s", "1"});
  const std::string id = SubmitJob(*first, "/v1/explore", kSlowSweep);
  WaitForState(*first, id, "running");
  auto second = Replica({"--job-lease-s", "1"});
  EXPECT_EQ(first->Stop(SIGKILL), -1);  // Killed: no clean exit.
  const auto killed = Clock::now();

  const Json done = WaitForState(*second, id, "done");
  // The lease (1 s) expires, then the second replica's next poll (0.2 s) takes
  // it and runs it from the start: never before the lease ran out.
  EXPECT_GE(SecondsSince(killed), 0.5);
  EXPECT_EQ(done["resumes"], 1) << done.dump();
  const Answer result = Get(*second, "/v1/jobs/" + id + "/result");
  ASSERT_EQ(result.status, 200);
  ASSERT_EQ(result.body["rows"].size(), kSlowSweepRows);
  const Answer direct = PostJson(*second, "/v1/explore", kSlowSweep);
  EXPECT_EQ(WithoutTimings(result.body["rows"]), WithoutTimings(direct.body["rows"]));
}

// Ids of a GET /v1/jobs page, in order.
std::vector<std::string> IdsOf(const Answer& page) {
  std::vector<std::string> ids;
  for (const Json& job : page.body["jobs"]) ids.push_back(job["id"]);
  return ids;
}

// GET /v1/jobs from the database: newest first, a state filter and pages, the same order from
// another replica; a failed job's error is the error object its endpoint answered; a row an
// older server wrote (error a bare message) reads back wrapped.
TEST_F(PostgresJobsTest, TheListIsNewestFirstFilteredAndPagedAndErrorsAreObjects) {
  auto replica = Replica({"--job-workers", "1"});
  const std::string slow = SubmitJob(*replica, "/v1/explore", kLongSweep);
  WaitForState(*replica, slow, "running");
  const std::string q1 = SubmitJob(*replica, "/v1/bat/properties", kQuick);
  const std::string q2 = SubmitJob(*replica, "/v1/bat/properties", kQuick);
  // One worker: the quick jobs wait behind the sweep (~2.5 s in Release).
  const Answer running = Get(*replica, "/v1/jobs?state=running");
  ASSERT_EQ(running.status, 200) << running.body.dump();
  EXPECT_EQ(IdsOf(running), (std::vector<std::string>{slow}));
  EXPECT_EQ(running.body["total"], 1);
  EXPECT_EQ(IdsOf(Get(*replica, "/v1/jobs?state=queued")), (std::vector<std::string>{q2, q1}));
  const Answer first = Get(*replica, "/v1/jobs?limit=2");
  EXPECT_EQ(IdsOf(first), (std::vector<std::string>{q2, q1}));
  EXPECT_EQ(first.body["total"], 3);
  EXPECT_EQ(first.body["next_offset"], 2);
  const Answer second = Get(*replica, "/v1/jobs?limit=2&offset=2");
  EXPECT_EQ(IdsOf(second), (std::vector<std::string>{slow}));
  EXPECT_TRUE(second.body["next_offset"].is_null());
  EXPECT_EQ(second.body["jobs"][0]["path"], "/v1/explore");
  EXPECT_EQ(Delete(*replica, "/v1/jobs/" + slow).status, 202);
  WaitForState(*replica, slow, "cancelled");
  WaitForState(*replica, q2, "done");

  // Refused by core while it runs (no bat of the family meets the targets): a failed job.
  const std::string failed = SubmitJob(
      *replica, "/v1/bat/fit",
      R"({"bat": {"preset": "paper-wood"},
          "targets": {"mass_kg": 0.885, "balance_point_m": 0.564}})");
  const Json status = WaitForState(*replica, failed, "failed");
  EXPECT_EQ(status["status"], 422);
  EXPECT_EQ(status["error"]["code"], "Infeasible") << status.dump();
  EXPECT_EQ(status["error"]["field"], "targets") << status.dump();
  EXPECT_EQ(status["error"].size(), 3u) << status.dump();  // no "closest": that is the result's
  const Answer result = Get(*replica, "/v1/jobs/" + failed + "/result");
  EXPECT_EQ(result.status, 422);
  EXPECT_EQ(status["error"]["message"], result.body["message"]);
  EXPECT_EQ(IdsOf(Get(*replica, "/v1/jobs?state=failed")), (std::vector<std::string>{failed}));
  EXPECT_EQ(IdsOf(Get(*replica, "/v1/jobs?state=cancelled")), (std::vector<std::string>{slow}));

  ASSERT_EQ(cluster_.Psql("UPDATE sweetspot_jobs SET error = 'an older server''s message' "
                          "WHERE id = '" + failed + "'"),
            "");
  EXPECT_EQ(Get(*replica, "/v1/jobs/" + failed).body["error"],
            (Json{{"code", "Infeasible"},
                  {"message", "an older server's message"},
                  {"field", nullptr}}));

  auto other = Replica();
  EXPECT_EQ(IdsOf(Get(*other, "/v1/jobs")), (std::vector<std::string>{failed, q2, q1, slow}));
  const Answer bad = Get(*other, "/v1/jobs?state=sleeping");
  EXPECT_EQ(bad.status, 400);
  EXPECT_EQ(bad.body["field"], "state");
}

// A cancelled optimisation keeps its best design so far in the database: the job is
// cancelled with status 200, and its result is the design with termination no_convergence,
// read through another replica.
TEST_F(PostgresJobsTest, ACancelledOptimisationKeepsItsBestDesignSoFar) {
  auto replica = Replica();
  // 64 COBYLA starts of min_sting: ~0.2 s each in Release, ~13 s in all; cancelled after one.
  const std::string id = SubmitJob(*replica, "/v1/optimize", R"({
    "bat": {"three_segment": {"length_m": 0.8636, "handle_radius_m": 0.0125,
            "barrel_radius_m": 0.033, "taper_start_m": 0.30, "taper_end_m": 0.55},
            "material": "ash"},
    "variables": [{"path": "three_segment.taper_start_m", "min": 0.1, "max": 0.5},
                  {"path": "three_segment.barrel_radius_m", "min": 0.028, "max": 0.0331}],
    "constraints": {"mass_kg": 0.88, "balance_point_m": {"min": 0.56, "max": 0.60}},
    "objective": "min_sting", "cor": 0.5,
    "options": {"max_time_s": 60, "starts": 64, "seed": 1}})");
  const auto deadline = Clock::now() + kMustHappen;
  Json status = Get(*replica, "/v1/jobs/" + id).body;
  while (!(status["progress"].get<double>() > 0.0) && Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    status = Get(*replica, "/v1/jobs/" + id).body;
  }
  ASSERT_EQ(status["state"], "running") << status.dump();
  EXPECT_EQ(Delete(*replica, "/v1/jobs/" + id).status, 202);
  const Json cancelled = WaitForState(*replica, id, "cancelled");
  EXPECT_EQ(cancelled["status"], 200);
  EXPECT_TRUE(cancelled["error"].is_null());

  auto other = Replica();
  const Answer result = Get(*other, "/v1/jobs/" + id + "/result");
  ASSERT_EQ(result.status, 200) << result.body.dump();
  EXPECT_EQ(result.body["summary"]["termination"], "no_convergence");
  const std::string message = result.body["summary"]["message"];
  EXPECT_EQ(message.rfind("cancelled", 0), 0u) << message;
  const int ran = result.body["summary"]["spread"]["starts"];
  EXPECT_GE(ran, 1);
  EXPECT_LT(ran, 64);
  // The kept design meets the mass equality: the chosen start is a feasible one, within
  // kFeasibleRelative = 1e-6 of the constraint's scale (0.88 kg), 8.8e-7 kg < 1e-6 kg.
  EXPECT_NEAR(result.body["properties"]["mass_kg"].get<double>(), 0.88, 1e-6);
  EXPECT_EQ(IdsOf(Get(*other, "/v1/jobs?state=cancelled")), (std::vector<std::string>{id}));
}

TEST_F(PostgresJobsTest, AJobWhoseReplicasKeepDyingFailsWithTheReasonAfterMaxResumes) {
  auto first = Replica({"--job-lease-s", "1", "--job-max-resumes", "0"});
  const std::string id = SubmitJob(*first, "/v1/explore", kSlowSweep);
  WaitForState(*first, id, "running");
  auto second = Replica({"--job-lease-s", "1", "--job-max-resumes", "0"});
  first->Stop(SIGKILL);
  const Json failed = WaitForState(*second, id, "failed");
  EXPECT_EQ(failed["status"], 503);
  EXPECT_EQ(failed["error"]["code"], "Interrupted") << failed.dump();
  EXPECT_TRUE(failed["error"]["field"].is_null()) << failed.dump();
  EXPECT_NE(failed["error"]["message"].get<std::string>().find("limit max_resumes = 0"),
            std::string::npos)
      << failed.dump();
  const Answer result = Get(*second, "/v1/jobs/" + id + "/result");
  EXPECT_EQ(result.status, 503);
  EXPECT_EQ(result.body["code"], "Interrupted");
}

TEST_F(PostgresJobsTest, CancelThroughOneReplicaStopsTheJobOnAnotherWithinASecond) {
  auto runner = Replica();
  const std::string id = SubmitJob(*runner, "/v1/explore", kLongSweep);
  WaitForState(*runner, id, "running");
  auto other = Replica();

  // Progress reported by the runner is visible from the other replica.
  double progress = 0.0;
  const auto deadline = Clock::now() + kMustHappen;
  while (progress <= 0.0 && Clock::now() < deadline) {
    const Answer status = Get(*other, "/v1/jobs/" + id);
    ASSERT_EQ(status.body["state"], "running") << status.body.dump();
    progress = status.body["progress"].get<double>();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_GT(progress, 0.0);
  EXPECT_LT(progress, 1.0);

  const auto asked = Clock::now();
  const Answer cancel = Delete(*other, "/v1/jobs/" + id);
  ASSERT_EQ(cancel.status, 202) << cancel.body.dump();
  EXPECT_EQ(cancel.body["cancel_requested"], true);
  Json state = Get(*other, "/v1/jobs/" + id).body;
  while (state["state"] == "running" && SecondsSince(asked) < 30) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    state = Get(*other, "/v1/jobs/" + id).body;
  }
  const double took_s = SecondsSince(asked);
  EXPECT_EQ(state["state"], "cancelled") << state.dump();
  // The issue's second: the runner's replica gets the cancel notice at once
  // (or sees the flag at its next lease renewal, every 0.5 s) and the sweep
  // stops between two designs (~2 ms).
  EXPECT_LE(took_s, 1.0 * kSlowdown) << "cancel took " << took_s << " s";
  std::cout << "[ measured ] cancel through the other replica took " << took_s << " s\n";
  EXPECT_EQ(Get(*runner, "/v1/jobs/" + id + "/result").body["code"], "Cancelled");
  // The runner's replica is free again: a new job runs there and finishes.
  const std::string next = SubmitJob(*runner, "/v1/bat/properties", kQuick);
  WaitForState(*runner, next, "done");
}

TEST_F(PostgresJobsTest, ReplicasStartingAtOnceMigrateTheDatabaseOnce) {
  ASSERT_EQ(cluster_.Psql("CREATE DATABASE fresh"), "");
  constexpr int kReplicas = 4;
  std::vector<std::unique_ptr<ServerProcess>> replicas(kReplicas);
  std::vector<std::thread> starters;
  for (int i = 0; i < kReplicas; ++i) {
    starters.emplace_back([&, i] { replicas[i] = Replica({}, "fresh"); });
  }
  for (std::thread& starter : starters) starter.join();
  // Each migration (1: the jobs, 2: result pieces) applied by exactly one replica.
  int applied_1 = 0;
  int applied_2 = 0;
  for (auto& replica : replicas) {
    ASSERT_GT(replica->port(), 0) << replica->log();
    applied_1 += replica->log().find("applied schema migration 1") != std::string::npos ? 1 : 0;
    applied_2 += replica->log().find("applied schema migration 2") != std::string::npos ? 1 : 0;
  }
  EXPECT_EQ(applied_1, 1);
  EXPECT_EQ(applied_2, 1);
  EXPECT_EQ(
      cluster_.Psql("SELECT count(*), max(version) FROM sweetspot_schema_migrations", "fresh"),
      "2|2");
  // And every replica works on it.
  const std::string id = SubmitJob(*replicas[3], "/v1/bat/properties", kQuick);
  WaitForState(*replicas[0], id, "done");
}

TEST_F(PostgresJobsTest, ANewerSchemaIsRefusedWithTheReason) {
  auto first = Replica();
  first->Stop();
  ASSERT_EQ(cluster_.Psql("INSERT INTO sweetspot_schema_migrations (version, applied_by) "
                          "VALUES (99, 'the future')"),
            "");
  ServerProcess refused;
  EXPECT_FALSE(refused.Start({"--jobs-db", cluster_.Uri()}));
  EXPECT_NE(refused.log().find("its schema is at version 99, newer than this server's 2"),
            std::string::npos)
      << refused.log();
}

TEST_F(PostgresJobsTest, DatabaseStoppedAndRestartedUnderLoadLosesNothing) {
  // Leases of 60 s outlast the outage even under sanitizers (about 15 s there):
  // a job whose lease ran out would be run again by the other replica.
  auto a = Replica({"--job-workers", "2", "--job-lease-s", "60"});
  auto b = Replica({"--job-workers", "2", "--job-lease-s", "60"});
  // A job that runs while the database goes away: it finishes, and its result
  // is committed once the database is back.
  const std::string long_id = SubmitJob(*a, "/v1/explore", kLongSweep);
  WaitForState(*a, long_id, "running");  // On either replica: the queue is shared.

  // Load: two clients submitting quick jobs and reading them back through both
  // replicas, for the whole test.
  std::atomic<bool> stop{false};
  std::mutex mutex;
  std::set<std::string> accepted;  // 202s: each must end done.
  std::atomic<int> unavailable{0};
  std::atomic<int> other_failures{0};
  std::atomic<int> retry_after{0};
  std::vector<std::thread> clients;
  for (int c = 0; c < 2; ++c) {
    clients.emplace_back([&, c] {
      ServerProcess& submit_to = c == 0 ? *a : *b;
      while (!stop) {
        httplib::Client client("127.0.0.1", submit_to.port());
        client.set_read_timeout(std::chrono::seconds(30));
        const auto posted = client.Post(
            "/v1/jobs", std::string(R"({"path": "/v1/bat/properties", "body": )") + kQuick + "}",
            "application/json");
        if (!posted) {
          ++other_failures;
        } else if (posted->status == 202) {
          std::lock_guard lock(mutex);
          accepted.insert(Json::parse(posted->body)["id"].get<std::string>());
        } else if (posted->status == 503 &&
                   Json::parse(posted->body, nullptr, false).value("code", "") == "Unavailable") {
          ++unavailable;
          if (posted->get_header_value("Retry-After") == "1") ++retry_after;
        } else {
          ++other_failures;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    });
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  cluster_.Stop();
  // While it is away: the servers answer (503 for jobs, 200 for the rest).
  const auto outage = Clock::now();
  Answer status;
  do {
    status = Get(*b, "/v1/jobs/" + long_id);
  } while (status.status != 503 && SecondsSince(outage) < 10);
  EXPECT_EQ(status.status, 503) << status.body.dump();
  EXPECT_EQ(status.body["code"], "Unavailable");
  EXPECT_EQ(Get(*a, "/health").status, 200);
  EXPECT_EQ(PostJson(*b, "/v1/bat/properties", kQuick).status, 200);
  // The database stays away until the running job has finished (on whichever
  // replica claimed it).
  const std::string kept = "job " + long_id + " finished while the database was away";
  auto logs = [&] { return a->log() + b->log(); };
  while (logs().find(kept) == std::string::npos && SecondsSince(outage) < 120) {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_NE(logs().find(kept), std::string::npos) << logs();
  const double outage_s = SecondsSince(outage);
  ASSERT_TRUE(cluster_.Resume()) << cluster_.why();
  // Back: requests succeed again by themselves (no restart of the replicas).
  const auto back = Clock::now();
  while (Get(*b, "/v1/jobs/" + long_id).status != 200 && SecondsSince(back) < 30) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  stop = true;
  for (std::thread& client : clients) client.join();

  EXPECT_GT(unavailable.load(), 0);
  EXPECT_EQ(retry_after.load(), unavailable.load());
  EXPECT_EQ(other_failures.load(), 0);
  EXPECT_GT(accepted.size(), 10u);
  for (const std::string& id : accepted) {
    const Json done = WaitForState(*a, id, "done");
    EXPECT_EQ(done["resumes"], 0) << done.dump();
  }
  const Json long_done = WaitForState(*b, long_id, "done");
  EXPECT_EQ(long_done["resumes"], 0) << "the running job was run again: " << long_done.dump();
  EXPECT_EQ(Get(*b, "/v1/jobs/" + long_id + "/result").body["rows"].size(), kLongSweepRows);
  EXPECT_NE(a->log().find("reachable again"), std::string::npos) << a->log();
  EXPECT_NE(logs().find("job " + long_id + " committed"), std::string::npos) << logs();
  std::cout << "[ measured ] database away " << outage_s << " s; " << accepted.size()
            << " jobs accepted (all done), " << unavailable.load()
            << " submits answered 503 Unavailable with Retry-After: 1\n";
}

TEST_F(PostgresJobsTest, AResultOverTheLimitFailsTheJobWholeNeverTruncated) {
  auto replica = Replica({"--job-max-result-bytes", "4096"});
  // An explore whose estimated result is over 4 KiB is refused at submit (no job); a scene
  // is not estimated: a 200-point curve (about 14 KB) fails its job when it is stored. The
  // properties' answer is under the limit.
  const auto refused = PostJson(*replica, "/v1/jobs",
                                Json{{"path", "/v1/explore"}, {"body", Json::parse(kSlowSweep)}}
                                    .dump());
  EXPECT_EQ(refused.status, 413);
  const std::string big =
      SubmitJob(*replica, "/v1/sweet-spot",
                R"({"bat": {"preset": "paper-wood"}, "outputs": ["exit_speed_curve"],
                    "options": {"curve_samples": 200}})");
  const Json failed = WaitForState(*replica, big, "failed");
  EXPECT_EQ(failed["status"], 413);
  EXPECT_EQ(failed["error"]["code"], "TooBig");
  const std::string error = failed["error"]["message"];
  EXPECT_NE(error.find("more than the jobs database keeps (max_result_bytes = 4096)"),
            std::string::npos)
      << error;
  const Answer result = Get(*replica, "/v1/jobs/" + big + "/result");
  EXPECT_EQ(result.status, 413);
  EXPECT_EQ(result.body["code"], "TooBig");

  const std::string small = SubmitJob(*replica, "/v1/bat/properties", kQuick);
  WaitForState(*replica, small, "done");
  EXPECT_EQ(WithoutTimings(Get(*replica, "/v1/jobs/" + small + "/result").body),
            WithoutTimings(PostJson(*replica, "/v1/bat/properties", kQuick).body));
}

// --job-max-time-s with PostgreSQL: the replica running the job checks the limit at each lease
// renewal (every 0.5 s here at most), sets the job's cancel flag and commits it failed (408
// Timeout) naming the limit; no replica runs it again.
TEST_F(PostgresJobsTest, AJobRunningPastTheTimeLimitIsStoppedAndFailed) {
  auto replica = Replica({"--job-max-time-s", "0.5"});
  // 10,000 flexible impacts (~40 s of work, far past the limit); an explore this long would
  // be refused at submit by its estimate, a scene is not estimated.
  const std::string id = SubmitJob(*replica, "/v1/sweet-spot", testing::kLongFlexibleCurve);
  const Json failed = WaitForState(*replica, id, "failed");
  EXPECT_EQ(failed["status"], 408);
  EXPECT_EQ(failed["error"]["code"], "Timeout");
  EXPECT_NE(
      failed["error"]["message"].get<std::string>().find("ran longer than max_time_s = 0.5 s"),
      std::string::npos)
      << failed.dump();
  EXPECT_EQ(failed["resumes"], 0);
  // At the limit plus at most one renewal period (0.5 s) and the curve point in flight; 2 s
  // more absorbs a loaded 2-core machine and still fails a job left to run its ~40 s.
  const double ran_s = failed["finished_s"].get<double>() - failed["started_s"].get<double>();
  std::cout << "[ measured ] a job over max_time_s = 0.5 s ran " << ran_s << " s\n";
  EXPECT_GE(ran_s, 0.5);
  EXPECT_LT(ran_s, 0.5 + 0.5 + 2.0) << failed.dump();
  const Answer result = Get(*replica, "/v1/jobs/" + id + "/result");
  EXPECT_EQ(result.status, 408);
  EXPECT_EQ(result.body["code"], "Timeout");
}

}  // namespace
}  // namespace sweetspot
