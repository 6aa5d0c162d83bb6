// What both job services share (JobManager in one process, PostgresJobService
// across replicas): their limits (JobConfig), the job's JSON and the answers
// for unknown, unfinished and cancelled jobs, ids, and the time formats.
#pragma once

#include <nlohmann/json.hpp>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <string_view>

#include "api/job_service.hpp"
#include "api/response.hpp"
#include "core/refusal.hpp"
#include "server/jobs/job_store.hpp"

namespace sweetspot::server {

/// Limits of the job services, with their defaults.
struct JobConfig {
  int workers = 2;                 ///< Threads running jobs (per replica), in [1, 64].
  std::size_t max_queued = 64;     ///< Queued (not yet running) jobs; beyond: 429, [1, 1e6].
  std::size_t max_kept = 1000;     ///< Finished jobs kept, oldest finished dropped first, [1, 1e6].
  double keep_results_s = 3600.0;  ///< How long a finished job is kept after it finished, s (> 0).
  /// Times a job whose server died under it is run again, [0, 100]: at start-up
  /// (one process), or once its lease expires (PostgreSQL).
  int max_resumes = 2;
  /// PostgreSQL: how long a running job's claim lasts without renewal, s, [1, 3600]. The
  /// replica running it renews it every lease_s / 4 (at most every 0.5 s); a replica that
  /// died leaves its jobs to the others after this long.
  double lease_s = 10.0;
  /// The largest result a job may have, bytes, [1024, 1e12], with every store (SQLite,
  /// PostgreSQL, memory only; a result over kResultChunkBytes is stored in pieces as it is
  /// produced, so no column holds it whole). A larger result makes the job failed (status 413,
  /// code TooBig, as the contract pairs them) with its size and this limit in the message: never
  /// truncated; a streamed one is stopped as soon as it passes it.
  std::size_t max_result_bytes = 256u << 20;
  /// One process (JobManager): the finished jobs' results held in memory in total, bytes
  /// (serialised size), [1024, 1e12]. With a SQLite store, results larger than
  /// kMaxLoadedResultBytes live in the database only (read back on GET) and the oldest small
  /// ones leave memory first once the total is over this; with no store (memory only), the
  /// oldest finished jobs are dropped (their ids 404) until the rest fit, and a result larger
  /// than this alone fails its job like max_result_bytes.
  std::size_t max_results_memory_bytes = 256u << 20;
  /// The longest a job may run, s, (0, 1e6]: then its cancel flag is set and it ends failed
  /// (status 408, code Timeout) naming this limit. Per run: a job run again after a restart
  /// gets it afresh.
  double max_time_s = 600.0;

  /// True when every field is in range; otherwise the refusal in *refusal (if non-null): field,
  /// value and rule, its Message() "field = value: rule".
  bool Validate(core::Refusal* refusal) const;
};

/// A job service the server owns: the api's calls plus the server's stop.
class ServerJobService : public api::JobService {
 public:
  /// Stops accepting jobs (503 ShuttingDown) and starting queued ones; waits up
  /// to `grace_s` seconds (or until EndGrace()) for the running jobs to finish,
  /// then asks the rest to stop and joins the workers. Idempotent.
  virtual void Shutdown(double grace_s) = 0;
  /// Ends a running Shutdown's grace period now (e.g. on a second SIGTERM).
  virtual void EndGrace() = 0;
};

/// The fields of a job's JSON (api/job_service.hpp) as values.
struct JobView {
  std::string id;                        ///< 32 hex digits.
  std::string state;                     ///< "queued", "running", "done", "failed", "cancelled".
  double progress = 0.0;                 ///< 0..1.
  std::string path;                      ///< The inner request's path.
  double created_unix_s = 0.0;           ///< Submit time, s since the Unix epoch.
  std::optional<double> started_unix_s;  ///< Start (of the last run), s since the epoch.
  std::optional<double> finished_unix_s;  ///< Finish, s since the epoch.
  std::string created_at;                 ///< Submit time, ISO-8601 UTC.
  std::optional<int> status;             ///< Inner status once done or failed.
  std::optional<nlohmann::json> error;   ///< The error object once failed.
  bool cancel_requested = false;         ///< DELETE asked it to stop.
  int resumes = 0;                       ///< Times it was run again after its server died.
  std::optional<double> expires_in_s;    ///< Until a finished job is dropped, s.
};

/// The job's JSON (api/job_service.hpp): its times absolute (created_at, started_at,
/// finished_at: ISO-8601 UTC) and relative to its submit (created_s = 0, started_s,
/// finished_s: s after created_at, never negative, rounded to microseconds), never relative to
/// a process's start, so they read the same after a restart and from every replica.
nlohmann::json JobJson(const JobView& job);

/// 404 NotFound "no job with id ...".
api::Response JobNotFound(const std::string& id);
/// 409 NotReady for a queued or running job's result.
api::Response JobNotReady(const std::string& id, const std::string& state);
/// 409 Cancelled for a cancelled job's result.
api::Response JobWasCancelled(const std::string& id);
/// 503 Interrupted: the job's server died under it more than max_resumes times;
/// its message in *message.
api::Response JobInterrupted(int resumes, int max_resumes, std::string* message);
/// The message of JobInterrupted with `resumes` spelled as given (e.g. "%s" for a template).
std::string InterruptedMessage(const std::string& resumes, int max_resumes);

/// 408 Timeout: the job ran longer than max_time_s = `max_time_s` s and was stopped.
api::Response JobTimedOut(double max_time_s);
/// 413 TooBig: "the job's result is [at least ]`size` bytes, more than `keeper` keeps (`limit`
/// = `value`): ... raise `flag`" (e.g. "the jobs database", "max_result_bytes",
/// "--job-max-result-bytes"); "at least" when `stopped`: its producer was stopped there.
api::Response JobResultTooBig(std::size_t size, const std::string& keeper, const std::string& limit,
                              std::size_t value, const std::string& flag, bool stopped = false);

/// The answer of a job whose streamed answer stopped before its end (StreamOutcome::kStopped):
/// never the rows made so far (docs/api.md, "A sweep that does not finish"). `cancelled` (its
/// cancel flag: DELETE, the time limit, a shutdown): 409 Cancelled; otherwise the sweep itself
/// failed (out of memory): 503 Unavailable.
api::Response IncompleteStreamAnswer(bool cancelled);

/// What CollectJobStream did.
enum class StreamOutcome {
  kComplete,     ///< The producer ran to its end: the whole body is in text or written.
  kOverLimit,    ///< More than the limit arrived: the producer was told to stop.
  kStopped,      ///< The producer stopped by itself (cancelled): the body is incomplete.
  kWriteFailed,  ///< A piece could not be written (CollectedStream::write_error): stopped.
};

/// Receives piece `seq` (0, 1, ...; kResultChunkBytes each but the last) of a result as it is
/// produced; false with *error when it cannot keep it (the producer is then stopped).
using ResultChunkWriter =
    std::function<bool(std::uint64_t seq, std::string_view bytes, std::string* error)>;

/// What CollectJobStream produced.
struct CollectedStream {
  StreamOutcome outcome = StreamOutcome::kComplete;  ///< How the producer ended.
  std::size_t bytes = 0;     ///< Bytes produced (up to the first chunk over the limit).
  bool chunked = false;      ///< The body went to the writer in pieces; text is empty.
  std::uint64_t pieces = 0;  ///< Pieces written.
  std::string write_error;   ///< The writer's message (kWriteFailed).
};

/// Runs a streamed answer's producer (Response::stream, e.g. a sweep) into response->text, at
/// most `max_bytes` of it: the chunk that goes over makes the sink refuse, which stops the
/// sweep at once instead of after it built the whole body. With `write`, a body that grows
/// past kResultChunkBytes is handed to it in pieces of that size as it is produced (text then
/// holds less than one piece at a time and is empty at the end, `chunked`): never whole in
/// memory. Clears stream. Without a stream: kComplete and text.size().
CollectedStream CollectJobStream(api::Response* response, std::size_t max_bytes,
                                 const ResultChunkWriter& write = nullptr);

/// A result the job services keep, from a streamed JSON answer (content type application/json,
/// in text): in pieces (`chunked`), its content type becomes "" (the pieces are the JSON text,
/// as a store keeps a JSON body); whole and at most kResultChunkBytes, it becomes its parsed
/// body again (stored and sent as any JSON answer: the same bytes); larger (a store without
/// pieces, or none), it stays text, ended by the newline the server ends JSON answers with.
/// Returns false (and leaves it) when a text to parse is not JSON.
bool NormalizeJsonResult(api::Response* response, bool chunked);

/// The quoted id for messages ("\"abc\"", cut when long, control characters escaped).
std::string QuoteJobId(const std::string& id);
/// "2024-05-01T12:00:00.123Z".
std::string IsoUtc(std::chrono::system_clock::time_point time);
/// IsoUtc of `unix_s` seconds since the Unix epoch.
std::string IsoUtcOfUnixSeconds(double unix_s);
/// A JSON body serialised for a store; never throws (invalid UTF-8 is replaced).
std::string SerializeJobBody(const nlohmann::json& body);
/// The failure's message of an inner response: its "message", else its status.
std::string FailureMessage(const api::Response& response);
/// The error object of a failed job whose inner response is `response`
/// (api::JobErrorObject of its status, body and FailureMessage).
nlohmann::json FailureObject(const api::Response& response);
/// A failed job's error object as a store keeps it (compact JSON text).
std::string StoredJobError(const nlohmann::json& error);
/// A failed job's error object read back from a store: `stored` when it is an
/// error object's JSON (rows written since errors are objects), else the bare
/// message of an older row wrapped by api::JobErrorObject(status, body, stored)
/// (`body`: the stored inner answer if at hand, else null).
nlohmann::json ReadStoredJobError(const std::string& stored, int status,
                                  const nlohmann::json& body = nullptr);
/// An engine seeded from std::random_device with 256 bits.
std::mt19937_64 SeededEngine();
/// A new id: 32 lowercase hex digits (128 random bits).
std::string NewJobId(std::mt19937_64& random);

}  // namespace sweetspot::server
