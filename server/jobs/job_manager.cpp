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
#include "server/jobs/job_manager_job.hpp"

namespace sweetspot::server {

using api::ApiError;
using api::Request;
using api::Response;
using api::ToResponse;

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
      ReleaseJobRequest(&job->inner);  // Frees the body now.
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
          ReleaseJobRequest(&job.inner);
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
  JobView view;
  view.id = job.id;
  view.state = StateName(job.state);
  view.progress = ProgressOf(job);
  view.path = job.path;
  // Absolute (a stored job's times are its stored ones, whatever this process's start).
  view.created_unix_s = ToUnixSeconds(job.created);
  if (job.started) view.started_unix_s = ToUnixSeconds(*job.started);
  if (job.finished) {
    view.finished_unix_s = ToUnixSeconds(*job.finished);
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

std::string JobManager::NewIdLocked() {
  std::string id;
  do {
    id = NewJobId(random_);
  } while (jobs_.count(id) != 0);
  return id;
}

}  // namespace sweetspot::server
