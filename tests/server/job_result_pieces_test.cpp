// Results written in pieces as they are produced (server/jobs/job_store.hpp, kResultChunkBytes):
// the SQLite store's pieces read back across their boundaries and deleted with their job, a
// database of schema 1 migrated in place, and a JobManager collecting streamed answers (a sweep's
// JSON as /v1/explore streams it for a job) into the store's pieces, into a JSON body, or over
// its limit into 413 TooBig.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <stdlib.h>

#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "server/jobs/job_manager.hpp"
#include "server/jobs/sqlite_job_store.hpp"

namespace sweetspot::server {
// In a namespace of its own: the test programs are unity builds (cmake/BuildSpeed.cmake).
namespace job_result_pieces_test {
namespace {

namespace fs = std::filesystem;
using api::Request;
using api::Response;
using Json = nlohmann::json;

// A fresh directory under the test temp dir, removed with its files at the end.
class TempDir {
 public:
  TempDir() {
    std::string pattern = (fs::path(::testing::TempDir()) / "sweetspot-pieces-XXXXXX").string();
    if (mkdtemp(pattern.data()) != nullptr) path_ = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    if (!path_.empty()) fs::remove_all(path_, ignored);
  }
  std::string File(const std::string& name) const { return (path_ / name).string(); }

 private:
  fs::path path_;
};

// `bytes` bytes that differ from piece to piece and within them.
std::string Pattern(std::size_t bytes) {
  std::string out(bytes, ' ');
  for (std::size_t i = 0; i < bytes; ++i) out[i] = static_cast<char>('a' + (i * 7 + i / 4093) % 26);
  return out;
}

// The whole body of a sourced answer, read 64 KiB at a time as the server reads it.
std::string ReadAll(const api::BodySource& source) {
  std::string out;
  while (out.size() < source.bytes) {
    const std::size_t before = out.size();
    if (!source.read(out.size(), 64 * 1024, &out) || out.size() == before) break;
  }
  return out;
}

JobRecord DoneRecord(const std::string& id) {
  JobRecord record;
  record.id = id;
  record.state = "done";
  record.method = "POST";
  record.path = "/v1/explore";
  record.created_at = "2024-05-01T12:00:00.123Z";
  record.created_unix_s = 1.0;
  record.status = 200;
  record.content_type = "text/csv";
  return record;
}

TEST(JobResultPiecesTest, SqlitePiecesAreReadAcrossTheirBoundariesAndDeletedWithTheirJob) {
  TempDir dir;
  std::string error;
  auto store = SqliteJobStore::Open(dir.File("jobs.db"), &error);
  ASSERT_TRUE(store) << error;
  ASSERT_TRUE(store->KeepsResultChunks());
  const std::string body = Pattern(2 * kResultChunkBytes + 12345);
  for (std::uint64_t seq = 0; seq * kResultChunkBytes < body.size(); ++seq) {
    ASSERT_TRUE(store->SaveResultChunk(
        "job", seq, std::string_view(body).substr(seq * kResultChunkBytes, kResultChunkBytes),
        &error))
        << error;
  }
  JobRecord record = DoneRecord("job");
  record.chunked_bytes = body.size();
  ASSERT_TRUE(store->Save(record, &error)) << error;

  std::vector<JobRecord> records;
  ASSERT_TRUE(store->LoadAll(&records, &error)) << error;
  ASSERT_EQ(records.size(), 1u);
  EXPECT_TRUE(records[0].result_in_store);
  EXPECT_EQ(records[0].chunked_bytes, std::optional<std::uint64_t>(body.size()));
  std::optional<StoredResult> stored;
  ASSERT_TRUE(store->OpenResult("job", &stored, &error)) << error;
  ASSERT_TRUE(stored);
  EXPECT_TRUE(stored->chunked);
  EXPECT_EQ(stored->bytes, body.size());
  EXPECT_EQ(stored->content_type, "text/csv");
  // Across the first boundary, at the start of the last piece, and the whole.
  std::string piece;
  ASSERT_TRUE(store->ReadResult(*stored, kResultChunkBytes - 100, 300, &piece, &error)) << error;
  EXPECT_EQ(piece, body.substr(kResultChunkBytes - 100, 300));
  piece.clear();
  ASSERT_TRUE(store->ReadResult(*stored, 2 * kResultChunkBytes, 65536, &piece, &error)) << error;
  EXPECT_EQ(piece, body.substr(2 * kResultChunkBytes));
  std::string whole;
  while (whole.size() < body.size()) {
    ASSERT_TRUE(store->ReadResult(*stored, whole.size(), 65536, &whole, &error)) << error;
  }
  EXPECT_EQ(whole, body);

  ASSERT_TRUE(store->Delete("job", &error)) << error;
  piece.clear();
  EXPECT_FALSE(store->ReadResult(*stored, 0, 100, &piece, &error));
  EXPECT_EQ(piece, "");
}

TEST(JobResultPiecesTest, ADatabaseOfSchemaOneIsMigratedInPlaceAndKeepsItsJobs) {
  TempDir dir;
  const std::string path = dir.File("jobs.db");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  // Schema 1 as the server before pieces wrote it, with one finished job.
  ASSERT_EQ(sqlite3_exec(db,
                         "CREATE TABLE jobs (id TEXT PRIMARY KEY NOT NULL, state TEXT NOT NULL, "
                         "method TEXT NOT NULL, path TEXT NOT NULL, body TEXT NOT NULL, progress "
                         "REAL NOT NULL, cancel_requested INTEGER NOT NULL, resumes INTEGER NOT "
                         "NULL, created_at TEXT NOT NULL, created_unix_s REAL NOT NULL, "
                         "started_unix_s REAL, finished_unix_s REAL, status INTEGER NOT NULL, "
                         "response_json TEXT NOT NULL, response_text TEXT NOT NULL, content_type "
                         "TEXT NOT NULL, error TEXT NOT NULL); INSERT INTO jobs VALUES ('old', "
                         "'done', 'POST', '/v1/explore', '', 1, 0, 0, 'x', 1, 1, 2, 200, "
                         "'{\"rows\":[]}', '', '', ''); PRAGMA user_version = 1;",
                         nullptr, nullptr, nullptr),
            SQLITE_OK);
  ASSERT_EQ(sqlite3_close(db), SQLITE_OK);
  std::string error;
  auto store = SqliteJobStore::Open(path, &error);
  ASSERT_TRUE(store) << error;
  std::vector<JobRecord> records;
  ASSERT_TRUE(store->LoadAll(&records, &error)) << error;
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].response_json, "{\"rows\":[]}");
  EXPECT_FALSE(records[0].chunked_bytes);
  ASSERT_TRUE(store->SaveResultChunk("new", 0, "abc", &error)) << error;
  store.reset();
  ASSERT_EQ(sqlite3_open(path.c_str(), &db), SQLITE_OK);
  sqlite3_stmt* statement = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "PRAGMA user_version", -1, &statement, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(statement), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(statement, 0), 2);
  sqlite3_finalize(statement);
  sqlite3_close(db);
}

// A runner answering with a stream of `{"rows":[...]}` of `rows` rows of about 100 bytes.
api::JobRunner JsonStream(int rows) {
  return [rows](const Request&, core::Progress*) {
    Response out = Response::Text(200, std::string(), "application/json");
    out.stream = [rows](const api::ChunkSink& sink) {
      if (!sink("{\"rows\":[")) return false;
      for (int i = 0; i < rows; ++i) {
        const std::string row =
            (i == 0 ? "" : ",") + Json{{"index", i}, {"text", Pattern(80)}}.dump();
        if (!sink(row)) return false;
      }
      return sink("],\"summary\":{\"rows\":" + std::to_string(rows) + "}}");
    };
    return out;
  };
}

// The body the whole answer of JsonStream(rows) is sent as: its compact dump and a newline.
std::string JsonStreamBody(int rows) {
  Json answer{{"rows", Json::array()}, {"summary", {{"rows", rows}}}};
  for (int i = 0; i < rows; ++i) answer["rows"].push_back({{"index", i}, {"text", Pattern(80)}});
  return answer.dump() + "\n";
}

Json WaitFinished(const JobManager& jobs, const std::string& id) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  Response status = jobs.Status(id);
  while (status.status == 200 &&
         (status.body["state"] == "queued" || status.body["state"] == "running")) {
    if (std::chrono::steady_clock::now() > deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    status = jobs.Status(id);
  }
  return status.body;
}

TEST(JobResultPiecesTest, AStreamedJsonAnswerGoesToThePiecesAndComesBackAsTheWholeAnswer) {
  TempDir dir;
  std::string error;
  auto store = SqliteJobStore::Open(dir.File("jobs.db"), &error);
  ASSERT_TRUE(store) << error;
  JobPersistence persistence;
  persistence.store = store.get();
  constexpr int kRows = 30000;  // About 3.3 MB: four pieces.
  JobManager jobs(JobConfig{}, JsonStream(kRows), persistence);
  const std::string id = jobs.Submit({"POST", "/v1/explore", "{}"}).body["id"];
  EXPECT_EQ(WaitFinished(jobs, id)["state"], "done");
  const Response result = jobs.Result(id);
  EXPECT_EQ(result.status, 200);
  EXPECT_EQ(result.content_type, "application/json");
  ASSERT_TRUE(result.source);
  const std::string expected = JsonStreamBody(kRows);
  EXPECT_EQ(result.source->bytes, expected.size());
  EXPECT_EQ(ReadAll(*result.source), expected);
  std::vector<JobRecord> records;
  ASSERT_TRUE(store->LoadAll(&records, &error)) << error;
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0].chunked_bytes, std::optional<std::uint64_t>(expected.size() - 1));
  EXPECT_EQ(records[0].content_type, "");  // JSON, as a JSON body is stored.
}

TEST(JobResultPiecesTest, ASmallStreamedJsonAnswerIsAJsonBodyAndABigOneInMemoryIsItsText) {
  // Small: the parsed body, as any JSON answer (the server sends its dump and a newline).
  JobManager small(JobConfig{}, JsonStream(3));
  const std::string id = small.Submit({"POST", "/v1/explore", "{}"}).body["id"];
  EXPECT_EQ(WaitFinished(small, id)["state"], "done");
  Response result = small.Result(id);
  EXPECT_EQ(result.content_type, "");
  EXPECT_EQ(result.body.dump() + "\n", JsonStreamBody(3));
  // Over 1 MiB with no store: its text, not values several times its size.
  JobManager big(JobConfig{}, JsonStream(20000));
  const std::string big_id = big.Submit({"POST", "/v1/explore", "{}"}).body["id"];
  EXPECT_EQ(WaitFinished(big, big_id)["state"], "done");
  result = big.Result(big_id);
  EXPECT_EQ(result.content_type, "application/json");
  EXPECT_EQ(result.text, JsonStreamBody(20000));
}

TEST(JobResultPiecesTest, AStreamedAnswerOverTheLimitIsStoppedAndFailsWithTooBig) {
  TempDir dir;
  {
    std::string error;
    auto store = SqliteJobStore::Open(dir.File("jobs.db"), &error);
    ASSERT_TRUE(store) << error;
    JobPersistence persistence;
    persistence.store = store.get();
    JobConfig config;
    config.max_result_bytes = 2 * kResultChunkBytes + 1000;  // Two pieces written, then over.
    JobManager jobs(config, JsonStream(40000), persistence);
    const std::string id = jobs.Submit({"POST", "/v1/explore", "{}"}).body["id"];
    const Json failed = WaitFinished(jobs, id);
    EXPECT_EQ(failed["state"], "failed");
    EXPECT_EQ(failed["status"], 413);
    EXPECT_EQ(failed["error"]["code"], "TooBig");
    EXPECT_NE(failed["error"]["message"].get<std::string>().find("at least"), std::string::npos)
        << failed.dump();
  }  // The store closed: its file may be opened here.
  // Its pieces are gone with the answer.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(dir.File("jobs.db").c_str(), &db), SQLITE_OK);
  sqlite3_stmt* statement = nullptr;
  ASSERT_EQ(
      sqlite3_prepare_v2(db, "SELECT count(*) FROM job_result_chunks", -1, &statement, nullptr),
      SQLITE_OK);
  if (sqlite3_step(statement) == SQLITE_ROW) {
    EXPECT_EQ(sqlite3_column_int(statement, 0), 0);
  }
  sqlite3_finalize(statement);
  sqlite3_close(db);
}

}  // namespace
}  // namespace job_result_pieces_test
}  // namespace sweetspot::server
