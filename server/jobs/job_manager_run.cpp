// JobManager's workers: a job run, its result kept (in memory or the store) and its end;
// the watchdog of max_time_s; the bound on results held in memory.
#include "server/jobs/job_manager.hpp"

#include <algorithm>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "api/json_reader.hpp"
#include "server/jobs/job_manager_job.hpp"

namespace sweetspot::server {

using api::ApiError;
using api::Request;
using api::Response;
using api::ToResponse;

void JobManager::WorkerLoop() {
  std::unique_lock lock(mutex_);
  while (true) {
    work_cv_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
    if (stopping_) return;  // Shutdown() cancelled whatever was queued.
    const std::shared_ptr<Job> job = jobs_.at(queue_.front());  // Queued jobs are never evicted.
    queue_.pop_front();
    job->state = State::kRunning;
    job->started = Clock::now();
    ++busy_;
    running_.push_back(job);
    watchdog_cv_.notify_all();
    // Saved with the request, so a job the process dies under can be resumed.
    SaveLocked(*job);
    Request inner = job->inner;  // The runner's copy: job->inner is read under the lock.
    lock.unlock();
    RunOutcome run = RunJob(*job, std::move(inner));
    lock.lock();
    --busy_;
    running_.erase(std::find(running_.begin(), running_.end(), job));
    idle_cv_.notify_all();
    FinishRunLocked(job, std::move(run));
  }
}

JobManager::RunOutcome JobManager::RunJob(Job& job, Request inner) {
  RunOutcome run;
  try {
    run.response = runner_(inner, &job.progress);
  } catch (...) {  // Nothing may leave a worker thread; details stay out of the answer.
    run.threw = true;
  }
  ReleaseJobRequest(&inner);
  // Without a store a result lives in memory: max_results_memory_bytes bounds it too.
  run.memory_bound =
      persistence_.store == nullptr && config_.max_results_memory_bytes < config_.max_result_bytes;
  const std::size_t largest =
      run.memory_bound ? config_.max_results_memory_bytes : config_.max_result_bytes;
  // A store that keeps pieces gets a streamed answer's bytes as they are produced: a result
  // over kResultChunkBytes is never whole in memory.
  ResultChunkWriter write;
  if (persistence_.store != nullptr && persistence_.store->KeepsResultChunks()) {
    write = [store = persistence_.store, id = job.id](std::uint64_t seq, std::string_view bytes,
                                                      std::string* error) {
      return store->SaveResultChunk(id, seq, bytes, error);
    };
  }
  // Outside the lock: a streamed answer (a sweep) is run here, stopped once over the limit; a
  // 2xx answer's size, its JSON serialised once for the size and the store.
  CollectedStream streamed;
  if (!run.threw) streamed = CollectJobStream(&run.response, largest, write);
  run.chunks = streamed.pieces;
  if (streamed.outcome == StreamOutcome::kStopped) {
    // Cancelled (DELETE, the time limit, a shutdown) or failed: an incomplete body is no answer.
    KeepOnlyJobStatus(&run.response);
    run.response = IncompleteStreamAnswer(job.progress.Cancelled());
  } else if (streamed.outcome == StreamOutcome::kWriteFailed) {
    KeepOnlyJobStatus(&run.response);
    run.response = ToResponse(
        ApiError{503, api::ErrorCode::kUnavailable,
                 "the job's result could not be saved in the jobs database (" +
                     streamed.write_error + "): it is not kept; submit the job again later",
                 ""});
  } else if (streamed.outcome == StreamOutcome::kComplete && !run.threw &&
             !NormalizeJsonResult(&run.response, streamed.chunked)) {
    run.threw = true;  // A JSON stream that is not JSON: the handler's bug.
  }
  run.answered = !run.threw && run.response.status >= 200 && run.response.status < 300;
  run.bytes = streamed.bytes;
  if (run.answered && streamed.chunked) {
    run.chunked_bytes = streamed.bytes;
  } else if (run.answered && run.response.content_type.empty()) {
    run.serialized = SerializeJobBody(run.response.body);
    run.bytes = run.serialized.size();
  }
  run.too_big =
      run.answered && (run.bytes > largest || streamed.outcome == StreamOutcome::kOverLimit);
  if (run.too_big) {
    const bool stopped = streamed.outcome == StreamOutcome::kOverLimit;
    KeepOnlyJobStatus(&run.response);
    run.response =
        run.memory_bound
            ? JobResultTooBig(run.bytes, "this server's memory", "max_results_memory_bytes",
                              largest, "--job-results-memory-bytes", stopped)
            : JobResultTooBig(run.bytes, "the job service", "max_result_bytes", largest,
                              "--job-max-result-bytes", stopped);
    run.serialized.clear();
    run.chunked_bytes.reset();
  }
  if (!run.answered || run.too_big) run.bytes = 0;  // Counted below from the stored answer.
  return run;
}

void JobManager::FinishRunLocked(const std::shared_ptr<Job>& job, RunOutcome run) {
  const Clock::time_point now = Clock::now();
  const bool keep = run.answered && !run.too_big;
  if (job->cancel_requested) {
    // A 2xx answer is kept (an optimisation's best design so far) unless it is too big;
    // anything else is dropped.
    if (keep) {
      job->result = std::move(run.response);
      job->chunked_bytes = run.chunked_bytes;
      job->kept_result = true;
    }
    FinishLocked(*job, State::kCancelled, now);
  } else if (job->timed_out) {
    job->result = JobTimedOut(config_.max_time_s);
    job->error = FailureObject(job->result);
    run.serialized.clear();
    FinishLocked(*job, State::kFailed, now);
  } else if (job->interrupted) {
    // Shutdown cut it short: its result (if any) is discarded, and it is
    // queued again, saved for the next start, which runs it from the start.
    DropChunksLocked(job->id, run.chunks);
    job->state = State::kQueued;
    job->started.reset();
    queue_.push_front(job->id);
    SaveLocked(*job);
    return;
  } else if (run.threw) {
    job->result = ToResponse(ApiError{500, api::ErrorCode::kInternalError, "internal error", ""});
    job->error = FailureObject(job->result);
    FinishLocked(*job, State::kFailed, now);
  } else if (keep) {
    job->result = std::move(run.response);
    job->chunked_bytes = run.chunked_bytes;
    FinishLocked(*job, State::kDone, now);
  } else {
    job->error = FailureObject(run.response);
    job->result = std::move(run.response);
    FinishLocked(*job, State::kFailed, now);
  }
  if (!job->chunked_bytes) DropChunksLocked(job->id, run.chunks);  // Pieces of a lost answer.
  ReleaseJobRequest(&job->inner);  // Frees the body; a finished job is never run again.
  std::size_t bytes = run.bytes;
  if (bytes == 0 && job->result.content_type.empty() && !job->chunked_bytes) {
    bytes = job->kept_result || job->state != State::kCancelled
                ? SerializeJobBody(job->result.body).size()  // An error object: small.
                : 0;
  }
  std::string why;
  bool saved = SaveLocked(*job, &why, &run.serialized);
  if (!saved && job->state != State::kCancelled) {
    // Never done (or failed with an answer) without it stored: failed with the store's
    // message, saved as such (small), so the next start neither shows a result nor runs it
    // again. Should that save fail too, its row is deleted (below).
    KeepOnlyJobStatus(&job->result);  // Frees the answer that could not be stored.
    job->result = ToResponse(ApiError{503, api::ErrorCode::kUnavailable,
                                      "the job's result could not be saved in the jobs database (" +
                                          why + "): it is not kept; submit the job again later",
                                      ""});
    job->error = FailureObject(job->result);
    job->state = State::kFailed;
    if (job->chunked_bytes) DropChunksLocked(job->id, run.chunks);
    job->chunked_bytes.reset();
    bytes = SerializeJobBody(job->result.body).size();
    saved = SaveLocked(*job);
  } else if (!saved && job->kept_result) {
    job->kept_result = false;  // A cancelled job whose answer could not be stored keeps none.
    KeepOnlyJobStatus(&job->result);
    job->result.status = 0;
    if (job->chunked_bytes) DropChunksLocked(job->id, run.chunks);
    job->chunked_bytes.reset();
    bytes = 0;
    saved = SaveLocked(*job);
  }
  // Not even that fits (a full disk): no row is better than its "running" one, which the
  // next start would run again and, after max_resumes, fail as if the server had died.
  if (!saved) ForgetLocked(job->id);
  KeepResultLocked(*job, bytes, saved);
  EvictLocked(now);
}

void JobManager::DropChunksLocked(const std::string& id, std::uint64_t chunks) const {
  if (chunks == 0 || persistence_.store == nullptr) return;
  std::string error;
  if (!persistence_.store->DeleteResultChunks(id, &error) && persistence_.on_store_error) {
    persistence_.on_store_error("cannot delete the result pieces of job " + id + ": " + error);
  }
}

void JobManager::WatchdogLoop() {
  const auto limit = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(config_.max_time_s));
  std::unique_lock lock(mutex_);
  while (!watchdog_stop_) {
    const Clock::time_point now = Clock::now();
    std::optional<Clock::time_point> next;
    for (const std::shared_ptr<Job>& job : running_) {
      if (job->timed_out) continue;
      const Clock::time_point deadline = *job->started + limit;
      if (deadline <= now) {
        job->timed_out = true;  // The worker makes it failed when the runner returns.
        job->progress.Cancel();
      } else if (!next || deadline < *next) {
        next = deadline;
      }
    }
    if (next) {
      watchdog_cv_.wait_until(lock, *next);
    } else {
      watchdog_cv_.wait(lock);
    }
  }
}

void JobManager::KeepResultLocked(Job& job, std::size_t bytes, bool saved) {
  const bool has_result =
      job.state == State::kDone || job.state == State::kFailed || job.kept_result;
  if (!has_result) return;
  if (persistence_.store != nullptr && !saved) return;  // An error object the store refused.
  if (persistence_.store != nullptr && bytes > kMaxLoadedResultBytes) {
    KeepOnlyJobStatus(&job.result);  // Read back by Result().
    job.result_in_store = true;
    return;
  }
  if (bytes == 0) return;  // Nothing to count (an empty body).
  job.memory_bytes = bytes;
  memory_results_bytes_ += bytes;
  in_memory_.push_back(job.id);
  TrimMemoryLocked();
}

void JobManager::ForgetResultLocked(Job& job) const {
  if (job.memory_bytes == 0) return;
  memory_results_bytes_ -= job.memory_bytes;
  job.memory_bytes = 0;
  // Usually the oldest (eviction); a DELETE may take any.
  if (!in_memory_.empty() && in_memory_.front() == job.id) {
    in_memory_.pop_front();
  } else if (const auto it = std::find(in_memory_.begin(), in_memory_.end(), job.id);
             it != in_memory_.end()) {
    in_memory_.erase(it);
  }
}

void JobManager::TrimMemoryLocked() {
  while (memory_results_bytes_ > config_.max_results_memory_bytes && !in_memory_.empty()) {
    const std::shared_ptr<Job> job = FindLocked(in_memory_.front());
    in_memory_.pop_front();
    if (!job || job->memory_bytes == 0) continue;
    memory_results_bytes_ -= job->memory_bytes;
    job->memory_bytes = 0;
    if (persistence_.store != nullptr) {
      KeepOnlyJobStatus(&job->result);  // Saved: Result() reads it back.
      job->result_in_store = true;
    } else {
      finished_.erase(std::find(finished_.begin(), finished_.end(), job->id));
      jobs_.erase(job->id);
    }
  }
}

}  // namespace sweetspot::server
