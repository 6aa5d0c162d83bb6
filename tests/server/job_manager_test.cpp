#include "server/jobs/job_manager.hpp"

#include <gtest/gtest.h>

#include "tests/refusal_text.hpp"

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <limits>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace job_manager_test {
namespace {

using api::Request;
using api::Response;


using std::chrono::milliseconds;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;

// How long a test waits for something that must happen. Only reached when the
// code under test is broken (a hang), so it is generous: sanitizer builds on a
// loaded 2-core machine are slow, and a normal run never gets near it.
constexpr auto kMustHappen = std::chrono::seconds(10);

// The bound on "promptly" after a cancel: every cancel-aware runner below polls
// Cancelled() at least once a millisecond, and what follows (a lock, a few
// assignments, a thread join) takes microseconds. 2 s is >1000x that, which
// absorbs TSan's slowdown and other builds competing for the 2 cores, yet
// still fails if a cancel is not forwarded to the runner (the runner would then
// wait for kMustHappen or forever).
constexpr auto kPrompt = std::chrono::seconds(2);

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
// failed assertion cannot leave a runner that ignores cancel blocked forever).
struct OpenOnExit {
  Gate& gate;
  ~OpenOnExit() { gate.Open(); }
};

Response Echo(const Request& inner, core::Progress* /*progress*/) {
  return {200, Json{{"method", inner.method}, {"path", inner.path}, {"body", inner.body}}};
}

// A runner that signals `started`, then waits for `release` (or a cancel).
JobRunner Blocking(Gate* started, Gate* release) {
  return [started, release](const Request& inner, core::Progress* progress) {
    started->Open();
    release->Wait(progress);
    return Echo(inner, progress);
  };
}

Request Post(std::string path, std::string body = "{}") {
  return Request{"POST", std::move(path), std::move(body)};
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

std::string IdOf(const Response& submitted) {
  EXPECT_EQ(submitted.status, 202) << submitted.body.dump();
  return submitted.body.value("id", "");
}

bool IsHex128(const std::string& id) {
  return id.size() == 32 && id.find_first_not_of("0123456789abcdef") == std::string::npos;
}

void ExpectError(const Response& response, int status, const std::string& code,
                 const std::string& message) {
  EXPECT_EQ(response.status, status);
  EXPECT_EQ(response.body, (Json{{"code", code}, {"message", message}, {"field", nullptr}}));
}

// --- JobConfig ---------------------------------------------------------------

TEST(JobConfigTest, DefaultsAreValid) {
  const JobConfig config;
  std::string why = "untouched";
  EXPECT_TRUE(Validates(config, &why));
  EXPECT_EQ(why, "untouched");
  EXPECT_TRUE(config.Validate(nullptr));
  EXPECT_EQ(config.workers, 2);
  EXPECT_EQ(config.max_queued, 64u);
  EXPECT_EQ(config.max_kept, 1000u);
  EXPECT_EQ(config.keep_results_s, 3600.0);
}

std::string WhyInvalid(const JobConfig& config) {
  std::string why;
  EXPECT_FALSE(Validates(config, &why));
  EXPECT_FALSE(config.Validate(nullptr));
  return why;
}

TEST(JobConfigTest, EachRuleNamesFieldValueAndRule) {
  JobConfig config;
  config.workers = 0;
  EXPECT_EQ(WhyInvalid(config), "workers = 0: must be in [1, 64]");
  config.workers = 65;
  EXPECT_EQ(WhyInvalid(config), "workers = 65: must be in [1, 64]");
  config.workers = 64;
  EXPECT_TRUE(config.Validate(nullptr));

  config = JobConfig{};
  config.max_queued = 0;
  EXPECT_EQ(WhyInvalid(config), "max_queued = 0: must be in [1, 1000000]");
  config.max_queued = 1000001;
  EXPECT_EQ(WhyInvalid(config), "max_queued = 1000001: must be in [1, 1000000]");

  config = JobConfig{};
  config.max_kept = 0;
  EXPECT_EQ(WhyInvalid(config), "max_kept = 0: must be in [1, 1000000]");
  config.max_kept = 1000001;
  EXPECT_EQ(WhyInvalid(config), "max_kept = 1000001: must be in [1, 1000000]");

  config = JobConfig{};
  config.keep_results_s = 0.0;
  EXPECT_EQ(WhyInvalid(config), "keep_results_s = 0: must be finite and > 0");
  config.keep_results_s = -1.5;
  EXPECT_EQ(WhyInvalid(config), "keep_results_s = -1.5: must be finite and > 0");
  config.keep_results_s = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(WhyInvalid(config), "keep_results_s = nan: must be finite and > 0");
  config.keep_results_s = std::numeric_limits<double>::infinity();
  EXPECT_EQ(WhyInvalid(config), "keep_results_s = inf: must be finite and > 0");
}

TEST(JobManagerTest, ConstructorRefusesInvalidConfigAndEmptyRunner) {
  JobConfig config;
  config.workers = 0;
  try {
    JobManager jobs(config, Echo);
    FAIL() << "an invalid config was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_STREQ(error.what(), "invalid JobConfig: workers = 0: must be in [1, 64]");
  }
  EXPECT_THROW(JobManager(JobConfig{}, JobRunner{}), std::invalid_argument);
}

// --- Lifecycle ---------------------------------------------------------------

TEST(JobManagerTest, SubmitRunsToDoneWithResultVerbatim) {
  std::atomic<int> calls{0};
  JobManager jobs(JobConfig{}, [&calls](const Request& inner, core::Progress*) {
    ++calls;
    Response response{201, Json{{"echo", inner.body}, {"method", inner.method}}};
    return response;
  });
  const Response submitted = jobs.Submit(Post("/v1/sweet-spot", R"({"bat":1})"));
  ASSERT_EQ(submitted.status, 202);
  const Json& queued = submitted.body;
  const std::string id = queued["id"];
  EXPECT_TRUE(IsHex128(id)) << id;
  EXPECT_EQ(queued["state"], "queued");
  EXPECT_EQ(queued["progress"], 0.0);
  EXPECT_EQ(queued["path"], "/v1/sweet-spot");
  EXPECT_TRUE(queued["created_s"].is_number());
  EXPECT_GE(queued["created_s"].get<double>(), 0.0);
  EXPECT_TRUE(queued["started_s"].is_null());
  EXPECT_TRUE(queued["finished_s"].is_null());
  EXPECT_TRUE(queued["status"].is_null());
  EXPECT_TRUE(queued["error"].is_null());
  EXPECT_EQ(queued["cancel_requested"], false);
  EXPECT_TRUE(queued["expires_in_s"].is_null());
  const std::string created_at = queued["created_at"];
  ASSERT_EQ(created_at.size(), 24u) << created_at;  // 2024-05-01T12:00:00.123Z
  EXPECT_EQ(created_at[10], 'T');
  EXPECT_EQ(created_at[19], '.');
  EXPECT_EQ(created_at.back(), 'Z');

  const Json done = WaitForState(jobs, id, "done");
  EXPECT_EQ(done["id"], id);
  EXPECT_EQ(done["progress"], 1.0);
  EXPECT_EQ(done["status"], 201);
  EXPECT_TRUE(done["error"].is_null());
  EXPECT_LE(done["created_s"].get<double>(), done["started_s"].get<double>());
  EXPECT_LE(done["started_s"].get<double>(), done["finished_s"].get<double>());
  EXPECT_GT(done["expires_in_s"].get<double>(), 3500.0);
  EXPECT_LE(done["expires_in_s"].get<double>(), 3600.0);

  const Response result = jobs.Result(id);
  EXPECT_EQ(result.status, 201);
  EXPECT_EQ(result.body, (Json{{"echo", R"({"bat":1})"}, {"method", "POST"}}));
  EXPECT_EQ(jobs.Result(id).body, result.body);  // Reading a result does not consume it.
  EXPECT_EQ(calls.load(), 1);
}

TEST(JobManagerTest, ResultPassesTextBodiesThrough) {
  JobManager jobs(JobConfig{}, [](const Request&, core::Progress*) {
    Response response;
    response.text = "a,b\n1,2\n";
    response.content_type = "text/csv";
    return response;
  });
  const std::string id = IdOf(jobs.Submit(Post("/v1/explore")));
  WaitForState(jobs, id, "done");
  const Response result = jobs.Result(id);
  EXPECT_EQ(result.status, 200);
  EXPECT_EQ(result.text, "a,b\n1,2\n");
  EXPECT_EQ(result.content_type, "text/csv");
}

TEST(JobManagerTest, ProgressIsVisibleWhileRunning) {
  Gate reported, release;
  JobManager jobs(JobConfig{}, [&](const Request& inner, core::Progress* progress) {
    progress->Report(0.5);
    reported.Open();
    release.Wait(progress);
    return Echo(inner, progress);
  });
  const std::string id = IdOf(jobs.Submit(Post("/v1/explore")));
  ASSERT_TRUE(reported.WaitForOpen());
  const Response running = jobs.Status(id);
  EXPECT_EQ(running.status, 200);
  EXPECT_EQ(running.body["state"], "running");
  EXPECT_EQ(running.body["progress"], 0.5);
  EXPECT_TRUE(running.body["started_s"].is_number());
  EXPECT_TRUE(running.body["finished_s"].is_null());
  EXPECT_TRUE(running.body["status"].is_null());
  ExpectError(
      jobs.Result(id), 409, "NotReady",
      "job \"" + id + "\" is running: its result is ready once its state is done or failed");
  release.Open();
  const Json done = WaitForState(jobs, id, "done");
  EXPECT_EQ(done["progress"], 1.0);
  EXPECT_EQ(done["status"], 200);
}

TEST(JobManagerTest, FailedOnClientErrorKeepsTheInnerErrorBody) {
  const Json inner_error{{"code", "Infeasible"},
                         {"message", "targets.mass_kg = 5: no bat of this shape reaches it"},
                         {"field", "targets.mass_kg"}};
  JobManager jobs(JobConfig{}, [&](const Request&, core::Progress* progress) {
    progress->Report(0.25);
    return Response{422, inner_error};
  });
  const std::string id = IdOf(jobs.Submit(Post("/v1/bat/fit")));
  const Json failed = WaitForState(jobs, id, "failed");
  EXPECT_EQ(failed["status"], 422);
  EXPECT_EQ(failed["error"], inner_error);  // The error object, as the endpoint answered it.
  EXPECT_EQ(failed["progress"], 0.25);  // Frozen at the last report.
  EXPECT_TRUE(failed["finished_s"].is_number());
  const Response result = jobs.Result(id);
  EXPECT_EQ(result.status, 422);
  EXPECT_EQ(result.body, inner_error);
}

TEST(JobManagerTest, FailedOnServerErrorWithoutMessageNamesTheStatus) {
  JobManager jobs(JobConfig{}, [](const Request&, core::Progress*) {
    return Response{501, Json::array()};
  });
  const std::string id = IdOf(jobs.Submit(Post("/v1/optimize")));
  const Json failed = WaitForState(jobs, id, "failed");
  EXPECT_EQ(failed["status"], 501);
  // Not an error envelope: wrapped, the status named in the message.
  EXPECT_EQ(failed["error"], (Json{{"code", "InternalError"},
                                   {"message", "the request failed with HTTP status 501"},
                                   {"field", nullptr}}));
  EXPECT_EQ(jobs.Result(id).status, 501);
  EXPECT_EQ(jobs.Result(id).body, Json::array());
}

TEST(JobManagerTest, ThrowingRunnerFailsWithInternalErrorAndWorkersSurvive) {
  std::atomic<int> calls{0};
  JobConfig config;
  config.workers = 1;  // The same worker must survive both throws.
  JobManager jobs(config, [&calls](const Request& inner, core::Progress*) -> Response {
    ++calls;
    if (inner.body == "std") throw std::runtime_error("secret internal detail");
    if (inner.body == "int") throw 42;
    return Response{200, Json{{"ok", true}}};
  });
  for (const char* body : {"std", "int"}) {
    const std::string id = IdOf(jobs.Submit(Post("/v1/collision", body)));
    const Json failed = WaitForState(jobs, id, "failed");
    EXPECT_EQ(failed["status"], 500);
    EXPECT_EQ(failed["error"], (Json{{"code", "InternalError"},
                                     {"message", "internal error"},
                                     {"field", nullptr}}));
    ExpectError(jobs.Result(id), 500, "InternalError", "internal error");
  }
  const std::string ok = IdOf(jobs.Submit(Post("/v1/collision", "fine")));
  WaitForState(jobs, ok, "done");
  EXPECT_EQ(calls.load(), 3);
}

TEST(JobManagerTest, UnknownIdIs404EverywhereAndLongIdsAreCut) {
  JobManager jobs(JobConfig{}, Echo);
  ExpectError(jobs.Status("abc"), 404, "NotFound", "no job with id \"abc\"");
  ExpectError(jobs.Result("abc"), 404, "NotFound", "no job with id \"abc\"");
  ExpectError(jobs.Cancel("abc"), 404, "NotFound", "no job with id \"abc\"");
  const Response long_id = jobs.Status(std::string(1000, 'f'));
  EXPECT_EQ(long_id.status, 404);
  EXPECT_LT(long_id.body["message"].get<std::string>().size(), 100u);
}

// --- Cancellation ------------------------------------------------------------

TEST(JobManagerTest, CancelRunningJobStopsItPromptly) {
  // The runner returns once it has seen the cancel and the test has asked
  // twice: without `asked`, a fast runner could finish between the two DELETEs
  // (seen under ASan), and the second would delete the cancelled job.
  Gate started, asked;
  std::atomic<bool> saw_cancel{false};
  JobManager jobs(JobConfig{}, [&](const Request& inner, core::Progress* progress) {
    started.Open();
    while (!progress->Cancelled()) std::this_thread::sleep_for(milliseconds(1));
    saw_cancel = true;
    asked.WaitForOpen();
    // What a cancelled sweep answers (an error, dropped); a 2xx would be kept
    // (RunnerThatFinishesAfterCancelIsStillCancelled).
    return Response{409, Json{{"code", "Cancelled"}, {"message", inner.path}, {"field", nullptr}}};
  });
  OpenOnExit open_asked{asked};
  const std::string id = IdOf(jobs.Submit(Post("/v1/optimize")));
  ASSERT_TRUE(started.WaitForOpen());

  const auto cancel_time = Clock::now();
  const Response cancelling = jobs.Cancel(id);
  EXPECT_EQ(cancelling.status, 202);
  EXPECT_EQ(cancelling.body["state"], "running");
  EXPECT_EQ(cancelling.body["cancel_requested"], true);
  EXPECT_EQ(jobs.Cancel(id).status, 202);  // Asking again changes nothing.
  asked.Open();

  const Json cancelled = WaitForState(jobs, id, "cancelled");
  EXPECT_LT(Clock::now() - cancel_time, kPrompt);
  EXPECT_TRUE(saw_cancel.load());
  EXPECT_TRUE(cancelled["status"].is_null());
  EXPECT_TRUE(cancelled["error"].is_null());
  EXPECT_TRUE(cancelled["finished_s"].is_number());
  EXPECT_EQ(cancelled["cancel_requested"], true);
  ExpectError(jobs.Result(id), 409, "Cancelled",
              "job \"" + id + "\" was cancelled: it has no result");
}

TEST(JobManagerTest, RunnerThatFinishesAfterCancelIsStillCancelled) {
  Gate started, release;
  JobManager jobs(JobConfig{}, [&](const Request& inner, core::Progress* progress) {
    started.Open();
    release.Wait(nullptr);  // Ignores the cancel flag.
    return Echo(inner, progress);
  });
  OpenOnExit open_release{release};
  const std::string id = IdOf(jobs.Submit(Post("/v1/explore")));
  ASSERT_TRUE(started.WaitForOpen());
  EXPECT_EQ(jobs.Cancel(id).status, 202);
  EXPECT_EQ(jobs.Status(id).body["state"], "running");  // Until the runner returns.
  release.Open();
  const Json cancelled = WaitForState(jobs, id, "cancelled");
  // Its 2xx answer is kept (an optimisation's best design so far): the result and its status.
  EXPECT_EQ(cancelled["status"], 200);
  EXPECT_TRUE(cancelled["error"].is_null());
  const Response result = jobs.Result(id);
  EXPECT_EQ(result.status, 200);
  EXPECT_EQ(result.body, Echo(Post("/v1/explore"), nullptr).body);
}

TEST(JobManagerTest, ACancelledRunnersErrorAnswerIsDroppedAndTheResultIs409) {
  Gate started;
  JobManager jobs(JobConfig{}, [&](const Request&, core::Progress* progress) {
    started.Open();
    while (!progress->Cancelled()) std::this_thread::sleep_for(milliseconds(1));
    return Response{409, Json{{"code", "Cancelled"}, {"message", "the sweep was cancelled"},
                              {"field", nullptr}}};
  });
  const std::string id = IdOf(jobs.Submit(Post("/v1/explore")));
  ASSERT_TRUE(started.WaitForOpen());
  EXPECT_EQ(jobs.Cancel(id).status, 202);
  const Json cancelled = WaitForState(jobs, id, "cancelled");
  EXPECT_TRUE(cancelled["status"].is_null());
  ExpectError(jobs.Result(id), 409, "Cancelled",
              "job \"" + id + "\" was cancelled: it has no result");
}

// GET /v1/jobs: newest submitted first, filtered by state, paged with limit and offset.
TEST(JobManagerTest, ListIsNewestFirstFilteredByStateAndPaged) {
  Gate started, release;
  JobConfig config;
  config.workers = 1;
  JobManager jobs(config, Blocking(&started, &release));
  OpenOnExit open_release{release};
  std::vector<std::string> ids;  // oldest first
  ids.push_back(IdOf(jobs.Submit(Post("/v1/explore"))));
  ASSERT_TRUE(started.WaitForOpen());  // ids[0] runs; the next four wait behind it
  for (int i = 0; i < 4; ++i) ids.push_back(IdOf(jobs.Submit(Post("/v1/compare"))));
  auto list = [&](std::optional<std::string> state, std::size_t limit, std::size_t offset) {
    const Response r = jobs.List(api::JobListQuery{std::move(state), limit, offset});
    EXPECT_EQ(r.status, 200);
    return r.body;
  };
  auto ids_of = [](const Json& page) {
    std::vector<std::string> out;
    for (const Json& job : page["jobs"]) out.push_back(job["id"]);
    return out;
  };
  const Json all = list(std::nullopt, 100, 0);
  EXPECT_EQ(ids_of(all), (std::vector<std::string>{ids[4], ids[3], ids[2], ids[1], ids[0]}));
  EXPECT_EQ(all["total"], 5);
  EXPECT_TRUE(all["next_offset"].is_null());
  // Each entry is the job's JSON, as GET /v1/jobs/{id} gives it.
  EXPECT_EQ(all["jobs"][4], jobs.Status(ids[0]).body);
  EXPECT_EQ(all["jobs"][4]["path"], "/v1/explore");

  const Json running = list("running", 100, 0);
  EXPECT_EQ(ids_of(running), (std::vector<std::string>{ids[0]}));
  EXPECT_EQ(running["total"], 1);
  const Json queued = list("queued", 100, 0);
  EXPECT_EQ(ids_of(queued), (std::vector<std::string>{ids[4], ids[3], ids[2], ids[1]}));
  EXPECT_EQ(list("done", 100, 0)["jobs"], Json::array());
  EXPECT_EQ(list("done", 100, 0)["total"], 0);

  // Pages of two: [4 3] next 2, [2 1] next 4, [0] last.
  const Json first = list(std::nullopt, 2, 0);
  EXPECT_EQ(ids_of(first), (std::vector<std::string>{ids[4], ids[3]}));
  EXPECT_EQ(first["next_offset"], 2);
  const Json second = list(std::nullopt, 2, 2);
  EXPECT_EQ(ids_of(second), (std::vector<std::string>{ids[2], ids[1]}));
  EXPECT_EQ(second["next_offset"], 4);
  const Json last = list(std::nullopt, 2, 4);
  EXPECT_EQ(ids_of(last), (std::vector<std::string>{ids[0]}));
  EXPECT_TRUE(last["next_offset"].is_null());
  const Json beyond = list(std::nullopt, 2, 9);
  EXPECT_EQ(beyond["jobs"], Json::array());
  EXPECT_EQ(beyond["total"], 5);
  EXPECT_TRUE(beyond["next_offset"].is_null());

  // A cancelled queued job moves to its state's list.
  EXPECT_EQ(jobs.Cancel(ids[2]).status, 200);
  EXPECT_EQ(ids_of(list("cancelled", 100, 0)), (std::vector<std::string>{ids[2]}));
  EXPECT_EQ(list("queued", 100, 0)["total"], 3);
}

TEST(JobManagerTest, CancelQueuedJobAtOnceItNeverRunsAndFreesItsSlot) {
  Gate started, release;
  std::atomic<int> calls{0};
  JobConfig config;
  config.workers = 1;
  config.max_queued = 1;
  JobManager jobs(config, [&](const Request& inner, core::Progress* progress) {
    ++calls;
    started.Open();
    release.Wait(progress);
    return Echo(inner, progress);
  });
  const std::string first = IdOf(jobs.Submit(Post("/v1/explore", "1")));
  ASSERT_TRUE(started.WaitForOpen());
  const std::string second = IdOf(jobs.Submit(Post("/v1/explore", "2")));
  EXPECT_EQ(jobs.Submit(Post("/v1/explore", "x")).status, 429);
  ExpectError(
      jobs.Result(second), 409, "NotReady",
      "job \"" + second + "\" is queued: its result is ready once its state is done or failed");

  const Response cancelled = jobs.Cancel(second);
  EXPECT_EQ(cancelled.status, 200);
  EXPECT_EQ(cancelled.body["state"], "cancelled");
  EXPECT_EQ(cancelled.body["progress"], 0.0);
  EXPECT_TRUE(cancelled.body["started_s"].is_null());
  EXPECT_TRUE(cancelled.body["finished_s"].is_number());
  EXPECT_EQ(jobs.Status(second).body["state"], "cancelled");

  const std::string third = IdOf(jobs.Submit(Post("/v1/explore", "3")));  // The slot is free.
  release.Open();
  WaitForState(jobs, first, "done");
  WaitForState(jobs, third, "done");
  EXPECT_EQ(jobs.Result(third).body["body"], "3");
  EXPECT_EQ(jobs.Status(second).body["state"], "cancelled");
  EXPECT_EQ(calls.load(), 2);  // The cancelled job never ran.
}

TEST(JobManagerTest, CancelFinishedJobDeletesIt) {
  JobManager jobs(JobConfig{}, Echo);
  const std::string id = IdOf(jobs.Submit(Post("/v1/collision")));
  const Json done = WaitForState(jobs, id, "done");
  const Response deleted = jobs.Cancel(id);
  EXPECT_EQ(deleted.status, 200);
  Json expected = done;
  expected["deleted"] = true;
  expected.erase("expires_in_s");  // Decreases between the two reads.
  Json got = deleted.body;
  got.erase("expires_in_s");
  EXPECT_EQ(got, expected);
  ExpectError(jobs.Status(id), 404, "NotFound", "no job with id \"" + id + "\"");
  EXPECT_EQ(jobs.Cancel(id).status, 404);
  EXPECT_EQ(jobs.CountsByState().at("done"), 0);
}

// --- Limits and eviction -----------------------------------------------------

TEST(JobManagerTest, FullQueueAnswers429WhileTheWorkerIsBlocked) {
  Gate started, release;
  JobConfig config;
  config.workers = 1;
  config.max_queued = 2;
  JobManager jobs(config, Blocking(&started, &release));
  const std::string running = IdOf(jobs.Submit(Post("/v1/explore", "0")));
  ASSERT_TRUE(started.WaitForOpen());
  const std::string a = IdOf(jobs.Submit(Post("/v1/explore", "a")));
  const std::string b = IdOf(jobs.Submit(Post("/v1/explore", "b")));
  ExpectError(jobs.Submit(Post("/v1/explore", "c")), 429, "TooBusy",
              "job queue is full: 2 jobs queued (limit max_queued = 2); retry later");
  EXPECT_EQ(jobs.CountsByState().at("queued"), 2);  // The refused job left no trace.
  release.Open();
  for (const std::string& id : {running, a, b}) WaitForState(jobs, id, "done");
  EXPECT_EQ(jobs.Result(b).body["body"], "b");
}

TEST(JobManagerTest, QueueLimitDoesNotDependOnWhenTheWorkerWakesUp) {
  // Without waiting for the worker: a job an idle worker is about to take
  // does not count as queued, so exactly workers + max_queued jobs fit.
  Gate started, release;
  JobConfig config;
  config.workers = 1;
  config.max_queued = 1;
  JobManager jobs(config, Blocking(&started, &release));
  EXPECT_EQ(jobs.Submit(Post("/v1/explore")).status, 202);
  EXPECT_EQ(jobs.Submit(Post("/v1/explore")).status, 202);
  ExpectError(jobs.Submit(Post("/v1/explore")), 429, "TooBusy",
              "job queue is full: 1 jobs queued (limit max_queued = 1); retry later");
  release.Open();
}

TEST(JobManagerTest, EvictsOldestFinishedJobsBeyondMaxKept) {
  JobConfig config;
  config.workers = 1;  // Jobs finish in submission order.
  config.max_kept = 3;
  JobManager jobs(config, Echo);
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) ids.push_back(IdOf(jobs.Submit(Post("/v1/collision"))));
  WaitForState(jobs, ids.back(), "done");
  EXPECT_EQ(jobs.Status(ids[0]).status, 404);
  EXPECT_EQ(jobs.Status(ids[1]).status, 404);
  for (int i = 2; i < 5; ++i) EXPECT_EQ(jobs.Result(ids[i]).status, 200) << i;
  EXPECT_EQ(jobs.CountsByState().at("done"), 3);
}

TEST(JobManagerTest, EvictsFinishedJobsAfterKeepResultsButNeverUnfinishedOnes) {
  Gate started, release;
  JobConfig config;
  config.keep_results_s = 0.1;
  JobManager jobs(config, [&](const Request& inner, core::Progress* progress) {
    if (inner.body == "block") {
      started.Open();
      release.Wait(progress);
    }
    return Echo(inner, progress);
  });
  const std::string blocked = IdOf(jobs.Submit(Post("/v1/explore", "block")));
  ASSERT_TRUE(started.WaitForOpen());
  const auto submit_time = Clock::now();
  const std::string quick = IdOf(jobs.Submit(Post("/v1/collision", "quick")));
  // Poll until the quick job is gone: it finished after submit_time, so it
  // cannot vanish before keep_results_s has passed (a lower bound, not racy).
  const auto deadline = submit_time + kMustHappen;
  while (jobs.Status(quick).status == 200 && Clock::now() < deadline) {
    std::this_thread::sleep_for(milliseconds(5));
  }
  EXPECT_EQ(jobs.Status(quick).status, 404);
  EXPECT_GE(Clock::now() - submit_time, milliseconds(100));
  // The running job is older than keep_results_s and stays.
  EXPECT_EQ(jobs.Status(blocked).body["state"], "running");
  release.Open();
  WaitForState(jobs, blocked, "done");
}

TEST(JobManagerTest, CountsByStateHasEveryState) {
  Gate started, release;
  JobConfig config;
  config.workers = 1;
  JobManager jobs(config, [&](const Request& inner, core::Progress* progress) {
    if (inner.body == "fail") return Response{400, Json{{"message", "no"}}};
    if (inner.body == "block") {
      started.Open();
      release.Wait(progress);
    }
    return Echo(inner, progress);
  });
  using Counts = std::map<std::string, int>;
  EXPECT_EQ(jobs.CountsByState(),
            (Counts{{"queued", 0}, {"running", 0}, {"done", 0}, {"failed", 0}, {"cancelled", 0}}));
  const std::string done = IdOf(jobs.Submit(Post("/v1/a", "ok")));
  const std::string failed = IdOf(jobs.Submit(Post("/v1/a", "fail")));
  WaitForState(jobs, done, "done");
  WaitForState(jobs, failed, "failed");
  IdOf(jobs.Submit(Post("/v1/a", "block")));
  ASSERT_TRUE(started.WaitForOpen());
  const std::string cancelled = IdOf(jobs.Submit(Post("/v1/a", "x")));
  EXPECT_EQ(jobs.Cancel(cancelled).status, 200);
  IdOf(jobs.Submit(Post("/v1/a", "y")));
  EXPECT_EQ(jobs.CountsByState(),
            (Counts{{"queued", 1}, {"running", 1}, {"done", 1}, {"failed", 1}, {"cancelled", 1}}));
  release.Open();
}

// --- Shutdown and concurrency ------------------------------------------------

TEST(JobManagerTest, ShutdownWithRunningJobsReturnsPromptly) {
  Gate both_started;
  std::atomic<int> running{0};
  JobConfig config;
  config.workers = 2;
  JobManager jobs(config, [&](const Request& inner, core::Progress* progress) {
    if (++running == 2) both_started.Open();
    while (!progress->Cancelled()) std::this_thread::sleep_for(milliseconds(1));
    return Echo(inner, progress);
  });
  std::vector<std::string> ids;
  for (int i = 0; i < 5; ++i) ids.push_back(IdOf(jobs.Submit(Post("/v1/explore"))));
  ASSERT_TRUE(both_started.WaitForOpen());

  const auto before = Clock::now();
  jobs.Shutdown();
  EXPECT_LT(Clock::now() - before, kPrompt);
  for (const std::string& id : ids) {
    const Response status = jobs.Status(id);  // Still readable after Shutdown.
    EXPECT_EQ(status.status, 200);
    EXPECT_EQ(status.body["state"], "cancelled");
  }
  EXPECT_EQ(running.load(), 2);  // The queued three never ran.
  ExpectError(jobs.Submit(Post("/v1/explore")), 503, "ShuttingDown",
              "the server is shutting down and accepts no new jobs");
  jobs.Shutdown();  // Idempotent.
}

TEST(JobManagerTest, DestructorCancelsRunningJobsPromptly) {
  Gate started;
  Clock::time_point before;
  {
    JobManager jobs(JobConfig{}, [&](const Request& inner, core::Progress* progress) {
      started.Open();
      while (!progress->Cancelled()) std::this_thread::sleep_for(milliseconds(1));
      return Echo(inner, progress);
    });
    IdOf(jobs.Submit(Post("/v1/optimize")));
    ASSERT_TRUE(started.WaitForOpen());
    before = Clock::now();
  }
  EXPECT_LT(Clock::now() - before, kPrompt);
}

TEST(JobManagerTest, ConcurrentShutdownCallsAllWaitForTheJoin) {
  JobManager jobs(JobConfig{}, Echo);
  std::vector<std::thread> threads;
  for (int i = 0; i < 4; ++i) threads.emplace_back([&jobs] { jobs.Shutdown(); });
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(jobs.Submit(Post("/v1/a")).status, 503);
}

TEST(JobManagerTest, ManyConcurrentSubmitsAllFinishWithTheirOwnResults) {
  constexpr int kThreads = 8;
  constexpr int kJobsPerThread = 50;
  JobConfig config;
  config.workers = 4;
  config.max_queued = kThreads * kJobsPerThread;  // Nothing is refused.
  JobManager jobs(config, [](const Request& inner, core::Progress* progress) {
    progress->Report(0.5);
    return Response{200, Json{{"body", inner.body}, {"path", inner.path}}};
  });
  std::vector<std::vector<std::string>> ids(kThreads);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&jobs, &ids, t] {
      for (int i = 0; i < kJobsPerThread; ++i) {
        const Response submitted =
            jobs.Submit(Post("/v1/t" + std::to_string(t), std::to_string(t * 1000 + i)));
        if (submitted.status == 202) ids[t].push_back(submitted.body["id"]);
        (void)jobs.CountsByState();  // Readers run alongside writers.
      }
    });
  }
  for (std::thread& thread : threads) thread.join();

  std::set<std::string> unique;
  for (int t = 0; t < kThreads; ++t) {
    ASSERT_EQ(ids[t].size(), static_cast<std::size_t>(kJobsPerThread)) << t;
    for (int i = 0; i < kJobsPerThread; ++i) {
      const std::string& id = ids[t][i];
      EXPECT_TRUE(IsHex128(id)) << id;
      unique.insert(id);
      WaitForState(jobs, id, "done");
      const Response result = jobs.Result(id);
      EXPECT_EQ(result.status, 200);
      EXPECT_EQ(result.body, (Json{{"body", std::to_string(t * 1000 + i)},
                                   {"path", "/v1/t" + std::to_string(t)}}));
    }
  }
  EXPECT_EQ(unique.size(), static_cast<std::size_t>(kThreads * kJobsPerThread));
  EXPECT_EQ(jobs.CountsByState().at("done"), kThreads * kJobsPerThread);
}

TEST(JobManagerTest, EachManagerDrawsItsOwnIds) {
  JobManager first(JobConfig{}, Echo);
  JobManager second(JobConfig{}, Echo);
  const std::string a = IdOf(first.Submit(Post("/v1/a")));
  const std::string b = IdOf(second.Submit(Post("/v1/a")));
  EXPECT_NE(a, b);
  EXPECT_EQ(second.Status(a).status, 404);  // No shared registry.
}

}  // namespace
}  // namespace job_manager_test
}  // namespace sweetspot::server
