// Jobs: long requests run in a bounded worker pool, polled and cancelled by id
// (POST /v1/jobs, GET /v1/jobs/{id}, GET /v1/jobs/{id}/result,
// DELETE /v1/jobs/{id}). HTTP-agnostic like the rest of the api layer: the
// manager runs an inner Request through a JobRunner (in the service, the
// router's Dispatch) and answers with Responses in the contract's envelope.
//
// States (the contract's five): queued -> running -> done | failed | cancelled;
// queued -> cancelled. A job's JSON:
//   {"id":          32 lowercase hex digits (128 random bits),
//    "state":       "queued" | "running" | "done" | "failed" | "cancelled",
//    "progress":    0..1 (0 while queued, the runner's reports while running,
//                   1 when done, frozen at the last report when failed/cancelled),
//    "path":        the inner request's path,
//    "created_s", "started_s", "finished_s":
//                   seconds since the manager started (steady clock, so differences
//                   are durations); null until the event happened,
//    "created_at":  wall-clock submit time, ISO-8601 UTC ("2024-05-01T12:00:00.123Z"),
//    "status":      the inner HTTP status once done or failed, else null,
//    "error":       the failure's message once failed, else null,
//    "cancel_requested": true once DELETE (or Shutdown) asked the job to stop,
//    "expires_in_s": seconds until a finished job's result is dropped (at most;
//                   count eviction may drop it sooner), null while unfinished}
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <random>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "api/response.hpp"
#include "api/router.hpp"
#include "core/progress.hpp"

namespace sweetspot::api {

/// Limits of a JobManager, with their defaults.
struct JobConfig {
  int workers = 2;                 ///< Threads running jobs, in [1, 64].
  std::size_t max_queued = 64;     ///< Queued (not yet running) jobs; beyond: 429, [1, 1e6].
  std::size_t max_kept = 1000;     ///< Finished jobs kept, oldest finished dropped first, [1, 1e6].
  double keep_results_s = 3600.0;  ///< How long a finished job is kept after it finished, s (> 0).

  /// True when every field is in range; otherwise "field = value: rule" in *why (if non-null).
  bool IsValid(std::string* why) const;
};

/// Runs one inner request. Called on a worker thread, concurrently with other
/// calls (must be thread-safe). Long work polls progress->Cancelled() and
/// returns soon after it turns true (its result is then discarded), and may
/// call progress->Report(fraction). A 2xx response makes the job done, any
/// other status failed; an exception makes it failed with "internal error".
using JobRunner = std::function<Response(const Request& inner, core::Progress* progress)>;

/// Queues, runs, reports and cancels jobs. Thread-safe; owns its worker
/// threads; no globals. Finished jobs are dropped lazily (checked on every
/// call) once older than keep_results_s or beyond max_kept; a dropped id 404s.
class JobManager {
 public:
  /// Starts config.workers threads. Throws std::invalid_argument when
  /// !config.IsValid() (the message is IsValid's) or `runner` is empty.
  JobManager(JobConfig config, JobRunner runner);
  /// Shutdown(): cancels queued and running jobs and joins the workers.
  ~JobManager();
  JobManager(const JobManager&) = delete;
  JobManager& operator=(const JobManager&) = delete;

  /// Queues `inner`: 202 with the job's JSON (state "queued"); 429 "TooBusy"
  /// when max_queued jobs already wait; 503 "ShuttingDown" after Shutdown().
  Response Submit(const Request& inner);

  /// 200 with the job's JSON; 404 "NotFound" for an unknown (or dropped) id.
  Response Status(const std::string& id) const;

  /// The job's result. done or failed: the inner response verbatim (status,
  /// body, text, content type); a runner that threw gives 500 "InternalError".
  /// queued or running: 409 "NotReady"; cancelled: 409 "Cancelled"; unknown: 404.
  Response Result(const std::string& id) const;

  /// DELETE. queued: cancelled at once, 200 with the job (state "cancelled").
  /// running: asks the runner to stop (Progress::Cancel()), 202 with the job
  /// (state still "running", "cancel_requested": true); it turns "cancelled"
  /// when the runner returns. done/failed/cancelled: the job is deleted, 200
  /// with its last JSON plus "deleted": true (its id then 404s). Unknown: 404.
  Response Cancel(const std::string& id);

  /// Number of jobs in each state; always has the keys queued, running, done,
  /// failed and cancelled (for the Prometheus gauge).
  std::map<std::string, int> CountsByState() const;

  /// Stops accepting jobs, cancels queued and running ones and joins the
  /// workers (promptly if the runners poll Cancelled()). Idempotent; jobs stay
  /// readable afterwards.
  void Shutdown();

 private:
  using Clock = std::chrono::steady_clock;
  enum class State { kQueued, kRunning, kDone, kFailed, kCancelled };
  struct Job;

  static const char* StateName(State state);
  void WorkerLoop();
  // The following require mutex_ to be held.
  void FinishLocked(Job& job, State state, Clock::time_point now);
  void EvictLocked(Clock::time_point now) const;
  std::shared_ptr<Job> FindLocked(const std::string& id) const;
  nlohmann::json ToJsonLocked(const Job& job, Clock::time_point now) const;
  std::string NewIdLocked();

  const JobConfig config_;
  const JobRunner runner_;
  const Clock::time_point start_;

  mutable std::mutex mutex_;
  std::condition_variable work_cv_;  // Signalled when queue_ grows or stopping_ is set.
  // Jobs by id. Mutable: const readers drop expired finished jobs (lazy eviction).
  mutable std::unordered_map<std::string, std::shared_ptr<Job>> jobs_;
  std::deque<std::string> queue_;             // Queued ids, oldest first.
  mutable std::deque<std::string> finished_;  // Finished ids, oldest finished first.
  int busy_ = 0;                              // Workers running a job.
  bool stopping_ = false;                     // Set by Shutdown().
  std::mt19937_64 random_;                    // Id source, seeded from std::random_device.

  std::once_flag shutdown_once_;
  std::vector<std::thread> workers_;
};

}  // namespace sweetspot::api
