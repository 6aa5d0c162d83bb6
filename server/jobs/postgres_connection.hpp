// PostgresJobService's access to the database (libpq): statements with text or binary
// parameters, and a pool of connections re-made when lost. Private to server/jobs/postgres_*.
#pragma once

#include <libpq-fe.h>

#include <cstddef>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/response.hpp"

// The database's clock, in s since the Unix epoch: leases are compared on one
// clock whatever the replicas' clocks say.
#define SWEETSPOT_NOW "extract(epoch from clock_timestamp())"

namespace sweetspot::server::pg {

using Param = std::optional<std::string>;  // nullopt: SQL NULL.
using PgResult = std::unique_ptr<PGresult, decltype(&PQclear)>;

/// A statement's parameters beyond the text ones: `binary` is sent as the bytes of parameter
/// number `index` (1-based, bytea), and the result is asked for in binary when `binary_result`.
struct BinaryParts {
  int index = 0;               ///< The binary parameter's number; 0: none.
  std::string_view binary;     ///< Its bytes.
  bool binary_result = false;  ///< Results in binary (bytea as its bytes).
};

/// libpq's message without its trailing newline.
std::string Message(const char* text);
/// The text of a value ("" for NULL).
std::string Text(const PGresult* result, int row, int column);
/// A number's value.
double Number(const PGresult* result, int row, int column);
/// A number's value, or nullopt for NULL.
std::optional<double> OptionalNumber(const PGresult* result, int row, int column);
/// Runs `sql` with `params` (text; nullopt = NULL) on `connection`: true with its
/// result in *out (if non-null) when it succeeded, else false with libpq's message.
/// Without parameters `sql` may hold several statements (a migration); the result
/// is the last one's.
bool Execute(PGconn* connection, const std::string& sql, const std::vector<Param>& params,
             PgResult* out, std::string* error, const BinaryParts& binary = {});
/// `value` with 17 significant digits.
std::string Decimal(double value);
/// A name for this process's leases: host, pid and 64 random bits.
std::string LeaseOwner();
/// 503 Unavailable: the jobs database cannot be reached.
api::Response Unavailable();

// Idle connections kept per replica.
inline constexpr std::size_t kMaxIdleConnections = 16;

/// Ignores libpq's notices ("relation ... already exists, skipping" is not worth a log line).
void IgnoreNotice(void*, const char*);

/// Connections to the database: taken by one thread at a time, re-made when lost.
class Connections {
 public:
  explicit Connections(std::string uri) : uri_(std::move(uri)) {}
  ~Connections() {
    for (PGconn* connection : idle_) PQfinish(connection);
  }

  // Runs `sql` with `params` (text); true with its result in *out when it
  // succeeded. A lost connection is dropped with every idle one (a restarted
  // database loses them all) and the statement is tried once more on a new one:
  // every statement here may run twice without harm.
  bool Run(const std::string& sql, const std::vector<Param>& params, PgResult* out,
           std::string* error, const BinaryParts& binary = {}) {
    for (int attempt = 0; attempt < 2; ++attempt) {
      PGconn* connection = Take(error);
      if (connection == nullptr) return false;
      if (Execute(connection, sql, params, out, error, binary)) {
        Give(connection);
        return true;
      }
      if (PQstatus(connection) == CONNECTION_OK) {  // An SQL error: not worth a retry.
        Give(connection);
        return false;
      }
      PQfinish(connection);
      DropIdle();
    }
    return false;
  }

  // Runs `body` on one connection inside a transaction (BEGIN ... COMMIT, or
  // ROLLBACK when anything failed).
  bool Transaction(const std::function<bool(PGconn*, std::string*)>& body, std::string* error) {
    PGconn* connection = Take(error);
    if (connection == nullptr) return false;
    auto exec = [&](const char* sql) { return Execute(connection, sql, {}, nullptr, error); };
    bool ok = exec("BEGIN") && body(connection, error) && exec("COMMIT");
    if (!ok) {
      std::string ignored = *error;
      PgResult rollback(PQexec(connection, "ROLLBACK"), &PQclear);
      *error = ignored;
    }
    if (PQstatus(connection) == CONNECTION_OK) {
      Give(connection);
    } else {
      PQfinish(connection);
      DropIdle();
    }
    return ok;
  }

  // A new connection of its own (not pooled; PQfinish it), or null with *error.
  PGconn* Connect(std::string* error) const {
    // The URI's own settings win over these defaults (later keywords override).
    const char* keys[] = {"connect_timeout",
                          "keepalives_idle",
                          "keepalives_interval",
                          "keepalives_count",
                          "application_name",
                          "dbname",
                          nullptr};
    const char* values[] = {"3", "10", "3", "3", "sweetspot-server", uri_.c_str(), nullptr};
    PGconn* connection = PQconnectdbParams(keys, values, /*expand_dbname=*/1);
    if (connection == nullptr || PQstatus(connection) != CONNECTION_OK) {
      *error = Message(connection != nullptr ? PQerrorMessage(connection) : "out of memory");
      PQfinish(connection);
      return nullptr;
    }
    // "relation ... already exists, skipping" and the like are not worth a log line.
    PQsetNoticeProcessor(connection, IgnoreNotice, nullptr);
    return connection;
  }

 private:
  PGconn* Take(std::string* error) {
    {
      std::lock_guard lock(mutex_);
      if (!idle_.empty()) {
        PGconn* connection = idle_.back();
        idle_.pop_back();
        return connection;
      }
    }
    return Connect(error);
  }

  void Give(PGconn* connection) {
    std::lock_guard lock(mutex_);
    if (idle_.size() < kMaxIdleConnections) {
      idle_.push_back(connection);
    } else {
      PQfinish(connection);
    }
  }

  void DropIdle() {
    std::vector<PGconn*> dropped;
    {
      std::lock_guard lock(mutex_);
      dropped.swap(idle_);
    }
    for (PGconn* connection : dropped) PQfinish(connection);
  }

  const std::string uri_;
  std::mutex mutex_;
  std::vector<PGconn*> idle_;
};

}  // namespace sweetspot::server::pg
