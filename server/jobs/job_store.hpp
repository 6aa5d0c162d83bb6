// Where a JobManager keeps its jobs so that they survive a restart: a small
// storage interface JobManager calls and the SQLite store implements (
// server/jobs/sqlite_job_store.hpp). Database-agnostic: a record is plain
// values, the store only saves, deletes and loads them.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sweetspot::server {

/// One job as stored: everything needed to show it, give its result, or run it
/// again after a restart. Times are wall-clock seconds since the Unix epoch.
struct JobRecord {
  std::string id;         ///< 32 lowercase hex digits.
  std::string state;      ///< "queued", "running", "done", "failed" or "cancelled".
  std::string method;     ///< The inner request's method ("POST").
  std::string path;       ///< The inner request's path ("/v1/explore").
  std::string body;       ///< The inner request's body; kept only while the job is unfinished.
  double progress = 0.0;  ///< Last saved progress, in [0, 1].
  bool cancel_requested = false;  ///< DELETE asked the job to stop.
  int resumes = 0;                ///< Times the job was re-queued after the server died under it.
  std::string created_at;         ///< Submit time, ISO-8601 UTC ("2024-05-01T12:00:00.123Z").
  double created_unix_s = 0.0;    ///< Submit time, s since the Unix epoch.
  std::optional<double> started_unix_s;   ///< When a worker took it, s since the epoch.
  std::optional<double> finished_unix_s;  ///< When it reached done/failed/cancelled, s.
  int status = 0;             ///< The inner response's HTTP status; 0 until done or failed.
  std::string response_json;  ///< The inner response's JSON body, serialised; "" if none.
  std::string response_text;  ///< A non-JSON inner response body (with content_type).
  std::string content_type;   ///< The non-JSON body's type; "" for a JSON body.
  std::string error;          ///< The failure's message (failed), else "".
  /// LoadAll left the result (response_json, response_text) out because it is larger than
  /// kMaxLoadedResultBytes (or in pieces): LoadResult or OpenResult reads it.
  bool result_in_store = false;
  /// Set when the result is not in response_json/response_text but in the pieces written by
  /// JobStore::SaveResultChunk while the job ran: its length, bytes (JSON when content_type is
  /// empty, as response_json would hold it).
  std::optional<std::uint64_t> chunked_bytes;
};

/// A result larger than this is written to the store in pieces of this size as it is produced
/// (JobStore::SaveResultChunk; the last piece may be shorter), never whole in memory; a smaller
/// one is saved with its record. Bytes.
inline constexpr std::size_t kResultChunkBytes = 1u << 20;

/// LoadAll returns results up to this size (bytes of response_json plus response_text); larger
/// ones stay in the store (JobRecord::result_in_store), so a restart does not load them all.
inline constexpr std::size_t kMaxLoadedResultBytes = 64 * 1024;

/// Where a stored result is, for reading it piece by piece (JobStore::OpenResult, ReadResult).
struct StoredResult {
  int status = 0;            ///< The inner response's HTTP status.
  std::string content_type;  ///< The non-JSON body's type; "" for a JSON body.
  std::uint64_t bytes = 0;   ///< The body's length as stored, bytes.
  std::int64_t row = 0;      ///< The store's handle of the record (SQLite: its rowid).
  std::string id;            ///< The job's id.
  bool chunked = false;      ///< In pieces of kResultChunkBytes (JobRecord::chunked_bytes).
  /// The body itself, when the store read it whole (JobStore's default OpenResult); else null.
  std::shared_ptr<const std::string> loaded;
};

/// Saves, deletes and loads job records. Implementations are thread-safe.
/// Every call reports failure by returning false with a message in *error
/// (if non-null); none throws.
class JobStore {
 public:
  virtual ~JobStore() = default;

  /// Inserts `record`, or replaces the record with the same id. Durable once
  /// it returns true (survives the process being killed).
  virtual bool Save(const JobRecord& record, std::string* error) = 0;

  /// Removes the record with this id (no error if there is none).
  virtual bool Delete(const std::string& id, std::string* error) = 0;

  /// Every stored record, oldest created first (replaces *records); results larger than
  /// kMaxLoadedResultBytes are left out (JobRecord::result_in_store).
  virtual bool LoadAll(std::vector<JobRecord>* records, std::string* error) = 0;

  /// The stored result of job `id` (status, response_json, response_text, content_type; the
  /// other fields may be left empty) in *record, or nullopt when there is no such job.
  virtual bool LoadResult(const std::string& id, std::optional<JobRecord>* record,
                          std::string* error) = 0;

  /// Opens the stored result of job `id` for reading piece by piece (*result: nullopt when
  /// there is no such job). This default reads it whole with LoadResult.
  virtual bool OpenResult(const std::string& id, std::optional<StoredResult>* result,
                          std::string* error) {
    std::optional<JobRecord> record;
    if (!LoadResult(id, &record, error)) return false;
    result->reset();
    if (!record) return true;
    StoredResult out;
    out.status = record->status;
    out.content_type = record->content_type;
    out.loaded = std::make_shared<const std::string>(
        record->content_type.empty() ? std::move(record->response_json)
                                     : std::move(record->response_text));
    out.bytes = out.loaded->size();
    *result = std::move(out);
    return true;
  }

  /// Appends at most `max` bytes of `result`'s body from `offset` to *out; false when the
  /// record is gone (deleted, replaced) or unreadable.
  virtual bool ReadResult(const StoredResult& result, std::uint64_t offset, std::size_t max,
                          std::string* out, std::string* error) {
    if (!result.loaded || offset > result.loaded->size()) {
      if (error != nullptr) *error = "the result is not open";
      return false;
    }
    out->append(result.loaded->substr(offset, max));
    return true;
  }

  /// True when SaveResultChunk works (SqliteJobStore); else results are saved whole with their
  /// records, as Save takes them.
  virtual bool KeepsResultChunks() const { return false; }

  /// Stores piece `seq` (0, 1, ... in order; kResultChunkBytes each but the last) of job `id`'s
  /// result while the job runs; the record saved when it finishes names the length
  /// (JobRecord::chunked_bytes). A piece of the same number is replaced. This default cannot.
  virtual bool SaveResultChunk(const std::string& id, std::uint64_t seq, std::string_view bytes,
                               std::string* error) {
    (void)id;
    (void)seq;
    (void)bytes;
    if (error != nullptr) *error = "this store keeps no result pieces";
    return false;
  }

  /// Drops the result pieces of job `id` (none is no error). Delete drops them too.
  virtual bool DeleteResultChunks(const std::string& id, std::string* error) {
    (void)id;
    (void)error;
    return true;
  }
};

}  // namespace sweetspot::server
