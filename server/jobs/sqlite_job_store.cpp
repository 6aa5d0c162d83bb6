#include "server/jobs/sqlite_job_store.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <utility>

namespace sweetspot::server {
namespace {

constexpr double kMaxBusyTimeoutS = 60.0;
constexpr std::size_t kMinMaxBytes = 65536;
constexpr std::size_t kMaxMaxBytes = 1000000000000000;

// The columns, in the order of the statements' parameters and results.
constexpr const char* kColumns =
    "id, state, method, path, body, progress, cancel_requested, resumes, created_at, "
    "created_unix_s, started_unix_s, finished_unix_s, status, response_json, response_text, "
    "content_type, error, result_bytes";

constexpr const char* kCreateTable =
    "CREATE TABLE IF NOT EXISTS jobs ("
    " id TEXT PRIMARY KEY NOT NULL,"
    " state TEXT NOT NULL CHECK (state IN ('queued', 'running', 'done', 'failed', 'cancelled')),"
    " method TEXT NOT NULL,"
    " path TEXT NOT NULL,"
    " body TEXT NOT NULL,"
    " progress REAL NOT NULL,"
    " cancel_requested INTEGER NOT NULL,"
    " resumes INTEGER NOT NULL,"
    " created_at TEXT NOT NULL,"
    " created_unix_s REAL NOT NULL,"
    " started_unix_s REAL,"
    " finished_unix_s REAL,"
    " status INTEGER NOT NULL,"
    " response_json TEXT NOT NULL,"
    " response_text TEXT NOT NULL,"
    " content_type TEXT NOT NULL,"
    " error TEXT NOT NULL,"
    " result_bytes INTEGER)";

// Version 2: a result over kResultChunkBytes is written in pieces as it is produced
// (JobRecord::chunked_bytes says how long it is; NULL: in response_json/response_text).
constexpr const char* kAddResultBytes = "ALTER TABLE jobs ADD COLUMN result_bytes INTEGER";
constexpr const char* kCreateChunks =
    "CREATE TABLE IF NOT EXISTS job_result_chunks ("
    " job_id TEXT NOT NULL,"
    " seq INTEGER NOT NULL,"
    " data BLOB NOT NULL,"
    " PRIMARY KEY (job_id, seq))";

// The text of column `index` (bytes as stored; NULL gives "").
std::string ColumnText(sqlite3_stmt* statement, int index) {
  const auto* text = sqlite3_column_text(statement, index);
  const int bytes = sqlite3_column_bytes(statement, index);
  if (text == nullptr || bytes <= 0) return {};
  return std::string(reinterpret_cast<const char*>(text), static_cast<std::size_t>(bytes));
}

// Resets a statement after use (its bindings too) so it holds no lock or data.
// sqlite3_reset repeats the last step's error, which the caller already
// reported, so its result is not a new failure.
void Rewind(sqlite3_stmt* statement) {
  sqlite3_reset(statement);
  sqlite3_clear_bindings(statement);
}

}  // namespace

bool SqliteJobStoreOptions::Validate(core::Refusal* refusal) const {
  if (!std::isfinite(busy_timeout_s) || busy_timeout_s < 0 || busy_timeout_s > kMaxBusyTimeoutS) {
    if (refusal == nullptr) return false;
    std::ostringstream shown, rule;  // written as a stream writes them (6 significant digits)
    shown << busy_timeout_s;
    rule << "must be in [0, " << kMaxBusyTimeoutS << "]";
    return core::Refuse(refusal, core::QuotedRefusal("busy_timeout_s", shown.str(), rule.str()));
  }
  if (max_bytes != 0 && (max_bytes < kMinMaxBytes || max_bytes > kMaxMaxBytes)) {
    if (refusal == nullptr) return false;
    return core::Refuse(
        refusal, core::QuotedRefusal("max_bytes", std::to_string(max_bytes),
                                     "must be 0 (no limit) or in [" + std::to_string(kMinMaxBytes) +
                                         ", " + std::to_string(kMaxMaxBytes) + "]"));
  }
  return true;
}

SqliteJobStore::SqliteJobStore(std::string path) : path_(std::move(path)) {}

std::unique_ptr<SqliteJobStore> SqliteJobStore::Open(const std::string& path, std::string* error,
                                                     const SqliteJobStoreOptions& options) {
  if (core::Refusal refused; !options.Validate(&refused)) {
    if (error != nullptr) *error = "invalid SqliteJobStoreOptions: " + refused.Message();
    return nullptr;
  }
  std::string why;
  std::unique_ptr<SqliteJobStore> store(new SqliteJobStore(path));
  if (!store->Initialize(options, &why)) {
    if (error != nullptr) *error = "jobs database \"" + path + "\": " + why;
    return nullptr;  // The destructor closes whatever was opened.
  }
  return store;
}

std::string SqliteJobStore::Failure(const std::string& what, int code) const {
  std::string message = what + ": ";
  message += db_ != nullptr ? sqlite3_errmsg(db_) : sqlite3_errstr(code);
  message += " (code " + std::to_string(code) + ")";
  if ((code & 0xff) == SQLITE_BUSY || (code & 0xff) == SQLITE_LOCKED) {
    message += "; another process (or connection) holds the database: each server needs its own";
  }
  return message;
}

bool SqliteJobStore::Initialize(const SqliteJobStoreOptions& options, std::string* error) {
  std::lock_guard lock(mutex_);
  int code =
      sqlite3_open_v2(path_.c_str(), &db_,
                      SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE | SQLITE_OPEN_FULLMUTEX, nullptr);
  if (code != SQLITE_OK) {
    *error = Failure("cannot open or create it", code);
    return false;
  }
  if ((code = sqlite3_extended_result_codes(db_, 1)) != SQLITE_OK) {
    *error = Failure("sqlite3_extended_result_codes", code);
    return false;
  }
  const int busy_ms = static_cast<int>(std::lround(options.busy_timeout_s * 1000.0));
  if ((code = sqlite3_busy_timeout(db_, busy_ms)) != SQLITE_OK) {
    *error = Failure("sqlite3_busy_timeout", code);
    return false;
  }
  auto exec = [this, error](const char* sql) {
    const int rc = sqlite3_exec(db_, sql, nullptr, nullptr, nullptr);
    if (rc != SQLITE_OK) *error = Failure(sql, rc);
    return rc == SQLITE_OK;
  };
  // Runs one statement that returns one value into *value; false after setting *error.
  auto query_text = [this, error](const char* sql, std::string* value) {
    sqlite3_stmt* statement = nullptr;
    int rc = sqlite3_prepare_v2(db_, sql, -1, &statement, nullptr);
    if (rc == SQLITE_OK) {
      rc = sqlite3_step(statement);
      if (rc == SQLITE_ROW) {
        *value = ColumnText(statement, 0);
        rc = SQLITE_OK;
      }
    }
    if (rc != SQLITE_OK) *error = Failure(sql, rc);
    sqlite3_finalize(statement);  // Its result repeats the step's error, reported above.
    return rc == SQLITE_OK;
  };
  // Exclusive before WAL: the lock is taken by the first write below and kept
  // until close, and WAL then needs no shared-memory file.
  std::string mode;
  if (!query_text("PRAGMA locking_mode = EXCLUSIVE", &mode)) return false;
  if (!query_text("PRAGMA journal_mode = WAL", &mode)) return false;
  if (mode != "wal" && mode != "memory") {  // "memory" for ":memory:".
    *error = "PRAGMA journal_mode = WAL: the journal mode is \"" + mode + "\", not \"wal\"";
    return false;
  }
  if (!exec("PRAGMA synchronous = NORMAL")) return false;

  // Takes the write lock now, so a second server is refused here and not later.
  if (!exec("BEGIN IMMEDIATE")) return false;
  std::string version_text;
  bool ok = query_text("PRAGMA user_version", &version_text);
  const int version = ok ? std::atoi(version_text.c_str()) : 0;
  if (ok && version > kSchemaVersion) {
    *error = "its schema version is " + std::to_string(version) + ", newer than this server's " +
             std::to_string(kSchemaVersion) + ": use a newer server or another database";
    ok = false;
  }
  if (ok && version < kSchemaVersion) {
    // 0: a new file; 1: the jobs without result pieces.
    ok = (version == 0 ? exec(kCreateTable) : exec(kAddResultBytes)) && exec(kCreateChunks) &&
         exec(("PRAGMA user_version = " + std::to_string(kSchemaVersion)).c_str());
  }
  if (!ok) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);  // *error has the first failure.
    return false;
  }
  if (!exec("COMMIT")) return false;
  if (options.max_bytes != 0) {
    std::string page_size;
    if (!query_text("PRAGMA page_size", &page_size)) return false;
    const long long pages =
        static_cast<long long>(options.max_bytes) / std::max(1LL, std::atoll(page_size.c_str()));
    std::string granted;  // SQLite never sets it below the file's current page count.
    if (!query_text(("PRAGMA max_page_count = " + std::to_string(pages)).c_str(), &granted)) {
      return false;
    }
  }

  const std::string save_sql = std::string("INSERT OR REPLACE INTO jobs (") + kColumns +
                               ") VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, "
                               "?13, ?14, ?15, ?16, ?17, ?18)";
  // Results over kMaxLoadedResultBytes are left out (sizes in bytes: a BLOB's length), and
  // results in pieces.
  const std::string big =
      "(result_bytes IS NOT NULL OR length(CAST(response_json AS BLOB)) + "
      "length(CAST(response_text AS BLOB)) > " +
      std::to_string(kMaxLoadedResultBytes) + ")";
  const std::string load_sql =
      "SELECT id, state, method, path, body, progress, cancel_requested, resumes, created_at, "
      "created_unix_s, started_unix_s, finished_unix_s, status, CASE WHEN " +
      big + " THEN '' ELSE response_json END, CASE WHEN " + big +
      " THEN '' ELSE response_text END, content_type, error, " + big +
      ", result_bytes FROM jobs ORDER BY created_unix_s, id";
  const char* delete_sql = "DELETE FROM jobs WHERE id = ?1";
  const char* chunk_sql =
      "INSERT OR REPLACE INTO job_result_chunks (job_id, seq, data) VALUES (?1, ?2, ?3)";
  const char* delete_chunks_sql = "DELETE FROM job_result_chunks WHERE job_id = ?1";
  const char* result_sql =
      "SELECT status, response_json, response_text, content_type FROM jobs WHERE id = ?1";
  for (auto [sql, statement] :
       {std::pair{save_sql.c_str(), &save_}, std::pair{load_sql.c_str(), &load_},
        std::pair{delete_sql, &delete_}, std::pair{result_sql, &result_},
        std::pair{chunk_sql, &save_chunk_}, std::pair{delete_chunks_sql, &delete_chunks_}}) {
    if ((code = sqlite3_prepare_v2(db_, sql, -1, statement, nullptr)) != SQLITE_OK) {
      *error = Failure(std::string("prepare ") + sql, code);
      return false;
    }
  }
  return true;
}

SqliteJobStore::~SqliteJobStore() {
  std::lock_guard lock(mutex_);
  // sqlite3_finalize returns the statement's last error, already reported.
  for (sqlite3_stmt* statement : {save_, delete_, load_, result_, save_chunk_, delete_chunks_}) {
    sqlite3_finalize(statement);
  }
  // With every statement finalized, close cannot be SQLITE_BUSY; there is no
  // one left to report another failure to, and the OS releases the lock anyway.
  sqlite3_close(db_);
}

bool SqliteJobStore::Save(const JobRecord& record, std::string* error) {
  std::lock_guard lock(mutex_);
  int code = SQLITE_OK;
  int index = 0;
  auto text = [&](const std::string& value) {
    if (code == SQLITE_OK) {
      code = sqlite3_bind_text64(save_, ++index, value.data(), value.size(), SQLITE_STATIC,
                                 SQLITE_UTF8);
    }
  };
  auto real = [&](const std::optional<double>& value) {
    if (code == SQLITE_OK) {
      ++index;
      code = value ? sqlite3_bind_double(save_, index, *value) : sqlite3_bind_null(save_, index);
    }
  };
  auto integer = [&](long long value) {
    if (code == SQLITE_OK) code = sqlite3_bind_int64(save_, ++index, value);
  };
  text(record.id);
  text(record.state);
  text(record.method);
  text(record.path);
  text(record.body);
  real(record.progress);
  integer(record.cancel_requested ? 1 : 0);
  integer(record.resumes);
  text(record.created_at);
  real(record.created_unix_s);
  real(record.started_unix_s);
  real(record.finished_unix_s);
  integer(record.status);
  text(record.response_json);
  text(record.response_text);
  text(record.content_type);
  text(record.error);
  if (code == SQLITE_OK) {
    ++index;
    code = record.chunked_bytes
               ? sqlite3_bind_int64(save_, index, static_cast<sqlite3_int64>(*record.chunked_bytes))
               : sqlite3_bind_null(save_, index);
  }
  if (code != SQLITE_OK) {
    if (error != nullptr) *error = Failure("bind parameter " + std::to_string(index), code);
    Rewind(save_);
    return false;
  }
  code = sqlite3_step(save_);
  const bool ok = code == SQLITE_DONE;
  if (!ok && error != nullptr) *error = Failure("save job " + record.id, code);
  Rewind(save_);
  return ok;
}

bool SqliteJobStore::Delete(const std::string& id, std::string* error) {
  std::lock_guard lock(mutex_);
  return DeleteLocked(delete_chunks_, id, "delete the result of job ", error) &&
         DeleteLocked(delete_, id, "delete job ", error);
}

bool SqliteJobStore::DeleteResultChunks(const std::string& id, std::string* error) {
  std::lock_guard lock(mutex_);
  return DeleteLocked(delete_chunks_, id, "delete the result of job ", error);
}

bool SqliteJobStore::DeleteLocked(sqlite3_stmt* statement, const std::string& id,
                                  const std::string& what, std::string* error) {
  int code = sqlite3_bind_text64(statement, 1, id.data(), id.size(), SQLITE_STATIC, SQLITE_UTF8);
  if (code == SQLITE_OK) {
    code = sqlite3_step(statement);
    if (code == SQLITE_DONE) code = SQLITE_OK;
  }
  if (code != SQLITE_OK && error != nullptr) *error = Failure(what + id, code);
  Rewind(statement);
  return code == SQLITE_OK;
}

bool SqliteJobStore::SaveResultChunk(const std::string& id, std::uint64_t seq,
                                     std::string_view bytes, std::string* error) {
  std::lock_guard lock(mutex_);
  int code = sqlite3_bind_text64(save_chunk_, 1, id.data(), id.size(), SQLITE_STATIC, SQLITE_UTF8);
  if (code == SQLITE_OK) code = sqlite3_bind_int64(save_chunk_, 2, static_cast<sqlite3_int64>(seq));
  if (code == SQLITE_OK) {
    code = sqlite3_bind_blob64(save_chunk_, 3, bytes.data(), bytes.size(), SQLITE_STATIC);
  }
  if (code == SQLITE_OK) {
    code = sqlite3_step(save_chunk_);
    if (code == SQLITE_DONE) code = SQLITE_OK;
  }
  if (code != SQLITE_OK && error != nullptr) {
    *error = Failure("save piece " + std::to_string(seq) + " of the result of job " + id, code);
  }
  Rewind(save_chunk_);
  return code == SQLITE_OK;
}

bool SqliteJobStore::LoadAll(std::vector<JobRecord>* records, std::string* error) {
  std::lock_guard lock(mutex_);
  records->clear();
  int code = SQLITE_OK;
  while ((code = sqlite3_step(load_)) == SQLITE_ROW) {
    auto optional_real = [this](int column) -> std::optional<double> {
      if (sqlite3_column_type(load_, column) == SQLITE_NULL) return std::nullopt;
      return sqlite3_column_double(load_, column);
    };
    JobRecord record;
    record.id = ColumnText(load_, 0);
    record.state = ColumnText(load_, 1);
    record.method = ColumnText(load_, 2);
    record.path = ColumnText(load_, 3);
    record.body = ColumnText(load_, 4);
    record.progress = sqlite3_column_double(load_, 5);
    record.cancel_requested = sqlite3_column_int64(load_, 6) != 0;
    record.resumes = static_cast<int>(sqlite3_column_int64(load_, 7));
    record.created_at = ColumnText(load_, 8);
    record.created_unix_s = sqlite3_column_double(load_, 9);
    record.started_unix_s = optional_real(10);
    record.finished_unix_s = optional_real(11);
    record.status = static_cast<int>(sqlite3_column_int64(load_, 12));
    record.response_json = ColumnText(load_, 13);
    record.response_text = ColumnText(load_, 14);
    record.content_type = ColumnText(load_, 15);
    record.error = ColumnText(load_, 16);
    record.result_in_store = sqlite3_column_int64(load_, 17) != 0;
    if (sqlite3_column_type(load_, 18) != SQLITE_NULL) {
      record.chunked_bytes = static_cast<std::uint64_t>(sqlite3_column_int64(load_, 18));
    }
    records->push_back(std::move(record));
  }
  const bool ok = code == SQLITE_DONE;
  if (!ok) {
    records->clear();
    if (error != nullptr) *error = Failure("load jobs", code);
  }
  Rewind(load_);
  return ok;
}

bool SqliteJobStore::LoadResult(const std::string& id, std::optional<JobRecord>* record,
                                std::string* error) {
  std::lock_guard lock(mutex_);
  record->reset();
  int code = sqlite3_bind_text64(result_, 1, id.data(), id.size(), SQLITE_STATIC, SQLITE_UTF8);
  if (code == SQLITE_OK) {
    code = sqlite3_step(result_);
    if (code == SQLITE_ROW) {
      JobRecord found;
      found.id = id;
      found.status = static_cast<int>(sqlite3_column_int64(result_, 0));
      found.response_json = ColumnText(result_, 1);
      found.response_text = ColumnText(result_, 2);
      found.content_type = ColumnText(result_, 3);
      *record = std::move(found);
      code = SQLITE_OK;
    } else if (code == SQLITE_DONE) {
      code = SQLITE_OK;
    }
  }
  if (code != SQLITE_OK && error != nullptr) *error = Failure("load the result of job " + id, code);
  Rewind(result_);
  return code == SQLITE_OK;
}

bool SqliteJobStore::OpenResult(const std::string& id, std::optional<StoredResult>* result,
                                std::string* error) {
  std::lock_guard lock(mutex_);
  result->reset();
  sqlite3_stmt* find = nullptr;
  int code = sqlite3_prepare_v2(
      db_, "SELECT rowid, status, content_type, result_bytes FROM jobs WHERE id = ?1", -1, &find,
      nullptr);
  if (code == SQLITE_OK) {
    code = sqlite3_bind_text64(find, 1, id.data(), id.size(), SQLITE_STATIC, SQLITE_UTF8);
  }
  StoredResult found;
  bool exists = false;
  if (code == SQLITE_OK) {
    code = sqlite3_step(find);
    if (code == SQLITE_ROW) {
      found.row = sqlite3_column_int64(find, 0);
      found.status = static_cast<int>(sqlite3_column_int64(find, 1));
      found.content_type = ColumnText(find, 2);
      found.id = id;
      if (sqlite3_column_type(find, 3) != SQLITE_NULL) {
        found.chunked = true;
        found.bytes = static_cast<std::uint64_t>(sqlite3_column_int64(find, 3));
      }
      exists = true;
      code = SQLITE_OK;
    } else if (code == SQLITE_DONE) {
      code = SQLITE_OK;
    }
  }
  sqlite3_finalize(find);
  if (code == SQLITE_OK && exists && !found.chunked) {
    sqlite3_blob* blob = nullptr;
    code = sqlite3_blob_open(db_, "main", "jobs",
                             found.content_type.empty() ? "response_json" : "response_text",
                             found.row, 0, &blob);
    if (code == SQLITE_OK) found.bytes = static_cast<std::uint64_t>(sqlite3_blob_bytes(blob));
    sqlite3_blob_close(blob);
  }
  if (code != SQLITE_OK) {
    if (error != nullptr) *error = Failure("open the result of job " + id, code);
    return false;
  }
  if (exists) *result = std::move(found);
  return true;
}

bool SqliteJobStore::ReadResult(const StoredResult& result, std::uint64_t offset,
                                std::size_t max, std::string* out, std::string* error) {
  if (offset >= result.bytes || max == 0) return true;
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(max, result.bytes - offset));
  std::lock_guard lock(mutex_);
  if (result.chunked) return ReadChunksLocked(result, offset, n, out, error);
  sqlite3_blob* blob = nullptr;
  int code = sqlite3_blob_open(db_, "main", "jobs",
                               result.content_type.empty() ? "response_json" : "response_text",
                               result.row, 0, &blob);
  if (code == SQLITE_OK && static_cast<std::uint64_t>(sqlite3_blob_bytes(blob)) != result.bytes) {
    code = SQLITE_ABORT;  // the row now holds another result
  }
  if (code == SQLITE_OK) {
    const std::size_t before = out->size();
    out->resize(before + n);
    code = sqlite3_blob_read(blob, out->data() + before, static_cast<int>(n),
                             static_cast<int>(offset));
    if (code != SQLITE_OK) out->resize(before);
  }
  sqlite3_blob_close(blob);
  if (code != SQLITE_OK) {
    if (error != nullptr) *error = Failure("read the result of row " + std::to_string(result.row), code);
    return false;
  }
  return true;
}

bool SqliteJobStore::ReadChunksLocked(const StoredResult& result, std::uint64_t offset,
                                      std::size_t n, std::string* out, std::string* error) {
  sqlite3_stmt* find = nullptr;
  int code =
      sqlite3_prepare_v2(db_, "SELECT rowid FROM job_result_chunks WHERE job_id = ?1 AND seq = ?2",
                         -1, &find, nullptr);
  const std::size_t before = out->size();
  while (code == SQLITE_OK && n > 0) {
    const std::uint64_t seq = offset / kResultChunkBytes;
    const auto within = static_cast<int>(offset % kResultChunkBytes);
    code = sqlite3_bind_text64(find, 1, result.id.data(), result.id.size(), SQLITE_STATIC,
                               SQLITE_UTF8);
    if (code == SQLITE_OK) code = sqlite3_bind_int64(find, 2, static_cast<sqlite3_int64>(seq));
    if (code == SQLITE_OK) code = sqlite3_step(find);
    const sqlite3_int64 row = code == SQLITE_ROW ? sqlite3_column_int64(find, 0) : 0;
    if (code == SQLITE_DONE) code = SQLITE_ABORT;  // the piece is gone (job deleted)
    if (code == SQLITE_ROW) code = SQLITE_OK;
    Rewind(find);
    sqlite3_blob* blob = nullptr;
    if (code == SQLITE_OK)
      code = sqlite3_blob_open(db_, "main", "job_result_chunks", "data", row, 0, &blob);
    std::size_t take = 0;
    if (code == SQLITE_OK) {
      const int length = sqlite3_blob_bytes(blob);
      take = std::min<std::size_t>(n, static_cast<std::size_t>(std::max(0, length - within)));
      if (take == 0) code = SQLITE_ABORT;  // shorter than the record says
    }
    if (code == SQLITE_OK) {
      const std::size_t at = out->size();
      out->resize(at + take);
      code = sqlite3_blob_read(blob, out->data() + at, static_cast<int>(take), within);
      offset += take;
      n -= take;
    }
    sqlite3_blob_close(blob);
  }
  sqlite3_finalize(find);
  if (code != SQLITE_OK) {
    out->resize(before);
    if (error != nullptr) *error = Failure("read the result of job " + result.id, code);
    return false;
  }
  return true;
}

}  // namespace sweetspot::server
