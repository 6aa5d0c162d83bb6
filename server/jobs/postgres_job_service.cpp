#include "server/jobs/postgres_job_service.hpp"

#include <libpq-fe.h>
#include <poll.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <random>
#include <thread>
#include <utility>
#include <vector>

#include "api/json_reader.hpp"
#include "core/progress.hpp"

namespace sweetspot::server {
namespace {

using Clock = std::chrono::steady_clock;
using Param = std::optional<std::string>;  // nullopt: SQL NULL.
using PgResult = std::unique_ptr<PGresult, decltype(&PQclear)>;

// The database's clock, in s since the Unix epoch: leases are compared on one
// clock whatever the replicas' clocks say.
#define SWEETSPOT_NOW "extract(epoch from clock_timestamp())"

// Serialises migrations of replicas starting at once (any constant unique to us).
constexpr long long kMigrationLockKey = 7305861723461;
// Idle connections kept per replica.
constexpr std::size_t kMaxIdleConnections = 16;
// How often an idle worker looks for queued jobs another replica submitted.
constexpr auto kPollInterval = std::chrono::milliseconds(200);
// How often expired leases and old results are swept.
constexpr auto kSweepInterval = std::chrono::seconds(1);

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
};
constexpr int kSchemaVersion = static_cast<int>(sizeof(kMigrations) / sizeof(kMigrations[0]));

// The columns of a job's JSON, then the database's clock.
constexpr const char* kViewColumns =
    "id, state, progress, path, created_at, created_unix_s, started_unix_s, finished_unix_s, "
    "status, error, cancel_requested, resumes, " SWEETSPOT_NOW;

void IgnoreNotice(void*, const char*) {}

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

namespace {

// libpq's message without its trailing newline.
std::string Message(const char* text) {
  std::string out = text != nullptr ? text : "";
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return out.empty() ? "unknown error" : out;
}

std::string Text(const PGresult* result, int row, int column) {
  return PQgetisnull(result, row, column) ? std::string() : PQgetvalue(result, row, column);
}

double Number(const PGresult* result, int row, int column) {
  return std::strtod(PQgetvalue(result, row, column), nullptr);
}

std::optional<double> OptionalNumber(const PGresult* result, int row, int column) {
  if (PQgetisnull(result, row, column)) return std::nullopt;
  return Number(result, row, column);
}

// Runs `sql` with `params` (text; nullopt = NULL) on `connection`: true with its
// result in *out (if non-null) when it succeeded, else false with libpq's message.
// Without parameters `sql` may hold several statements (a migration); the result
// is the last one's.
bool Execute(PGconn* connection, const std::string& sql, const std::vector<Param>& params,
             PgResult* out, std::string* error) {
  std::vector<const char*> values;
  values.reserve(params.size());
  for (const Param& param : params) values.push_back(param ? param->c_str() : nullptr);
  PgResult result(params.empty()
                      ? PQexec(connection, sql.c_str())
                      : PQexecParams(connection, sql.c_str(), static_cast<int>(values.size()),
                                     nullptr, values.data(), nullptr, nullptr, 0),
                  &PQclear);
  const ExecStatusType status = result ? PQresultStatus(result.get()) : PGRES_FATAL_ERROR;
  if (status != PGRES_COMMAND_OK && status != PGRES_TUPLES_OK) {
    *error = Message(result ? PQresultErrorMessage(result.get()) : PQerrorMessage(connection));
    return false;
  }
  if (out != nullptr) *out = std::move(result);
  return true;
}

std::string Decimal(double value) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.17g", value);
  return text;
}

// A name for this process's leases: host, pid and 64 random bits.
std::string LeaseOwner() {
  char host[256] = "unknown";
  gethostname(host, sizeof(host) - 1);
  std::mt19937_64 random = SeededEngine();
  char tail[32];
  std::snprintf(tail, sizeof(tail), "%016llx", static_cast<unsigned long long>(random()));
  return std::string(host) + ":" + std::to_string(getpid()) + ":" + tail;
}

api::Response Unavailable() {
  return api::ToResponse(api::ApiError{503, api::ErrorCode::kUnavailable,
                                       "the jobs database cannot be reached; retry later", ""});
}

}  // namespace

bool IsPostgresUri(const std::string& text) {
  return text.rfind("postgresql://", 0) == 0 || text.rfind("postgres://", 0) == 0;
}

// Connections to the database: taken by one thread at a time, re-made when lost.
class Connections {
 public:
  explicit Connections(std::string uri) : uri_(std::move(uri)) {}
  ~Connections() {
    for (PGconn* connection : idle_) PQfinish(connection);
  }

  // Runs `sql` with `params` (text); true with its result in *out when it
  // succeeded. A lost connection is dropped with every idle one (a restarted
  // database loses them all) and the statement is tried once more on a new one:
  // every statement here may run twice without harm.
  bool Run(const std::string& sql, const std::vector<Param>& params, PgResult* out,
           std::string* error) {
    for (int attempt = 0; attempt < 2; ++attempt) {
      PGconn* connection = Take(error);
      if (connection == nullptr) return false;
      if (Execute(connection, sql, params, out, error)) {
        Give(connection);
        return true;
      }
      if (PQstatus(connection) == CONNECTION_OK) {  // An SQL error: not worth a retry.
        Give(connection);
        return false;
      }
      PQfinish(connection);
      DropIdle();
    }
    return false;
  }

  // Runs `body` on one connection inside a transaction (BEGIN ... COMMIT, or
  // ROLLBACK when anything failed).
  bool Transaction(const std::function<bool(PGconn*, std::string*)>& body, std::string* error) {
    PGconn* connection = Take(error);
    if (connection == nullptr) return false;
    auto exec = [&](const char* sql) { return Execute(connection, sql, {}, nullptr, error); };
    bool ok = exec("BEGIN") && body(connection, error) && exec("COMMIT");
    if (!ok) {
      std::string ignored = *error;
      PgResult rollback(PQexec(connection, "ROLLBACK"), &PQclear);
      *error = ignored;
    }
    if (PQstatus(connection) == CONNECTION_OK) {
      Give(connection);
    } else {
      PQfinish(connection);
      DropIdle();
    }
    return ok;
  }

  // A new connection of its own (not pooled; PQfinish it), or null with *error.
  PGconn* Connect(std::string* error) const {
    // The URI's own settings win over these defaults (later keywords override).
    const char* keys[] = {"connect_timeout", "keepalives_idle", "keepalives_interval",
                          "keepalives_count", "application_name", "dbname", nullptr};
    const char* values[] = {"3", "10", "3", "3", "sweetspot-server", uri_.c_str(), nullptr};
    PGconn* connection = PQconnectdbParams(keys, values, /*expand_dbname=*/1);
    if (connection == nullptr || PQstatus(connection) != CONNECTION_OK) {
      *error = Message(connection != nullptr ? PQerrorMessage(connection) : "out of memory");
      PQfinish(connection);
      return nullptr;
    }
    // "relation ... already exists, skipping" and the like are not worth a log line.
    PQsetNoticeProcessor(connection, IgnoreNotice, nullptr);
    return connection;
  }

 private:
  PGconn* Take(std::string* error) {
    {
      std::lock_guard lock(mutex_);
      if (!idle_.empty()) {
        PGconn* connection = idle_.back();
        idle_.pop_back();
        return connection;
      }
    }
    return Connect(error);
  }

  void Give(PGconn* connection) {
    std::lock_guard lock(mutex_);
    if (idle_.size() < kMaxIdleConnections) {
      idle_.push_back(connection);
    } else {
      PQfinish(connection);
    }
  }

  void DropIdle() {
    std::vector<PGconn*> dropped;
    {
      std::lock_guard lock(mutex_);
      dropped.swap(idle_);
    }
    for (PGconn* connection : dropped) PQfinish(connection);
  }

  const std::string uri_;
  std::mutex mutex_;
  std::vector<PGconn*> idle_;
};

struct PostgresJobService::Impl {
  // A job this replica runs.
  struct Running {
    std::string id;
    core::Progress progress;                    // Shared with the runner.
    std::atomic<bool> cancel_requested{false};  // Seen in the database (or asked here).
    std::atomic<bool> lost{false};              // Another replica owns it now.
    std::atomic<bool> interrupted{false};       // Shutdown hands it back to the queue.
    std::atomic<bool> timed_out{false};         // Ran longer than max_time_s (the heartbeat).
    Clock::time_point started = Clock::now();   // When this replica claimed it.
    // The finishing statement's parameters, while its commit waits for the database.
    std::optional<std::pair<std::string, std::vector<Param>>> unsaved;
  };

  Impl(std::string uri_in, JobConfig config_in, api::JobRunner runner_in,
       std::function<void(const std::string&)> log_in)
      : config(config_in),
        runner(std::move(runner_in)),
        log(std::move(log_in)),
        db(std::move(uri_in)),
        owner(LeaseOwner()),
        wall_start_unix_s(std::chrono::duration<double>(
                              std::chrono::system_clock::now().time_since_epoch())
                              .count()),
        random(SeededEngine()) {}

  bool Migrate(std::string* error);
  void Wake();
  void ListenLoop();
  void WorkerLoop();
  bool ClaimAndRun();
  void HeartbeatLoop();
  bool Renew(Running& job);
  void Sweep();
  bool Query(const std::string& sql, const std::vector<Param>& params, PgResult* out) const;
  void Report(const std::string& message) const;
  JobView ViewOf(const PGresult* result, int row) const;

  const JobConfig config;
  const api::JobRunner runner;
  const std::function<void(const std::string&)> log;
  mutable Connections db;
  const std::string owner;
  const double wall_start_unix_s;  // The wall clock when this replica started, s.

  mutable std::mutex mutex;
  std::condition_variable work_cv;   // `wakeups` moved, or stopping.
  std::uint64_t wakeups = 0;         // Bumped by a submit here or a NOTIFY from a replica.
  std::atomic<bool> listen_stop{false};  // Ends ListenLoop.
  std::thread listener;
  std::condition_variable idle_cv;   // A runner returned, or the grace ended.
  std::condition_variable beat_cv;   // The heartbeat must stop.
  std::map<std::string, std::shared_ptr<Running>> running;  // Claimed here, not yet committed.
  int busy = 0;                      // Runners running.
  bool stopping = false;             // Shutdown started: no claims, no submits.
  bool grace_ended = false;          // EndGrace().
  bool heartbeat_stop = false;       // The workers are joined.
  mutable std::atomic<bool> reachable{true};  // For logging each outage once.
  std::mt19937_64 random;            // Ids, under `mutex`.
  std::once_flag shutdown_once;
  std::vector<std::thread> workers;
  std::thread heartbeat;
};

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
  view.created_s = Number(result, row, 5) - wall_start_unix_s;
  if (auto started = OptionalNumber(result, row, 6)) view.started_s = *started - wall_start_unix_s;
  if (auto finished = OptionalNumber(result, row, 7)) {
    view.finished_s = *finished - wall_start_unix_s;
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

void PostgresJobService::Impl::WorkerLoop() {
  while (true) {
    std::uint64_t seen = 0;
    {
      std::lock_guard lock(mutex);
      if (stopping) return;
      seen = wakeups;
    }
    if (ClaimAndRun()) continue;
    std::unique_lock lock(mutex);
    work_cv.wait_for(lock, kPollInterval, [&] { return stopping || wakeups != seen; });
  }
}

bool PostgresJobService::Impl::ClaimAndRun() {
  // The oldest queued job, or a running one whose replica stopped renewing its
  // lease (and that may be resumed once more).
  const std::string claim =
      "WITH next AS (SELECT id FROM sweetspot_jobs WHERE state = 'queued' OR "
      "(state = 'running' AND lease_expires_unix_s < " SWEETSPOT_NOW
      " AND NOT cancel_requested AND resumes < $2) ORDER BY seq LIMIT 1 FOR UPDATE SKIP LOCKED) "
      "UPDATE sweetspot_jobs j SET resumes = j.resumes + CASE WHEN j.state = 'running' THEN 1 "
      "ELSE 0 END, state = 'running', progress = 0, started_unix_s = " SWEETSPOT_NOW
      ", lease_owner = $1, lease_expires_unix_s = " SWEETSPOT_NOW
      " + $3 FROM next WHERE j.id = next.id RETURNING j.id, j.method, j.path, j.body";
  PgResult claimed(nullptr, &PQclear);
  if (!Query(claim,
             {owner, std::to_string(config.max_resumes), Decimal(config.lease_s)}, &claimed) ||
      PQntuples(claimed.get()) == 0) {
    return false;
  }
  auto job = std::make_shared<Running>();
  job->id = Text(claimed.get(), 0, 0);
  api::Request inner{Text(claimed.get(), 0, 1), Text(claimed.get(), 0, 2),
                     Text(claimed.get(), 0, 3)};
  claimed.reset();
  {
    std::lock_guard lock(mutex);
    running[job->id] = job;
    ++busy;
    if (stopping) {  // Shutdown began while this claim was on its way.
      job->interrupted = true;
      job->progress.Cancel();
    }
  }

  api::Response response;
  bool threw = false;
  if (!job->progress.Cancelled()) {
    try {
      response = runner(inner, &job->progress);
    } catch (...) {  // Nothing may leave a worker thread; details stay out of the answer.
      threw = true;
    }
  }
  inner = api::Request{};
  // A streamed answer (a CSV or NDJSON sweep) runs here, stopped once over max_result_bytes.
  std::size_t streamed_bytes = 0;
  const StreamOutcome streamed =
      threw ? StreamOutcome::kComplete
            : CollectJobStream(&response, config.max_result_bytes, &streamed_bytes);
  if (streamed == StreamOutcome::kStopped) {  // Cancelled: an incomplete body is no answer.
    response = api::ToResponse(api::ApiError{
        409, api::ErrorCode::kCancelled, "the job was stopped before its answer was complete", ""});
  } else if (streamed == StreamOutcome::kOverLimit) {
    response = JobResultTooBig(streamed_bytes, "the jobs database", "max_result_bytes",
                               config.max_result_bytes, "--job-max-result-bytes", true);
  }
  if (job->timed_out && !job->lost && !job->cancel_requested) {
    threw = false;  // Failed below with the limit named, whatever the runner answered.
    response = JobTimedOut(config.max_time_s);
  }

  // What the job became, as the statement that commits it.
  std::optional<std::pair<std::string, std::vector<Param>>> finish;
  const std::string where = " WHERE id = $1 AND lease_owner = $2 AND state = 'running'";
  if (job->lost) {
    // Another replica runs it now: nothing of this run is kept.
  } else if (job->cancel_requested) {
    // The runner's 2xx answer is kept (an optimisation's best design so far), unless it is
    // over max_result_bytes; anything else is dropped (status 0).
    std::string status = "0", json, text, content_type;
    if (!threw && response.status >= 200 && response.status < 300) {
      if (response.content_type.empty()) {
        json = SerializeJobBody(response.body);
      } else {
        text = std::move(response.text);
        content_type = response.content_type;
      }
      if (json.size() + text.size() <= config.max_result_bytes) {
        status = std::to_string(response.status);
      } else {
        json.clear();
        text.clear();
        content_type.clear();
      }
    }
    finish.emplace("UPDATE sweetspot_jobs SET state = 'cancelled', progress = $3, body = '', "
                   "status = $4, response_json = $5, response_text = $6, content_type = $7, "
                   "finished_unix_s = " SWEETSPOT_NOW
                   ", lease_owner = NULL, lease_expires_unix_s = NULL" + where,
                   std::vector<Param>{job->id, owner, Decimal(job->progress.Fraction()),
                                      std::move(status), std::move(json), std::move(text),
                                      std::move(content_type)});
  } else if (job->interrupted && !job->timed_out) {
    // Back to the queue for another replica or the next start (no resume counted),
    // unless a DELETE arrived meanwhile.
    finish.emplace(
        "UPDATE sweetspot_jobs SET state = CASE WHEN cancel_requested THEN 'cancelled' ELSE "
        "'queued' END, progress = 0, started_unix_s = NULL, finished_unix_s = CASE WHEN "
        "cancel_requested THEN " SWEETSPOT_NOW " ELSE NULL END, body = CASE WHEN "
        "cancel_requested THEN '' ELSE body END, lease_owner = NULL, lease_expires_unix_s = NULL" +
            where,
        std::vector<Param>{job->id, owner});
  } else {
    std::string state = "done";
    std::string error;
    std::string json;
    std::string text;
    std::string content_type;
    if (threw) {
      state = "failed";
      response =
          api::ToResponse(api::ApiError{500, api::ErrorCode::kInternalError, "internal error", ""});
      error = StoredJobError(FailureObject(response));
    } else if (response.status < 200 || response.status >= 300) {
      state = "failed";
      error = StoredJobError(FailureObject(response));
    }
    if (response.content_type.empty()) {
      json = SerializeJobBody(response.body);
    } else {
      text = std::move(response.text);
      content_type = response.content_type;
    }
    const std::size_t size = json.size() + text.size();
    if (size > config.max_result_bytes) {
      state = "failed";
      response = JobResultTooBig(size, "the jobs database", "max_result_bytes",
                                 config.max_result_bytes, "--job-max-result-bytes");
      error = StoredJobError(FailureObject(response));
      json = SerializeJobBody(response.body);
      text.clear();
      content_type.clear();
    }
    // Any owner: a finished result stands even if the lease ran out meanwhile
    // (the database was away) and another replica took the job again; that
    // replica stops it at its next renewal.
    finish.emplace(
        "UPDATE sweetspot_jobs SET state = CASE WHEN cancel_requested THEN 'cancelled' ELSE $2 "
        "END, progress = CASE WHEN cancel_requested THEN $3::double precision ELSE $4 END, "
        "status = $5, response_json = $6, response_text = $7, content_type = $8, error = $9, "
        "body = '', finished_unix_s = " SWEETSPOT_NOW
        ", lease_owner = NULL, lease_expires_unix_s = NULL WHERE id = $1 AND state = 'running'",
        std::vector<Param>{job->id, state, Decimal(job->progress.Fraction()),
                           state == "done" ? "1" : Decimal(job->progress.Fraction()),
                           std::to_string(response.status), std::move(json), std::move(text),
                           std::move(content_type), std::move(error)});
  }
  response = api::Response{};

  PgResult done(nullptr, &PQclear);
  const bool saved = !finish || Query(finish->first, finish->second, &done);
  if (saved && job->interrupted && !job->cancel_requested) {
    Query("SELECT pg_notify('sweetspot_jobs', '')", {}, &done);  // Queued again: tell the others.
  }
  {
    std::lock_guard lock(mutex);
    if (saved) {
      running.erase(job->id);
    } else {
      job->unsaved = std::move(finish);  // The heartbeat commits it when the database returns.
    }
    --busy;
  }
  if (!saved) {
    Report("job " + job->id + " finished while the database was away: its result is kept "
           "here until it can be committed");
  }
  idle_cv.notify_all();
  return true;
}

bool PostgresJobService::Impl::Renew(Running& job) {
  PgResult renewed(nullptr, &PQclear);
  if (!Query("UPDATE sweetspot_jobs SET lease_expires_unix_s = " SWEETSPOT_NOW
             " + $3, progress = $4 WHERE id = $1 AND lease_owner = $2 AND state = 'running' "
             "RETURNING cancel_requested",
             {job.id, owner, Decimal(config.lease_s), Decimal(job.progress.Fraction())},
             &renewed)) {
    return false;
  }
  if (PQntuples(renewed.get()) == 0) {  // Another replica claimed it (or it was deleted).
    job.lost = true;
    job.progress.Cancel();
  } else if (Text(renewed.get(), 0, 0) == "t" && !job.cancel_requested) {
    job.cancel_requested = true;
    job.progress.Cancel();
  }
  return true;
}

void PostgresJobService::Impl::Sweep() {
  // Jobs whose replica died and that may not run again: cancelled if a DELETE
  // asked for it, else failed with the reason.
  const std::string message = InterruptedMessage("%s", config.max_resumes);
  PgResult ignored(nullptr, &PQclear);
  Query("WITH expired AS (SELECT id FROM sweetspot_jobs WHERE state = 'running' AND "
        "lease_expires_unix_s < " SWEETSPOT_NOW
        " AND (cancel_requested OR resumes >= $1) FOR UPDATE SKIP LOCKED) "
        "UPDATE sweetspot_jobs j SET state = CASE WHEN j.cancel_requested THEN 'cancelled' ELSE "
        "'failed' END, status = CASE WHEN j.cancel_requested THEN 0 ELSE 503 END, error = CASE "
        "WHEN j.cancel_requested THEN '' ELSE json_build_object('code', 'Interrupted', "
        "'message', format($2, j.resumes), 'field', NULL)::text END, response_json = CASE "
        "WHEN j.cancel_requested THEN '' ELSE json_build_object('code', 'Interrupted', "
        "'message', format($2, j.resumes), 'field', NULL)::text END, body = '', "
        "finished_unix_s = " SWEETSPOT_NOW
        ", lease_owner = NULL, lease_expires_unix_s = NULL FROM expired WHERE j.id = expired.id",
        {std::to_string(config.max_resumes), message}, &ignored);
  // Finished jobs past keep_results_s, and the oldest beyond max_kept.
  Query("DELETE FROM sweetspot_jobs WHERE finished_unix_s <= " SWEETSPOT_NOW
        " - $1 OR id IN (SELECT id FROM sweetspot_jobs WHERE finished_unix_s IS NOT NULL "
        "ORDER BY finished_unix_s DESC, seq DESC OFFSET $2)",
        {Decimal(config.keep_results_s), std::to_string(config.max_kept)}, &ignored);
}

void PostgresJobService::Impl::HeartbeatLoop() {
  const auto period = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(std::min(config.lease_s / 4.0, 0.5)));
  Clock::time_point next_sweep = Clock::now();
  std::unique_lock lock(mutex);
  while (true) {
    const bool last = heartbeat_stop;  // One more pass commits what the workers left.
    // Copies taken under the lock: a worker may set `unsaved` meanwhile.
    using Unsaved = std::optional<std::pair<std::string, std::vector<Param>>>;
    std::vector<std::pair<std::shared_ptr<Running>, Unsaved>> jobs;
    for (const auto& [id, job] : running) jobs.emplace_back(job, job->unsaved);
    lock.unlock();
    const Clock::time_point now = Clock::now();
    for (const auto& [job, unsaved] : jobs) {
      // The time limit, checked every period (at most 0.5 s late).
      if (!unsaved && !job->timed_out &&
          std::chrono::duration<double>(now - job->started).count() >= config.max_time_s) {
        job->timed_out = true;
        job->progress.Cancel();
      }
    }
    for (const auto& [job, unsaved] : jobs) {
      if (!Renew(*job)) break;  // The database is away: try again next period.
      if (unsaved && !job->lost) {
        PgResult ignored(nullptr, &PQclear);
        if (!Query(unsaved->first, unsaved->second, &ignored)) break;
        Report("job " + job->id + " committed");
      }
      if (unsaved || job->lost) {
        std::lock_guard erase_lock(mutex);
        running.erase(job->id);
      }
    }
    if (!last && Clock::now() >= next_sweep) {
      Sweep();
      next_sweep = Clock::now() + kSweepInterval;
    }
    lock.lock();
    if (last) return;
    beat_cv.wait_for(lock, period, [this] { return heartbeat_stop; });
  }
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
                      kViewColumns,
                  {id, inner.method, inner.path, inner.body, IsoUtc(std::chrono::system_clock::now()),
                   Decimal(created_unix_s), std::to_string(self.config.max_queued)},
                  &inserted)) {
    return Unavailable();
  }
  if (PQntuples(inserted.get()) == 0) {
    // Either the queue is full, or a retried insert had already landed.
    PgResult found(nullptr, &PQclear);
    if (!self.Query(std::string("SELECT ") + kViewColumns + " FROM sweetspot_jobs WHERE id = $1",
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
  if (!self.Query(std::string("SELECT ") + kViewColumns +
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
  if (!self.Query(std::string("SELECT ") + kViewColumns + where +
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

api::Response PostgresJobService::Result(const std::string& id) const {
  const Impl& self = *impl_;
  PgResult found(nullptr, &PQclear);
  if (!self.Query("SELECT state, status, response_json, response_text, content_type FROM "
                  "sweetspot_jobs WHERE id = $1 AND (finished_unix_s IS NULL OR "
                  "finished_unix_s > " SWEETSPOT_NOW " - $2)",
                  {id, Decimal(self.config.keep_results_s)}, &found)) {
    return Unavailable();
  }
  if (PQntuples(found.get()) == 0) return JobNotFound(id);
  const std::string state = Text(found.get(), 0, 0);
  const int status = std::atoi(PQgetvalue(found.get(), 0, 1));
  // A cancelled job has a result only when it kept the runner's 2xx answer.
  if (state == "cancelled" && (status < 200 || status >= 300)) return JobWasCancelled(id);
  if (state != "done" && state != "failed" && state != "cancelled") return JobNotReady(id, state);
  const std::string content_type = Text(found.get(), 0, 4);
  if (!content_type.empty()) {
    return api::Response::Text(status, Text(found.get(), 0, 3), content_type);
  }
  nlohmann::json body = nlohmann::json::parse(Text(found.get(), 0, 2), nullptr, false);
  if (body.is_discarded()) {  // Only a damaged database gets here.
    return api::ToResponse(api::ApiError{500, api::ErrorCode::kInternalError,
                                         "the stored result of this job could not be read", ""});
  }
  return {status, std::move(body)};
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
                        kViewColumns,
                    {id}, &changed)) {
      return Unavailable();
    }
    if (PQntuples(changed.get()) == 1) return {200, JobJson(self.ViewOf(changed.get(), 0))};
    if (!self.Query(std::string("UPDATE sweetspot_jobs SET cancel_requested = true WHERE id = $1 "
                                "AND state = 'running' RETURNING ") +
                        kViewColumns,
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
                        SWEETSPOT_NOW " - $2 RETURNING " + kViewColumns,
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
