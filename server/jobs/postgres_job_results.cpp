// PostgresJobService's results: a result over kResultChunkBytes is written to
// sweetspot_job_result_chunks piece by piece while its job runs (only while this replica holds
// the job's lease), and every result is read back as the client takes it, a piece of 1 MiB
// at a time: never whole in memory.
#include <libpq-fe.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>
#include <utility>

#include "api/json_reader.hpp"
#include "server/jobs/postgres_job_impl.hpp"

namespace sweetspot::server {
using namespace pg;  // NOLINT: this file is left out of the unity build (server/CMakeLists.txt).

bool PostgresJobService::Impl::WriteChunk(Running& job, std::uint64_t seq, std::string_view bytes,
                                          std::string* error) {
  // Binary ($3): the piece's bytes as they are. Written only while the lease is ours: a replica
  // that lost the job (its lease expired, another one runs it) writes nothing more.
  BinaryParts binary;
  binary.index = 3;
  binary.binary = bytes;
  PgResult written(nullptr, &PQclear);
  std::string why;
  if (!db.Run("INSERT INTO sweetspot_job_result_chunks (id, seq, data) SELECT $1, $2::bigint, "
              "$3::bytea WHERE EXISTS (SELECT 1 FROM sweetspot_jobs WHERE id = $1 AND "
              "lease_owner = $4 AND state = 'running') ON CONFLICT (id, seq) DO UPDATE SET "
              "data = EXCLUDED.data",
              {job.id, std::to_string(seq), std::nullopt, owner}, &written, &why, binary)) {
    *error = why;
    Report("cannot save piece " + std::to_string(seq) + " of the result of job " + job.id + ": " +
           why);
    return false;
  }
  if (std::atoll(PQcmdTuples(written.get())) == 0) {
    job.lost = true;  // Another replica claimed it (or it was deleted): this run ends here.
    job.progress.Cancel();
    *error = "the job is no longer this replica's";
    return false;
  }
  return true;
}

namespace {

// The piece of a result a fetch last read (each GET holds at most one: 1 MiB), so that the
// connection loop's 64 KiB refills cost one query per piece, not one each.
struct PieceCache {
  std::mutex mutex;
  std::int64_t seq = -1;  // The piece in `data`; -1: none yet.
  std::string data;
};

// Appends `n` bytes of job `id`'s result pieces from `offset` to *out (one or two pieces).
bool ReadPieces(Connections& db, const std::string& id, PieceCache& cache, std::uint64_t offset,
                std::size_t n, std::string* out) {
  std::lock_guard lock(cache.mutex);
  while (n > 0) {
    const auto seq = static_cast<std::int64_t>(offset / kResultChunkBytes);
    const std::uint64_t within = offset % kResultChunkBytes;
    if (cache.seq != seq) {
      BinaryParts binary;
      binary.binary_result = true;
      PgResult piece(nullptr, &PQclear);
      std::string ignored;
      if (!db.Run("SELECT data FROM sweetspot_job_result_chunks WHERE id = $1 AND seq = $2",
                  {id, std::to_string(seq)}, &piece, &ignored, binary) ||
          PQntuples(piece.get()) != 1) {
        return false;  // The database is away, or the job was deleted meanwhile.
      }
      cache.data.assign(PQgetvalue(piece.get(), 0, 0),
                        static_cast<std::size_t>(PQgetlength(piece.get(), 0, 0)));
      cache.seq = seq;
    }
    if (within >= cache.data.size()) return false;  // Shorter than the job's row says.
    const std::size_t take = std::min<std::size_t>(n, cache.data.size() - within);
    out->append(cache.data, static_cast<std::size_t>(within), take);
    offset += take;
    n -= take;
  }
  return true;
}

}  // namespace

api::Response PostgresJobService::Result(const std::string& id) const {
  const Impl& self = *impl_;
  PgResult found(nullptr, &PQclear);
  if (!self.Query("SELECT state, status, response_json, response_text, content_type, "
                  "result_bytes FROM sweetspot_jobs WHERE id = $1 AND (finished_unix_s IS NULL "
                  "OR finished_unix_s > " SWEETSPOT_NOW " - $2)",
                  {id, Decimal(self.config.keep_results_s)}, &found)) {
    return Unavailable();
  }
  if (PQntuples(found.get()) == 0) return JobNotFound(id);
  const std::string state = Text(found.get(), 0, 0);
  const int status = std::atoi(PQgetvalue(found.get(), 0, 1));
  // A cancelled job has a result only when it kept the runner's 2xx answer.
  if (state == "cancelled" && (status < 200 || status >= 300)) return JobWasCancelled(id);
  if (state != "done" && state != "failed" && state != "cancelled") return JobNotReady(id, state);
  const std::string content_type = Text(found.get(), 0, 4);
  const bool json = content_type.empty();
  // JSON is sent as the server sends any JSON answer: its compact text and a newline.
  const std::string type = json ? "application/json" : content_type;
  if (PQgetisnull(found.get(), 0, 5)) {
    std::string body = Text(found.get(), 0, json ? 2 : 3);
    found.reset();
    if (json) body.push_back('\n');
    return api::Response::Text(status, std::move(body), type);
  }
  const auto bytes =
      static_cast<std::uint64_t>(std::strtoull(PQgetvalue(found.get(), 0, 5), nullptr, 10));
  api::Response out = api::Response::Text(status, std::string(), type);
  auto source = std::make_shared<api::BodySource>();
  source->bytes = bytes + (json ? 1 : 0);
  source->read = [db = &self.db, id, bytes, json, cache = std::make_shared<PieceCache>()](
                     std::uint64_t offset, std::size_t max, std::string* piece) {
    if (offset < bytes) {
      const auto n = static_cast<std::size_t>(std::min<std::uint64_t>(max, bytes - offset));
      if (!ReadPieces(*db, id, *cache, offset, n, piece)) return false;
      offset += n;
      max -= n;
    }
    if (json && offset == bytes && max > 0) piece->push_back('\n');
    return true;
  };
  out.source = std::move(source);
  return out;
}

}  // namespace sweetspot::server
