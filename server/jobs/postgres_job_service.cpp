#include "server/jobs/postgres_job_service.hpp"

#include <libpq-fe.h>
#include <poll.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <utility>

#include "api/json_reader.hpp"
#include "server/jobs/postgres_job_impl.hpp"

namespace sweetspot::server {
using namespace pg;  // NOLINT: this file is left out of the unity build (server/CMakeLists.txt).
namespace {

using Clock = std::chrono::steady_clock;

// Serialises migrations of replicas starting at once (any constant unique to us).
constexpr long long kMigrationLockKey = 7305861723461;
// The schema, one migration per version; never edit a released one, add one.
const char* const kMigrations[] = {
    // 1: the jobs, their results, and the queue's lease.
    R"sql(
CREATE TABLE sweetspot_jobs (
  seq bigserial UNIQUE,
  id text PRIMARY KEY,
  state text NOT NULL CHECK (state IN ('queued', 'running', 'done', 'failed', 'cancelled')),
  method text NOT NULL,
  path text NOT NULL,
  body text NOT NULL DEFAULT '',
  progress double precision NOT NULL DEFAULT 0,
  cancel_requested boolean NOT NULL DEFAULT false,
  resumes integer NOT NULL DEFAULT 0,
  created_at text NOT NULL,
  created_unix_s double precision NOT NULL,
  started_unix_s double precision,
  finished_unix_s double precision,
  status integer NOT NULL DEFAULT 0,
  response_json text NOT NULL DEFAULT '',
  response_text text NOT NULL DEFAULT '',
  content_type text NOT NULL DEFAULT '',
  error text NOT NULL DEFAULT '',
  lease_owner text,
  lease_expires_unix_s double precision
);
CREATE INDEX sweetspot_jobs_by_state ON sweetspot_jobs (state, seq);
CREATE INDEX sweetspot_jobs_finished ON sweetspot_jobs (finished_unix_s)
  WHERE finished_unix_s IS NOT NULL;
)sql",
    // 2: a result over kResultChunkBytes in pieces, written while its job runs (result_bytes
    // says how long it is; NULL: in response_json/response_text). Stored uncompressed: a piece
    // is written once and read back whole, without decompression's CPU.
    R"sql(
ALTER TABLE sweetspot_jobs ADD COLUMN result_bytes bigint;
CREATE TABLE sweetspot_job_result_chunks (
  id text NOT NULL REFERENCES sweetspot_jobs (id) ON DELETE CASCADE,
  seq bigint NOT NULL,
  data bytea NOT NULL,
  PRIMARY KEY (id, seq)
);
ALTER TABLE sweetspot_job_result_chunks ALTER COLUMN data SET STORAGE EXTERNAL;
)sql",
};
constexpr int kSchemaVersion = static_cast<int>(sizeof(kMigrations) / sizeof(kMigrations[0]));

}  // namespace

std::string RedactedUri(const std::string& uri) {
  const auto scheme = uri.find("://");
  if (scheme == std::string::npos) return uri;
  const auto at = uri.find('@', scheme + 3);
  if (at == std::string::npos) return uri;
  const auto colon = uri.find(':', scheme + 3);
  if (colon == std::string::npos || colon > at) return uri;
  return uri.substr(0, colon + 1) + "***" + uri.substr(at);
}

bool IsPostgresUri(const std::string& text) {
  return text.rfind("postgresql://", 0) == 0 || text.rfind("postgres://", 0) == 0;
}

void PostgresJobService::Impl::Report(const std::string& message) const {
  if (log) log(message);
}

bool PostgresJobService::Impl::Query(const std::string& sql, const std::vector<Param>& params,
                                     PgResult* out) const {
  std::string error;
  if (db.Run(sql, params, out, &error)) {
    if (!reachable.exchange(true)) Report("reachable again");
    return true;
  }
  if (reachable.exchange(false)) Report("cannot be used: " + error);
  return false;
}

bool PostgresJobService::Impl::Migrate(std::string* error) {
  return db.Transaction(
      [this](PGconn* connection, std::string* why) {
        auto exec = [&](const std::string& sql, PgResult* out = nullptr) {
          return Execute(connection, sql, {}, out, why);
        };
        PgResult current(nullptr, &PQclear);
        if (!exec("SELECT pg_advisory_xact_lock(" + std::to_string(kMigrationLockKey) + ")") ||
            !exec("CREATE TABLE IF NOT EXISTS sweetspot_schema_migrations ("
                  "version integer PRIMARY KEY, applied_at timestamptz NOT NULL DEFAULT now(), "
                  "applied_by text NOT NULL)") ||
            !exec("SELECT coalesce(max(version), 0) FROM sweetspot_schema_migrations", &current)) {
          return false;
        }
        const int version = std::atoi(PQgetvalue(current.get(), 0, 0));
        if (version > kSchemaVersion) {
          *why = "its schema is at version " + std::to_string(version) +
                 ", newer than this server's " + std::to_string(kSchemaVersion) +
                 ": run a newer sweetspot-server";
          return false;
        }
        for (int next = version + 1; next <= kSchemaVersion; ++next) {
          if (!exec(kMigrations[next - 1])) return false;
          if (!Execute(connection,
                       "INSERT INTO sweetspot_schema_migrations (version, applied_by) VALUES (" +
                           std::to_string(next) + ", $1)",
                       {owner}, nullptr, why)) {
            return false;
          }
          Report("applied schema migration " + std::to_string(next));
        }
        return true;
      },
      error);
}

JobView PostgresJobService::Impl::ViewOf(const PGresult* result, int row) const {
  const double db_now = Number(result, row, 12);
  JobView view;
  view.id = Text(result, row, 0);
  view.state = Text(result, row, 1);
  view.progress = Number(result, row, 2);
  view.path = Text(result, row, 3);
  view.created_at = Text(result, row, 4);
  view.created_unix_s = Number(result, row, 5);
  view.started_unix_s = OptionalNumber(result, row, 6);
  if (auto finished = OptionalNumber(result, row, 7)) {
    view.finished_unix_s = *finished;
    view.expires_in_s = config.keep_results_s - (db_now - *finished);
  }
  const int status = std::atoi(PQgetvalue(result, row, 8));
  // A cancelled job shows its status when it kept the runner's 2xx answer.
  if (view.state == "done" || view.state == "failed" ||
      (view.state == "cancelled" && status >= 200 && status < 300)) {
    view.status = status;
  }
  if (view.state == "failed") view.error = ReadStoredJobError(Text(result, row, 9), status);
  view.cancel_requested = Text(result, row, 10) == "t";
  view.resumes = std::atoi(PQgetvalue(result, row, 11));
  return view;
}

void PostgresJobService::Impl::Wake() {
  {
    std::lock_guard lock(mutex);
    ++wakeups;
  }
  work_cv.notify_all();
}

void PostgresJobService::Impl::ListenLoop() {
  // Another replica's submit wakes this replica's idle workers at once (LISTEN /
  // NOTIFY); without it they would find the job at their next poll.
  PGconn* connection = nullptr;
  while (!listen_stop) {
    if (connection == nullptr) {
      std::string ignored;
      connection = db.Connect(&ignored);
      if (connection != nullptr) {
        PgResult listening(PQexec(connection, "LISTEN sweetspot_jobs; LISTEN sweetspot_cancel"),
                           &PQclear);
        if (!listening || PQresultStatus(listening.get()) != PGRES_COMMAND_OK) {
          PQfinish(connection);
          connection = nullptr;
        }
      }
      if (connection == nullptr) {  // Away: the workers poll meanwhile.
        std::this_thread::sleep_for(std::chrono::milliseconds(200));
        continue;
      }
      Wake();  // Jobs may have been queued while it was away.
    }
    pollfd ready{PQsocket(connection), POLLIN, 0};
    if (poll(&ready, 1, 200) < 0 || !PQconsumeInput(connection)) {
      PQfinish(connection);
      connection = nullptr;
      continue;
    }
    bool notified = false;
    while (PGnotify* notice = PQnotifies(connection)) {
      if (std::string(notice->relname) == "sweetspot_cancel") {
        // A DELETE on some replica: stop the job now if it runs here (the next
        // lease renewal would see the flag too, within 0.5 s).
        std::lock_guard lock(mutex);
        const auto it = running.find(notice->extra);
        if (it != running.end()) {
          it->second->cancel_requested = true;
          it->second->progress.Cancel();
        }
      } else {
        notified = true;
      }
      PQfreemem(notice);
    }
    if (notified) Wake();
  }
  PQfinish(connection);
}

PostgresJobService::PostgresJobService(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::unique_ptr<PostgresJobService> PostgresJobService::Open(
    const std::string& uri, const JobConfig& config, api::JobRunner runner,
    std::function<void(const std::string&)> log, std::string* error) {
  auto fail = [&](const std::string& why) -> std::unique_ptr<PostgresJobService> {
    if (error != nullptr) *error = "jobs database " + RedactedUri(uri) + ": " + why;
    return nullptr;
  };
  std::string why;
  if (!IsPostgresUri(uri)) return fail("not a postgresql:// URI");
  if (core::Refusal refused; !config.Validate(&refused))
    return fail("invalid JobConfig: " + refused.Message());
  if (!runner) return fail("the runner is empty");
  auto impl = std::make_unique<Impl>(uri, config, std::move(runner), std::move(log));
  if (!impl->Migrate(&why)) return fail(why);
  std::unique_ptr<PostgresJobService> service(new PostgresJobService(std::move(impl)));
  Impl& self = *service->impl_;
  for (int i = 0; i < config.workers; ++i) self.workers.emplace_back([&self] { self.WorkerLoop(); });
  self.heartbeat = std::thread([&self] { self.HeartbeatLoop(); });
  self.listener = std::thread([&self] { self.ListenLoop(); });
  return service;
}

PostgresJobService::~PostgresJobService() { Shutdown(0.0); }

int PostgresJobService::SchemaVersion() { return kSchemaVersion; }

api::Response PostgresJobService::Submit(const api::Request& inner) {
  Impl& self = *impl_;
  std::string id;
  {
    std::lock_guard lock(self.mutex);
    if (self.stopping) {
      return api::ToResponse(api::ApiError{503, api::ErrorCode::kShuttingDown,
                                           "the server is shutting down and accepts no new jobs",
                                           ""});
    }
    id = NewJobId(self.random);
  }
  const double created_unix_s =
      std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  PgResult inserted(nullptr, &PQclear);
  if (!self.Query(std::string("INSERT INTO sweetspot_jobs (id, state, method, path, body, "
                              "created_at, created_unix_s) SELECT $1, 'queued', $2, $3, $4, $5, "
                              "$6 WHERE (SELECT count(*) FROM sweetspot_jobs WHERE state = "
                              "'queued') < $7 ON CONFLICT (id) DO NOTHING RETURNING ") +
                      kPostgresViewColumns,
                  {id, inner.method, inner.path, inner.body, IsoUtc(std::chrono::system_clock::now()),
                   Decimal(created_unix_s), std::to_string(self.config.max_queued)},
                  &inserted)) {
    return Unavailable();
  }
  if (PQntuples(inserted.get()) == 0) {
    // Either the queue is full, or a retried insert had already landed.
    PgResult found(nullptr, &PQclear);
    if (!self.Query(std::string("SELECT ") + kPostgresViewColumns + " FROM sweetspot_jobs WHERE id = $1",
                    {id}, &found)) {
      return Unavailable();
    }
    if (PQntuples(found.get()) == 0) {
      PgResult queued(nullptr, &PQclear);
      if (!self.Query("SELECT count(*) FROM sweetspot_jobs WHERE state = 'queued'", {}, &queued)) {
        return Unavailable();
      }
      return api::ToResponse(api::ApiError{429, api::ErrorCode::kTooBusy,
                                           "job queue is full: " + Text(queued.get(), 0, 0) +
                                               " jobs queued on all replicas (limit max_queued = " +
                                               std::to_string(self.config.max_queued) +
                                               "); retry later",
                                           ""});
    }
    inserted = std::move(found);
  }
  PgResult notified(nullptr, &PQclear);  // Wakes the other replicas' idle workers.
  self.Query("SELECT pg_notify('sweetspot_jobs', '')", {}, &notified);
  self.Wake();
  return {202, JobJson(self.ViewOf(inserted.get(), 0))};
}

api::Response PostgresJobService::Status(const std::string& id) const {
  const Impl& self = *impl_;
  PgResult found(nullptr, &PQclear);
  if (!self.Query(std::string("SELECT ") + kPostgresViewColumns +
                      " FROM sweetspot_jobs WHERE id = $1 AND (finished_unix_s IS NULL OR "
                      "finished_unix_s > " SWEETSPOT_NOW " - $2)",
                  {id, Decimal(self.config.keep_results_s)}, &found)) {
    return Unavailable();
  }
  if (PQntuples(found.get()) == 0) return JobNotFound(id);
  return {200, JobJson(self.ViewOf(found.get(), 0))};
}

api::Response PostgresJobService::List(const api::JobListQuery& query) const {
  const Impl& self = *impl_;
  // The kept jobs ($1: keep_results_s) in state $2 (NULL: any), newest submitted first.
  const std::string where =
      " FROM sweetspot_jobs WHERE (finished_unix_s IS NULL OR finished_unix_s > " SWEETSPOT_NOW
      " - $1) AND ($2::text IS NULL OR state = $2)";
  const Param state = query.state ? Param(*query.state) : Param();
  PgResult found(nullptr, &PQclear);
  PgResult counted(nullptr, &PQclear);
  if (!self.Query(std::string("SELECT ") + kPostgresViewColumns + where +
                      " ORDER BY seq DESC LIMIT $3 OFFSET $4",
                  {Decimal(self.config.keep_results_s), state, std::to_string(query.limit),
                   std::to_string(query.offset)},
                  &found) ||
      !self.Query("SELECT count(*)" + where, {Decimal(self.config.keep_results_s), state},
                  &counted)) {
    return Unavailable();
  }
  nlohmann::json jobs = nlohmann::json::array();
  for (int row = 0; row < PQntuples(found.get()); ++row) {
    jobs.push_back(JobJson(self.ViewOf(found.get(), row)));
  }
  // The count runs after the page: jobs submitted in between only raise it.
  const std::size_t total = std::max<std::size_t>(
      std::strtoull(PQgetvalue(counted.get(), 0, 0), nullptr, 10), query.offset + jobs.size());
  const std::size_t next = query.offset + jobs.size();
  nlohmann::json next_offset =
      next < total && !jobs.empty() ? nlohmann::json(next) : nlohmann::json();
  return {200, nlohmann::json{{"jobs", std::move(jobs)},
                              {"total", total},
                              {"next_offset", std::move(next_offset)}}};
}

api::Response PostgresJobService::Cancel(const std::string& id) {
  Impl& self = *impl_;
  // A job may move on between two statements (queued -> running -> done): try
  // each transition again a few times.
  for (int attempt = 0; attempt < 3; ++attempt) {
    PgResult changed(nullptr, &PQclear);
    if (!self.Query(std::string("UPDATE sweetspot_jobs SET state = 'cancelled', "
                                "cancel_requested = true, body = '', finished_unix_s = ") +
                        SWEETSPOT_NOW " WHERE id = $1 AND state = 'queued' RETURNING " +
                        kPostgresViewColumns,
                    {id}, &changed)) {
      return Unavailable();
    }
    if (PQntuples(changed.get()) == 1) return {200, JobJson(self.ViewOf(changed.get(), 0))};
    if (!self.Query(std::string("UPDATE sweetspot_jobs SET cancel_requested = true WHERE id = $1 "
                                "AND state = 'running' RETURNING ") +
                        kPostgresViewColumns,
                    {id}, &changed)) {
      return Unavailable();
    }
    if (PQntuples(changed.get()) == 1) {
      PgResult notified(nullptr, &PQclear);  // The replica running it stops it at once.
      self.Query("SELECT pg_notify('sweetspot_cancel', $1)", {id}, &notified);
      {
        // Running here: stop it now.
        std::lock_guard lock(self.mutex);
        const auto it = self.running.find(id);
        if (it != self.running.end()) {
          it->second->cancel_requested = true;
          it->second->progress.Cancel();
        }
      }
      return {202, JobJson(self.ViewOf(changed.get(), 0))};
    }
    if (!self.Query(std::string("DELETE FROM sweetspot_jobs WHERE id = $1 AND state IN ('done', "
                                "'failed', 'cancelled') AND finished_unix_s > ") +
                        SWEETSPOT_NOW " - $2 RETURNING " + kPostgresViewColumns,
                    {id, Decimal(self.config.keep_results_s)}, &changed)) {
      return Unavailable();
    }
    if (PQntuples(changed.get()) == 1) {
      nlohmann::json body = JobJson(self.ViewOf(changed.get(), 0));
      body["deleted"] = true;
      return {200, std::move(body)};
    }
    PgResult exists(nullptr, &PQclear);
    if (!self.Query("SELECT 1 FROM sweetspot_jobs WHERE id = $1 AND (finished_unix_s IS NULL OR "
                    "finished_unix_s > " SWEETSPOT_NOW " - $2)",
                    {id, Decimal(self.config.keep_results_s)}, &exists)) {
      return Unavailable();
    }
    if (PQntuples(exists.get()) == 0) break;
  }
  return JobNotFound(id);
}

std::map<std::string, int> PostgresJobService::CountsByState() const {
  const Impl& self = *impl_;
  PgResult counted(nullptr, &PQclear);
  if (!self.Query("SELECT state, count(*) FROM sweetspot_jobs WHERE finished_unix_s IS NULL OR "
                  "finished_unix_s > " SWEETSPOT_NOW " - $1 GROUP BY state",
                  {Decimal(self.config.keep_results_s)}, &counted)) {
    return {};
  }
  std::map<std::string, int> counts{
      {"queued", 0}, {"running", 0}, {"done", 0}, {"failed", 0}, {"cancelled", 0}};
  for (int row = 0; row < PQntuples(counted.get()); ++row) {
    counts[Text(counted.get(), row, 0)] = std::atoi(PQgetvalue(counted.get(), row, 1));
  }
  return counts;
}

void PostgresJobService::Shutdown(double grace_s) {
  Impl& self = *impl_;
  std::call_once(self.shutdown_once, [&self, grace_s] {
    {
      std::unique_lock lock(self.mutex);
      self.stopping = true;
      self.work_cv.notify_all();
      if (grace_s > 0 && std::isfinite(grace_s)) {
        const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                 std::chrono::duration<double>(std::min(grace_s, 1e6)));
        self.idle_cv.wait_until(lock, deadline,
                                [&self] { return self.busy == 0 || self.grace_ended; });
      }
      for (const auto& [id, job] : self.running) {
        job->interrupted = true;
        job->progress.Cancel();
      }
    }
    for (std::thread& worker : self.workers) {
      if (worker.joinable()) worker.join();
    }
    {
      std::lock_guard lock(self.mutex);
      self.heartbeat_stop = true;
    }
    self.beat_cv.notify_all();
    if (self.heartbeat.joinable()) self.heartbeat.join();
    self.listen_stop = true;
    if (self.listener.joinable()) self.listener.join();
    std::lock_guard lock(self.mutex);
    for (const auto& [id, job] : self.running) {
      if (job->unsaved) {
        self.Report("job " + id + " finished but could not be committed before the stop: "
                    "another replica runs it again once its lease expires");
      }
    }
  });
}

void PostgresJobService::EndGrace() {
  {
    std::lock_guard lock(impl_->mutex);
    impl_->grace_ended = true;
  }
  impl_->idle_cv.notify_all();
}

}  // namespace sweetspot::server
