// JobManager's job (server/jobs/job_manager.hpp), shared by its source files: job_manager.cpp
// (the api's calls), job_manager_run.cpp (the workers, the watchdog, results in memory) and
// job_manager_store.cpp (records saved and loaded). Private to them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>

#include "server/jobs/job_manager.hpp"

namespace sweetspot::server {

// Frees a request's body. Assigning a new Request would not: a std::string moved from a short
// one keeps its old buffer (libstdc++), so a 1 MB body stayed allocated.
inline void ReleaseJobRequest(api::Request* request) { std::string().swap(request->body); }

// Leaves only the status of a result, freeing its body (see ReleaseJobRequest: a 10 MB CSV text
// stayed allocated per job when the result was replaced by assignment).
inline void KeepOnlyJobStatus(api::Response* result) {
  const int status = result->status;
  api::Response empty(status, nullptr);
  std::swap(*result, empty);  // `empty` now owns the old buffers and frees them here.
}

struct JobManager::Job {
  std::string id;                             // 32 hex digits.
  std::uint64_t seq = 0;                      // Submit order (for the list's ties).
  std::string path;                           // The inner request's path.
  api::Request inner;                         // Cleared once the job is finished.
  State state = State::kQueued;               // Current state.
  core::Progress progress;                    // Shared with the runner.
  bool cancel_requested = false;              // DELETE or Shutdown asked it to stop.
  bool interrupted = false;                   // Shutdown (with a store) asked it to stop.
  int resumes = 0;                            // Re-queued after the server died under it.
  Clock::time_point created;                  // Submit time.
  std::optional<Clock::time_point> started;   // When a worker took it.
  std::optional<Clock::time_point> finished;  // When it reached a final state.
  std::string created_at;                     // Submit time, ISO-8601 UTC.
  api::Response result;                       // The inner response (done, failed, kept).
  bool kept_result = false;                   // Cancelled, with the runner's 2xx in result.
  nlohmann::json error;                       // The failure's error object (failed), else null.
  bool timed_out = false;                     // The watchdog stopped it (max_time_s).
  bool result_in_store = false;               // result holds only the status; the store has it.
  std::size_t memory_bytes = 0;               // Its result's bytes counted in memory.
  // Its result is in the store's pieces (JobStore::SaveResultChunk), this many bytes.
  std::optional<std::uint64_t> chunked_bytes;
};

}  // namespace sweetspot::server
