// What the job handlers (POST /v1/jobs, GET /v1/jobs, GET /v1/jobs/{id},
// GET /v1/jobs/{id}/result, DELETE /v1/jobs/{id}) call: an interface the api
// layer defines and the server implements, because threads and databases
// belong to the server (server/jobs/: JobManager in one process with an
// optional SQLite store, PostgresJobService shared by every replica).
//
// States (the contract's five): queued -> running -> done | failed | cancelled;
// queued -> cancelled. A job's JSON:
//   {"id":          32 lowercase hex digits (128 random bits),
//    "state":       "queued" | "running" | "done" | "failed" | "cancelled",
//    "progress":    0..1 (0 while queued, the runner's reports while running,
//                   1 when done, frozen at the last report when failed/cancelled),
//    "path":        the inner request's path,
//    "created_at", "started_at", "finished_at":
//                   wall-clock times, ISO-8601 UTC ("2024-05-01T12:00:00.123Z"): the submit,
//                   the start of the last run, the finish; null until the event happened,
//    "created_s", "started_s", "finished_s":
//                   the same times in seconds after the submit (created_s is 0; started_s
//                   the wait in the queue), never relative to a process's start, so they
//                   read the same after a restart and from every replica; null until then,
//    "status":      the inner HTTP status once done or failed (or cancelled
//                   with a kept result), else null,
//    "error":       once failed, the error object the inner request answered
//                   ({"code", "message", "field"}, as the synchronous endpoint
//                   returns it), else null,
//    "cancel_requested": true once DELETE (or a shutdown without a store) asked
//                   the job to stop,
//    "resumes":     times the job was run again because the server running it died,
//    "expires_in_s": seconds until a finished job's result is dropped (at most;
//                   count eviction may drop it sooner), null while unfinished}
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "api/response.hpp"
#include "api/router.hpp"
#include "core/progress.hpp"

namespace sweetspot::api {

/// Runs one inner request. Called on a worker thread, concurrently with other
/// calls (must be thread-safe). Long work polls progress->Cancelled() and
/// returns soon after it turns true (a 2xx result is then kept with the
/// cancelled job, anything else discarded), and may
/// call progress->Report(fraction). A 2xx response makes the job done, any
/// other status failed; an exception makes it failed with "internal error".
/// It may answer with Response::stream: the job service then runs the producer
/// on the same thread, stops it past its result limit, and takes a producer that
/// returns false (cancelled) as no answer.
using JobRunner = std::function<Response(const Request& inner, core::Progress* progress)>;

/// GET /v1/jobs's query, validated by the handler (HandleJobList).
struct JobListQuery {
  std::optional<std::string> state;  ///< Only jobs in this state (one of the five); all if empty.
  std::size_t limit = 100;           ///< Most jobs on the page (1..ApiLimits::max_jobs_page).
  std::size_t offset = 0;            ///< Jobs skipped first, in the list's order (newest first).
};

/// A job's failure as the error object {"code", "message", "field"} of the
/// contract's envelope: `body`'s code, message and field when it is one (the
/// inner request's error answer), else {"code": InternalError for a status
/// >= 500 or without one, else InvalidValue; "message": `message`; "field": null}
/// (jobs stored before errors were objects kept only the message).
nlohmann::json JobErrorObject(int status, const nlohmann::json& body, const std::string& message);

/// Accepts, shows, lists, cancels and returns the results of jobs. Every call
/// answers with a Response in the contract's envelope and never throws;
/// implementations are thread-safe.
class JobService {
 public:
  virtual ~JobService() = default;

  /// Queues `inner`: 202 with the job's JSON (state "queued"); 429 "TooBusy"
  /// when the queue is full; 503 "ShuttingDown" once the server stops; 503
  /// "Unavailable" (with Retry-After) when the job store cannot be reached.
  virtual Response Submit(const Request& inner) = 0;

  /// 200 with the job's JSON; 404 "NotFound" for an unknown (or dropped) id.
  virtual Response Status(const std::string& id) const = 0;

  /// GET /v1/jobs: 200 with {"jobs": [job JSON, ...], "total": jobs matching the
  /// filter, "next_offset": the offset of the next page, or null on the last}:
  /// newest submitted first, `query.state` only if set, `query.limit` jobs from
  /// `query.offset`.
  virtual Response List(const JobListQuery& query) const = 0;

  /// The job's result. done or failed: the inner response verbatim (status,
  /// body, text, content type); a runner that threw gives 500 "InternalError".
  /// cancelled: the inner 2xx response when the runner still gave one (an
  /// optimisation keeps its best design so far, termination no_convergence),
  /// else 409 "Cancelled". queued or running: 409 "NotReady"; unknown: 404.
  virtual Response Result(const std::string& id) const = 0;

  /// DELETE. queued: cancelled at once, 200 with the job (state "cancelled").
  /// running: asks the runner to stop, 202 with the job (state still
  /// "running", "cancel_requested": true); it turns "cancelled" when the
  /// runner returns. done/failed/cancelled: the job is deleted, 200 with its
  /// last JSON plus "deleted": true (its id then 404s). Unknown: 404.
  virtual Response Cancel(const std::string& id) = 0;

  /// Number of jobs in each state; always has the keys queued, running, done,
  /// failed and cancelled (for the Prometheus gauge). Empty when the store
  /// cannot be reached.
  virtual std::map<std::string, int> CountsByState() const = 0;
};

}  // namespace sweetspot::api
