// JobManager with a JobStore: what is saved on each state change, what a new
// manager on the same store (a restart) loads, resumes or marks failed, and
// how Shutdown's grace period ends. The store here is an in-memory fake; the
// SQLite store has its own tests (tests/server/sqlite_job_store_test.cpp) and
// the real restart is tested with the server process (tests/server/jobs_restart_test.cpp).
#include "server/jobs/job_store.hpp"

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <limits>
#include <map>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "server/jobs/job_manager.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace job_store_test {
namespace {

// A text answer's body: `text`, or read from its source piece by piece (a stored result).
std::string BodyText(const api::Response& response) {
  if (!response.source) return response.text;
  std::string body;
  while (body.size() < response.source->bytes) {
    const std::size_t before = body.size();
    if (!response.source->read(body.size(), 1000, &body) || body.size() == before) break;
  }
  return body;
}

using api::Request;
using api::Response;


using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;

// How long a test waits for something that must happen: only reached when the
// code under test is broken (a hang); generous for sanitizer builds on a loaded
// 2-core machine, never approached by a passing run.
constexpr auto kMustHappen = std::chrono::seconds(10);

// "Promptly": the runners below poll Cancelled() every millisecond and the rest
// is a lock and a join (microseconds); 2 s absorbs sanitizers and a busy machine
// and still fails when a grace period or a cancel is not cut short.
constexpr auto kPrompt = std::chrono::seconds(2);

// A JobStore in memory, shared by the "processes" (managers) of one test.
class FakeStore : public JobStore {
 public:
  bool Save(const JobRecord& record, std::string* error) override {
    std::lock_guard lock(mutex_);
    if (fail_saves_ || record.response_json.size() + record.response_text.size() > room_) {
      *error = "disk full";
      return false;
    }
    records_[record.id] = record;
    ++saves_;
    return true;
  }
  bool Delete(const std::string& id, std::string* error) override {
    std::lock_guard lock(mutex_);
    if (fail_saves_) {
      *error = "disk full";
      return false;
    }
    records_.erase(id);
    return true;
  }
  bool LoadAll(std::vector<JobRecord>* records, std::string* error) override {
    std::lock_guard lock(mutex_);
    if (fail_load_) {
      *error = "file is not a database";
      return false;
    }
    records->clear();
    for (const auto& [id, record] : records_) records->push_back(record);
    std::stable_sort(records->begin(), records->end(), [](const auto& a, const auto& b) {
      return a.created_unix_s < b.created_unix_s;
    });
    return true;
  }

  bool LoadResult(const std::string& id, std::optional<JobRecord>* record,
                  std::string* /*error*/) override {
    std::lock_guard lock(mutex_);
    ++result_loads_;
    const auto it = records_.find(id);
    if (it == records_.end()) {
      record->reset();
    } else {
      *record = it->second;
    }
    return true;
  }

  std::optional<JobRecord> Get(const std::string& id) {
    std::lock_guard lock(mutex_);
    const auto it = records_.find(id);
    if (it == records_.end()) return std::nullopt;
    return it->second;
  }
  std::size_t size() {
    std::lock_guard lock(mutex_);
    return records_.size();
  }
  void Put(const JobRecord& record) {
    std::lock_guard lock(mutex_);
    records_[record.id] = record;
  }
  void FailSaves(bool fail) {
    std::lock_guard lock(mutex_);
    fail_saves_ = fail;
  }
  // Saves of records whose result is over `bytes` fail ("disk full"), as on a nearly full disk.
  void RoomForResults(std::size_t bytes) {
    std::lock_guard lock(mutex_);
    room_ = bytes;
  }
  int result_loads() {
    std::lock_guard lock(mutex_);
    return result_loads_;
  }
  void FailLoad(bool fail) {
    std::lock_guard lock(mutex_);
    fail_load_ = fail;
  }
  int saves() {
    std::lock_guard lock(mutex_);
    return saves_;
  }

 private:
  std::mutex mutex_;
  std::map<std::string, JobRecord> records_;
  bool fail_saves_ = false;
  bool fail_load_ = false;
  std::size_t room_ = std::numeric_limits<std::size_t>::max();
  int saves_ = 0;
  int result_loads_ = 0;
};

// A one-shot signal between the test thread and runners.
class Gate {
 public:
  void Open() {
    std::lock_guard lock(mutex_);
    open_ = true;
    cv_.notify_all();
  }
  // Waits until Open() or until `progress` is cancelled; true when opened.
  bool Wait(const core::Progress* progress) {
    std::unique_lock lock(mutex_);
    while (!open_) {
      if (core::IsCancelled(progress)) return false;
      cv_.wait_for(lock, milliseconds(1));
    }
    return true;
  }
  // Waits until Open(), at most kMustHappen; true when opened.
  bool WaitForOpen() {
    std::unique_lock lock(mutex_);
    return cv_.wait_for(lock, kMustHappen, [this] { return open_; });
  }

 private:
  std::mutex mutex_;
  std::condition_variable cv_;
  bool open_ = false;
};

// Opens a gate when it goes out of scope (declared after the manager, so a
// failed assertion cannot leave a runner blocked forever).
struct OpenOnExit {
  Gate& gate;
  ~OpenOnExit() { gate.Open(); }
};

Response Echo(const Request& inner, core::Progress* /*progress*/) {
  return {200, Json{{"method", inner.method}, {"path", inner.path}, {"body", inner.body}}};
}

// Counts its calls, then echoes.
struct CountingEcho {
  std::atomic<int>* calls;
  Response operator()(const Request& inner, core::Progress* progress) const {
    ++*calls;
    return Echo(inner, progress);
  }
};

Request Post(std::string path, std::string body = "{}") {
  return Request{"POST", std::move(path), std::move(body)};
}

JobPersistence On(FakeStore* store, std::vector<std::string>* errors = nullptr) {
  JobPersistence persistence;
  persistence.store = store;
  if (errors != nullptr) {
    persistence.on_store_error = [errors](const std::string& message) {
      errors->push_back(message);
    };
  }
  return persistence;
}

std::string IdOf(const Response& submitted) {
  EXPECT_EQ(submitted.status, 202) << submitted.body.dump();
  return submitted.body.value("id", "");
}

// Polls Status until `id` is in `state` (or gone, or kMustHappen passes).
Json WaitForState(const JobManager& jobs, const std::string& id, const std::string& state) {
  const auto deadline = Clock::now() + kMustHappen;
  Response status = jobs.Status(id);
  while (status.status == 200 && status.body["state"] != state && Clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(1));
    status = jobs.Status(id);
  }
  EXPECT_EQ(status.status, 200) << status.body.dump();
  EXPECT_EQ(status.body["state"], state) << status.body.dump();
  return status.body;
}

// Polls the store until the record of `id` is in `state`.
JobRecord WaitForStoredState(FakeStore& store, const std::string& id, const std::string& state) {
  const auto deadline = Clock::now() + kMustHappen;
  std::optional<JobRecord> record = store.Get(id);
  while ((!record || record->state != state) && Clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(1));
    record = store.Get(id);
  }
  EXPECT_TRUE(record.has_value()) << id;
  if (!record) return {};
  EXPECT_EQ(record->state, state);
  return *record;
}

double UnixNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// A stored record as a previous process left it.
JobRecord Stored(const std::string& id, const std::string& state, double created_unix_s) {
  JobRecord record;
  record.id = id;
  record.state = state;
  record.method = "POST";
  record.path = "/v1/explore";
  record.body = R"({"n":")" + id + "\"}";
  record.created_at = "2024-05-01T12:00:00.123Z";
  record.created_unix_s = created_unix_s;
  return record;
}

std::string Hex(char digit) { return std::string(32, digit); }

// --- JobConfig::max_resumes ----------------------------------------------------

TEST(JobStoreConfigTest, MaxResumesDefaultAndRange) {
  JobConfig config;
  EXPECT_EQ(config.max_resumes, 2);
  std::string why;
  config.max_resumes = 0;
  EXPECT_TRUE(Validates(config, &why)) << why;
  config.max_resumes = 100;
  EXPECT_TRUE(Validates(config, &why)) << why;
  config.max_resumes = -1;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "max_resumes = -1: must be in [0, 100]");
  config.max_resumes = 101;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "max_resumes = 101: must be in [0, 100]");
}

// --- What is saved -------------------------------------------------------------

TEST(JobStoreTest, EveryStateChangeIsSavedBeforeItIsVisible) {
  FakeStore store;
  Gate started, release;
  JobConfig config;
  config.workers = 1;
  JobManager jobs(
      config,
      [&](const Request& inner, core::Progress* progress) {
        progress->Report(0.25);
        started.Open();
        release.Wait(progress);
        return Response{201, Json{{"echo", inner.body}}};
      },
      On(&store));
  OpenOnExit open_release{release};
  const Response submitted = jobs.Submit(Post("/v1/compare", R"({"a":1})"));
  const std::string id = IdOf(submitted);
  // A 202 means it is stored: the record is there as soon as Submit returns.
  const std::optional<JobRecord> queued = store.Get(id);
  ASSERT_TRUE(queued.has_value());
  EXPECT_TRUE(queued->state == "queued" || queued->state == "running") << queued->state;
  EXPECT_EQ(queued->method, "POST");
  EXPECT_EQ(queued->path, "/v1/compare");
  EXPECT_EQ(queued->body, R"({"a":1})");
  EXPECT_EQ(queued->created_at, submitted.body["created_at"]);
  EXPECT_NEAR(queued->created_unix_s, UnixNow(), 5.0);
  EXPECT_EQ(queued->resumes, 0);

  ASSERT_TRUE(started.WaitForOpen());
  const JobRecord running = WaitForStoredState(store, id, "running");
  EXPECT_EQ(running.body, R"({"a":1})");  // Kept while running: needed to resume it.
  ASSERT_TRUE(running.started_unix_s.has_value());
  EXPECT_LE(running.created_unix_s, *running.started_unix_s);
  EXPECT_FALSE(running.finished_unix_s.has_value());
  EXPECT_EQ(running.status, 0);

  release.Open();
  WaitForState(jobs, id, "done");
  const JobRecord done = WaitForStoredState(store, id, "done");
  EXPECT_EQ(done.body, "");  // A finished job is never run again.
  EXPECT_EQ(done.progress, 1.0);
  EXPECT_EQ(done.status, 201);
  EXPECT_EQ(done.response_json, R"({"echo":"{\"a\":1}"})");
  EXPECT_EQ(done.content_type, "");
  EXPECT_EQ(done.error, "");
  ASSERT_TRUE(done.finished_unix_s.has_value());
  EXPECT_LE(*done.started_unix_s, *done.finished_unix_s);

  // DELETE of a finished job deletes its record.
  EXPECT_EQ(jobs.Cancel(id).status, 200);
  EXPECT_FALSE(store.Get(id).has_value());
}

TEST(JobStoreTest, CancelsAndFailuresAreSaved) {
  FakeStore store;
  Gate started;
  JobConfig config;
  config.workers = 1;
  JobManager jobs(
      config,
      [&](const Request& inner, core::Progress* progress) {
        if (inner.body == "fail") {
          progress->Report(0.5);
          return Response{422, Json{{"code", "Infeasible"}, {"message", "no bat"}}};
        }
        started.Open();
        while (!progress->Cancelled()) std::this_thread::sleep_for(milliseconds(1));
        return Echo(inner, progress);
      },
      On(&store));
  const std::string failed = IdOf(jobs.Submit(Post("/v1/bat/fit", "fail")));
  WaitForState(jobs, failed, "failed");
  const JobRecord failed_record = WaitForStoredState(store, failed, "failed");
  EXPECT_EQ(failed_record.status, 422);
  // The error object, as JSON text (old rows hold a bare message: SqliteJobStoreTest).
  EXPECT_EQ(failed_record.error, R"({"code":"Infeasible","field":null,"message":"no bat"})");
  EXPECT_EQ(failed_record.progress, 0.5);
  EXPECT_EQ(failed_record.response_json, R"({"code":"Infeasible","message":"no bat"})");

  const std::string running = IdOf(jobs.Submit(Post("/v1/explore", "run")));
  ASSERT_TRUE(started.WaitForOpen());
  const std::string queued = IdOf(jobs.Submit(Post("/v1/explore", "wait")));
  EXPECT_EQ(jobs.Cancel(queued).status, 200);
  const JobRecord cancelled = WaitForStoredState(store, queued, "cancelled");
  EXPECT_TRUE(cancelled.cancel_requested);
  EXPECT_TRUE(cancelled.finished_unix_s.has_value());
  EXPECT_EQ(cancelled.body, "");

  // A cancel asked of a running job is saved at once: a crash before the
  // runner returns must not resume a job its client cancelled.
  EXPECT_EQ(jobs.Cancel(running).status, 202);
  const std::optional<JobRecord> asked = store.Get(running);
  ASSERT_TRUE(asked.has_value());
  EXPECT_TRUE(asked->cancel_requested);
  // Its runner answered 200 after the cancel: that answer is saved with it.
  const JobRecord kept = WaitForStoredState(store, running, "cancelled");
  EXPECT_EQ(kept.status, 200);
  EXPECT_EQ(kept.response_json, Echo(Post("/v1/explore", "run"), nullptr).body.dump());
  EXPECT_EQ(kept.error, "");
}

TEST(JobStoreTest, TextResultsAreSavedAndLoadedAsText) {
  FakeStore store;
  std::string id;
  {
    JobManager jobs(
        JobConfig{},
        [](const Request&, core::Progress*) {
          return Response::Text(200, "a,b\n1,2\n", "text/csv");
        },
        On(&store));
    id = IdOf(jobs.Submit(Post("/v1/explore")));
    WaitForState(jobs, id, "done");
  }
  const std::optional<JobRecord> record = store.Get(id);
  ASSERT_TRUE(record.has_value());
  EXPECT_EQ(record->response_text, "a,b\n1,2\n");
  EXPECT_EQ(record->content_type, "text/csv");
  EXPECT_EQ(record->response_json, "");

  JobManager restarted(JobConfig{}, Echo, On(&store));
  const Response result = restarted.Result(id);
  EXPECT_EQ(result.status, 200);
  EXPECT_EQ(BodyText(result), "a,b\n1,2\n");
  EXPECT_EQ(result.content_type, "text/csv");
}

// --- Restart: what comes back ----------------------------------------------------

TEST(JobStoreTest, FinishedJobsAndResultsSurviveARestart) {
  FakeStore store;
  std::string done, failed;
  Json done_json, failed_json;
  {
    JobConfig config;
    config.workers = 1;
    JobManager jobs(
        config,
        [](const Request& inner, core::Progress* progress) {
          if (inner.body == "fail") {
            return Response{400, Json{{"code", "InvalidValue"}, {"message", "bad"}}};
          }
          return Echo(inner, progress);
        },
        On(&store));
    done = IdOf(jobs.Submit(Post("/v1/sweet-spot", "ok")));
    failed = IdOf(jobs.Submit(Post("/v1/sweet-spot", "fail")));
    done_json = WaitForState(jobs, done, "done");
    failed_json = WaitForState(jobs, failed, "failed");
  }
  std::atomic<int> calls{0};
  JobManager restarted(JobConfig{}, CountingEcho{&calls}, On(&store));
  for (const auto& [id, before] : {std::pair{done, done_json}, std::pair{failed, failed_json}}) {
    const Response status = restarted.Status(id);
    ASSERT_EQ(status.status, 200);
    // Times are the job's, not the manager's: after its submit (*_s, equal within the
    // microsecond they are rounded to) and absolute (*_at, equal); everything else is equal.
    Json after = status.body;
    for (const char* key : {"created_s", "started_s", "finished_s"}) {
      EXPECT_GE(after[key].get<double>(), 0.0) << key;
      EXPECT_NEAR(after[key].get<double>(), before[key].get<double>(), 2e-6) << key;
      after.erase(key);
    }
    Json expected = before;
    for (const char* key : {"created_s", "started_s", "finished_s", "expires_in_s"}) {
      expected.erase(key);
    }
    EXPECT_GT(after["expires_in_s"].get<double>(), 3500.0);
    after.erase("expires_in_s");
    EXPECT_EQ(after, expected);
  }
  EXPECT_EQ(restarted.Result(done).status, 200);
  EXPECT_EQ(restarted.Result(done).body,
            (Json{{"method", "POST"}, {"path", "/v1/sweet-spot"}, {"body", "ok"}}));
  EXPECT_EQ(restarted.Result(failed).status, 400);
  EXPECT_EQ(restarted.Result(failed).body, (Json{{"code", "InvalidValue"}, {"message", "bad"}}));
  EXPECT_EQ(calls.load(), 0);  // Finished jobs are never run again.
  EXPECT_EQ(restarted.CountsByState().at("done"), 1);
  EXPECT_EQ(restarted.CountsByState().at("failed"), 1);
}

TEST(JobStoreTest, QueuedJobsRunAfterARestartInTheirOrder) {
  FakeStore store;
  const double now = UnixNow();
  store.Put(Stored(Hex('b'), "queued", now - 2.0));
  store.Put(Stored(Hex('a'), "queued", now - 1.0));
  std::mutex mutex;
  std::vector<std::string> order;
  JobConfig config;
  config.workers = 1;
  JobManager jobs(
      config,
      [&](const Request& inner, core::Progress* progress) {
        std::lock_guard lock(mutex);
        order.push_back(inner.body);
        return Echo(inner, progress);
      },
      On(&store));
  WaitForState(jobs, Hex('a'), "done");
  WaitForState(jobs, Hex('b'), "done");
  std::lock_guard lock(mutex);
  EXPECT_EQ(order, (std::vector<std::string>{R"({"n":")" + Hex('b') + "\"}",
                                             R"({"n":")" + Hex('a') + "\"}"}));
  const Json status = jobs.Status(Hex('a')).body;
  EXPECT_EQ(status["resumes"], 0);  // Never started before: not a resume.
  EXPECT_EQ(status["created_at"], "2024-05-01T12:00:00.123Z");
  EXPECT_EQ(status["created_s"], 0.0);  // After its submit, s: not before this manager's start.
  // Submitted 1 s before this manager started, run at once: started about 1 s after it.
  EXPECT_NEAR(status["started_s"].get<double>(), 1.0, 0.5);
}

TEST(JobStoreTest, JobRunningWhenTheProcessDiedIsResumedFromTheStart) {
  FakeStore store;
  JobRecord running = Stored(Hex('c'), "running", UnixNow() - 10.0);
  running.started_unix_s = running.created_unix_s + 1.0;
  running.progress = 0.0;
  store.Put(running);
  std::atomic<int> calls{0};
  Gate release;
  JobManager jobs(
      JobConfig{},
      [&](const Request& inner, core::Progress* progress) {
        ++calls;
        release.Wait(progress);
        return Echo(inner, progress);
      },
      On(&store));
  OpenOnExit open_release{release};
  // Saved as re-queued (with its resume counted) before anything runs it.
  const std::optional<JobRecord> requeued = store.Get(Hex('c'));
  ASSERT_TRUE(requeued.has_value());
  EXPECT_TRUE(requeued->state == "queued" || requeued->state == "running") << requeued->state;
  EXPECT_EQ(requeued->resumes, 1);
  EXPECT_EQ(requeued->body, running.body);

  release.Open();
  const Json done = WaitForState(jobs, Hex('c'), "done");
  EXPECT_EQ(done["resumes"], 1);
  // Started again by this manager, 10 s after its submit (the first start was 1 s after it).
  EXPECT_GE(done["started_s"].get<double>(), 9.5);
  EXPECT_EQ(jobs.Result(Hex('c')).body,
            (Json{{"method", "POST"}, {"path", "/v1/explore"}, {"body", running.body}}));
  EXPECT_EQ(calls.load(), 1);
  EXPECT_EQ(WaitForStoredState(store, Hex('c'), "done").resumes, 1);
}

TEST(JobStoreTest, JobRunningWhenTheProcessDiedTooOftenIsFailedWithItsReason) {
  for (const int max_resumes : {0, 2}) {
    FakeStore store;
    JobRecord running = Stored(Hex('d'), "running", UnixNow() - 10.0);
    running.started_unix_s = running.created_unix_s + 1.0;
    running.resumes = max_resumes;
    store.Put(running);
    std::atomic<int> calls{0};
    JobConfig config;
    config.max_resumes = max_resumes;
    JobManager jobs(config, CountingEcho{&calls}, On(&store));
    const std::string reason =
        "interrupted by a server restart: the job was running when the server died, and it "
        "had already been resumed " +
        std::to_string(max_resumes) + " times (limit max_resumes = " + std::to_string(max_resumes) +
        ")";
    const Response status = jobs.Status(Hex('d'));
    ASSERT_EQ(status.status, 200);
    EXPECT_EQ(status.body["state"], "failed");
    EXPECT_EQ(status.body["error"],
              (Json{{"code", "Interrupted"}, {"message", reason}, {"field", nullptr}}));
    EXPECT_EQ(status.body["status"], 503);
    EXPECT_EQ(status.body["resumes"], max_resumes);
    EXPECT_NEAR(status.body["started_s"].get<double>(), 1.0, 1e-3);  // The start that was cut.
    EXPECT_GE(status.body["finished_s"].get<double>(), 9.5);         // Failed by this manager.
    const Response result = jobs.Result(Hex('d'));
    EXPECT_EQ(result.status, 503);
    EXPECT_EQ(result.body,
              (Json{{"code", "Interrupted"}, {"message", reason}, {"field", nullptr}}));
    const std::optional<JobRecord> saved = store.Get(Hex('d'));
    ASSERT_TRUE(saved.has_value());
    EXPECT_EQ(saved->state, "failed");
    EXPECT_EQ(Json::parse(saved->error),
              (Json{{"code", "Interrupted"}, {"message", reason}, {"field", nullptr}}));
    EXPECT_EQ(saved->status, 503);
    EXPECT_EQ(saved->body, "");
    EXPECT_EQ(calls.load(), 0);
  }
}

TEST(JobStoreTest, JobCancelledWhileRunningWhenTheProcessDiedIsCancelled) {
  FakeStore store;
  JobRecord running = Stored(Hex('e'), "running", UnixNow() - 10.0);
  running.started_unix_s = running.created_unix_s + 1.0;
  running.cancel_requested = true;
  store.Put(running);
  std::atomic<int> calls{0};
  JobManager jobs(JobConfig{}, CountingEcho{&calls}, On(&store));
  const Json status = jobs.Status(Hex('e')).body;
  EXPECT_EQ(status["state"], "cancelled");
  EXPECT_EQ(status["cancel_requested"], true);
  EXPECT_EQ(store.Get(Hex('e'))->state, "cancelled");
  EXPECT_EQ(jobs.Result(Hex('e')).status, 409);
  EXPECT_EQ(calls.load(), 0);
}

TEST(JobStoreTest, LoadingDropsAndDeletesWhatIsTooOldOrBeyondMaxKept) {
  FakeStore store;
  const double now = UnixNow();
  auto finished = [&](char digit, double finished_ago_s) {
    JobRecord record = Stored(Hex(digit), "done", now - finished_ago_s - 1.0);
    record.body.clear();
    record.started_unix_s = record.created_unix_s;
    record.finished_unix_s = now - finished_ago_s;
    record.status = 200;
    record.response_json = "{}";
    record.progress = 1.0;
    store.Put(record);
  };
  finished('1', 7200.0);  // Older than keep_results_s.
  finished('2', 30.0);    // The oldest of the three recent ones: beyond max_kept = 2.
  finished('3', 20.0);
  finished('4', 10.0);
  JobConfig config;
  config.max_kept = 2;
  JobManager jobs(config, Echo, On(&store));
  EXPECT_EQ(jobs.Status(Hex('1')).status, 404);
  EXPECT_EQ(jobs.Status(Hex('2')).status, 404);
  EXPECT_EQ(jobs.Status(Hex('3')).status, 200);
  EXPECT_EQ(jobs.Status(Hex('4')).status, 200);
  EXPECT_NEAR(jobs.Status(Hex('4')).body["expires_in_s"].get<double>(), 3590.0, 5.0);
  EXPECT_FALSE(store.Get(Hex('1')).has_value());
  EXPECT_FALSE(store.Get(Hex('2')).has_value());
  EXPECT_EQ(store.size(), 2u);
}

TEST(JobStoreTest, AnUnreadableStoredResultFailsThatJobOnly) {
  FakeStore store;
  JobRecord broken = Stored(Hex('5'), "done", UnixNow() - 1.0);
  broken.finished_unix_s = broken.created_unix_s;
  broken.status = 200;
  broken.response_json = "{not json";
  store.Put(broken);
  store.Put(Stored(Hex('6'), "bogus", UnixNow()));
  std::vector<std::string> errors;
  JobManager jobs(JobConfig{}, Echo, On(&store, &errors));
  const Json status = jobs.Status(Hex('5')).body;
  EXPECT_EQ(status["state"], "failed");
  EXPECT_EQ(status["error"], (Json{{"code", "InternalError"},
                                   {"message", "the stored result of this job could not be read"},
                                   {"field", nullptr}}));
  EXPECT_EQ(jobs.Result(Hex('5')).status, 500);
  EXPECT_EQ(jobs.Status(Hex('6')).status, 404);
  EXPECT_EQ(errors, (std::vector<std::string>{"job " + Hex('6') +
                                              " has an unknown state \"bogus\": skipped"}));
}

// --- Store failures --------------------------------------------------------------

TEST(JobStoreTest, LoadFailureThrowsWithTheStoresReason) {
  FakeStore store;
  store.FailLoad(true);
  try {
    JobManager jobs(JobConfig{}, Echo, On(&store));
    FAIL() << "a store that cannot be read was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_STREQ(error.what(), "cannot load the jobs: file is not a database");
  }
}

TEST(JobStoreTest, SaveFailureOnSubmitIs503AndTheJobIsNotQueued) {
  FakeStore store;
  std::vector<std::string> errors;
  std::atomic<int> calls{0};
  JobManager jobs(JobConfig{}, CountingEcho{&calls}, On(&store, &errors));
  store.FailSaves(true);
  const Response refused = jobs.Submit(Post("/v1/explore"));
  EXPECT_EQ(refused.status, 503);
  EXPECT_EQ(refused.body,
            (Json{{"code", "Unavailable"},
                  {"message", "the job could not be saved in the jobs database; retry later"},
                  {"field", nullptr}}));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0].rfind("cannot save job ", 0), 0u) << errors[0];
  EXPECT_NE(errors[0].find(" (queued): disk full"), std::string::npos) << errors[0];
  EXPECT_EQ(jobs.CountsByState().at("queued"), 0);
  store.FailSaves(false);
  const std::string id = IdOf(jobs.Submit(Post("/v1/explore")));
  WaitForState(jobs, id, "done");
  EXPECT_EQ(calls.load(), 1);
}

// --- Shutdown with a store -------------------------------------------------------

TEST(JobStoreTest, ShutdownKeepsQueuedAndInterruptedJobsForTheNextStart) {
  FakeStore store;
  Gate started;
  JobConfig config;
  config.workers = 1;
  std::string running, queued;
  {
    JobManager jobs(
        config,
        [&](const Request& inner, core::Progress* progress) {
          progress->Report(0.5);
          started.Open();
          while (!progress->Cancelled()) std::this_thread::sleep_for(milliseconds(1));
          return Echo(inner, progress);  // Discarded: Shutdown interrupted it.
        },
        On(&store));
    running = IdOf(jobs.Submit(Post("/v1/explore", "first")));
    ASSERT_TRUE(started.WaitForOpen());
    queued = IdOf(jobs.Submit(Post("/v1/explore", "second")));
    const auto before = Clock::now();
    jobs.Shutdown();
    EXPECT_LT(Clock::now() - before, kPrompt);
    for (const std::string& id : {running, queued}) {
      const Json status = jobs.Status(id).body;
      EXPECT_EQ(status["state"], "queued") << id;
      EXPECT_EQ(status["cancel_requested"], false) << id;
      EXPECT_TRUE(status["started_s"].is_null()) << id;
      EXPECT_EQ(status["progress"], 0.0) << id;
    }
    EXPECT_EQ(jobs.Cancel(queued).status, 200);  // Still cancellable after Shutdown.
    EXPECT_EQ(jobs.Status(queued).body["state"], "cancelled");
  }
  const std::optional<JobRecord> kept = store.Get(running);
  ASSERT_TRUE(kept.has_value());
  EXPECT_EQ(kept->state, "queued");
  EXPECT_EQ(kept->body, "first");
  EXPECT_FALSE(kept->started_unix_s.has_value());
  EXPECT_EQ(kept->resumes, 0);  // A clean stop is not a crash: no resume is used up.
  EXPECT_EQ(store.Get(queued)->state, "cancelled");

  JobManager next(config, Echo, On(&store));
  const Json done = WaitForState(next, running, "done");
  EXPECT_EQ(done["resumes"], 0);
  EXPECT_EQ(next.Result(running).body["body"], "first");
  EXPECT_EQ(next.Status(queued).body["state"], "cancelled");
}

TEST(JobStoreTest, ShutdownGraceLetsARunningJobFinish) {
  FakeStore store;
  Gate started, release;
  JobConfig config;
  config.workers = 1;
  JobManager jobs(
      config,
      [&](const Request& inner, core::Progress* progress) {
        if (inner.body == "slow") {
          started.Open();
          release.Wait(progress);
        }
        return Echo(inner, progress);
      },
      On(&store));
  OpenOnExit open_release{release};
  const std::string slow = IdOf(jobs.Submit(Post("/v1/explore", "slow")));
  ASSERT_TRUE(started.WaitForOpen());
  const std::string waiting = IdOf(jobs.Submit(Post("/v1/explore", "quick")));

  std::atomic<bool> returned{false};
  std::thread stopper([&] {
    jobs.Shutdown(60.0);  // Far longer than the test: it must end when the job does.
    returned = true;
  });
  // During the grace: no new jobs, the queued one is not started, the running one runs on.
  const auto deadline = Clock::now() + kMustHappen;
  while (jobs.Submit(Post("/v1/explore")).status != 503 && Clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(1));
  }
  const Response refused = jobs.Submit(Post("/v1/explore"));
  EXPECT_EQ(refused.status, 503);
  EXPECT_EQ(refused.body["code"], "ShuttingDown");
  EXPECT_EQ(jobs.Status(slow).body["state"], "running");
  EXPECT_FALSE(returned.load());

  const auto released = Clock::now();
  release.Open();
  stopper.join();
  EXPECT_LT(Clock::now() - released, kPrompt);
  EXPECT_EQ(jobs.Status(slow).body["state"], "done");
  EXPECT_EQ(store.Get(slow)->state, "done");
  EXPECT_EQ(jobs.Status(waiting).body["state"], "queued");  // Kept for the next start.
  EXPECT_EQ(store.Get(waiting)->state, "queued");
}

TEST(JobStoreTest, ShutdownGraceEndsAtItsDeadlineOrOnEndGrace) {
  for (const bool end_grace : {false, true}) {
    FakeStore store;
    Gate started;
    JobConfig config;
    config.workers = 1;  // Jobs submitted while waiting for the 503 stay queued.
    JobManager jobs(
        config,
        [&](const Request& inner, core::Progress* progress) {
          started.Open();
          while (!progress->Cancelled()) std::this_thread::sleep_for(milliseconds(1));
          return Echo(inner, progress);
        },
        On(&store));
    const std::string id = IdOf(jobs.Submit(Post("/v1/explore")));
    ASSERT_TRUE(started.WaitForOpen());
    const auto before = Clock::now();
    const double grace_s = end_grace ? 60.0 : 0.2;
    std::thread stopper([&] { jobs.Shutdown(grace_s); });
    if (end_grace) {
      // Shutdown sets "stopping" and starts waiting in one critical section, so
      // once Submit answers 503 the grace period is under way: end it.
      const auto deadline = Clock::now() + kMustHappen;
      while (jobs.Submit(Post("/v1/explore")).status != 503 && Clock::now() < deadline) {
        std::this_thread::sleep_for(milliseconds(1));
      }
      jobs.EndGrace();
    }
    stopper.join();
    const auto took = Clock::now() - before;
    if (!end_grace) {
      EXPECT_GE(took, milliseconds(200));
    }
    EXPECT_LT(took, kPrompt + milliseconds(200));
    EXPECT_EQ(jobs.Status(id).body["state"], "queued") << end_grace;
    EXPECT_EQ(store.Get(id)->state, "queued") << end_grace;
  }
}

TEST(JobStoreTest, WithoutAStoreShutdownStillCancelsWhatIsLeft) {
  Gate started;
  JobConfig config;
  config.workers = 1;
  JobManager jobs(config, [&](const Request& inner, core::Progress* progress) {
    started.Open();
    while (!progress->Cancelled()) std::this_thread::sleep_for(milliseconds(1));
    return Echo(inner, progress);
  });
  const std::string running = IdOf(jobs.Submit(Post("/v1/explore")));
  ASSERT_TRUE(started.WaitForOpen());
  const std::string queued = IdOf(jobs.Submit(Post("/v1/explore")));
  jobs.Shutdown(0.05);
  EXPECT_EQ(jobs.Status(running).body["state"], "cancelled");
  EXPECT_EQ(jobs.Status(queued).body["state"], "cancelled");
}

// --- Limits: a result the store cannot keep, big results, the time limit ------------------

// A job is done only once its result is saved: a store that refuses it ("disk full") makes
// the job failed with the store's message, saved as such, so the next start neither shows a
// result nor runs the job again.
TEST(JobStoreTest, AResultTheStoreCannotSaveFailsTheJobAndIsNotRunAgain) {
  FakeStore store;
  store.RoomForResults(1000);
  std::vector<std::string> errors;
  std::string id;
  {
    JobManager jobs(
        JobConfig{},
        [](const Request&, core::Progress*) {
          return Response{200, Json{{"rows", std::string(5000, 'x')}}};
        },
        On(&store, &errors));
    id = IdOf(jobs.Submit(Post("/v1/explore")));
    const Json failed = WaitForState(jobs, id, "failed");
    EXPECT_EQ(failed["status"], 503);
    EXPECT_EQ(failed["error"]["code"], "Unavailable");
    EXPECT_EQ(failed["error"]["message"],
              "the job's result could not be saved in the jobs database (disk full): it is not "
              "kept; submit the job again later");
    EXPECT_EQ(jobs.Result(id).status, 503);
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_NE(errors[0].find(" (done): disk full"), std::string::npos) << errors[0];
  }
  ASSERT_TRUE(store.Get(id));
  EXPECT_EQ(store.Get(id)->state, "failed");
  std::atomic<int> calls{0};
  JobManager restarted(JobConfig{}, CountingEcho{&calls}, On(&store));
  const Response status = restarted.Status(id);
  EXPECT_EQ(status.body["state"], "failed");
  EXPECT_EQ(status.body["resumes"], 0);
  EXPECT_EQ(calls.load(), 0);
}

// Results over kMaxLoadedResultBytes are not kept in memory: Result() reads them from the
// store (as the stored JSON text), also after a restart; small ones stay in memory.
TEST(JobStoreTest, BigResultsAreReadBackFromTheStore) {
  FakeStore store;
  const std::string rows(kMaxLoadedResultBytes, 'x');  // Serialised: 2 bytes more.
  std::string big, small;
  const auto runner = [&rows](const Request& inner, core::Progress* progress) {
    return inner.body == "big" ? Response{200, Json{{"rows", rows}}} : Echo(inner, progress);
  };
  for (int start = 0; start < 2; ++start) {
    JobManager jobs(JobConfig{}, runner, On(&store));
    if (start == 0) {
      big = IdOf(jobs.Submit(Post("/v1/explore", "big")));
      small = IdOf(jobs.Submit(Post("/v1/explore", "small")));
      WaitForState(jobs, big, "done");
      WaitForState(jobs, small, "done");
    }
    const int loads = store.result_loads();
    const Response result = jobs.Result(big);
    EXPECT_EQ(store.result_loads(), loads + 1);
    EXPECT_EQ(result.status, 200);
    EXPECT_EQ(result.content_type, "application/json");
    EXPECT_EQ(BodyText(result), (Json{{"rows", rows}}.dump() + "\n"));
    EXPECT_EQ(jobs.Result(small).body,
              (Json{{"method", "POST"}, {"path", "/v1/explore"}, {"body", "small"}}));
    EXPECT_EQ(store.result_loads(), loads + 1);  // The small one came from memory.
  }
}

// With a store, the small results held in memory total at most max_results_memory_bytes:
// beyond it the oldest leave memory (the store keeps them) and are read back.
TEST(JobStoreTest, SmallResultsBeyondTheMemoryBudgetAreReadBackFromTheStore) {
  FakeStore store;
  JobConfig config;
  config.workers = 1;
  config.max_results_memory_bytes = 1024;
  const auto runner = [](const Request&, core::Progress*) {
    return Response{200, Json{{"rows", std::string(600, 'x')}}};  // ~611 bytes serialised.
  };
  JobManager jobs(config, runner, On(&store));
  const std::string first = IdOf(jobs.Submit(Post("/v1/explore")));
  WaitForState(jobs, first, "done");
  const std::string second = IdOf(jobs.Submit(Post("/v1/explore")));
  WaitForState(jobs, second, "done");
  EXPECT_EQ(jobs.Result(second).body, (Json{{"rows", std::string(600, 'x')}}));
  EXPECT_EQ(store.result_loads(), 0);
  const Response oldest = jobs.Result(first);
  EXPECT_EQ(store.result_loads(), 1);
  EXPECT_EQ(BodyText(oldest), (Json{{"rows", std::string(600, 'x')}}.dump() + "\n"));
}

// A job running longer than max_time_s has its cancel flag set and ends failed (408 Timeout)
// naming the limit; a 2xx answer it gives after the cancel is not kept.
TEST(JobStoreTest, AJobPastItsTimeLimitIsCancelledAndFailed) {
  FakeStore store;
  JobConfig config;
  config.max_time_s = 0.2;
  JobManager jobs(
      config,
      [](const Request& inner, core::Progress* progress) {
        const auto deadline = Clock::now() + kMustHappen;
        while (!progress->Cancelled() && Clock::now() < deadline) {
          std::this_thread::sleep_for(milliseconds(1));
        }
        return Echo(inner, progress);
      },
      On(&store));
  const std::string id = IdOf(jobs.Submit(Post("/v1/explore")));
  const Json failed = WaitForState(jobs, id, "failed");
  EXPECT_EQ(failed["status"], 408);
  EXPECT_EQ(failed["error"]["code"], "Timeout");
  EXPECT_EQ(failed["error"]["message"],
            "the job ran longer than max_time_s = 0.2 s and was stopped (--job-max-time-s): ask "
            "for fewer designs or starts, or raise the limit");
  // Stopped at the limit: the runner polls every millisecond; 2 s (kPrompt) absorbs a loaded
  // machine and still fails a job left to run to kMustHappen (10 s).
  const double ran_s = failed["finished_s"].get<double>() - failed["started_s"].get<double>();
  EXPECT_GE(ran_s, 0.2);
  EXPECT_LT(ran_s, 0.2 + std::chrono::duration<double>(kPrompt).count());
  EXPECT_EQ(jobs.Result(id).status, 408);
  EXPECT_EQ(store.Get(id)->state, "failed");
}

TEST(JobStoreConfigTest, TimeAndMemoryLimitsDefaultsAndRanges) {
  JobConfig config;
  EXPECT_EQ(config.max_time_s, 600.0);
  EXPECT_EQ(config.max_results_memory_bytes, 256u << 20);
  std::string why;
  config.max_time_s = 0;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "max_time_s = 0: must be in (0, 1e+06]");
  config.max_time_s = 600;
  config.max_results_memory_bytes = 1000;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_EQ(why, "max_results_memory_bytes = 1000: must be in [1024, 1000000000000]");
  config.max_results_memory_bytes = 1024;
  EXPECT_TRUE(Validates(config, &why));
}

}  // namespace
}  // namespace job_store_test
}  // namespace sweetspot::server
