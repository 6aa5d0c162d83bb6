// PostgresJobService: one job store and one queue for every replica, in a
// PostgreSQL database (libpq). Any replica accepts, lists, shows, cancels and
// returns the result of any job; the replicas' workers share the queue.
//
// - Queue: a worker claims the oldest queued job with
//   `SELECT ... FOR UPDATE SKIP LOCKED` (so two replicas never take the same
//   job and never wait on each other) and holds a lease on it
//   (JobConfig::lease_s) that its replica renews every lease_s / 4, at most
//   every 0.5 s, together with the job's progress. A submit wakes the idle
//   workers of every replica (NOTIFY sweetspot_jobs, which each replica LISTENs
//   to); besides, idle workers look for work every 0.2 s.
// - A replica that dies (SIGKILL, lost machine) stops renewing: once the lease
//   has expired, another replica claims the job again and runs it from the start
//   (safe: a jobbable request is a deterministic function of its body), up to
//   JobConfig::max_resumes times; after that the job is failed with status 503,
//   code Interrupted.
// - Cancel: DELETE sets cancel_requested in the database and notifies
//   sweetspot_cancel; the replica running the job stops its runner on the
//   notice, or at its next renewal (within 0.5 s) if the notice was lost.
// - Schema: created and migrated by the server at start, inside a transaction
//   holding a PostgreSQL advisory lock, so replicas starting at once apply each
//   migration once; versions are rows of sweetspot_schema_migrations. A
//   database with a newer schema than this server knows is refused.
// - The database going away: every request that needs it answers 503
//   Unavailable (the server adds Retry-After: 1); connections are re-made on
//   the next request; a job that finished while the database was away keeps
//   its result in memory (and its lease renewed) until the commit succeeds.
// - Results: one over kResultChunkBytes (a streamed sweep) is written to
//   sweetspot_job_result_chunks in 1 MiB pieces as it is produced (only while this
//   replica holds the job's lease), the job's row naming its length (result_bytes);
//   smaller ones are stored with the row. Every result is read back as the client
//   takes it (GET .../result holds a piece at a time, never the whole). One larger
//   than JobConfig::max_result_bytes fails the job with status 413, code TooBig,
//   and its size in the message: never truncated.
// - Shutdown: no new claims; running jobs get the grace period; those still
//   running then are handed back to the queue (state queued, no resume
//   counted) for another replica or the next start.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>

#include "server/jobs/job_common.hpp"

namespace sweetspot::server {

/// True when `text` is a PostgreSQL connection URI ("postgresql://" or "postgres://").
bool IsPostgresUri(const std::string& text);

/// `uri` with its password (if any) replaced by "***", for messages and logs.
std::string RedactedUri(const std::string& uri);

/// The jobs of every replica in one PostgreSQL database. Thread-safe.
class PostgresJobService final : public ServerJobService {
 public:
  /// Connects to `uri` (a libpq URI; connect_timeout defaults to 3 s), creates or
  /// migrates the schema, and starts config.workers worker threads plus one
  /// thread renewing leases. Null with "jobs database <uri without password>: why"
  /// in *error when the configuration is invalid, the database cannot be reached,
  /// or its schema is newer than this server's. `log` receives store failures
  /// after start (may be empty; called from any thread).
  static std::unique_ptr<PostgresJobService> Open(const std::string& uri, const JobConfig& config,
                                                  api::JobRunner runner,
                                                  std::function<void(const std::string&)> log,
                                                  std::string* error);
  /// Shutdown(0).
  ~PostgresJobService() override;
  PostgresJobService(const PostgresJobService&) = delete;
  PostgresJobService& operator=(const PostgresJobService&) = delete;

  /// See api::JobService; 503 Unavailable when the database cannot be reached.
  api::Response Submit(const api::Request& inner) override;
  api::Response Status(const std::string& id) const override;
  /// Newest submitted first (by the database's submit order), filtered and paged in SQL.
  api::Response List(const api::JobListQuery& query) const override;
  api::Response Result(const std::string& id) const override;
  api::Response Cancel(const std::string& id) override;
  std::map<std::string, int> CountsByState() const override;

  /// Stops claiming, waits up to grace_s (or EndGrace) for running jobs, then
  /// stops the rest and hands them back to the queue. Idempotent.
  void Shutdown(double grace_s) override;
  void EndGrace() override;

  /// The schema version this server creates and understands.
  static int SchemaVersion();

 private:
  struct Impl;
  explicit PostgresJobService(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace sweetspot::server
