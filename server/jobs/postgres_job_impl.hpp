// PostgresJobService's state (server/jobs/postgres_job_service.hpp), shared by its source
// files: postgres_job_service.cpp (the api's calls, the schema, LISTEN), postgres_job_worker.cpp
// (claims, runs, leases, sweeps) and postgres_job_results.cpp (results in pieces, read back as
// the client takes them). Private to them.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <string_view>
#include <thread>
#include <utility>
#include <vector>

#include "core/progress.hpp"
#include "server/jobs/job_common.hpp"
#include "server/jobs/postgres_connection.hpp"
#include "server/jobs/postgres_job_service.hpp"

namespace sweetspot::server {

// How often an idle worker looks for queued jobs another replica submitted.
inline constexpr auto kPostgresPollInterval = std::chrono::milliseconds(200);
// How often expired leases and old results are swept.
inline constexpr auto kPostgresSweepInterval = std::chrono::seconds(1);

// The columns of a job's JSON, then the database's clock.
inline constexpr const char* kPostgresViewColumns =
    "id, state, progress, path, created_at, created_unix_s, started_unix_s, finished_unix_s, "
    "status, error, cancel_requested, resumes, " SWEETSPOT_NOW;

struct PostgresJobService::Impl {
  // A job this replica runs.
  struct Running {
    std::string id;
    core::Progress progress;                    // Shared with the runner.
    std::atomic<bool> cancel_requested{false};  // Seen in the database (or asked here).
    std::atomic<bool> lost{false};              // Another replica owns it now.
    std::atomic<bool> interrupted{false};       // Shutdown hands it back to the queue.
    std::atomic<bool> timed_out{false};         // Ran longer than max_time_s (the heartbeat).
    std::chrono::steady_clock::time_point started =
        std::chrono::steady_clock::now();  // When this replica claimed it.
    // The finishing statement's parameters, while its commit waits for the database.
    std::optional<std::pair<std::string, std::vector<pg::Param>>> unsaved;
    std::uint64_t chunks = 0;   // Result pieces written to the database by this run.
    bool keeps_pieces = false;  // The finishing statement names them (result_bytes).
  };
  // What a run produced (RunClaimed), for FinishStatement.
  struct RunOutcome {
    api::Response response;                      // The answer (or the error it became).
    bool threw = false;                          // The runner threw.
    std::optional<std::uint64_t> chunked_bytes;  // The answer is in the pieces: its bytes.
  };
  using Statement = std::pair<std::string, std::vector<pg::Param>>;

  Impl(std::string uri_in, JobConfig config_in, api::JobRunner runner_in,
       std::function<void(const std::string&)> log_in)
      : config(config_in),
        runner(std::move(runner_in)),
        log(std::move(log_in)),
        db(std::move(uri_in)),
        owner(pg::LeaseOwner()),
        random(SeededEngine()) {}

  bool Migrate(std::string* error);
  void Wake();
  void ListenLoop();
  void WorkerLoop();
  bool ClaimAndRun();
  // Claims the oldest queued job (or one whose lease expired): null when there is none.
  std::shared_ptr<Running> Claim(api::Request* inner);
  // Runs a claimed job's request and collects its answer (a streamed one into the result
  // pieces, past kResultChunkBytes), checked against max_result_bytes and the time limit.
  RunOutcome RunClaimed(Running& job, api::Request inner);
  // The statement that commits what the run became (none when another replica owns it).
  std::optional<Statement> FinishStatement(Running& job, RunOutcome run);
  // Commits `finish`, or leaves it to the heartbeat while the database is away.
  void Commit(const std::shared_ptr<Running>& job, std::optional<Statement> finish);
  // Writes piece `seq` of the running job's result; false (and *error) when it cannot (the
  // database is away, or another replica owns the job: `lost`).
  bool WriteChunk(Running& job, std::uint64_t seq, std::string_view bytes, std::string* error);
  void HeartbeatLoop();
  bool Renew(Running& job);
  void Sweep();
  bool Query(const std::string& sql, const std::vector<pg::Param>& params, pg::PgResult* out) const;
  void Report(const std::string& message) const;
  JobView ViewOf(const PGresult* result, int row) const;

  const JobConfig config;
  const api::JobRunner runner;
  const std::function<void(const std::string&)> log;
  mutable pg::Connections db;
  const std::string owner;

  mutable std::mutex mutex;
  std::condition_variable work_cv;       // `wakeups` moved, or stopping.
  std::uint64_t wakeups = 0;             // Bumped by a submit here or a NOTIFY from a replica.
  std::atomic<bool> listen_stop{false};  // Ends ListenLoop.
  std::thread listener;
  std::condition_variable idle_cv;  // A runner returned, or the grace ended.
  std::condition_variable beat_cv;  // The heartbeat must stop.
  std::map<std::string, std::shared_ptr<Running>> running;  // Claimed here, not yet committed.
  int busy = 0;                                             // Runners running.
  bool stopping = false;                      // Shutdown started: no claims, no submits.
  bool grace_ended = false;                   // EndGrace().
  bool heartbeat_stop = false;                // The workers are joined.
  mutable std::atomic<bool> reachable{true};  // For logging each outage once.
  std::mt19937_64 random;                     // Ids, under `mutex`.
  std::once_flag shutdown_once;
  std::vector<std::thread> workers;
  std::thread heartbeat;
};

}  // namespace sweetspot::server
