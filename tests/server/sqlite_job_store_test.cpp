// The SQLite JobStore on temporary files: every field round-trips through a
// close and reopen, replace/delete/order, one server per file, schema
// versions, unusable files, and a JobManager restarted on the same database.
#include "server/jobs/sqlite_job_store.hpp"

#include <gtest/gtest.h>

#include <sqlite3.h>
#include <stdlib.h>
#include "tests/refusal_text.hpp"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "server/jobs/job_manager.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace sqlite_job_store_test {
namespace {

namespace fs = std::filesystem;

// A fresh directory under the test temp dir, removed with its files at the end.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::path(::testing::TempDir()) / "sweetspot-store-XXXXXX").string();
    if (mkdtemp(pattern.data()) != nullptr) path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    if (!path_.empty()) fs::remove_all(path_, ignored);
  }
  const fs::path& path() const { return path_; }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

JobRecord FullRecord(const std::string& id, double created_unix_s) {
  JobRecord record;
  record.id = id;
  record.state = "done";
  record.method = "POST";
  record.path = "/v1/explore";
  record.body = std::string("{\"k\": \"\xc3\xa9t\xc3\xa9\"}") + std::string(1, '\0') + "tail";
  record.progress = 0.75;
  record.cancel_requested = true;
  record.resumes = 2;
  record.created_at = "2024-05-01T12:00:00.123Z";
  record.created_unix_s = created_unix_s;
  record.started_unix_s = created_unix_s + 0.5;
  record.finished_unix_s = created_unix_s + 1.25;
  record.status = 422;
  record.response_json = R"({"code":"Infeasible","message":"no bat"})";
  record.response_text = "a,b\n1,2\n";
  record.content_type = "text/csv";
  record.error = "no bat";
  return record;
}

void ExpectSameRecord(const JobRecord& a, const JobRecord& b) {
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.state, b.state);
  EXPECT_EQ(a.method, b.method);
  EXPECT_EQ(a.path, b.path);
  EXPECT_EQ(a.body, b.body);
  EXPECT_EQ(a.progress, b.progress);
  EXPECT_EQ(a.cancel_requested, b.cancel_requested);
  EXPECT_EQ(a.resumes, b.resumes);
  EXPECT_EQ(a.created_at, b.created_at);
  EXPECT_EQ(a.created_unix_s, b.created_unix_s);
  EXPECT_EQ(a.started_unix_s, b.started_unix_s);
  EXPECT_EQ(a.finished_unix_s, b.finished_unix_s);
  EXPECT_EQ(a.status, b.status);
  EXPECT_EQ(a.response_json, b.response_json);
  EXPECT_EQ(a.response_text, b.response_text);
  EXPECT_EQ(a.content_type, b.content_type);
  EXPECT_EQ(a.error, b.error);
}

std::unique_ptr<SqliteJobStore> OpenOrFail(const std::string& path) {
  std::string error;
  auto store = SqliteJobStore::Open(path, &error);
  EXPECT_NE(store, nullptr) << error;
  EXPECT_EQ(error, "");
  return store;
}

std::vector<JobRecord> LoadAll(SqliteJobStore& store) {
  std::vector<JobRecord> records;
  std::string error;
  EXPECT_TRUE(store.LoadAll(&records, &error)) << error;
  return records;
}

TEST(SqliteJobStoreOptionsTest, DefaultsAreValidAndTheRangeIsChecked) {
  SqliteJobStoreOptions options;
  std::string why = "untouched";
  EXPECT_TRUE(Validates(options, &why));
  EXPECT_EQ(why, "untouched");
  EXPECT_EQ(options.busy_timeout_s, 2.0);
  options.busy_timeout_s = -1;
  EXPECT_FALSE(Validates(options, &why));
  EXPECT_EQ(why, "busy_timeout_s = -1: must be in [0, 60]");
  options.busy_timeout_s = 61;
  EXPECT_FALSE(options.Validate(nullptr));
  std::string error;
  EXPECT_EQ(SqliteJobStore::Open(":memory:", &error, options), nullptr);
  EXPECT_EQ(error, "invalid SqliteJobStoreOptions: busy_timeout_s = 61: must be in [0, 60]");
}

TEST(SqliteJobStoreTest, EveryFieldSurvivesCloseAndReopen) {
  TempDir dir;
  ASSERT_FALSE(dir.path().empty());
  const std::string path = dir.File("jobs.db");
  const JobRecord full = FullRecord(std::string(32, 'a'), 1714564800.123456);
  JobRecord sparse;  // Optional times absent, empty strings, a large body.
  sparse.id = std::string(32, 'b');
  sparse.state = "queued";
  sparse.method = "POST";
  sparse.path = "/v1/compare";
  sparse.body = std::string(1 << 20, 'x');
  sparse.created_at = "2024-05-01T12:00:01.000Z";
  sparse.created_unix_s = 1714564801.0;
  {
    auto store = OpenOrFail(path);
    ASSERT_NE(store, nullptr);
    std::string error;
    EXPECT_TRUE(store->Save(full, &error)) << error;
    EXPECT_TRUE(store->Save(sparse, &error)) << error;
    EXPECT_TRUE(fs::exists(path + "-wal"));  // WAL journal while open.
  }
  auto reopened = OpenOrFail(path);
  ASSERT_NE(reopened, nullptr);
  const std::vector<JobRecord> records = LoadAll(*reopened);
  ASSERT_EQ(records.size(), 2u);
  ExpectSameRecord(records[0], full);
  ExpectSameRecord(records[1], sparse);
  EXPECT_FALSE(records[1].started_unix_s.has_value());
  EXPECT_FALSE(records[1].finished_unix_s.has_value());
}

TEST(SqliteJobStoreTest, SaveReplacesDeleteRemovesLoadOrdersByCreation) {
  auto store = OpenOrFail(":memory:");
  ASSERT_NE(store, nullptr);
  std::string error;
  JobRecord late = FullRecord(std::string(32, '1'), 300.0);
  JobRecord early = FullRecord(std::string(32, '2'), 100.0);
  JobRecord middle = FullRecord(std::string(32, '3'), 200.0);
  for (const JobRecord& record : {late, early, middle}) {
    ASSERT_TRUE(store->Save(record, &error)) << error;
  }
  std::vector<JobRecord> records = LoadAll(*store);
  ASSERT_EQ(records.size(), 3u);
  EXPECT_EQ(records[0].id, early.id);
  EXPECT_EQ(records[1].id, middle.id);
  EXPECT_EQ(records[2].id, late.id);

  middle.state = "failed";
  middle.error = "changed";
  ASSERT_TRUE(store->Save(middle, &error)) << error;
  ASSERT_TRUE(store->Delete(late.id, &error)) << error;
  ASSERT_TRUE(store->Delete("no such id", &error)) << error;
  records = LoadAll(*store);
  ASSERT_EQ(records.size(), 2u);
  ExpectSameRecord(records[0], early);
  ExpectSameRecord(records[1], middle);
}

TEST(SqliteJobStoreTest, ASecondOpenOfTheSameFileIsRefusedUntilTheFirstCloses) {
  TempDir dir;
  const std::string path = dir.File("jobs.db");
  auto first = OpenOrFail(path);
  ASSERT_NE(first, nullptr);
  SqliteJobStoreOptions quick;
  quick.busy_timeout_s = 0.05;
  std::string error;
  EXPECT_EQ(SqliteJobStore::Open(path, &error, quick), nullptr);
  EXPECT_EQ(error.rfind("jobs database \"" + path + "\": ", 0), 0u) << error;
  EXPECT_NE(error.find("database is locked"), std::string::npos) << error;
  EXPECT_NE(error.find("each server needs its own"), std::string::npos) << error;
  first.reset();
  EXPECT_NE(OpenOrFail(path), nullptr);
}

TEST(SqliteJobStoreTest, ANewerSchemaIsRefusedAndLeftAlone) {
  TempDir dir;
  const std::string path = dir.File("jobs.db");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "PRAGMA user_version = 3", nullptr, nullptr, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_close(db), SQLITE_OK);
  std::string error;
  EXPECT_EQ(SqliteJobStore::Open(path, &error), nullptr);
  EXPECT_EQ(error, "jobs database \"" + path +
                       "\": its schema version is 3, newer than this server's 2: use a newer "
                       "server or another database");
  // Still version 3 and without a jobs table: nothing was rewritten.
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* statement = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db,
                               "SELECT (SELECT user_version FROM pragma_user_version), "
                               "(SELECT count(*) FROM sqlite_master WHERE name = 'jobs')",
                               -1, &statement, nullptr),
            SQLITE_OK);
  ASSERT_EQ(sqlite3_step(statement), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(statement, 0), 3);
  EXPECT_EQ(sqlite3_column_int(statement, 1), 0);
  sqlite3_finalize(statement);
  sqlite3_close(db);
}

TEST(SqliteJobStoreTest, TheSchemaVersionIsWritten) {
  TempDir dir;
  const std::string path = dir.File("jobs.db");
  OpenOrFail(path).reset();
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* statement = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA user_version", -1, &statement, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(statement), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(statement, 0), SqliteJobStore::kSchemaVersion);
  sqlite3_finalize(statement);
  sqlite3_close(db);
}

TEST(SqliteJobStoreTest, UnusableFilesAreRefusedWithTheReason) {
  TempDir dir;
  const std::string garbage = dir.File("garbage.db");
  std::ofstream(garbage) << std::string(4096, 'g');
  std::string error;
  EXPECT_EQ(SqliteJobStore::Open(garbage, &error), nullptr);
  EXPECT_EQ(error.rfind("jobs database \"" + garbage + "\": ", 0), 0u) << error;
  EXPECT_NE(error.find("file is not a database"), std::string::npos) << error;

  const std::string missing_dir = dir.File("no/such/dir/jobs.db");
  EXPECT_EQ(SqliteJobStore::Open(missing_dir, &error), nullptr);
  EXPECT_EQ(error, "jobs database \"" + missing_dir +
                       "\": cannot open or create it: unable to open database file (code 14)");
}

TEST(SqliteJobStoreTest, AJobManagerRestartedOnTheSameFileGetsItsJobsBack) {
  TempDir dir;
  const std::string path = dir.File("jobs.db");
  const auto echo = [](const api::Request& inner, core::Progress*) {
    return api::Response{200, nlohmann::json{{"body", inner.body}}};
  };
  std::string id;
  {
    auto store = OpenOrFail(path);
    ASSERT_NE(store, nullptr);
    JobPersistence persistence;
    persistence.store = store.get();
    JobManager jobs(JobConfig{}, echo, persistence);
    const api::Response submitted = jobs.Submit({"POST", "/v1/compare", "payload"});
    ASSERT_EQ(submitted.status, 202);
    id = submitted.body["id"];
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (jobs.Status(id).body["state"] != "done" && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ASSERT_EQ(jobs.Status(id).body["state"], "done");
  }
  auto store = OpenOrFail(path);
  ASSERT_NE(store, nullptr);
  JobPersistence persistence;
  persistence.store = store.get();
  JobManager jobs(JobConfig{}, echo, persistence);
  EXPECT_EQ(jobs.Status(id).body["state"], "done");
  const api::Response result = jobs.Result(id);
  EXPECT_EQ(result.status, 200);
  EXPECT_EQ(result.body, (nlohmann::json{{"body", "payload"}}));
}

// Errors are objects and a cancelled job keeps its runner's 2xx answer, across a restart on
// the same file; rows written before errors were objects (a bare message) read back wrapped.
TEST(SqliteJobStoreTest, ErrorObjectsAndKeptResultsSurviveARestartAndOldErrorsAreWrapped) {
  TempDir dir;
  const std::string path = dir.File("jobs.db");
  const nlohmann::json infeasible{{"code", "Infeasible"},
                                  {"message", "no design meets the constraints"},
                                  {"field", "constraints"}};
  const nlohmann::json best{{"summary", {{"termination", "no_convergence"}}}, {"objective", 1.5}};
  const auto runner = [&](const api::Request& inner, core::Progress* progress) {
    if (inner.body == "fail") return api::Response{422, infeasible};
    while (!progress->Cancelled()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
    return api::Response{200, best};  // as a cancelled optimisation answers
  };
  auto wait_for = [](const JobManager& jobs, const std::string& id, const std::string& state) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (jobs.Status(id).body["state"] != state && std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    EXPECT_EQ(jobs.Status(id).body["state"], state);
  };
  std::string failed, cancelled;
  {
    auto store = OpenOrFail(path);
    ASSERT_NE(store, nullptr);
    JobPersistence persistence;
    persistence.store = store.get();
    JobManager jobs(JobConfig{}, runner, persistence);
    failed = jobs.Submit({"POST", "/v1/optimize", "fail"}).body["id"];
    cancelled = jobs.Submit({"POST", "/v1/optimize", "run"}).body["id"];
    wait_for(jobs, failed, "failed");
    wait_for(jobs, cancelled, "running");
    EXPECT_EQ(jobs.Cancel(cancelled).status, 202);
    wait_for(jobs, cancelled, "cancelled");
    // Two rows as an older server wrote them: the error a bare message, with and without an
    // error envelope in the stored answer.
    JobRecord old;
    old.id = std::string(32, 'a');
    old.state = "failed";
    old.method = "POST";
    old.path = "/v1/explore";
    old.created_at = "2024-05-01T12:00:00.123Z";
    old.created_unix_s = old.finished_unix_s.emplace(
        std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
            .count());
    old.status = 413;
    old.error = "parameters describe 25 designs, over the limit max_batch_samples = 20";
    old.response_json = nlohmann::json{{"code", "TooBig"},
                                       {"message", old.error},
                                       {"field", "parameters"}}
                            .dump();
    std::string why;
    ASSERT_TRUE(store->Save(old, &why)) << why;
    old.id = std::string(32, 'b');
    old.status = 500;
    old.error = "internal error";
    old.response_json = "[]";
    ASSERT_TRUE(store->Save(old, &why)) << why;
  }
  auto store = OpenOrFail(path);
  ASSERT_NE(store, nullptr);
  JobPersistence persistence;
  persistence.store = store.get();
  JobManager jobs(JobConfig{}, runner, persistence);

  const nlohmann::json failed_status = jobs.Status(failed).body;
  EXPECT_EQ(failed_status["state"], "failed");
  EXPECT_EQ(failed_status["status"], 422);
  EXPECT_EQ(failed_status["error"], infeasible);
  EXPECT_EQ(jobs.Result(failed).body, infeasible);

  const nlohmann::json cancelled_status = jobs.Status(cancelled).body;
  EXPECT_EQ(cancelled_status["state"], "cancelled");
  EXPECT_EQ(cancelled_status["status"], 200);
  EXPECT_TRUE(cancelled_status["error"].is_null());
  const api::Response kept = jobs.Result(cancelled);
  EXPECT_EQ(kept.status, 200);
  EXPECT_EQ(kept.body, best);

  EXPECT_EQ(jobs.Status(std::string(32, 'a')).body["error"],
            (nlohmann::json{{"code", "TooBig"},
                            {"message", "parameters describe 25 designs, over the limit "
                                        "max_batch_samples = 20"},
                            {"field", "parameters"}}));
  EXPECT_EQ(jobs.Status(std::string(32, 'b')).body["error"],
            (nlohmann::json{{"code", "InternalError"},
                            {"message", "internal error"},
                            {"field", nullptr}}));
}

// Results over kMaxLoadedResultBytes stay out of LoadAll (result_in_store); LoadResult reads
// them, byte for byte, and says when there is no such job.
TEST(SqliteJobStoreTest, BigResultsAreLeftOutOfLoadAllAndReadByLoadResult) {
  TempDir dir;
  std::string error;
  auto store = SqliteJobStore::Open(dir.File("jobs.db"), &error);
  ASSERT_TRUE(store) << error;
  JobRecord small = FullRecord("small", 1.0);
  JobRecord big = FullRecord("big", 2.0);
  big.response_text = std::string(kMaxLoadedResultBytes, 'x');  // Over: plus response_json.
  ASSERT_TRUE(store->Save(small, &error)) << error;
  ASSERT_TRUE(store->Save(big, &error)) << error;
  std::vector<JobRecord> records;
  ASSERT_TRUE(store->LoadAll(&records, &error)) << error;
  ASSERT_EQ(records.size(), 2u);
  ExpectSameRecord(records[0], small);
  EXPECT_FALSE(records[0].result_in_store);
  EXPECT_TRUE(records[1].result_in_store);
  EXPECT_EQ(records[1].response_json, "");
  EXPECT_EQ(records[1].response_text, "");
  EXPECT_EQ(records[1].content_type, "text/csv");
  std::optional<JobRecord> result;
  ASSERT_TRUE(store->LoadResult("big", &result, &error)) << error;
  ASSERT_TRUE(result);
  EXPECT_EQ(result->status, big.status);
  EXPECT_EQ(result->response_json, big.response_json);
  EXPECT_EQ(result->response_text, big.response_text);
  EXPECT_EQ(result->content_type, big.content_type);
  ASSERT_TRUE(store->LoadResult("none", &result, &error)) << error;
  EXPECT_FALSE(result);
}

// max_bytes caps the file (PRAGMA max_page_count): a save past it fails with SQLite's own
// "database or disk is full", as on a full disk, and what was saved before stays readable.
TEST(SqliteJobStoreTest, MaxBytesMakesSavesPastItFailAsOnAFullDisk) {
  TempDir dir;
  std::string error;
  SqliteJobStoreOptions options;
  options.max_bytes = 65536;
  auto store = SqliteJobStore::Open(dir.File("jobs.db"), &error, options);
  ASSERT_TRUE(store) << error;
  ASSERT_TRUE(store->Save(FullRecord("small", 1.0), &error)) << error;
  JobRecord big = FullRecord("big", 2.0);
  big.response_text = std::string(100000, 'x');
  EXPECT_FALSE(store->Save(big, &error));
  EXPECT_EQ(error, "save job big: database or disk is full (code 13)");
  std::vector<JobRecord> records;
  ASSERT_TRUE(store->LoadAll(&records, &error)) << error;
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].id, "small");
  options.max_bytes = 1000;
  EXPECT_FALSE(SqliteJobStore::Open(dir.File("other.db"), &error, options));
  EXPECT_EQ(error,
            "invalid SqliteJobStoreOptions: max_bytes = 1000: must be 0 (no limit) or in "
            "[65536, 1000000000000000]");
}

}  // namespace
}  // namespace sqlite_job_store_test
}  // namespace sweetspot::server
