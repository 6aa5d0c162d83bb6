#include "api/jobs.hpp"

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

namespace sweetspot::api {
namespace {

constexpr int kMaxWorkers = 64;
constexpr std::size_t kMaxQueuedLimit = 1000000;
constexpr std::size_t kMaxKeptLimit = 1000000;

// An engine seeded from std::random_device with 256 bits, one per manager.
std::mt19937_64 SeededEngine() {
  std::random_device device;
  std::seed_seq seed{device(), device(), device(), device(),
                     device(), device(), device(), device()};
  return std::mt19937_64(seed);
}

// "2024-05-01T12:00:00.123Z".
std::string IsoUtc(std::chrono::system_clock::time_point time) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(time.time_since_epoch());
  const std::time_t seconds = static_cast<std::time_t>(ms.count() / 1000);
  std::tm utc{};
  gmtime_r(&seconds, &utc);
  char date[32];
  std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%S", &utc);
  char text[48];
  std::snprintf(text, sizeof(text), "%s.%03dZ", date, static_cast<int>(ms.count() % 1000));
  return text;
}

// Seconds rounded to microseconds (keeps the JSON short).
double RoundedSeconds(double seconds) { return std::round(seconds * 1e6) / 1e6; }

// The quoted id for messages ("\"abc\"", cut when long, control characters escaped).
std::string QuoteId(const std::string& id) { return Show(nlohmann::json(id)); }

Response NotFound(const std::string& id) {
  return ToResponse(ApiError{404, "NotFound", "no job with id " + QuoteId(id), ""});
}

}  // namespace

struct JobManager::Job {
  std::string id;                             // 32 hex digits.
  std::string path;                           // The inner request's path.
  Request inner;                              // Moved out by the worker that runs it.
  State state = State::kQueued;               // Current state.
  core::Progress progress;                    // Shared with the runner.
  bool cancel_requested = false;              // DELETE or Shutdown asked it to stop.
  Clock::time_point created;                  // Submit time.
  std::optional<Clock::time_point> started;   // When a worker took it.
  std::optional<Clock::time_point> finished;  // When it reached a final state.
  std::string created_at;                     // Submit time, ISO-8601 UTC.
  Response result;                            // The inner response (done or failed).
  std::string error;                          // The failure's message (failed).
};

bool JobConfig::IsValid(std::string* why) const {
  auto fail = [why](const std::string& text) {
    if (why != nullptr) *why = text;
    return false;
  };
  if (workers < 1 || workers > kMaxWorkers) {
    return fail("workers = " + std::to_string(workers) + ": must be in [1, " +
                std::to_string(kMaxWorkers) + "]");
  }
  if (max_queued < 1 || max_queued > kMaxQueuedLimit) {
    return fail("max_queued = " + std::to_string(max_queued) + ": must be in [1, " +
                std::to_string(kMaxQueuedLimit) + "]");
  }
  if (max_kept < 1 || max_kept > kMaxKeptLimit) {
    return fail("max_kept = " + std::to_string(max_kept) + ": must be in [1, " +
                std::to_string(kMaxKeptLimit) + "]");
  }
  if (!std::isfinite(keep_results_s) || keep_results_s <= 0) {
    std::ostringstream text;
    text << "keep_results_s = " << keep_results_s << ": must be finite and > 0";
    return fail(text.str());
  }
  return true;
}

JobManager::JobManager(JobConfig config, JobRunner runner)
    : config_(config), runner_(std::move(runner)), start_(Clock::now()), random_(SeededEngine()) {
  std::string why;
  if (!config_.IsValid(&why)) throw std::invalid_argument("invalid JobConfig: " + why);
  if (!runner_) throw std::invalid_argument("invalid JobManager: the runner is empty");
  try {
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
      return ToResponse(
          ApiError{503, "ShuttingDown", "the server is shutting down and accepts no new jobs", ""});
    }
    // Jobs an idle worker is about to take do not count as waiting, so the
    // limit does not depend on how fast the workers wake up.
    const std::size_t idle = static_cast<std::size_t>(config_.workers - busy_);
    const std::size_t waiting = queue_.size() > idle ? queue_.size() - idle : 0;
    if (waiting >= config_.max_queued) {
      return ToResponse(ApiError{429, "TooBusy",
                                 "job queue is full: " + std::to_string(waiting) +
                                     " jobs queued (limit max_queued = " +
                                     std::to_string(config_.max_queued) + "); retry later",
                                 ""});
    }
    job->id = NewIdLocked();
    job->created = now;
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
  if (!job) return NotFound(id);
  return {200, ToJsonLocked(*job, now)};
}

Response JobManager::Result(const std::string& id) const {
  std::lock_guard lock(mutex_);
  EvictLocked(Clock::now());
  const std::shared_ptr<Job> job = FindLocked(id);
  if (!job) return NotFound(id);
  switch (job->state) {
    case State::kDone:
    case State::kFailed:
      return job->result;
    case State::kCancelled:
      return ToResponse(ApiError{409, "Cancelled",
                                 "job " + QuoteId(id) + " was cancelled: it has no result", ""});
    case State::kQueued:
    case State::kRunning:
      break;
  }
  return ToResponse(ApiError{409, "NotReady",
                             "job " + QuoteId(id) + " is " + StateName(job->state) +
                                 ": its result is ready once its state is done or failed",
                             ""});
}

Response JobManager::Cancel(const std::string& id) {
  std::lock_guard lock(mutex_);
  const Clock::time_point now = Clock::now();
  EvictLocked(now);
  const std::shared_ptr<Job> job = FindLocked(id);
  if (!job) return NotFound(id);
  switch (job->state) {
    case State::kQueued: {
      queue_.erase(std::find(queue_.begin(), queue_.end(), id));
      job->cancel_requested = true;
      job->progress.Cancel();
      job->inner = Request{};  // Frees the body now.
      FinishLocked(*job, State::kCancelled, now);
      nlohmann::json body = ToJsonLocked(*job, now);
      EvictLocked(now);  // max_kept may now be exceeded.
      return {200, std::move(body)};
    }
    case State::kRunning:
      job->cancel_requested = true;
      job->progress.Cancel();
      return {202, ToJsonLocked(*job, now)};
    case State::kDone:
    case State::kFailed:
    case State::kCancelled:
      break;
  }
  nlohmann::json body = ToJsonLocked(*job, now);
  body["deleted"] = true;
  finished_.erase(std::find(finished_.begin(), finished_.end(), id));
  jobs_.erase(id);
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

void JobManager::Shutdown() {
  std::call_once(shutdown_once_, [this] {
    {
      std::lock_guard lock(mutex_);
      stopping_ = true;
      const Clock::time_point now = Clock::now();
      for (const std::string& id : queue_) {
        Job& job = *jobs_.at(id);
        job.cancel_requested = true;
        job.progress.Cancel();
        job.inner = Request{};
        FinishLocked(job, State::kCancelled, now);
      }
      queue_.clear();
      for (const auto& [id, job] : jobs_) {
        if (job->state == State::kRunning) {
          job->cancel_requested = true;
          job->progress.Cancel();
        }
      }
      EvictLocked(now);
    }
    work_cv_.notify_all();
    for (std::thread& worker : workers_) {
      if (worker.joinable()) worker.join();
    }
  });
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
    Request inner = std::move(job->inner);
    job->inner = Request{};
    lock.unlock();

    Response response;
    bool threw = false;
    try {
      response = runner_(inner, &job->progress);
    } catch (...) {  // Nothing may leave a worker thread; details stay out of the answer.
      threw = true;
    }
    inner = Request{};

    lock.lock();
    --busy_;
    const Clock::time_point now = Clock::now();
    if (job->cancel_requested) {
      FinishLocked(*job, State::kCancelled, now);  // A cancelled job's result is discarded.
    } else if (threw) {
      job->error = "internal error";
      job->result = ToResponse(ApiError{500, "InternalError", job->error, ""});
      FinishLocked(*job, State::kFailed, now);
    } else if (response.status >= 200 && response.status < 300) {
      job->result = std::move(response);
      FinishLocked(*job, State::kDone, now);
    } else {
      const nlohmann::json& message = response.body.is_object() && response.body.contains("message")
                                          ? response.body["message"]
                                          : nlohmann::json();
      job->error = message.is_string()
                       ? message.get<std::string>()
                       : "the request failed with HTTP status " + std::to_string(response.status);
      job->result = std::move(response);
      FinishLocked(*job, State::kFailed, now);
    }
    EvictLocked(now);
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
    jobs_.erase(it);
    finished_.pop_front();
  }
}

std::shared_ptr<JobManager::Job> JobManager::FindLocked(const std::string& id) const {
  const auto it = jobs_.find(id);
  return it == jobs_.end() ? nullptr : it->second;
}

nlohmann::json JobManager::ToJsonLocked(const Job& job, Clock::time_point now) const {
  auto since_start = [this](Clock::time_point time) {
    return nlohmann::json(RoundedSeconds(std::chrono::duration<double>(time - start_).count()));
  };
  double progress = 0.0;
  switch (job.state) {
    case State::kQueued:
      progress = 0.0;
      break;
    case State::kDone:
      progress = 1.0;
      break;
    case State::kRunning:
    case State::kFailed:
    case State::kCancelled:
      progress = job.progress.Fraction();
      break;
  }
  const bool finished = job.finished.has_value();
  nlohmann::json json{
      {"id", job.id},
      {"state", StateName(job.state)},
      {"progress", progress},
      {"path", job.path},
      {"created_s", since_start(job.created)},
      {"started_s", job.started ? since_start(*job.started) : nlohmann::json()},
      {"finished_s", finished ? since_start(*job.finished) : nlohmann::json()},
      {"created_at", job.created_at},
      {"status", job.state == State::kDone || job.state == State::kFailed
                     ? nlohmann::json(job.result.status)
                     : nlohmann::json()},
      {"error", job.state == State::kFailed ? nlohmann::json(job.error) : nlohmann::json()},
      {"cancel_requested", job.cancel_requested},
  };
  if (finished) {
    const double age_s = std::chrono::duration<double>(now - *job.finished).count();
    json["expires_in_s"] = RoundedSeconds(std::max(0.0, config_.keep_results_s - age_s));
  } else {
    json["expires_in_s"] = nullptr;
  }
  return json;
}

std::string JobManager::NewIdLocked() {
  std::string id;
  do {
    char text[33];
    std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(random_()),
                  static_cast<unsigned long long>(random_()));
    id = text;
  } while (jobs_.count(id) != 0);
  return id;
}

}  // namespace sweetspot::api
