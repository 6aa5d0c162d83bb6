// PostgresJobService's workers: a job claimed, run (its result written in pieces as it is
// produced), committed; the heartbeat that renews leases, checks the time limit and sweeps.
#include <libpq-fe.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <utility>

#include "api/json_reader.hpp"
#include "server/jobs/postgres_job_impl.hpp"

namespace sweetspot::server {
using namespace pg;  // NOLINT: this file is left out of the unity build (server/CMakeLists.txt).
namespace {
using Clock = std::chrono::steady_clock;
}  // namespace

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
    work_cv.wait_for(lock, kPostgresPollInterval, [&] { return stopping || wakeups != seen; });
  }
}

bool PostgresJobService::Impl::ClaimAndRun() {
  api::Request inner;
  const std::shared_ptr<Running> job = Claim(&inner);
  if (!job) return false;
  RunOutcome run = RunClaimed(*job, std::move(inner));
  Commit(job, FinishStatement(*job, std::move(run)));
  return true;
}

std::shared_ptr<PostgresJobService::Impl::Running> PostgresJobService::Impl::Claim(
    api::Request* inner) {
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
  if (!Query(claim, {owner, std::to_string(config.max_resumes), Decimal(config.lease_s)},
             &claimed) ||
      PQntuples(claimed.get()) == 0) {
    return nullptr;
  }
  auto job = std::make_shared<Running>();
  job->id = Text(claimed.get(), 0, 0);
  *inner =
      api::Request{Text(claimed.get(), 0, 1), Text(claimed.get(), 0, 2), Text(claimed.get(), 0, 3)};
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
  return job;
}

PostgresJobService::Impl::RunOutcome PostgresJobService::Impl::RunClaimed(Running& job,
                                                                          api::Request inner) {
  RunOutcome run;
  if (!job.progress.Cancelled()) {
    try {
      run.response = runner(inner, &job.progress);
    } catch (...) {  // Nothing may leave a worker thread; details stay out of the answer.
      run.threw = true;
    }
  }
  inner = api::Request{};
  // A streamed answer (a sweep) runs here, stopped once over max_result_bytes; past
  // kResultChunkBytes its bytes go to the database in pieces as they are produced.
  CollectedStream streamed;
  if (!run.threw) {
    streamed = CollectJobStream(
        &run.response, config.max_result_bytes,
        [this, &job](std::uint64_t seq, std::string_view bytes, std::string* error) {
          return WriteChunk(job, seq, bytes, error);
        });
  }
  job.chunks = streamed.pieces;
  if (streamed.outcome == StreamOutcome::kStopped) {  // An incomplete body is no answer.
    run.response = IncompleteStreamAnswer(job.progress.Cancelled());
  } else if (streamed.outcome == StreamOutcome::kOverLimit) {
    run.response = JobResultTooBig(streamed.bytes, "the jobs database", "max_result_bytes",
                                   config.max_result_bytes, "--job-max-result-bytes", true);
  } else if (streamed.outcome == StreamOutcome::kWriteFailed) {
    run.response = api::ToResponse(
        api::ApiError{503, api::ErrorCode::kUnavailable,
                      "the job's result could not be saved in the jobs database (" +
                          streamed.write_error + "): it is not kept; submit the job again later",
                      ""});
  } else if (!run.threw) {
    if (!NormalizeJsonResult(&run.response, streamed.chunked)) run.threw = true;
    if (streamed.chunked) run.chunked_bytes = streamed.bytes;
  }
  if (job.timed_out && !job.lost && !job.cancel_requested) {
    run.threw = false;  // Failed below with the limit named, whatever the runner answered.
    run.response = JobTimedOut(config.max_time_s);
    run.chunked_bytes.reset();
  }
  return run;
}

std::optional<PostgresJobService::Impl::Statement> PostgresJobService::Impl::FinishStatement(
    Running& job, RunOutcome run) {
  const std::string where = " WHERE id = $1 AND lease_owner = $2 AND state = 'running'";
  api::Response& response = run.response;
  // The body as the row keeps it: JSON, text, or in the pieces (result_bytes).
  std::string json, text, content_type;
  Param result_bytes;
  auto take_body = [&]() {
    if (run.chunked_bytes) {
      result_bytes = std::to_string(*run.chunked_bytes);
      content_type = response.content_type;
      job.keeps_pieces = true;
    } else if (response.content_type.empty()) {
      json = SerializeJobBody(response.body);
    } else {
      text = std::move(response.text);
      content_type = response.content_type;
    }
  };
  if (job.lost) return std::nullopt;  // Another replica runs it now: nothing of this run is kept.
  if (job.cancel_requested) {
    // The runner's 2xx answer is kept (an optimisation's best design so far), unless it is
    // over max_result_bytes; anything else is dropped (status 0).
    std::string status = "0";
    if (!run.threw && response.status >= 200 && response.status < 300) {
      take_body();
      if (json.size() + text.size() <= config.max_result_bytes) {
        status = std::to_string(response.status);
      } else {
        json.clear();
        text.clear();
        content_type.clear();
      }
    }
    return Statement(
        "UPDATE sweetspot_jobs SET state = 'cancelled', progress = $3, body = '', "
        "status = $4, response_json = $5, response_text = $6, content_type = $7, "
        "result_bytes = $8, finished_unix_s = " SWEETSPOT_NOW
        ", lease_owner = NULL, lease_expires_unix_s = NULL" +
            where,
        {job.id, owner, Decimal(job.progress.Fraction()), std::move(status), std::move(json),
         std::move(text), std::move(content_type), std::move(result_bytes)});
  }
  if (job.interrupted && !job.timed_out) {
    // Back to the queue for another replica or the next start (no resume counted),
    // unless a DELETE arrived meanwhile.
    return Statement(
        "UPDATE sweetspot_jobs SET state = CASE WHEN cancel_requested THEN 'cancelled' ELSE "
        "'queued' END, progress = 0, started_unix_s = NULL, finished_unix_s = CASE WHEN "
        "cancel_requested THEN " SWEETSPOT_NOW
        " ELSE NULL END, body = CASE WHEN "
        "cancel_requested THEN '' ELSE body END, lease_owner = NULL, lease_expires_unix_s = NULL" +
            where,
        {job.id, owner});
  }
  std::string state = "done";
  std::string error;
  if (run.threw) {
    state = "failed";
    response =
        api::ToResponse(api::ApiError{500, api::ErrorCode::kInternalError, "internal error", ""});
    error = StoredJobError(FailureObject(response));
  } else if (response.status < 200 || response.status >= 300) {
    state = "failed";
    error = StoredJobError(FailureObject(response));
  }
  take_body();
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
  return Statement(
      "UPDATE sweetspot_jobs SET state = CASE WHEN cancel_requested THEN 'cancelled' ELSE $2 "
      "END, progress = CASE WHEN cancel_requested THEN $3::double precision ELSE $4 END, "
      "status = $5, response_json = $6, response_text = $7, content_type = $8, error = $9, "
      "result_bytes = $10, body = '', finished_unix_s = " SWEETSPOT_NOW
      ", lease_owner = NULL, lease_expires_unix_s = NULL WHERE id = $1 AND state = 'running'",
      {job.id, state, Decimal(job.progress.Fraction()),
       state == "done" ? "1" : Decimal(job.progress.Fraction()), std::to_string(response.status),
       std::move(json), std::move(text), std::move(content_type), std::move(error),
       std::move(result_bytes)});
}

void PostgresJobService::Impl::Commit(const std::shared_ptr<Running>& job,
                                      std::optional<Statement> finish) {
  PgResult done(nullptr, &PQclear);
  const bool saved = !finish || Query(finish->first, finish->second, &done);
  if (saved && job->interrupted && !job->cancel_requested) {
    Query("SELECT pg_notify('sweetspot_jobs', '')", {}, &done);  // Queued again: tell the others.
  }
  // The pieces of an answer not kept (another replica's run, if lost, may be writing its own).
  if (saved && job->chunks > 0 && !job->keeps_pieces && !job->lost) {
    Query("DELETE FROM sweetspot_job_result_chunks WHERE id = $1", {job->id}, &done);
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
    Report("job " + job->id +
           " finished while the database was away: its result is kept "
           "here until it can be committed");
  }
  idle_cv.notify_all();
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
  Query(
      "WITH expired AS (SELECT id FROM sweetspot_jobs WHERE state = 'running' AND "
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
      next_sweep = Clock::now() + kPostgresSweepInterval;
    }
    lock.lock();
    if (last) return;
    beat_cv.wait_for(lock, period, [this] { return heartbeat_stop; });
  }
}

}  // namespace sweetspot::server
