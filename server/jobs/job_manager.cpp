#include "server/jobs/job_manager.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "api/json_reader.hpp"

namespace sweetspot::server {

using api::ApiError;
using api::Request;
using api::Response;
using api::ToResponse;

namespace {

// Frees a request's body. Assigning a new Request would not: a std::string moved from a short
// one keeps its old buffer (libstdc++), so a 1 MB body stayed allocated.
void Release(Request* request) { std::string().swap(request->body); }

// Leaves only the status of a result, freeing its body (see Release: a 10 MB CSV text stayed
// allocated per job when the result was replaced by assignment).
void KeepOnlyStatus(Response* result) {
  const int status = result->status;
  Response empty(status, nullptr);
  std::swap(*result, empty);  // `empty` now owns the old buffers and frees them here.
}

}  // namespace

struct JobManager::Job {
  std::string id;                             // 32 hex digits.
  std::uint64_t seq = 0;                      // Submit order (for the list's ties).
  std::string path;                           // The inner request's path.
  Request inner;                              // Cleared once the job is finished.
  State state = State::kQueued;               // Current state.
  core::Progress progress;                    // Shared with the runner.
  bool cancel_requested = false;              // DELETE or Shutdown asked it to stop.
  bool interrupted = false;                   // Shutdown (with a store) asked it to stop.
  int resumes = 0;                            // Re-queued after the server died under it.
  Clock::time_point created;                  // Submit time.
  std::optional<Clock::time_point> started;   // When a worker took it.
  std::optional<Clock::time_point> finished;  // When it reached a final state.
  std::string created_at;                     // Submit time, ISO-8601 UTC.
  Response result;                            // The inner response (done, failed, kept).
  bool kept_result = false;                   // Cancelled, with the runner's 2xx in result.
  nlohmann::json error;                       // The failure's error object (failed), else null.
  bool timed_out = false;                     // The watchdog stopped it (max_time_s).
  bool result_in_store = false;               // result holds only the status; the store has it.
  std::size_t memory_bytes = 0;               // Its result's bytes counted in memory.
};

JobManager::JobManager(JobConfig config, JobRunner runner, JobPersistence persistence)
    : config_(config),
      runner_(std::move(runner)),
      persistence_(std::move(persistence)),
      start_(Clock::now()),
      wall_start_(std::chrono::system_clock::now()),
      random_(SeededEngine()) {
  if (core::Refusal why; !config_.Validate(&why))
    throw std::invalid_argument("invalid JobConfig: " + why.Message());
  if (!runner_) throw std::invalid_argument("invalid JobManager: the runner is empty");
  if (persistence_.store != nullptr) LoadFromStore();
  try {
    watchdog_ = std::thread([this] { WatchdogLoop(); });
    workers_.reserve(static_cast<std::size_t>(config_.workers));
    for (int i = 0; i < config_.workers; ++i) workers_.emplace_back([this] { WorkerLoop(); });
  } catch (...) {
    Shutdown();  // Joins the threads already started; the destructor will not run.
    throw;
  }
}

JobManager::~JobManager() { Shutdown(); }

const char* JobManager::StateName(State state) {
  switch (state) {
    case State::kQueued:
      return "queued";
    case State::kRunning:
      return "running";
    case State::kDone:
      return "done";
    case State::kFailed:
      return "failed";
    case State::kCancelled:
      return "cancelled";
  }
  return "unknown";
}

Response JobManager::Submit(const Request& inner) {
  auto job = std::make_shared<Job>();
  job->path = inner.path;
  job->inner = inner;
  job->created_at = IsoUtc(std::chrono::system_clock::now());
  nlohmann::json body;
  {
    std::lock_guard lock(mutex_);
    const Clock::time_point now = Clock::now();
    EvictLocked(now);
    if (stopping_) {
      return ToResponse(ApiError{503, api::ErrorCode::kShuttingDown,
                                 "the server is shutting down and accepts no new jobs", ""});
    }
    // Jobs an idle worker is about to take do not count as waiting, so the
    // limit does not depend on how fast the workers wake up.
    const std::size_t idle = static_cast<std::size_t>(config_.workers - busy_);
    const std::size_t waiting = queue_.size() > idle ? queue_.size() - idle : 0;
    if (waiting >= config_.max_queued) {
      return ToResponse(ApiError{429, api::ErrorCode::kTooBusy,
                                 "job queue is full: " + std::to_string(waiting) +
                                     " jobs queued (limit max_queued = " +
                                     std::to_string(config_.max_queued) + "); retry later",
                                 ""});
    }
    job->id = NewIdLocked();
    job->seq = next_seq_++;
    job->created = now;
    // Saved before it is visible: a 202 means the job survives a restart. The
    // store's own message goes to the log, never to the client.
    if (!SaveLocked(*job)) {
      return ToResponse(ApiError{503, api::ErrorCode::kUnavailable,
                                 "the job could not be saved in the jobs database; retry later",
                                 ""});
    }
    jobs_.emplace(job->id, job);
    queue_.push_back(job->id);
    body = ToJsonLocked(*job, now);
  }
  work_cv_.notify_one();
  return {202, std::move(body)};
}

Response JobManager::Status(const std::string& id) const {
  std::lock_guard lock(mutex_);
  const Clock::time_point now = Clock::now();
  EvictLocked(now);
  const std::shared_ptr<Job> job = FindLocked(id);
  if (!job) return JobNotFound(id);
  return {200, ToJsonLocked(*job, now)};
}

Response JobManager::List(const api::JobListQuery& query) const {
  std::lock_guard lock(mutex_);
  const Clock::time_point now = Clock::now();
  EvictLocked(now);
  std::vector<const Job*> all;
  all.reserve(jobs_.size());
  for (const auto& [id, job] : jobs_) {
    if (!query.state || *query.state == StateName(job->state)) all.push_back(job.get());
  }
  // Newest first; the submit order (seq) breaks ties of the clock.
  std::sort(all.begin(), all.end(), [](const Job* a, const Job* b) {
    return a->created != b->created ? a->created > b->created : a->seq > b->seq;
  });
  nlohmann::json list = nlohmann::json::array();
  const std::size_t from = std::min(query.offset, all.size());
  const std::size_t to = from + std::min(query.limit, all.size() - from);
  for (std::size_t i = from; i < to; ++i) list.push_back(ToJsonLocked(*all[i], now));
  nlohmann::json next_offset = to < all.size() ? nlohmann::json(to) : nlohmann::json();
  return {200, nlohmann::json{{"jobs", std::move(list)},
                              {"total", all.size()},
                              {"next_offset", std::move(next_offset)}}};
}

Response JobManager::Result(const std::string& id) const {
  {
    std::lock_guard lock(mutex_);
    EvictLocked(Clock::now());
    const std::shared_ptr<Job> job = FindLocked(id);
    if (!job) return JobNotFound(id);
    switch (job->state) {
      case State::kDone:
      case State::kFailed:
        if (!job->result_in_store) return job->result;
        break;
      case State::kCancelled:
        if (!job->kept_result) return JobWasCancelled(id);
        if (!job->result_in_store) return job->result;
        break;
      case State::kQueued:
      case State::kRunning:
        return JobNotReady(id, StateName(job->state));
    }
  }
  // Opened outside the lock, and read piece by piece as the client takes it (it can be
  // 256 MiB: never whole in memory); a job deleted meanwhile has no row.
  std::optional<StoredResult> stored;
  std::string error;
  if (!persistence_.store->OpenResult(id, &stored, &error)) {
    if (persistence_.on_store_error) {
      std::lock_guard lock(mutex_);  // on_store_error is called with the lock held.
      persistence_.on_store_error("cannot read the result of job " + id + ": " + error);
    }
    return ToResponse(ApiError{503, api::ErrorCode::kUnavailable,
                               "the job's result could not be read from the jobs database; "
                               "retry later",
                               ""});
  }
  if (!stored) return JobNotFound(id);
  const bool json = stored->content_type.empty();
  Response out = Response::Text(stored->status, std::string(),
                                json ? "application/json" : stored->content_type);
  auto source = std::make_shared<api::BodySource>();
  // A JSON body ends with a newline, as the server ends one.
  source->bytes = stored->bytes + (json ? 1 : 0);
  source->read = [store = persistence_.store, stored = *stored, json](
                     std::uint64_t offset, std::size_t max, std::string* piece) {
    if (offset < stored.bytes) {
      const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(max, stored.bytes - offset));
      std::string ignored;
      if (!store->ReadResult(stored, offset, n, piece, &ignored)) return false;
      offset += n;
      max -= n;
    }
    if (json && offset == stored.bytes && max > 0) piece->push_back('\n');
    return true;
  };
  out.source = std::move(source);
  return out;
}

Response JobManager::Cancel(const std::string& id) {
  std::lock_guard lock(mutex_);
  const Clock::time_point now = Clock::now();
  EvictLocked(now);
  const std::shared_ptr<Job> job = FindLocked(id);
  if (!job) return JobNotFound(id);
  switch (job->state) {
    case State::kQueued: {
      queue_.erase(std::find(queue_.begin(), queue_.end(), id));
      job->cancel_requested = true;
      job->progress.Cancel();
      Release(&job->inner);  // Frees the body now.
      FinishLocked(*job, State::kCancelled, now);
      SaveLocked(*job);
      nlohmann::json body = ToJsonLocked(*job, now);
      EvictLocked(now);  // max_kept may now be exceeded.
      return {200, std::move(body)};
    }
    case State::kRunning:
      if (!job->cancel_requested) {
        job->cancel_requested = true;
        job->progress.Cancel();
        SaveLocked(*job);  // A crash now must not resume a job the client cancelled.
      }
      return {202, ToJsonLocked(*job, now)};
    case State::kDone:
    case State::kFailed:
    case State::kCancelled:
      break;
  }
  nlohmann::json body = ToJsonLocked(*job, now);
  body["deleted"] = true;
  ForgetResultLocked(*job);
  finished_.erase(std::find(finished_.begin(), finished_.end(), id));
  jobs_.erase(id);
  ForgetLocked(id);
  return {200, std::move(body)};
}

std::map<std::string, int> JobManager::CountsByState() const {
  std::map<std::string, int> counts;
  for (State state :
       {State::kQueued, State::kRunning, State::kDone, State::kFailed, State::kCancelled}) {
    counts[StateName(state)] = 0;
  }
  std::lock_guard lock(mutex_);
  EvictLocked(Clock::now());
  for (const auto& [id, job] : jobs_) ++counts[StateName(job->state)];
  return counts;
}

void JobManager::Shutdown() { Shutdown(0.0); }

void JobManager::Shutdown(double grace_s) {
  std::call_once(shutdown_once_, [this, grace_s] {
    {
      std::unique_lock lock(mutex_);
      stopping_ = true;  // Submit answers 503; idle workers leave, busy ones after their job.
      if (persistence_.store == nullptr) {
        const Clock::time_point now = Clock::now();
        for (const std::string& id : queue_) {
          Job& job = *jobs_.at(id);
          job.cancel_requested = true;
          job.progress.Cancel();
          Release(&job.inner);
          FinishLocked(job, State::kCancelled, now);
        }
        queue_.clear();
      }  // With a store, queued jobs stay queued (and saved) for the next start.
      work_cv_.notify_all();
      if (grace_s > 0 && std::isfinite(grace_s)) {
        const auto deadline =
            Clock::now() + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(std::min(grace_s, 1e6)));
        idle_cv_.wait_until(lock, deadline, [this] { return busy_ == 0 || grace_ended_; });
      }
      for (const auto& [id, job] : jobs_) {
        if (job->state != State::kRunning || job->cancel_requested) continue;
        if (persistence_.store != nullptr) {
          job->interrupted = true;  // Back to the queue when its runner returns.
        } else {
          job->cancel_requested = true;
        }
        job->progress.Cancel();
      }
      EvictLocked(Clock::now());
    }
    for (std::thread& worker : workers_) {
      if (worker.joinable()) worker.join();
    }
    {
      std::lock_guard lock(mutex_);
      watchdog_stop_ = true;
    }
    watchdog_cv_.notify_all();
    if (watchdog_.joinable()) watchdog_.join();
  });
}

void JobManager::EndGrace() {
  {
    std::lock_guard lock(mutex_);
    grace_ended_ = true;
  }
  idle_cv_.notify_all();
}

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

    Response response;
    bool threw = false;
    try {
      response = runner_(inner, &job->progress);
    } catch (...) {  // Nothing may leave a worker thread; details stay out of the answer.
      threw = true;
    }
    inner = Request{};
    // Without a store a result lives in memory: max_results_memory_bytes bounds it too.
    const bool memory_bound = persistence_.store == nullptr &&
                              config_.max_results_memory_bytes < config_.max_result_bytes;
    const std::size_t largest =
        memory_bound ? config_.max_results_memory_bytes : config_.max_result_bytes;
    // Outside the lock: a streamed answer (a CSV or NDJSON sweep) is run here, stopped once
    // over the limit; a 2xx answer's size, its JSON serialised once for the size and the
    // store (a sweep's result can be 100 MB).
    std::size_t bytes = 0;
    StreamOutcome streamed = StreamOutcome::kComplete;
    if (!threw) streamed = CollectJobStream(&response, largest, &bytes);
    if (streamed == StreamOutcome::kStopped) {
      // Cancelled (DELETE, the time limit, a shutdown): an incomplete body is no answer.
      KeepOnlyStatus(&response);
      response = ToResponse(ApiError{409, api::ErrorCode::kCancelled,
                                     "the job was stopped before its answer was complete", ""});
    }
    const bool answered = !threw && response.status >= 200 && response.status < 300;
    std::string serialized;
    if (answered && response.content_type.empty()) {
      serialized = SerializeJobBody(response.body);
      bytes = serialized.size();
    }
    const bool too_big = answered && (bytes > largest || streamed == StreamOutcome::kOverLimit);
    if (too_big) {
      const bool stopped = streamed == StreamOutcome::kOverLimit;
      KeepOnlyStatus(&response);
      response = memory_bound
                     ? JobResultTooBig(bytes, "this server's memory", "max_results_memory_bytes",
                                       largest, "--job-results-memory-bytes", stopped)
                     : JobResultTooBig(bytes, "the job service", "max_result_bytes", largest,
                                       "--job-max-result-bytes", stopped);
      serialized.clear();
    }
    if (!answered || too_big) bytes = 0;  // Counted below from the stored answer.

    lock.lock();
    --busy_;
    running_.erase(std::find(running_.begin(), running_.end(), job));
    idle_cv_.notify_all();
    const Clock::time_point now = Clock::now();
    if (job->cancel_requested) {
      // A 2xx answer is kept (an optimisation's best design so far) unless it is too big;
      // anything else is dropped.
      if (answered && !too_big) {
        job->result = std::move(response);
        job->kept_result = true;
      }
      FinishLocked(*job, State::kCancelled, now);
    } else if (job->timed_out) {
      job->result = JobTimedOut(config_.max_time_s);
      job->error = FailureObject(job->result);
      serialized.clear();
      FinishLocked(*job, State::kFailed, now);
    } else if (job->interrupted) {
      // Shutdown cut it short: its result (if any) is discarded, and it is
      // queued again, saved for the next start, which runs it from the start.
      job->state = State::kQueued;
      job->started.reset();
      queue_.push_front(job->id);
      SaveLocked(*job);
      continue;
    } else if (threw) {
      job->result = ToResponse(ApiError{500, api::ErrorCode::kInternalError, "internal error", ""});
      job->error = FailureObject(job->result);
      FinishLocked(*job, State::kFailed, now);
    } else if (answered && !too_big) {
      job->result = std::move(response);
      FinishLocked(*job, State::kDone, now);
    } else {
      job->error = FailureObject(response);
      job->result = std::move(response);
      FinishLocked(*job, State::kFailed, now);
    }
    Release(&job->inner);  // Frees the body; a finished job is never run again.
    if (bytes == 0 && job->result.content_type.empty()) {
      bytes = job->kept_result || job->state != State::kCancelled
                  ? SerializeJobBody(job->result.body).size()  // An error object: small.
                  : 0;
    }
    std::string why;
    bool saved = SaveLocked(*job, &why, &serialized);
    if (!saved && job->state != State::kCancelled) {
      // Never done (or failed with an answer) without it stored: failed with the store's
      // message, saved as such (small), so the next start neither shows a result nor runs it
      // again. Should that save fail too, its row is deleted (below).
      KeepOnlyStatus(&job->result);  // Frees the answer that could not be stored.
      job->result =
          ToResponse(ApiError{503, api::ErrorCode::kUnavailable,
                              "the job's result could not be saved in the jobs database (" + why +
                                  "): it is not kept; submit the job again later",
                              ""});
      job->error = FailureObject(job->result);
      job->state = State::kFailed;
      bytes = SerializeJobBody(job->result.body).size();
      saved = SaveLocked(*job);
    } else if (!saved && job->kept_result) {
      job->kept_result = false;  // A cancelled job whose answer could not be stored keeps none.
      KeepOnlyStatus(&job->result);
      job->result.status = 0;
      bytes = 0;
      saved = SaveLocked(*job);
    }
    // Not even that fits (a full disk): no row is better than its "running" one, which the
    // next start would run again and, after max_resumes, fail as if the server had died.
    if (!saved) ForgetLocked(job->id);
    KeepResultLocked(*job, bytes, saved);
    EvictLocked(now);
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
    KeepOnlyStatus(&job.result);  // Read back by Result().
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
      KeepOnlyStatus(&job->result);  // Saved: Result() reads it back.
      job->result_in_store = true;
    } else {
      finished_.erase(std::find(finished_.begin(), finished_.end(), job->id));
      jobs_.erase(job->id);
    }
  }
}

void JobManager::FinishLocked(Job& job, State state, Clock::time_point now) {
  job.state = state;
  job.finished = now;
  finished_.push_back(job.id);
}

void JobManager::EvictLocked(Clock::time_point now) const {
  // finished_ is in order of finish time (taken under the lock), so the
  // oldest finished job is always at the front.
  while (!finished_.empty()) {
    const auto it = jobs_.find(finished_.front());
    const bool too_many = finished_.size() > config_.max_kept;
    const bool too_old = std::chrono::duration<double>(now - *it->second->finished).count() >=
                         config_.keep_results_s;
    if (!too_many && !too_old) break;
    ForgetResultLocked(*it->second);
    jobs_.erase(it);
    ForgetLocked(finished_.front());
    finished_.pop_front();
  }
}

std::shared_ptr<JobManager::Job> JobManager::FindLocked(const std::string& id) const {
  const auto it = jobs_.find(id);
  return it == jobs_.end() ? nullptr : it->second;
}

double JobManager::ProgressOf(const Job& job) {
  switch (job.state) {
    case State::kQueued:
      return 0.0;
    case State::kDone:
      return 1.0;
    case State::kRunning:
    case State::kFailed:
    case State::kCancelled:
      break;
  }
  return job.progress.Fraction();
}

nlohmann::json JobManager::ToJsonLocked(const Job& job, Clock::time_point now) const {
  auto since_start = [this](Clock::time_point time) {
    return std::chrono::duration<double>(time - start_).count();
  };
  JobView view;
  view.id = job.id;
  view.state = StateName(job.state);
  view.progress = ProgressOf(job);
  view.path = job.path;
  view.created_s = since_start(job.created);
  if (job.started) view.started_s = since_start(*job.started);
  if (job.finished) {
    view.finished_s = since_start(*job.finished);
    view.expires_in_s =
        config_.keep_results_s - std::chrono::duration<double>(now - *job.finished).count();
  }
  view.created_at = job.created_at;
  if (job.state == State::kDone || job.state == State::kFailed || job.kept_result) {
    view.status = job.result.status;
  }
  if (job.state == State::kFailed) view.error = job.error;
  view.cancel_requested = job.cancel_requested;
  view.resumes = job.resumes;
  return JobJson(view);
}

double JobManager::ToUnixSeconds(Clock::time_point time) const {
  const std::chrono::duration<double> since_epoch = wall_start_.time_since_epoch();
  return since_epoch.count() + std::chrono::duration<double>(time - start_).count();
}

JobManager::Clock::time_point JobManager::FromUnixSeconds(double unix_s) const {
  const std::chrono::duration<double> since_epoch = wall_start_.time_since_epoch();
  return start_ + std::chrono::duration_cast<Clock::duration>(
                      std::chrono::duration<double>(unix_s - since_epoch.count()));
}

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
    if (job.result.content_type.empty()) {
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
      Release(&job->inner);
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

std::string JobManager::NewIdLocked() {
  std::string id;
  do {
    id = NewJobId(random_);
  } while (jobs_.count(id) != 0);
  return id;
}

}  // namespace sweetspot::server
