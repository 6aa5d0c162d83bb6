// The job handlers against a recording JobService (no threads, no database): POST /v1/jobs
// validates the inner request as its endpoint does before submitting it, GET /v1/jobs
// validates its query (state, limit, offset) and hands it on, a failure becomes the error
// object, and a cancelled optimisation answers 200 with its best design so far.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "api/handlers/handlers.hpp"
#include "api/job_service.hpp"
#include "api/router.hpp"
#include "tests/contract_example.hpp"

namespace sweetspot::api {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace jobs_api_test {
namespace {

using Json = nlohmann::json;

// Records what the handlers hand on; answers 202 / 200 without running anything.
class RecordingJobs final : public JobService {
 public:
  Response Submit(const Request& inner) override {
    submitted.push_back(inner);
    return {202, Json{{"id", "0123456789abcdef0123456789abcdef"}, {"state", "queued"}}};
  }
  Response Status(const std::string&) const override { return {200, Json::object()}; }
  Response List(const JobListQuery& query) const override {
    listed.push_back(query);
    return {200, Json{{"jobs", Json::array()}, {"total", 0}, {"next_offset", nullptr}}};
  }
  Response Result(const std::string&) const override { return {200, Json::object()}; }
  Response Cancel(const std::string&) override { return {200, Json::object()}; }
  std::map<std::string, int> CountsByState() const override { return {}; }

  std::vector<Request> submitted;
  mutable std::vector<JobListQuery> listed;
};

// The contract's optimisation (tests/api/optimize_test.cpp) with `options` replaced.
Json Optimisation(const Json& options) {
  Json body = sweetspot::testing::ContractOptimisation();
  body["options"] = options;
  return body;
}

Response SubmitJob(RecordingJobs* jobs, const std::string& path, const Json& inner,
                   ApiLimits limits = {}) {
  Context context;
  context.jobs = jobs;
  context.limits = limits;
  return Dispatch({"POST", "/v1/jobs", Json{{"path", path}, {"body", inner}}.dump()}, context);
}

Response ListJobs(RecordingJobs* jobs, std::multimap<std::string, std::string> query,
                  ApiLimits limits = {}) {
  Context context;
  context.jobs = jobs;
  context.limits = limits;
  return Dispatch({"GET", "/v1/jobs", "", std::move(query)}, context);
}

// --- POST /v1/jobs validates first --------------------------------------------

TEST(JobSubmitTest, TheIssuesStarts500IsRefusedAtOnceAndNoJobIsMade) {
  RecordingJobs jobs;
  const Response r = SubmitJob(&jobs, "/v1/optimize", Optimisation({{"starts", 500}}));
  EXPECT_EQ(r.status, 400);
  EXPECT_EQ(r.body, (Json{{"code", "InvalidValue"},
                          {"message", "options.starts = 500: must be between 1 and 64"},
                          {"field", "options.starts"}}));
  EXPECT_TRUE(jobs.submitted.empty());
  // The synchronous endpoint gives the same answer.
  const Response direct =
      Dispatch({"POST", "/v1/optimize", Optimisation({{"starts", 500}}).dump()}, Context{});
  EXPECT_EQ(direct.status, 400);
  EXPECT_EQ(direct.body, r.body);
}

TEST(JobSubmitTest, AValidRequestIsSubmittedOnceAndUnchangedWithoutBeingRun) {
  RecordingJobs jobs;
  const Json inner = Optimisation({{"starts", 64}, {"max_time_s", 10}});
  const auto start = std::chrono::steady_clock::now();
  const Response r = SubmitJob(&jobs, "optimize", inner);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.status, 202) << r.body.dump();
  ASSERT_EQ(jobs.submitted.size(), 1u);
  EXPECT_EQ(jobs.submitted[0].method, "POST");
  EXPECT_EQ(jobs.submitted[0].path, "/v1/optimize");
  EXPECT_EQ(Json::parse(jobs.submitted[0].body), inner);
  // Validation does not solve: 64 starts of this design take seconds (the contract's 4 starts
  // about 0.1 s in Release); parsing it takes well under a millisecond. 0.5 s leaves room for a
  // loaded machine and sanitizers yet fails if the optimiser ran.
  EXPECT_LT(seconds, 0.5);
}

TEST(JobSubmitTest, EveryJobbableEndpointRefusesItsInvalidBodyAtSubmit) {
  struct Case {
    std::string path;
    Json body;
    int status;
    std::string field;
  };
  const std::vector<Case> cases = {
      {"/v1/bat/properties", Json{{"bat", {{"preset", "nope"}}}}, 400, "bat.preset"},
      {"/v1/sweet-spot", Json{{"bat", {{"preset", "paper-wood"}}}, {"cor", 7}}, 400, "cor"},
      {"/v1/explore",
       Json{{"bat", {{"preset", "paper-wood"}}},
            {"parameters", {{{"path", "cor"}, {"min", 0.4}, {"max", 0.6}, {"count", 3}}}},
            {"samples", 0},
            {"sampling", "lhs"}},
       400, "samples"},
      {"/v1/optimize", Optimisation({{"seed", -1}}), 400, "options.seed"},
      {"/v1/bat/fit", Json{{"bat", {{"preset", "paper-wood"}}}, {"targets", {{"mass_kg", "x"}}}},
       400, "targets.mass_kg"},
  };
  for (const Case& c : cases) {
    RecordingJobs jobs;
    const Response r = SubmitJob(&jobs, c.path, c.body);
    EXPECT_EQ(r.status, c.status) << c.path << ": " << r.body.dump();
    EXPECT_EQ(r.body.value("field", Json()), c.field) << c.path << ": " << r.body.dump();
    EXPECT_TRUE(jobs.submitted.empty()) << c.path;
    Context as_a_job;  // a job runs with the batch limits (--max-batch-samples)
    as_a_job.batch = true;
    const Response direct = Dispatch({"POST", c.path, c.body.dump()}, as_a_job);
    EXPECT_EQ(direct.body, r.body) << c.path;
  }
}

TEST(JobSubmitTest, AnExploreJobHasTheBatchLimitAtSubmitToo) {
  ApiLimits limits;
  limits.max_samples = 10;
  limits.max_batch_samples = 20;
  auto sweep = [](int count) {
    return Json{{"bat", {{"preset", "paper-wood"}}},
                {"parameters", {{{"path", "cor"}, {"min", 0.4}, {"max", 0.6}, {"count", count}}}}};
  };
  RecordingJobs jobs;
  EXPECT_EQ(SubmitJob(&jobs, "/v1/explore", sweep(20), limits).status, 202);  // over max_samples
  const Response over = SubmitJob(&jobs, "/v1/explore", sweep(21), limits);
  EXPECT_EQ(over.status, 413);
  EXPECT_EQ(over.body["message"],
            "parameters describe 21 designs, over the limit max_batch_samples = 20 "
            "(--max-batch-samples)");
  EXPECT_EQ(jobs.submitted.size(), 1u);
}

// Issue "Under attack, bounded", item 11a: 1,000,000 flexible designs were accepted as a job
// (~85 min of both cores). At submit, the estimated CPU time (designs x the per-design cost of
// the models the outputs need), wall time and result size are checked against the job limits.
TEST(JobSubmitTest, AnExploreJobOverItsEstimatedCostIsRefusedAtSubmit) {
  auto sweep = [](int count, const char* model) {
    return Json{{"bat", {{"preset", "paper-wood"}}},
                {"parameters", {{{"path", "cor"}, {"min", 0.4}, {"max", 0.6}, {"count", count}}}},
                {"outputs", {"max_exit_speed"}},
                {"options", {{"model", model}}}};
  };
  RecordingJobs jobs;
  const Response flexible = SubmitJob(&jobs, "/v1/explore", sweep(1000000, "flexible"));
  ASSERT_EQ(flexible.status, 413) << flexible.body.dump();
  EXPECT_EQ(flexible.body["code"], "TooBig");
  EXPECT_EQ(flexible.body["field"], "parameters");
  // 1e6 x 11.6 ms (benchmarks.md's flexible sweet spot with its modes fresh) = 11,600 s.
  EXPECT_EQ(flexible.body["message"],
            "a job of 1000000 designs: its CPU time is estimated at 11610 s (flexible exit "
            "speeds: 0.012 s per design), over the limit max_job_cpu_s = 3600; split it into "
            "shards (\"shard\": {\"index\", \"count\"}), fewer designs, or outputs that need "
            "cheaper models");
  // Half as many designs by the closed form (rigid_pivot: 10.5 us each, ~5 s; ~150 MB of rows)
  // are a job.
  EXPECT_EQ(SubmitJob(&jobs, "/v1/explore", sweep(500000, "rigid_pivot")).status, 202);
  EXPECT_EQ(jobs.submitted.size(), 1u);

  // Each limit is configuration, and each is named.
  ApiLimits limits;
  limits.max_job_time_s = 1;  // 1000 flexible designs: ~11.6 s on the api's one thread
  const Response slow = SubmitJob(&jobs, "/v1/explore", sweep(1000, "flexible"), limits);
  EXPECT_EQ(slow.status, 413);
  EXPECT_NE(slow.body["message"].get<std::string>().find(
                "its run time on 1 threads is estimated at 12 s"),
            std::string::npos)
      << slow.body.dump();
  EXPECT_NE(slow.body["message"].get<std::string>().find("over the limit job_max_time_s = 1;"),
            std::string::npos);
  limits = ApiLimits{};
  limits.max_job_result_bytes = 100000;  // 1000 rows of ~300 bytes: ~0.3 MB
  const Response large = SubmitJob(&jobs, "/v1/explore", sweep(1000, "rigid_pivot"), limits);
  EXPECT_EQ(large.status, 413);
  EXPECT_NE(large.body["message"].get<std::string>().find(
                "bytes per row), over the limit job_max_result_bytes = 100000;"),
            std::string::npos)
      << large.body.dump();
  limits.max_job_result_bytes = 1000000;
  EXPECT_EQ(SubmitJob(&jobs, "/v1/explore", sweep(1000, "rigid_pivot"), limits).status, 202);
  EXPECT_EQ(jobs.submitted.size(), 2u);
}

TEST(JobSubmitTest, ValidateOnlyAnswersValidWithoutCallingCore) {
  Context context;
  context.validate_only = true;
  const Response r =
      Dispatch({"POST", "/v1/optimize", Optimisation({{"starts", 64}}).dump()}, context);
  EXPECT_EQ(r.status, 200);
  EXPECT_EQ(r.body, (Json{{"valid", true}}));
}

// --- GET /v1/jobs's query -----------------------------------------------------

TEST(JobListTest, DefaultsAreAllStatesOneHundredFromTheStart) {
  RecordingJobs jobs;
  EXPECT_EQ(ListJobs(&jobs, {}).status, 200);
  ASSERT_EQ(jobs.listed.size(), 1u);
  EXPECT_FALSE(jobs.listed[0].state.has_value());
  EXPECT_EQ(jobs.listed[0].limit, 100u);
  EXPECT_EQ(jobs.listed[0].offset, 0u);
  // A configured page smaller than the default lowers the default.
  ApiLimits small;
  small.max_jobs_page = 7;
  EXPECT_EQ(ListJobs(&jobs, {}, small).status, 200);
  EXPECT_EQ(jobs.listed[1].limit, 7u);
}

TEST(JobListTest, StateLimitAndOffsetAreHandedOn) {
  RecordingJobs jobs;
  ASSERT_EQ(ListJobs(&jobs, {{"state", "running"}, {"limit", "1000"}, {"offset", "40"}}).status,
            200);
  ASSERT_EQ(jobs.listed.size(), 1u);
  EXPECT_EQ(jobs.listed[0].state, "running");
  EXPECT_EQ(jobs.listed[0].limit, 1000u);  // the default max_jobs_page
  EXPECT_EQ(jobs.listed[0].offset, 40u);
  for (const char* state : {"queued", "running", "done", "failed", "cancelled"}) {
    EXPECT_EQ(ListJobs(&jobs, {{"state", state}}).status, 200) << state;
  }
}

TEST(JobListTest, BadQueriesAre400NamingTheParameter) {
  struct Case {
    std::multimap<std::string, std::string> query;
    std::string code;
    std::string message;
  };
  const std::vector<Case> cases = {
      {{{"state", "sleeping"}},
       "InvalidValue",
       "state = \"sleeping\": must be one of queued, running, done, failed, cancelled"},
      {{{"limit", "0"}}, "InvalidValue", "limit = \"0\": must be a whole number in [1, 1000]"},
      {{{"limit", "1001"}},
       "InvalidValue",
       "limit = \"1001\": must be a whole number in [1, 1000]"},
      {{{"limit", "-1"}}, "InvalidValue", "limit = \"-1\": must be a whole number in [1, 1000]"},
      {{{"offset", "1.5"}},
       "InvalidValue",
       "offset = \"1.5\": must be a whole number in [0, 1000000000]"},
      {{{"offset", "99999999999999999999"}},
       "InvalidValue",
       "offset = \"99999999999999999999\": must be a whole number in [0, 1000000000]"},
      {{{"state", "done"}, {"state", "failed"}},
       "InvalidValue",
       "state = \"done\": may be given once"},
      {{{"page", "2"}},
       "UnknownField",
       "page = \"2\": is not a parameter of GET /v1/jobs (state, limit, offset)"},
  };
  for (const Case& c : cases) {
    RecordingJobs jobs;
    const Response r = ListJobs(&jobs, c.query);
    EXPECT_EQ(r.status, 400) << c.message;
    EXPECT_EQ(r.body["code"], c.code) << c.message;
    EXPECT_EQ(r.body["message"], c.message);
    EXPECT_EQ(r.body["field"], c.query.begin()->first);
    EXPECT_TRUE(jobs.listed.empty()) << c.message;
  }
}

// --- the error object ---------------------------------------------------------

TEST(JobErrorObjectTest, AnErrorEnvelopeIsKeptAndABareMessageIsWrapped) {
  const Json infeasible{{"code", "Infeasible"},
                        {"message", "no design meets the constraints"},
                        {"field", "constraints"},
                        {"closest", {{"bat", Json::object()}}}};
  // The envelope's three fields; the large "closest" stays in the result.
  EXPECT_EQ(JobErrorObject(422, infeasible, "ignored"),
            (Json{{"code", "Infeasible"},
                  {"message", "no design meets the constraints"},
                  {"field", "constraints"}}));
  auto wrapped = [](int status) {
    return JobErrorObject(status, nullptr, "old message")["code"].get<std::string>();
  };
  EXPECT_EQ(wrapped(400), "InvalidValue");
  EXPECT_EQ(wrapped(413), "TooBig");
  EXPECT_EQ(wrapped(422), "Infeasible");
  EXPECT_EQ(wrapped(500), "InternalError");
  EXPECT_EQ(wrapped(503), "Interrupted");
  EXPECT_EQ(JobErrorObject(400, Json::array(), "old message"),
            (Json{{"code", "InvalidValue"}, {"message", "old message"}, {"field", nullptr}}));
}

// --- a cancelled optimisation keeps its best design ----------------------------

TEST(CancelledOptimisationTest, AnswersTheBestDesignSoFarWithNoConvergence) {
  core::Progress progress;
  progress.Cancel();  // as DELETE /v1/jobs/{id} does while the job runs
  Context context;
  context.progress = &progress;
  context.batch = true;
  const Response r = Dispatch(
      {"POST", "/v1/optimize", Optimisation({{"starts", 4}, {"seed", 1}}).dump()}, context);
  ASSERT_EQ(r.status, 200) << r.body.dump();
  EXPECT_EQ(r.body["summary"]["termination"], "no_convergence");
  const std::string message = r.body["summary"]["message"];
  EXPECT_EQ(message.rfind("cancelled (", 0), 0u) << message;
  EXPECT_NE(message.find("the best design so far is kept"), std::string::npos) << message;
  // A design comes back: the bat in the request's form, inside the variables' bounds.
  const double taper_start = r.body["bat"]["three_segment"]["taper_start_m"];
  EXPECT_GE(taper_start, 0.1);
  EXPECT_LE(taper_start, 0.5);
  EXPECT_TRUE(r.body["objective_value"].is_number());
  // Later starts are not begun: one start ran.
  EXPECT_EQ(r.body["summary"]["spread"]["starts"], 1) << r.body["summary"].dump();
}

// A cancel between starts (or during one) leaves the multi-start unfinished: no_convergence even
// though the chosen start converged (without this the answer said "converged" after 3 of 64
// starts), with how many starts ran in the message.
TEST(CancelledOptimisationTest, ACancelAfterTheFirstStartIsNoConvergenceWithTheStartsRun) {
  core::Progress progress;
  std::thread canceller([&progress] {
    // The first start reports 1/64; bounded wait (10 s) in case the solve never reports.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (progress.Fraction() <= 0.0 && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    progress.Cancel();
  });
  Context context;
  context.progress = &progress;
  const Response r = Dispatch(
      {"POST", "/v1/optimize", Optimisation({{"starts", 64}, {"seed", 1}}).dump()}, context);
  canceller.join();
  ASSERT_EQ(r.status, 200) << r.body.dump();
  const Json& summary = r.body["summary"];
  EXPECT_EQ(summary["termination"], "no_convergence") << summary.dump();
  const int ran = summary["spread"]["starts"];
  EXPECT_GE(ran, 1);
  EXPECT_LT(ran, 64);  // the cancel came after the first of 64 starts, each tens of ms
  const std::string message = summary["message"];
  EXPECT_EQ(message.rfind("cancelled", 0), 0u) << message;
  EXPECT_NE(message.find("the best design so far is kept"), std::string::npos) << message;
  // The design is the chosen start's: inside the bounds, with its objective.
  const double taper_start = r.body["bat"]["three_segment"]["taper_start_m"];
  EXPECT_GE(taper_start, 0.1);
  EXPECT_LE(taper_start, 0.5);
  EXPECT_TRUE(r.body["objective_value"].is_number());
}

}  // namespace
}  // namespace jobs_api_test
}  // namespace sweetspot::api
