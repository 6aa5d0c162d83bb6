#include "server/jobs/job_common.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <sstream>
#include <string_view>

#include "api/json_reader.hpp"

namespace sweetspot::server {
namespace {

constexpr int kMaxWorkers = 64;
constexpr std::size_t kMaxQueuedLimit = 1000000;
constexpr std::size_t kMaxKeptLimit = 1000000;
constexpr int kMaxResumesLimit = 100;
constexpr double kMaxLeaseS = 3600.0;
constexpr std::size_t kMinResultBytes = 1024;
constexpr std::size_t kMaxResultBytes = 1000000000000;  // In pieces: no column holds it whole.
constexpr std::size_t kMaxResultsMemoryBytes = 1000000000000;
constexpr double kMaxJobTimeS = 1e6;

// Seconds rounded to microseconds (keeps the JSON short).
double RoundedSeconds(double seconds) { return std::round(seconds * 1e6) / 1e6; }

nlohmann::json OptionalSeconds(const std::optional<double>& seconds) {
  return seconds ? nlohmann::json(RoundedSeconds(*seconds)) : nlohmann::json();
}

}  // namespace

bool JobConfig::Validate(core::Refusal* refusal) const {
  auto fail = [refusal](core::Refusal why) { return core::Refuse(refusal, std::move(why)); };
  // "must be in [lo, hi]" with integer bounds.
  auto in = [](long long lo, long long hi) {
    return "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  };
  // A double as a stream writes it (6 significant digits), as these messages always have.
  auto streamed = [](double value) {
    std::ostringstream text;
    text << value;
    return text.str();
  };
  if (workers < 1 || workers > kMaxWorkers) {
    return fail(core::IntegerRefusal("workers", workers, in(1, kMaxWorkers)));
  }
  if (max_queued < 1 || max_queued > kMaxQueuedLimit) {
    return fail(
        core::QuotedRefusal("max_queued", std::to_string(max_queued), in(1, kMaxQueuedLimit)));
  }
  if (max_kept < 1 || max_kept > kMaxKeptLimit) {
    return fail(core::QuotedRefusal("max_kept", std::to_string(max_kept), in(1, kMaxKeptLimit)));
  }
  if (!std::isfinite(keep_results_s) || keep_results_s <= 0) {
    return fail(
        core::QuotedRefusal("keep_results_s", streamed(keep_results_s), "must be finite and > 0"));
  }
  if (max_resumes < 0 || max_resumes > kMaxResumesLimit) {
    return fail(core::IntegerRefusal("max_resumes", max_resumes, in(0, kMaxResumesLimit)));
  }
  if (!std::isfinite(lease_s) || lease_s < 1 || lease_s > kMaxLeaseS) {
    return fail(core::QuotedRefusal("lease_s", streamed(lease_s),
                                    "must be in [1, " + streamed(kMaxLeaseS) + "]"));
  }
  if (max_result_bytes < kMinResultBytes || max_result_bytes > kMaxResultBytes) {
    return fail(core::QuotedRefusal("max_result_bytes", std::to_string(max_result_bytes),
                                    "must be in [" + std::to_string(kMinResultBytes) + ", " +
                                        std::to_string(kMaxResultBytes) + "]"));
  }
  if (max_results_memory_bytes < kMinResultBytes ||
      max_results_memory_bytes > kMaxResultsMemoryBytes) {
    return fail(core::QuotedRefusal("max_results_memory_bytes",
                                    std::to_string(max_results_memory_bytes),
                                    "must be in [" + std::to_string(kMinResultBytes) + ", " +
                                        std::to_string(kMaxResultsMemoryBytes) + "]"));
  }
  if (!std::isfinite(max_time_s) || max_time_s <= 0 || max_time_s > kMaxJobTimeS) {
    return fail(core::QuotedRefusal("max_time_s", streamed(max_time_s),
                                    "must be in (0, " + streamed(kMaxJobTimeS) + "]"));
  }
  return true;
}

nlohmann::json JobJson(const JobView& job) {
  // After the submit, s: never negative (PostgreSQL's clock stamps the start and the finish,
  // the replica's the submit: a skew of a few ms between the two is not a time before it).
  auto after_submit = [&job](const std::optional<double>& unix_s) {
    return unix_s ? std::optional<double>(std::max(0.0, *unix_s - job.created_unix_s))
                  : std::nullopt;
  };
  auto iso = [](const std::optional<double>& unix_s) {
    return unix_s ? nlohmann::json(IsoUtcOfUnixSeconds(*unix_s)) : nlohmann::json();
  };
  return nlohmann::json{
      {"id", job.id},
      {"state", job.state},
      {"progress", job.progress},
      {"path", job.path},
      {"created_s", 0.0},
      {"started_s", OptionalSeconds(after_submit(job.started_unix_s))},
      {"finished_s", OptionalSeconds(after_submit(job.finished_unix_s))},
      {"created_at", job.created_at},
      {"started_at", iso(job.started_unix_s)},
      {"finished_at", iso(job.finished_unix_s)},
      {"status", job.status ? nlohmann::json(*job.status) : nlohmann::json()},
      {"error", job.error ? *job.error : nlohmann::json()},
      {"cancel_requested", job.cancel_requested},
      {"resumes", job.resumes},
      {"expires_in_s", job.expires_in_s ? nlohmann::json(RoundedSeconds(std::max(0.0, *job.expires_in_s)))
                                        : nlohmann::json()},
  };
}

std::string QuoteJobId(const std::string& id) { return api::Show(nlohmann::json(id)); }

api::Response JobNotFound(const std::string& id) {
  return api::ToResponse(
      api::ApiError{404, api::ErrorCode::kNotFound, "no job with id " + QuoteJobId(id), ""});
}

api::Response JobNotReady(const std::string& id, const std::string& state) {
  return api::ToResponse(api::ApiError{409, api::ErrorCode::kNotReady,
                                       "job " + QuoteJobId(id) + " is " + state +
                                           ": its result is ready once its state is done or failed",
                                       ""});
}

api::Response JobWasCancelled(const std::string& id) {
  return api::ToResponse(api::ApiError{409, api::ErrorCode::kCancelled,
                                       "job " + QuoteJobId(id) + " was cancelled: it has no result",
                                       ""});
}

std::string InterruptedMessage(const std::string& resumes, int max_resumes) {
  return "interrupted by a server restart: the job was running when the server "
         "died, and it had already been resumed " +
         resumes + " times (limit max_resumes = " + std::to_string(max_resumes) + ")";
}

api::Response JobTimedOut(double max_time_s) {
  std::ostringstream text;
  text << "the job ran longer than max_time_s = " << max_time_s
       << " s and was stopped (--job-max-time-s): ask for fewer designs or starts, or raise "
          "the limit";
  return api::ToResponse(api::ApiError{408, api::ErrorCode::kTimeout, text.str(), ""});
}

api::Response JobResultTooBig(std::size_t size, const std::string& keeper, const std::string& limit,
                              std::size_t value, const std::string& flag, bool stopped) {
  return api::ToResponse(api::ApiError{413, api::ErrorCode::kTooBig,
                                       "the job's result is " +
                                           std::string(stopped ? "at least " : "") +
                                           std::to_string(size) +
                                           " bytes, more than " + keeper + " keeps (" + limit +
                                           " = " + std::to_string(value) +
                                           "): ask for fewer rows or outputs, or raise " + flag,
                                       ""});
}

api::Response IncompleteStreamAnswer(bool cancelled) {
  if (cancelled) {
    return api::ToResponse(api::ApiError{409, api::ErrorCode::kCancelled,
                                         "the job was stopped before its answer was complete", ""});
  }
  return api::ToResponse(api::ApiError{
      503, api::ErrorCode::kUnavailable,
      "the job's answer stopped before it was complete (its sweep failed, e.g. out of memory): "
      "no partial answer is kept; submit the job again later",
      ""});
}

CollectedStream CollectJobStream(api::Response* response, std::size_t max_bytes,
                                 const ResultChunkWriter& write) {
  CollectedStream out;
  if (!response->stream) {
    out.bytes = response->text.size();
    return out;
  }
  std::string text;
  bool over = false;
  // Hands the full pieces at the front of `text` to the writer, keeping the rest.
  auto flush_full = [&]() {
    std::size_t at = 0;
    while (text.size() - at >= kResultChunkBytes) {
      if (!write(out.pieces, std::string_view(text).substr(at, kResultChunkBytes),
                 &out.write_error)) {
        return false;
      }
      ++out.pieces;
      at += kResultChunkBytes;
    }
    text.erase(0, at);
    return true;
  };
  bool write_failed = false;
  const bool complete = response->stream([&](std::string_view chunk) {
    out.bytes += chunk.size();
    if (out.bytes > max_bytes) {
      over = true;
      return false;  // Stops the producer.
    }
    text.append(chunk);
    if (write && text.size() >= kResultChunkBytes && !flush_full()) {
      write_failed = true;
      return false;
    }
    return true;
  });
  response->stream = nullptr;
  if (!over && !write_failed && complete && out.pieces > 0 && !text.empty()) {
    if (write(out.pieces, text, &out.write_error)) {
      ++out.pieces;
    } else {
      write_failed = true;
    }
  }
  out.chunked = out.pieces > 0;
  if (out.chunked) {
    std::string().swap(text);
  }
  response->text = std::move(text);
  if (over) {
    out.outcome = StreamOutcome::kOverLimit;
  } else if (write_failed) {
    out.outcome = StreamOutcome::kWriteFailed;
  } else if (!complete) {
    out.outcome = StreamOutcome::kStopped;
  }
  return out;
}

bool NormalizeJsonResult(api::Response* response, bool chunked) {
  if (response->content_type != "application/json") return true;
  if (chunked) {
    response->content_type.clear();  // Its pieces are the JSON text, as response_json holds it.
    return true;
  }
  if (response->text.size() > kResultChunkBytes) {
    // Kept in memory whole (no store keeps pieces): sent as it is, with the newline the server
    // ends a JSON answer with, rather than parsed into values several times its size.
    response->text.push_back('\n');
    return true;
  }
  nlohmann::json body = nlohmann::json::parse(response->text, nullptr, false);
  if (body.is_discarded()) return false;
  std::string().swap(response->text);
  response->body = std::move(body);
  response->content_type.clear();
  return true;
}

api::Response JobInterrupted(int resumes, int max_resumes, std::string* message) {
  *message = InterruptedMessage(std::to_string(resumes), max_resumes);
  return api::ToResponse(api::ApiError{503, api::ErrorCode::kInterrupted, *message, ""});
}

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

std::string IsoUtcOfUnixSeconds(double unix_s) {
  return IsoUtc(std::chrono::system_clock::time_point(
      std::chrono::duration_cast<std::chrono::system_clock::duration>(
          std::chrono::duration<double>(unix_s))));
}

std::string SerializeJobBody(const nlohmann::json& body) {
  return body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string FailureMessage(const api::Response& response) {
  if (response.body.is_object()) {
    const auto it = response.body.find("message");
    if (it != response.body.end() && it->is_string()) return it->get<std::string>();
  }
  return "the request failed with HTTP status " + std::to_string(response.status);
}

nlohmann::json FailureObject(const api::Response& response) {
  return api::JobErrorObject(response.status, response.body, FailureMessage(response));
}

std::string StoredJobError(const nlohmann::json& error) { return SerializeJobBody(error); }

nlohmann::json ReadStoredJobError(const std::string& stored, int status,
                                  const nlohmann::json& body) {
  if (!stored.empty() && stored.front() == '{') {
    nlohmann::json parsed = nlohmann::json::parse(stored, nullptr, false);
    if (parsed.is_object() && parsed.contains("code")) return parsed;
  }
  return api::JobErrorObject(status, body, stored);
}

std::mt19937_64 SeededEngine() {
  std::random_device device;
  std::seed_seq seed{device(), device(), device(), device(),
                     device(), device(), device(), device()};
  return std::mt19937_64(seed);
}

std::string NewJobId(std::mt19937_64& random) {
  char text[33];
  std::snprintf(text, sizeof(text), "%016llx%016llx", static_cast<unsigned long long>(random()),
                static_cast<unsigned long long>(random()));
  return text;
}

}  // namespace sweetspot::server
