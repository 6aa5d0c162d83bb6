// JobManager and its JobStore: a job as a record, saved and deleted; the jobs loaded at start.
#include "server/jobs/job_manager.hpp"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "api/json_reader.hpp"
#include "server/jobs/job_manager_job.hpp"

namespace sweetspot::server {

using api::ApiError;
using api::Request;
using api::Response;
using api::ToResponse;

JobRecord JobManager::RecordLocked(const Job& job, std::string* serialized) const {
  JobRecord record;
  record.id = job.id;
  record.state = StateName(job.state);
  record.method = job.inner.method;
  record.path = job.path;
  record.body = job.inner.body;  // Empty once finished (the body is freed then).
  record.progress = ProgressOf(job);
  record.cancel_requested = job.cancel_requested;
  record.resumes = job.resumes;
  record.created_at = job.created_at;
  record.created_unix_s = ToUnixSeconds(job.created);
  if (job.started) record.started_unix_s = ToUnixSeconds(*job.started);
  if (job.finished) record.finished_unix_s = ToUnixSeconds(*job.finished);
  if (job.state == State::kDone || job.state == State::kFailed || job.kept_result) {
    record.status = job.result.status;
    if (job.chunked_bytes) {
      record.chunked_bytes = job.chunked_bytes;  // The pieces hold it (JSON: content type "").
      record.content_type = job.result.content_type;
    } else if (job.result.content_type.empty()) {
      record.response_json = serialized != nullptr && !serialized->empty()
                                 ? std::move(*serialized)
                                 : SerializeJobBody(job.result.body);
    } else {
      record.response_text = job.result.text;
      record.content_type = job.result.content_type;
    }
    if (job.state == State::kFailed) record.error = StoredJobError(job.error);
  }
  return record;
}

bool JobManager::SaveLocked(const Job& job, std::string* why, std::string* serialized) const {
  if (persistence_.store == nullptr) return true;
  std::string error;
  if (persistence_.store->Save(RecordLocked(job, serialized), &error)) return true;
  if (why != nullptr) *why = error;
  if (persistence_.on_store_error) {
    persistence_.on_store_error("cannot save job " + job.id + " (" + StateName(job.state) +
                                "): " + error);
  }
  return false;
}

void JobManager::ForgetLocked(const std::string& id) const {
  if (persistence_.store == nullptr) return;
  std::string error;
  if (!persistence_.store->Delete(id, &error) && persistence_.on_store_error) {
    persistence_.on_store_error("cannot delete job " + id + ": " + error);
  }
}

void JobManager::LoadFromStore() {
  std::vector<JobRecord> records;
  std::string error;
  if (!persistence_.store->LoadAll(&records, &error)) {
    throw std::runtime_error("cannot load the jobs: " + error);
  }
  std::lock_guard lock(mutex_);
  const Clock::time_point now = Clock::now();
  std::vector<std::shared_ptr<Job>> finished;
  for (JobRecord& record : records) {
    bool changed = false;  // Its stored state must be rewritten.
    auto job = std::make_shared<Job>();
    job->id = record.id;
    job->seq = next_seq_++;  // Records come oldest created first.
    job->path = record.path;
    job->inner = Request{record.method, record.path, std::move(record.body)};
    job->cancel_requested = record.cancel_requested;
    job->resumes = record.resumes;
    job->created = FromUnixSeconds(record.created_unix_s);
    job->created_at = record.created_at;
    if (record.started_unix_s) job->started = FromUnixSeconds(*record.started_unix_s);
    if (record.finished_unix_s) job->finished = FromUnixSeconds(*record.finished_unix_s);
    // A cancelled job keeps the runner's 2xx answer when it gave one (status != 0).
    const bool kept = record.state == "cancelled" && record.status != 0;
    if (record.state == "done" || record.state == "failed" || kept) {
      job->state = record.state == "done"     ? State::kDone
                   : record.state == "failed" ? State::kFailed
                                              : State::kCancelled;
      job->kept_result = kept;
      job->progress.Report(record.progress);
      if (kept) job->progress.Cancel();
      const std::size_t bytes = record.response_json.size() + record.response_text.size();
      if (record.result_in_store || bytes > kMaxLoadedResultBytes) {
        job->result = Response(record.status, nullptr);  // Result() reads it back.
        job->result_in_store = true;
        job->chunked_bytes = record.chunked_bytes;
      } else if (!record.content_type.empty()) {
        job->memory_bytes = bytes;
        job->result = Response::Text(record.status, std::move(record.response_text),
                                     std::move(record.content_type));
      } else {
        nlohmann::json body = nlohmann::json::parse(record.response_json, nullptr, false);
        if (body.is_discarded()) {  // Only a damaged database gets here.
          job->state = State::kFailed;
          job->kept_result = false;
          body = ToResponse(ApiError{500, api::ErrorCode::kInternalError,
                                     "the stored result of this job could not be read", ""})
                     .body;
          record.status = 500;
          record.error.clear();
        }
        job->result = Response(record.status, std::move(body));
        job->memory_bytes = bytes;
      }
      if (job->state == State::kFailed) {
        job->error = ReadStoredJobError(record.error, record.status, job->result.body);
      }
    } else if (record.state == "cancelled") {
      job->state = State::kCancelled;
      job->progress.Report(record.progress);
      job->progress.Cancel();
    } else if (record.state == "queued") {
      job->state = State::kQueued;  // Never started: queued again as it was.
    } else if (record.state == "running") {
      // The process died while this job ran (a clean stop saves it as queued).
      job->finished.reset();
      if (job->cancel_requested) {
        job->state = State::kCancelled;
        job->progress.Report(record.progress);
        job->progress.Cancel();
        job->finished = now;
      } else if (job->resumes < config_.max_resumes) {
        ++job->resumes;
        job->started.reset();
        job->state = State::kQueued;  // Run again from the start: the request is deterministic.
      } else {
        job->state = State::kFailed;
        job->progress.Report(record.progress);
        job->finished = now;
        std::string message;
        job->result = JobInterrupted(job->resumes, config_.max_resumes, &message);
        job->error = FailureObject(job->result);
      }
      changed = true;
    } else {
      if (persistence_.on_store_error) {
        persistence_.on_store_error("job " + record.id + " has an unknown state " +
                                    QuoteJobId(record.state) + ": skipped");
      }
      continue;
    }
    if (job->state == State::kQueued) {
      queue_.push_back(job->id);  // Records come oldest first: the queue keeps its order.
    } else {
      ReleaseJobRequest(&job->inner);
      if (!job->finished) job->finished = now;
      finished.push_back(job);
    }
    jobs_[job->id] = job;
    if (changed) SaveLocked(*job);
  }
  std::stable_sort(finished.begin(), finished.end(),
                   [](const auto& a, const auto& b) { return *a->finished < *b->finished; });
  for (const auto& job : finished) {
    finished_.push_back(job->id);
    if (job->memory_bytes != 0) {
      memory_results_bytes_ += job->memory_bytes;
      in_memory_.push_back(job->id);
    }
  }
  EvictLocked(now);  // Drops (and deletes) what is too old or beyond max_kept.
  TrimMemoryLocked();
}

}  // namespace sweetspot::server
