// JobStore in an embedded SQLite database: the service's jobs and their
// results survive a restart (and a crash: every Save is committed before it
// returns). Lives in the server layer because it is I/O against a system
// library, like httplib; JobManager only sees the JobStore interface.
//
// The database: one table `jobs` (one row per job, the columns of
// JobRecord) and `job_result_chunks` (a result over kResultChunkBytes, in pieces written
// while its job ran: JobStore::SaveResultChunk), schema version in PRAGMA user_version
// (kSchemaVersion; a newer version is refused, never rewritten). WAL journal with
// synchronous=NORMAL: a commit survives the process being killed (SIGKILL, a
// crash), though the last commits may be lost on a power failure. Exclusive
// locking mode: one server per database file; a second one is refused at Open
// ("is locked") instead of running the first one's jobs too.
#pragma once

#include <cstddef>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <vector>

#include "core/refusal.hpp"
#include "server/jobs/job_store.hpp"

struct sqlite3;
struct sqlite3_stmt;

namespace sweetspot::server {

/// Options of SqliteJobStore::Open, with their defaults.
struct SqliteJobStoreOptions {
  /// How long a statement waits for a lock another connection holds, s, in [0, 60].
  /// Only a second process on the same file waits (and is then refused).
  double busy_timeout_s = 2.0;

  /// The largest the database file may grow, bytes; 0 = no limit but the disk's. Past it a save
  /// fails with SQLite's "database or disk is full", as on a full disk (PRAGMA max_page_count,
  /// rounded down to whole pages; never below the file's size at Open). 0 or in [65536, 1e15].
  std::size_t max_bytes = 0;

  /// True when every field is in range; otherwise the refusal in *refusal (if non-null): field,
  /// value and rule, its Message() "field = value: rule".
  bool Validate(core::Refusal* refusal) const;
};

/// A JobStore in one SQLite database file. Thread-safe: one connection,
/// serialized by a mutex, with prepared statements.
class SqliteJobStore final : public JobStore {
 public:
  /// The schema this code writes (PRAGMA user_version).
  static constexpr int kSchemaVersion = 2;

  /// Opens or creates the database at `path` (":memory:" for a private
  /// in-memory one), sets WAL and exclusive locking, creates or checks the
  /// schema. Null with the reason in *error (if non-null) when the file cannot
  /// be opened or created, is not a database, has a newer schema, or is locked
  /// by another process; or when `options` are invalid.
  static std::unique_ptr<SqliteJobStore> Open(const std::string& path, std::string* error,
                                              const SqliteJobStoreOptions& options = {});

  /// Finalizes the statements and closes the connection (releases the lock).
  ~SqliteJobStore() override;
  SqliteJobStore(const SqliteJobStore&) = delete;
  SqliteJobStore& operator=(const SqliteJobStore&) = delete;

  /// INSERT OR REPLACE of the record; committed when it returns true.
  bool Save(const JobRecord& record, std::string* error) override;
  /// DELETE by id; true also when there was no such row.
  bool Delete(const std::string& id, std::string* error) override;
  /// Every row, ordered by created_unix_s then id; results over kMaxLoadedResultBytes left out.
  bool LoadAll(std::vector<JobRecord>* records, std::string* error) override;
  /// SELECT of one row's result columns.
  bool LoadResult(const std::string& id, std::optional<JobRecord>* record,
                  std::string* error) override;
  /// The result's row and size, without reading it (SQLite's incremental blob I/O).
  bool OpenResult(const std::string& id, std::optional<StoredResult>* result,
                  std::string* error) override;
  /// One piece of the result, read from its row (a record replaced or deleted since is gone).
  bool ReadResult(const StoredResult& result, std::uint64_t offset, std::size_t max,
                  std::string* out, std::string* error) override;
  /// True: results over kResultChunkBytes go to the table job_result_chunks as they are made.
  bool KeepsResultChunks() const override { return true; }
  /// INSERT OR REPLACE of one piece; committed when it returns true.
  bool SaveResultChunk(const std::string& id, std::uint64_t seq, std::string_view bytes,
                       std::string* error) override;
  /// DELETE of the job's pieces.
  bool DeleteResultChunks(const std::string& id, std::string* error) override;

 private:
  explicit SqliteJobStore(std::string path);
  bool Initialize(const SqliteJobStoreOptions& options, std::string* error);
  // "what: SQLite's message (code N)" for the last failure on the connection.
  std::string Failure(const std::string& what, int code) const;
  // Runs `statement` (DELETE ... WHERE ... = ?1) for `id`; *error "what id: ..." on failure.
  bool DeleteLocked(sqlite3_stmt* statement, const std::string& id, const std::string& what,
                    std::string* error);
  // Reads `n` bytes from `offset` of a result in pieces (one or two pieces a call).
  bool ReadChunksLocked(const StoredResult& result, std::uint64_t offset, std::size_t n,
                        std::string* out, std::string* error);

  const std::string path_;
  std::mutex mutex_;                       // Serializes every use of the connection and statements.
  sqlite3* db_ = nullptr;                  // The connection.
  sqlite3_stmt* save_ = nullptr;           // INSERT OR REPLACE INTO jobs ...
  sqlite3_stmt* delete_ = nullptr;         // DELETE FROM jobs WHERE id = ?1
  sqlite3_stmt* load_ = nullptr;           // SELECT ... FROM jobs ORDER BY ...
  sqlite3_stmt* result_ = nullptr;         // SELECT status, response_json, ... WHERE id = ?1
  sqlite3_stmt* save_chunk_ = nullptr;     // INSERT OR REPLACE INTO job_result_chunks ...
  sqlite3_stmt* delete_chunks_ = nullptr;  // DELETE FROM job_result_chunks WHERE job_id = ?1
};

}  // namespace sweetspot::server
