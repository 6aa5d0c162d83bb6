// JobManager: the jobs of one server process (api::JobService), run in a
// bounded worker pool, optionally kept in a JobStore (SQLite) so that they
// survive a restart. The job JSON and the handlers' contract are in
// api/job_service.hpp; replicas that share jobs use PostgresJobService
// (server/jobs/postgres_job_service.hpp) instead.
//
// Persistence (optional, JobPersistence::store): every state change is saved before it is visible
// (submit, start, finish, cancel, delete, eviction), so jobs and results survive a restart. At
// construction the manager loads the store: finished jobs come back with their results
// (keep_results_s and max_kept still apply); queued jobs are queued again; a job that was running
// when the process died (crash, SIGKILL) is re-queued and run from the start (safe: a jobbable
// request has no side effects and is a deterministic function of its body, seeds included; only a
// solve cut by a wall-time budget may end elsewhere, as it could on any run) up to max_resumes
// times, after which it is marked failed with "interrupted by a server restart: ..." (status 503,
// code Interrupted) so that a request that kills the server cannot crash it forever. Shutdown with
// a store keeps queued jobs queued and puts interrupted running ones back in the queue (state
// "queued", saved) for the next start; without a store they are cancelled.
//
// A job is done only once its result is saved: when the store cannot save it (e.g. "database or
// disk is full") the job is failed (503 Unavailable, the store's message) and saved as such, so
// it is neither shown done nor run again at the next start (if even that save fails, its row is
// deleted: the job is failed here until the process stops, and unknown after a restart).
//
// Limits (JobConfig): a result over max_result_bytes fails its job (413 TooBig). Results held
// in memory are bounded: with a store, results over kMaxLoadedResultBytes live in the store
// only and Result() reads them back (as the stored JSON text), and the small ones leave memory,
// oldest first, once they total more than max_results_memory_bytes; with no store, the oldest
// finished jobs are dropped (404) instead. A store that keeps pieces (SQLite) gets a streamed
// answer (a sweep; /v1/explore's json too, for a job) as it is produced: past kResultChunkBytes
// it is written in 1 MiB pieces, so a result is never whole in memory, running or read back
// (a piece at a time, as the client takes it). A job running longer than max_time_s has its cancel
// flag set (a watchdog thread) and ends failed (408 Timeout) naming the limit.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <random>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "api/job_service.hpp"
#include "api/response.hpp"
#include "api/router.hpp"
#include "core/progress.hpp"
#include "server/jobs/job_common.hpp"
#include "server/jobs/job_store.hpp"

namespace sweetspot::server {

/// Runs one inner request (see api/job_service.hpp).
using JobRunner = api::JobRunner;

/// Where a JobManager keeps its jobs across restarts. Default: nowhere (memory only).
struct JobPersistence {
  /// The store; not owned, must outlive the manager. Null: jobs live in memory only.
  JobStore* store = nullptr;
  /// Told every store failure after construction ("cannot save job ...: why"); may be
  /// empty. Called with the manager's lock held: it must not call the manager.
  std::function<void(const std::string& message)> on_store_error;
};

/// Queues, runs, reports and cancels jobs. Thread-safe; owns its worker
/// threads; no globals. Finished jobs are dropped lazily (checked on every
/// call) once older than keep_results_s or beyond max_kept; a dropped id 404s.
class JobManager final : public ServerJobService {
 public:
  /// Loads the jobs kept in persistence.store (if any; see the file comment),
  /// then starts config.workers threads. Throws std::invalid_argument when
  /// !config.Validate() (the message is its refusal's) or `runner` is empty, and
  /// std::runtime_error "cannot load the jobs: why" when the store cannot be read.
  JobManager(JobConfig config, JobRunner runner, JobPersistence persistence = {});
  /// Shutdown() with no grace period.
  ~JobManager();
  JobManager(const JobManager&) = delete;
  JobManager& operator=(const JobManager&) = delete;

  /// Queues `inner`: 202 with the job's JSON (state "queued"); 429 "TooBusy"
  /// when max_queued jobs already wait; 503 "ShuttingDown" after Shutdown().
  api::Response Submit(const api::Request& inner) override;

  /// 200 with the job's JSON; 404 "NotFound" for an unknown (or dropped) id.
  api::Response Status(const std::string& id) const override;

  /// 200 with {"jobs": [...], "total", "next_offset"}: the kept jobs in
  /// query.state (all if unset), newest submitted first, query.limit of them
  /// from query.offset (api::JobService::List).
  api::Response List(const api::JobListQuery& query) const override;

  /// The job's result. done or failed: the inner response verbatim (status,
  /// body, text, content type; a result kept in the store only comes back as its
  /// JSON text, content type application/json); a runner that threw gives 500
  /// "InternalError"; 503 "Unavailable" when the store cannot read it.
  /// cancelled: the runner's 2xx answer when it gave one after the cancel (an
  /// optimisation's best design so far), else 409 "Cancelled".
  /// queued or running: 409 "NotReady"; unknown: 404.
  api::Response Result(const std::string& id) const override;

  /// DELETE. queued: cancelled at once, 200 with the job (state "cancelled").
  /// running: asks the runner to stop (Progress::Cancel()), 202 with the job
  /// (state still "running", "cancel_requested": true); it turns "cancelled"
  /// when the runner returns. done/failed/cancelled: the job is deleted, 200
  /// with its last JSON plus "deleted": true (its id then 404s). Unknown: 404.
  api::Response Cancel(const std::string& id) override;

  /// Number of jobs in each state; always has the keys queued, running, done,
  /// failed and cancelled (for the Prometheus gauge).
  std::map<std::string, int> CountsByState() const override;

  /// Shutdown(0): stops at once.
  void Shutdown();

  /// Stops accepting jobs (503 ShuttingDown) and starting queued ones; waits up
  /// to `grace_s` seconds (or until EndGrace()) for the running jobs to finish,
  /// then asks the rest to stop (Progress::Cancel()) and joins the workers
  /// (promptly if the runners poll Cancelled()). With a store, queued and
  /// interrupted jobs are kept as "queued" for the next start; without one they
  /// are cancelled. Idempotent (later calls wait for the first); jobs stay
  /// readable afterwards.
  void Shutdown(double grace_s) override;

  /// Ends a running Shutdown's grace period now (e.g. on a second SIGTERM).
  /// Harmless before or after Shutdown.
  void EndGrace() override;

 private:
  using Clock = std::chrono::steady_clock;
  enum class State { kQueued, kRunning, kDone, kFailed, kCancelled };
  struct Job;

  static const char* StateName(State state);
  // 0 while queued, 1 when done, else the runner's last report.
  static double ProgressOf(const Job& job);
  // What a run produced (RunJob, outside the lock), for FinishRunLocked.
  struct RunOutcome {
    api::Response response;     // The answer (or the error it became).
    bool threw = false;         // The runner threw.
    bool answered = false;      // A 2xx answer.
    bool too_big = false;       // Over the result limit: response is the 413.
    bool memory_bound = false;  // No store: max_results_memory_bytes was the limit.
    std::size_t bytes = 0;      // The kept answer's bytes; 0 when none is kept.
    std::string serialized;     // A JSON answer serialised once (for the store), or "".
    std::uint64_t chunks = 0;   // Result pieces written to the store.
    std::optional<std::uint64_t> chunked_bytes;  // The answer is in the pieces: its bytes.
  };
  void WorkerLoop();
  // Runs the job's request and collects its answer (streamed to the store's pieces when it
  // keeps them), checked against the result limits. Without the lock.
  RunOutcome RunJob(Job& job, api::Request inner);
  // Makes the job cancelled, failed, done or queued again from `run`, saves it and keeps its
  // result (in memory or the store).
  void FinishRunLocked(const std::shared_ptr<Job>& job, RunOutcome run);
  // Deletes the result pieces of job `id` when `chunks` were written (a failure is reported).
  void DropChunksLocked(const std::string& id, std::uint64_t chunks) const;
  void WatchdogLoop();   // Sets the cancel flag of jobs running longer than max_time_s.
  void LoadFromStore();  // Before the workers start.
  double ToUnixSeconds(Clock::time_point time) const;
  Clock::time_point FromUnixSeconds(double unix_s) const;
  // The following require mutex_ to be held.
  void FinishLocked(Job& job, State state, Clock::time_point now);
  void EvictLocked(Clock::time_point now) const;
  // `serialized`: the result's JSON already serialised (moved from), or null/empty.
  JobRecord RecordLocked(const Job& job, std::string* serialized = nullptr) const;
  // False (reported, and the store's message in *why if non-null) when the store failed.
  bool SaveLocked(const Job& job, std::string* why = nullptr,
                  std::string* serialized = nullptr) const;
  // Counts a finished job's result of `bytes` in memory, or leaves it to the store (saved and
  // over kMaxLoadedResultBytes), then trims memory to max_results_memory_bytes.
  void KeepResultLocked(Job& job, std::size_t bytes, bool saved);
  // Uncounts the job's result in memory (it leaves memory or the job is dropped).
  void ForgetResultLocked(Job& job) const;
  // Moves the oldest results out of memory (into the store only) or, without a store, drops
  // the oldest finished jobs, until max_results_memory_bytes holds.
  void TrimMemoryLocked();
  void ForgetLocked(const std::string& id) const;
  std::shared_ptr<Job> FindLocked(const std::string& id) const;
  nlohmann::json ToJsonLocked(const Job& job, Clock::time_point now) const;
  std::string NewIdLocked();

  const JobConfig config_;
  const JobRunner runner_;
  const JobPersistence persistence_;
  const Clock::time_point start_;
  const std::chrono::system_clock::time_point wall_start_;  // The wall clock at start_.

  mutable std::mutex mutex_;
  std::condition_variable work_cv_;  // Signalled when queue_ grows or stopping_ is set.
  std::condition_variable idle_cv_;  // Signalled when a worker finishes a job or grace ends.
  // Jobs by id. Mutable: const readers drop expired finished jobs (lazy eviction).
  mutable std::unordered_map<std::string, std::shared_ptr<Job>> jobs_;
  std::deque<std::string> queue_;             // Queued ids, oldest first.
  mutable std::deque<std::string> finished_;  // Finished ids, oldest finished first.
  int busy_ = 0;                              // Workers running a job.
  bool stopping_ = false;                     // Set by Shutdown().
  bool grace_ended_ = false;                  // Set by EndGrace().
  std::mt19937_64 random_;                    // Id source, seeded from std::random_device.
  std::uint64_t next_seq_ = 0;                // The next job's Job::seq.
  // Bytes of the results held in memory, and their jobs' ids, oldest finished first (ids of
  // jobs dropped meanwhile are skipped).
  mutable std::size_t memory_results_bytes_ = 0;
  mutable std::deque<std::string> in_memory_;
  std::vector<std::shared_ptr<Job>> running_;  // For the watchdog.
  std::condition_variable watchdog_cv_;        // Signalled when a job starts or at the stop.
  bool watchdog_stop_ = false;                 // Set by Shutdown() once the workers are joined.
  std::thread watchdog_;

  std::once_flag shutdown_once_;
  std::vector<std::thread> workers_;
};

}  // namespace sweetspot::server
