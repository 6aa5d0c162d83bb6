// Server configuration: defaults, command-line flags and environment variables.
// Precedence: flag > environment > default.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "server/jobs/job_common.hpp"
#include "api/limits.hpp"

namespace sweetspot::server {

/// Everything the HTTP service can be configured with.
struct ServerConfig {
  std::string host = "127.0.0.1";        ///< Address to bind (--host, SWEETSPOT_HOST). Loopback by default.
  int port = 8080;                       ///< TCP port, 0 = ephemeral (--port, SWEETSPOT_PORT).
  int threads = 8;                       ///< Worker threads for cheap requests (--threads, SWEETSPOT_THREADS), 1..1024. A connection holds one only while a request of it is being answered.
  int compute_threads = 0;               ///< Worker threads for requests that run models (explore, optimize, fit, modes, hertz and flexible scenes); 0 = one per core (--compute-threads, SWEETSPOT_COMPUTE_THREADS), 0..1024.
  int explore_threads = 0;               ///< Threads one /v1/explore sweep evaluates on (beyond its own: idle compute workers); 0 = one per core (--explore-threads, SWEETSPOT_EXPLORE_THREADS), 0..1024.
  int max_connections = 256;             ///< Open connections (reading, answered, idle keep-alive); beyond: 503 TooBusy at once, then closed (--max-connections, SWEETSPOT_MAX_CONNECTIONS).
  int max_connections_per_client = 128;  ///< Open connections from one client address; beyond: 503 TooBusy at once, then closed; behind a proxy every client has the proxy's address, so set it to max_connections there (--max-connections-per-client, SWEETSPOT_MAX_CONNECTIONS_PER_CLIENT), 1..100000.
  std::size_t max_unsent_bytes_per_client = 64u << 20;  ///< Answer bytes one client address's connections may leave unread, held by the server until they read them; an answer whose rest would exceed it is cut and its connection closed (--max-unsent-bytes-per-client, SWEETSPOT_MAX_UNSENT_BYTES_PER_CLIENT).
  double first_byte_timeout_s = 2.0;     ///< A new connection must send its first byte within this, s; else closed without an answer (--first-byte-timeout-s, SWEETSPOT_FIRST_BYTE_TIMEOUT_S).
  double max_request_time_s = 120.0;     ///< Longest a request that runs models may compute, s, from when a compute worker takes it; then stopped and answered 503 (a stream ends early) (--max-request-time-s, SWEETSPOT_MAX_REQUEST_TIME_S).
  std::string auth_token;                ///< If set, every path but /health and /ready needs "Authorization: Bearer <token>" (SWEETSPOT_AUTH_TOKEN, --auth-token-file).
  std::string cors_origin;               ///< CORS: the allowed Origin, or "*"; empty = no CORS headers (--cors-origin, SWEETSPOT_CORS_ORIGIN).
  std::size_t max_body_bytes = 1 << 20;  ///< Largest request body, bytes (--max-body-bytes, SWEETSPOT_MAX_BODY_BYTES).
  std::size_t max_head_bytes = 65536;    ///< Largest request head (request line and headers), bytes; beyond: 431 (--max-head-bytes, SWEETSPOT_MAX_HEAD_BYTES).
  double header_timeout_s = 10.0;        ///< A request head must arrive whole within this, s, from its first byte (from the accept for a new connection); else 408 and closed (--header-timeout-s, SWEETSPOT_HEADER_TIMEOUT_S).
  double body_min_rate_bytes_per_s = 32768;  ///< A body of N bytes must arrive within header_timeout_s + N / this, s; else 408 and closed (--body-min-rate-bytes-per-s, SWEETSPOT_BODY_MIN_RATE_BYTES_PER_S).
  double read_timeout_s = 10.0;          ///< Longest silence inside a request (head or body), s; else 408 and closed (--read-timeout-s, SWEETSPOT_READ_TIMEOUT_S).
  double write_timeout_s = 10.0;         ///< Socket write timeout, s (--write-timeout-s, SWEETSPOT_WRITE_TIMEOUT_S).
  double keep_alive_timeout_s = 5.0;     ///< Idle keep-alive timeout, s (--keep-alive-timeout-s, SWEETSPOT_KEEP_ALIVE_TIMEOUT_S).
  int keep_alive_max_requests = 10000;   ///< Requests per keep-alive connection (--keep-alive-max-requests, SWEETSPOT_KEEP_ALIVE_MAX_REQUESTS).
  bool access_log = true;                ///< One JSON line per request on stderr (--no-access-log, SWEETSPOT_ACCESS_LOG=0).
  api::ApiLimits limits;                 ///< Request limits (--max-json-depth, --max-knots, ...; see Usage()).
  JobConfig jobs;                   ///< Job pool (--job-workers, --job-queue, --job-keep-s, --jobs-kept, --job-max-resumes, --job-lease-s, --job-max-result-bytes, --job-results-memory-bytes, --job-max-time-s).
  std::string jobs_db = "sweetspot-jobs.db";  ///< Where jobs are kept: a SQLite file (relative to the working directory), a postgresql:// URI shared by replicas, or "none" = memory only (--jobs-db, SWEETSPOT_JOBS_DB).
  std::size_t jobs_db_max_bytes = 4ULL << 30;  ///< SQLite: the largest the jobs database file may grow, bytes (4 GiB: 16 results at --job-max-result-bytes); 0 = no limit but the disk's, else [65536, 1e15] (--jobs-db-max-bytes, SWEETSPOT_JOBS_DB_MAX_BYTES).
  double drain_s = 0.0;                  ///< On SIGTERM/SIGINT, how long the server keeps accepting and answering while GET /ready answers 503 (answers then carry Connection: close), s, [0, 3600]; then it stops accepting and shutdown_grace_s begins; 0 = stop accepting at once; a second signal ends it (--drain-s, SWEETSPOT_DRAIN_S).
  double shutdown_grace_s = 8.0;         ///< On SIGTERM/SIGINT, how long running jobs may still finish before they are interrupted, s, [0, 3600] (--shutdown-grace-s, SWEETSPOT_SHUTDOWN_GRACE_S).
  std::string web_root;                  ///< Folder of the design explorer's static files served at /; empty = "web" next to the executable (--web-root, SWEETSPOT_WEB_ROOT).

  /// True when every field is in range; otherwise the refusal in *refusal (if non-null): field,
  /// value and rule, its Message() "field = value: rule".
  bool Validate(core::Refusal* refusal) const;
};

/// The ServerConfig::jobs_db value that turns job persistence off.
inline constexpr const char* kNoJobsDb = "none";

/// What parsing the command line produced.
struct ParsedCommandLine {
  ServerConfig config;    ///< The configuration (valid when error is empty).
  bool show_help = false; ///< --help was given.
  std::string error;      ///< Non-empty on a bad flag, value or environment variable.
};

/// Reads the environment through `getenv` (injectable for tests), then the
/// flags in `args` (without the program name). Never throws.
ParsedCommandLine ParseCommandLine(
    const std::vector<std::string>& args,
    const std::function<std::optional<std::string>(const std::string&)>& getenv);

/// The --help text: every option, its environment variable and default.
std::string Usage(const std::string& program);

}  // namespace sweetspot::server
