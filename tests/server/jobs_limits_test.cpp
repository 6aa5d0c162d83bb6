// The job services under attack, bounded (the real sweetspot-server, jobs in SQLite in a
// temporary folder): big results do not pile up in the server's memory and one over
// --job-max-result-bytes fails its job; a jobs database that cannot write (--jobs-db-max-bytes,
// SQLite's own "database or disk is full") never shows a job done without its stored result and
// refuses submits with 503 + Retry-After; a job running past --job-max-time-s is stopped.
#include <gtest/gtest.h>
#include <httplib.h>
#include <stdlib.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "tests/sanitizers.hpp"
#include "tests/server/attack_client.hpp"
#include "tests/server/job_client.hpp"
#include "tests/server/server_process.hpp"

namespace sweetspot {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace jobs_limits_test {
namespace {

namespace fs = std::filesystem;
using testing::jobs::Answer;
using testing::jobs::ClientOf;
using testing::jobs::Clock;
using testing::jobs::Get;
using testing::jobs::Json;
using testing::jobs::kMustHappen;
using testing::jobs::kQuick;
using testing::jobs::PostJson;
using testing::jobs::SubmitJob;

using testing::jobs::TempDir;

// A cheap CSV sweep over `count` values of the COR (the rigid model: microseconds a design);
// its result is about 250 bytes a row with the bat's properties.
std::string CsvSweep(int count) {
  Json body = Json::parse(R"({"bat": {"preset": "paper-wood"},
      "outputs": ["max_exit_speed", "properties"], "format": "csv"})");
  body["parameters"] = {{{"path", "cor"}, {"min", 0.4}, {"max", 0.6}, {"count", count}}};
  return body.dump();
}

// Polls the job until it is done, failed or cancelled (at most kMustHappen); its JSON.
Json WaitFinished(testing::ServerProcess& server, const std::string& id) {
  const auto deadline = Clock::now() + kMustHappen;
  Answer answer = Get(server, "/v1/jobs/" + id);
  while (answer.status == 200 && Clock::now() < deadline &&
         (answer.body["state"] == "queued" || answer.body["state"] == "running")) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    answer = Get(server, "/v1/jobs/" + id);
  }
  EXPECT_EQ(answer.status, 200) << answer.body.dump();
  return answer.body;
}

// The server process's resident memory (VmRSS of /proc/<pid>/status), bytes; 0 if unread.
std::size_t ResidentBytes(pid_t pid) {
  std::ifstream status("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stoull(line.substr(6)) * 1024;  // In kB.
  }
  return 0;
}

std::vector<std::string> Args(const std::string& db, std::vector<std::string> more = {}) {
  std::vector<std::string> args{"--jobs-db", db, "--no-access-log"};
  args.insert(args.end(), more.begin(), more.end());
  return args;
}

// --- Item 3: bounded job memory -------------------------------------------------------------

// Before: every result stayed in the JobManager's memory (a 118 MB CSV per 266-byte submit;
// 10 of them added 1.15 GB). Now results over 64 KiB live in the SQLite database only and are
// read back on GET, byte for byte.
TEST(JobsLimitsTest, BigResultsStayInTheDatabaseNotInMemory) {
  TempDir dir("sweetspot-limits");
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start(Args(dir.File("jobs.db"), {"--job-workers", "1"}))) << server.log();
  constexpr int kRows = 40000;
  const std::string sweep = CsvSweep(kRows);
  // One job first: thread pools, allocator arenas and SQLite's page cache reach their
  // working size, so the baseline already holds one job's transient peak.
  const std::string first = SubmitJob(server, "/v1/explore", sweep);
  ASSERT_EQ(WaitFinished(server, first)["state"], "done");
  const auto first_result = ClientOf(server).Get(("/v1/jobs/" + first + "/result").c_str());
  ASSERT_TRUE(first_result);
  ASSERT_EQ(first_result->status, 200);
  const std::size_t result_bytes = first_result->body.size();
  ASSERT_GT(result_bytes, 8u << 20) << "the sweep should give a result of several MB";
  const std::size_t before = ResidentBytes(server.pid());
  ASSERT_GT(before, 0u);

  constexpr int kJobs = 8;
  std::vector<std::string> ids;
  for (int i = 0; i < kJobs; ++i) {
    ids.push_back(SubmitJob(server, "/v1/explore", sweep));
    ASSERT_EQ(WaitFinished(server, ids.back())["state"], "done");
  }
  const std::size_t after = ResidentBytes(server.pid());
  const std::size_t kept = kJobs * result_bytes;
  // Kept in memory, the results add kept bytes (8 x 10.1 MB; measured +69 MB for 7 jobs with
  // the server of 8127675). In the database they add only what is still mapped of the last
  // job's buffers and SQLite's page cache (2 MB): +0.5 to +2.0 MB measured, and once +19 MB
  // (one 16 MB string's capacity) sampled right after a job. Half of kept separates the two
  // with a margin both ways.
#if SWEETSPOT_UNDER_ASAN
  // Under AddressSanitizer freed memory sits in its quarantine (256 MiB by default), so the
  // resident size says nothing about what the server keeps; the Release pass checks it.
  (void)kept;
#else
  EXPECT_LT(after, before + kept / 2) << "VmRSS " << before << " -> " << after << " bytes; "
                                      << kJobs << " results of " << result_bytes << " bytes";
#endif
  std::printf("VmRSS %zu -> %zu bytes (+%.1f MB) after %d jobs of %zu-byte results\n", before,
              after, (static_cast<double>(after) - static_cast<double>(before)) / 1e6, kJobs,
              result_bytes);
  // Read back from the database, the same bytes as the first (the sweep is deterministic).
  const auto last = ClientOf(server).Get(("/v1/jobs/" + ids.back() + "/result").c_str());
  ASSERT_TRUE(last);
  EXPECT_EQ(last->status, 200);
  EXPECT_EQ(last->get_header_value("Content-Type").rfind("text/csv", 0), 0u);
  EXPECT_EQ(last->body, first_result->body);
}

// A stored result is sent as its client reads it, a piece at a time from the database: six
// clients that do not read a 10.1 MB result hold neither the server's memory nor their
// address's budget of unsent bytes (--max-unsent-bytes-per-client, 1 MiB here, would cut a
// result held whole), and each gets the whole result once it reads. Before: each GET read the
// result whole into memory and parked what the socket did not take.
TEST(JobsLimitsTest, StoredResultsAreSentAsTheClientReads) {
  TempDir dir("sweetspot-limits");
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start(Args(dir.File("jobs.db"), {"--max-unsent-bytes-per-client", "1048576"})))
      << server.log();
  const std::string id = SubmitJob(server, "/v1/explore", CsvSweep(40000));  // 10.1 MB
  ASSERT_EQ(WaitFinished(server, id)["state"], "done");
  const std::string get = "GET /v1/jobs/" + id + "/result HTTP/1.1\r\nHost: x\r\n\r\n";
  // Warm-up: one whole read (allocator arenas, SQLite's page cache).
  const std::string whole = testing::BodyOf(testing::Exchange(
      server.port(), "GET /v1/jobs/" + id + "/result HTTP/1.1\r\nConnection: close\r\n\r\n",
      30.0));
  const std::size_t before = ResidentBytes(server.pid());
  std::vector<int> readers;
  for (int i = 0; i < 6; ++i) {
    const int fd = testing::ConnectFrom(server.port(), "127.0.0.3", 4096);
    ASSERT_GE(fd, 0);
    ASSERT_TRUE(testing::SendAll(fd, get));
    readers.push_back(fd);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  const std::size_t parked = ResidentBytes(server.pid());
  std::cout << "[ measured ] six unread 10.1 MB results: VmRSS " << before << " -> " << parked
            << " bytes\n";
  // Every reader at once: one waiting for its turn would meet the server's write timeout
  // (10 s without taking a byte), as it should.
  std::vector<std::string> bodies(readers.size());
  std::vector<std::thread> reading;
  for (std::size_t i = 0; i < readers.size(); ++i) {
    reading.emplace_back([&, i] {
      const testing::ReadResult r = testing::ReadFor(readers[i], 60.0, [&](const std::string& b) {
        const std::size_t head = b.find("\r\n\r\n");
        return head != std::string::npos && b.size() >= head + 4 + whole.size();
      });
      close(readers[i]);
      bodies[i] = testing::BodyOf(r.bytes);
    });
  }
  for (auto& t : reading) t.join();
  for (const std::string& body : bodies) EXPECT_TRUE(body == whole) << body.size() << " bytes";
  ASSERT_GT(whole.size(), 10000000u);
  const auto metrics = ClientOf(server).Get("/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_NE(metrics->body.find(R"(sweetspot_connections_closed_total{reason="unsent_over_limit"} 0)"),
            std::string::npos);
#if !SWEETSPOT_UNDER_ASAN
  // Held whole, six parked results are about 6 x 10 MB; a piece at a time they are 6 x 64 KiB.
  // 20 MB separates the two with room for allocator slack.
  EXPECT_LT(parked, before + 20000000) << "VmRSS " << before << " -> " << parked;
#else
  (void)before;
  (void)parked;
#endif
}

// A result over --job-max-result-bytes fails its job with the size and the limit named,
// whatever the store (here SQLite; before, only PostgreSQL had the limit). A streamed sweep
// (CSV) is stopped as soon as its rows pass the limit, not after it built them all.
TEST(JobsLimitsTest, AResultOverTheLimitFailsTheJobNamingIt) {
  TempDir dir("sweetspot-limits");
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start(Args(dir.File("jobs.db"), {"--job-max-result-bytes", "1048576"})))
      << server.log();
  // An explore whose estimated result is over the limit is refused at submit: no job.
  const auto refused = ClientOf(server).Post(
      "/v1/jobs", Json{{"path", "/v1/explore"}, {"body", Json::parse(CsvSweep(40000))}}.dump(),
      "application/json");  // 10.1 MB
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 413);
  EXPECT_NE(refused->body.find("over the limit job_max_result_bytes = 1048576"),
            std::string::npos)
      << refused->body;
  // A result no estimate foresees (a compare of 9 bats x 10,000 curve points: 7.2 MB of
  // JSON) fails its job when it is stored.
  Json compare = Json::parse(R"({"baseline": {"preset": "paper-wood"}, "variants": [],
      "outputs": ["exit_speed_curve"], "options": {"curve_samples": 10000}})");
  for (int i = 0; i < 8; ++i) {
    compare["variants"].push_back(
        {{"name", "v" + std::to_string(i)}, {"bat", {{"preset", "paper-wood"}}}});
  }
  const std::string id = SubmitJob(server, "/v1/compare", compare.dump());
  const Json job = WaitFinished(server, id);
  EXPECT_EQ(job["state"], "failed") << job.dump();
  EXPECT_EQ(job["status"], 413);
  EXPECT_EQ(job["error"]["code"], "TooBig");
  const std::string message = job["error"]["message"].get<std::string>();
  EXPECT_EQ(message.rfind("the job's result is ", 0), 0u) << message;
  EXPECT_NE(message.find("(max_result_bytes = 1048576)"), std::string::npos) << message;
  EXPECT_NE(message.find("--job-max-result-bytes"), std::string::npos) << message;
  const Answer result = Get(server, "/v1/jobs/" + id + "/result");
  EXPECT_EQ(result.status, 413);
  EXPECT_EQ(result.body["code"], "TooBig");
}

// Memory only (--jobs-db none): results count against --job-results-memory-bytes; the oldest
// finished jobs are dropped beyond it, and a result larger than it fails its job.
TEST(JobsLimitsTest, WithoutADatabaseTheOldestResultsAreDroppedBeyondTheBudget) {
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start({"--jobs-db", "none", "--no-access-log", "--job-workers", "1",
                            "--job-results-memory-bytes", "2000000"}))
      << server.log();
  // ~0.75 MB each: two fit in 2 MB, three do not.
  const std::string sweep = CsvSweep(3000);
  std::vector<std::string> ids;
  for (int i = 0; i < 3; ++i) {
    ids.push_back(SubmitJob(server, "/v1/explore", sweep));
    ASSERT_EQ(WaitFinished(server, ids.back())["state"], "done");
  }
  const auto size = ClientOf(server).Get(("/v1/jobs/" + ids[2] + "/result").c_str());
  ASSERT_TRUE(size);
  ASSERT_GT(size->body.size(), 2000000u / 3);
  ASSERT_LT(size->body.size(), 2000000u / 2);
  EXPECT_EQ(Get(server, "/v1/jobs/" + ids[0]).status, 404);
  EXPECT_EQ(Get(server, "/v1/jobs/" + ids[1] + "/result").status, 200);
  EXPECT_EQ(Get(server, "/v1/jobs/" + ids[2] + "/result").status, 200);
  const std::string big = SubmitJob(server, "/v1/explore", CsvSweep(10000));  // ~2.5 MB.
  const Json failed = WaitFinished(server, big);
  EXPECT_EQ(failed["state"], "failed");
  EXPECT_EQ(failed["error"]["code"], "TooBig");
  EXPECT_NE(
      failed["error"]["message"].get<std::string>().find("(max_results_memory_bytes = 2000000)"),
      std::string::npos)
      << failed.dump();
}

// --- Item 8: a jobs database that cannot write ------------------------------------------------

// SQLite's own SQLITE_FULL ("database or disk is full"), reached through PRAGMA max_page_count
// (--jobs-db-max-bytes) exactly as on a full disk. Before: the job was shown done and served
// though its result was never saved, and after restarts it ran again until it failed as
// "the server died".
TEST(JobsLimitsTest, AFullDatabaseNeverShowsAJobDoneWithoutItsStoredResult) {
  TempDir dir("sweetspot-limits");
  const std::string db = dir.File("jobs.db");
  std::vector<std::string> accepted;
  std::set<std::string> done_before;  // Shown done by the first server.
  std::string big;
  {
    testing::ServerProcess server;
    ASSERT_TRUE(server.Start(Args(db, {"--jobs-db-max-bytes", "131072"}))) << server.log();
    // A 0.75 MB result cannot fit in 128 KiB: the job fails with the store's message.
    big = SubmitJob(server, "/v1/explore", CsvSweep(3000));
    const Json job = WaitFinished(server, big);
    EXPECT_EQ(job["state"], "failed") << job.dump();
    EXPECT_EQ(job["status"], 503);
    EXPECT_EQ(job["error"]["code"], "Unavailable");
    EXPECT_NE(job["error"]["message"].get<std::string>().find("database or disk is full"),
              std::string::npos)
        << job.dump();
    EXPECT_EQ(Get(server, "/v1/jobs/" + big + "/result").status, 503);

    // Small jobs until the database is full: then a submit is refused, 503 + Retry-After.
    httplib::Client client = ClientOf(server);
    const std::string submit = R"({"path": "/v1/sweet-spot", "body": )" + std::string(kQuick) + "}";
    std::optional<httplib::Response> refused;
    for (int i = 0; i < 2000; ++i) {
      auto answer = client.Post("/v1/jobs", submit, "application/json");
      ASSERT_TRUE(answer);
      if (answer->status == 503) {
        refused = *answer;
        break;
      }
      if (answer->status == 429) {  // The queue is full: let the workers catch up.
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
        continue;
      }
      ASSERT_EQ(answer->status, 202) << answer->body;
      accepted.push_back(Json::parse(answer->body)["id"]);
    }
    ASSERT_TRUE(refused.has_value())
        << "no submit was refused after " << accepted.size() << " jobs";
    EXPECT_EQ(refused->get_header_value("Retry-After"), "1");
    EXPECT_EQ(refused->get_header_value("Content-Type"), "application/json");
    const Json envelope = Json::parse(refused->body);
    EXPECT_EQ(envelope["code"], "Unavailable");
    EXPECT_EQ(envelope["field"], nullptr);
    EXPECT_NE(envelope["message"].get<std::string>().find("jobs database"), std::string::npos);
    EXPECT_GT(accepted.size(), 0u);
    // Every accepted job is done with its result, or failed naming the full store.
    for (const std::string& id : accepted) {
      const Json finished = WaitFinished(server, id);
      if (finished["state"] == "done") {
        done_before.insert(id);
        EXPECT_EQ(Get(server, "/v1/jobs/" + id + "/result").status, 200);
      } else {
        EXPECT_EQ(finished["state"], "failed") << finished.dump();
        EXPECT_EQ(finished["error"]["code"], "Unavailable") << finished.dump();
      }
    }
    EXPECT_EQ(server.Stop(SIGTERM), 0) << server.log();
  }
  // After a restart (no limit now) nothing runs again and nothing reads "the server died":
  // the jobs shown done are done with their result; the others are failed as before, or
  // unknown when not even their failure fitted in the database (their row was deleted rather
  // than left "running"); nobody was resumed.
  testing::ServerProcess again;
  ASSERT_TRUE(again.Start(Args(db))) << again.log();
  EXPECT_GT(done_before.size(), 0u);
  EXPECT_EQ(Get(again, "/v1/jobs/" + big).body["state"], "failed");
  for (const std::string& id : accepted) {
    const Answer job = Get(again, "/v1/jobs/" + id);
    if (done_before.count(id) != 0) {
      ASSERT_EQ(job.status, 200) << id;
      EXPECT_EQ(job.body["state"], "done") << job.body.dump();
      EXPECT_EQ(Get(again, "/v1/jobs/" + id + "/result").status, 200);
    } else if (job.status == 200) {
      EXPECT_EQ(job.body["state"], "failed") << job.body.dump();
      EXPECT_EQ(job.body["error"]["code"], "Unavailable") << job.body.dump();
    } else {
      EXPECT_EQ(job.status, 404) << job.body.dump();
    }
    if (job.status == 200) {
      EXPECT_EQ(job.body["resumes"], 0) << job.body.dump();
    }
  }
  EXPECT_EQ(Get(again, "/v1/jobs?state=running").body["total"], 0);
  EXPECT_EQ(Get(again, "/v1/jobs?state=queued").body["total"], 0);
  EXPECT_EQ(again.log().find("interrupted"), std::string::npos) << again.log();
}

// --- Item 11a: the per-job time limit --------------------------------------------------------

// Before: a job ran as long as its request asked (a flexible 1,000,000-design sweep: ~85 min
// of both cores). Now --job-max-time-s sets its cancel flag and it ends failed, naming it.
TEST(JobsLimitsTest, AJobRunningPastTheTimeLimitIsStoppedAndFailed) {
  TempDir dir("sweetspot-limits");
  testing::ServerProcess server;
  ASSERT_TRUE(server.Start(Args(dir.File("jobs.db"), {"--job-max-time-s", "0.5"}))) << server.log();
  // 10,000 flexible impacts (~40 s of work, far past the limit); an explore this long would
  // be refused at submit by its estimate, a scene is not estimated.
  const std::string id = SubmitJob(server, "/v1/sweet-spot", testing::kLongFlexibleCurve);
  const Json job = WaitFinished(server, id);
  EXPECT_EQ(job["state"], "failed") << job.dump();
  EXPECT_EQ(job["status"], 408);
  EXPECT_EQ(job["error"]["code"], "Timeout");
  EXPECT_NE(job["error"]["message"].get<std::string>().find("ran longer than max_time_s = 0.5 s"),
            std::string::npos)
      << job.dump();
  // Stopped at the limit: the curve checks its cancel flag between points (~4 ms each);
  // 2 s above the limit absorbs a loaded 2-core machine and still fails a job left to run
  // its ~40 s.
  const double ran_s = job["finished_s"].get<double>() - job["started_s"].get<double>();
  std::cout << "[ measured ] a job over max_time_s = 0.5 s ran " << ran_s << " s\n";
  EXPECT_GE(ran_s, 0.5);
  EXPECT_LT(ran_s, 0.5 + 2.0) << job.dump();
  EXPECT_EQ(Get(server, "/v1/jobs/" + id + "/result").status, 408);
}

// A sweep cancelled while it runs keeps no partial rows, whatever its format: its result is 409
// Cancelled (before, the CSV rows made so far were kept as a 200 answer, as if the sweep were
// complete, and an NDJSON job kept its rows and an {"error"} line as a 200 answer). With
// memory only and with the SQLite store (which keeps a result in pieces as it is made).
TEST(JobsLimitsTest, ACancelledSweepJobKeepsNoPartialRowsInAnyFormat) {
  TempDir dir("sweetspot-limits");
  for (const std::string& db : {std::string("none"), dir.File("jobs.db")}) {
    testing::ServerProcess server;
    ASSERT_TRUE(server.Start({"--jobs-db", db, "--no-access-log"})) << server.log();
    for (const char* format : {"csv", "ndjson", "json"}) {
      SCOPED_TRACE(db + " " + format);
      Json sweep = Json::parse(testing::jobs::kSlowSweep);  // ~15 s of Hertz designs, as above.
      sweep["parameters"][0]["count"] = 100;
      sweep["parameters"][1]["count"] = 100;
      sweep["format"] = format;
      const std::string id = SubmitJob(server, "/v1/explore", sweep.dump());
      testing::jobs::WaitForState(server, id, "running");
      // Some rows made first (~1.5 ms a design: a few hundred), so that a partial answer
      // would have rows to keep.
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
      EXPECT_EQ(testing::jobs::Delete(server, "/v1/jobs/" + id).status, 202);
      const Json job = WaitFinished(server, id);
      EXPECT_EQ(job["state"], "cancelled") << job.dump();
      EXPECT_EQ(job["status"], nullptr) << job.dump();
      const Answer result = Get(server, "/v1/jobs/" + id + "/result");
      EXPECT_EQ(result.status, 409);
      EXPECT_EQ(result.body["code"], "Cancelled") << result.body.dump();
    }
  }
}

}  // namespace
}  // namespace jobs_limits_test
}  // namespace sweetspot
