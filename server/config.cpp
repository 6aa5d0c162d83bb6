#include "server/config.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "core/geometry_format.hpp"

namespace sweetspot::server {
namespace {

// One option: flag name, environment variable, help text, and a setter that
// parses the text into the config (returns false with a rule on bad text).
struct Option {
  const char* flag;
  const char* env;
  const char* help;
  bool takes_value;
  std::function<bool(ServerConfig*, const std::string&, std::string* rule)> set;
};

bool ParseLong(const std::string& text, long long lo, long long hi, long long* out,
               std::string* rule) {
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end == nullptr || *end != '\0' || errno != 0 || value < lo || value > hi) {
    *rule = "must be an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    return false;
  }
  *out = value;
  return true;
}

bool ParseSeconds(const std::string& text, double* out, std::string* rule) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) || value <= 0 ||
      value > 3600) {
    *rule = "must be a number of seconds in (0, 3600]";
    return false;
  }
  *out = value;
  return true;
}

// A number of seconds in (0, max] (a limit longer than ParseSeconds' hour).
bool ParseSecondsUpTo(const std::string& text, double max, double* out, std::string* rule) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) || value <= 0 ||
      value > max) {
    *rule = "must be a number of seconds in (0, " + core::FormatNumber(max) + "]";
    return false;
  }
  *out = value;
  return true;
}

bool ParseBool(const std::string& text, bool* out, std::string* rule) {
  if (text == "1" || text == "true" || text == "yes" || text == "on") {
    *out = true;
  } else if (text == "0" || text == "false" || text == "no" || text == "off") {
    *out = false;
  } else {
    *rule = "must be one of 1, 0, true, false, yes, no, on, off";
    return false;
  }
  return true;
}

bool SetSize(std::size_t* out, const std::string& text, std::string* rule) {
  long long n = 0;
  if (!ParseLong(text, 1, 100000000, &n, rule)) return false;
  *out = static_cast<std::size_t>(n);
  return true;
}

const std::vector<Option>& Options() {
  static const std::vector<Option> options = {
      {"--host", "SWEETSPOT_HOST", "address to bind (default 127.0.0.1; 0.0.0.0 for all)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         if (v.empty()) {
           *rule = "must not be empty";
           return false;
         }
         c->host = v;
         return true;
       }},
      {"--port", "SWEETSPOT_PORT", "TCP port (default 8080; 0 = pick a free port)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long p = 0;
         if (!ParseLong(v, 0, 65535, &p, rule)) return false;
         c->port = static_cast<int>(p);
         return true;
       }},
      {"--threads", "SWEETSPOT_THREADS",
       "worker threads for cheap requests; a connection holds one only while a request of "
       "it is answered (default 8)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 1024, &n, rule)) return false;
         c->threads = static_cast<int>(n);
         return true;
       }},
      {"--compute-threads", "SWEETSPOT_COMPUTE_THREADS",
       "worker threads for requests that run models (explore, optimize, fit, modes, hertz and "
       "flexible scenes); 0 = one per core (default 0)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 0, 1024, &n, rule)) return false;
         c->compute_threads = static_cast<int>(n);
         return true;
       }},
      {"--explore-threads", "SWEETSPOT_EXPLORE_THREADS",
       "threads one /v1/explore sweep evaluates its designs on (the rows' order and bytes do "
       "not depend on it); those beyond the sweep's own come from the compute pool's idle "
       "workers; 0 = one per core (default 0)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 0, 1024, &n, rule)) return false;
         c->explore_threads = static_cast<int>(n);
         return true;
       }},
      {"--max-connections", "SWEETSPOT_MAX_CONNECTIONS",
       "open connections (reading, answered or idle keep-alive); beyond: 503 TooBusy at once, "
       "then closed (default 256)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 100000, &n, rule)) return false;
         c->max_connections = static_cast<int>(n);
         return true;
       }},
      {"--max-connections-per-client", "SWEETSPOT_MAX_CONNECTIONS_PER_CLIENT",
       "open connections from one client address; beyond: 503 TooBusy at once, then closed; "
       "behind a proxy every client has the proxy's address: set it to --max-connections "
       "there (default 128)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 100000, &n, rule)) return false;
         c->max_connections_per_client = static_cast<int>(n);
         return true;
       }},
      {"--max-unsent-bytes-per-client", "SWEETSPOT_MAX_UNSENT_BYTES_PER_CLIENT",
       "answer bytes one client address's connections may leave unread (held by the server "
       "until they read them); an answer whose rest would exceed it is cut and its "
       "connection closed (default 67108864)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 65536, 1LL << 40, &n, rule)) return false;
         c->max_unsent_bytes_per_client = static_cast<std::size_t>(n);
         return true;
       }},
      {"--first-byte-timeout-s", "SWEETSPOT_FIRST_BYTE_TIMEOUT_S",
       "a new connection must send its first byte within this many s; else it is closed "
       "without an answer (default 2)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->first_byte_timeout_s, rule);
       }},
      {"--max-request-time-s", "SWEETSPOT_MAX_REQUEST_TIME_S",
       "longest a request that runs models (the compute pool's) may compute, in s from when a "
       "compute worker takes it; then it is stopped and answered 503 with Retry-After (a "
       "streamed answer ends early); longer work belongs in POST /v1/jobs (default 120)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->max_request_time_s, rule);
       }},
      {"--auth-token-file", "SWEETSPOT_AUTH_TOKEN_FILE",
       "file holding a bearer token required on every path but /health (default: none; "
       "SWEETSPOT_AUTH_TOKEN may hold the token itself)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         std::ifstream in(v);
         std::string token;
         if (!in || !std::getline(in, token)) {
           *rule = "must name a readable file whose first line is the token";
           return false;
         }
         while (!token.empty() && (token.back() == '\r' || token.back() == ' ')) token.pop_back();
         if (token.size() < 16) {
           *rule = "the token must have at least 16 characters";
           return false;
         }
         c->auth_token = token;
         return true;
       }},
      {"--cors-origin", "SWEETSPOT_CORS_ORIGIN",
       "allow cross-origin requests from this Origin (or *); default: no CORS", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         if (v.empty()) {
           *rule = "must be an origin such as https://example.org, or *";
           return false;
         }
         c->cors_origin = v;
         return true;
       }},
      {"--max-body-bytes", "SWEETSPOT_MAX_BODY_BYTES",
       "largest request body in bytes (default 1048576)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 1LL << 30, &n, rule)) return false;
         c->max_body_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--max-head-bytes", "SWEETSPOT_MAX_HEAD_BYTES",
       "largest request head (request line and headers) in bytes; beyond: 431 (default 65536)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 256, 1LL << 24, &n, rule)) return false;
         c->max_head_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--header-timeout-s", "SWEETSPOT_HEADER_TIMEOUT_S",
       "a request head must arrive whole within this many s of its first byte (of the "
       "accept, for a new connection); else 408 and the connection is closed (default 10)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->header_timeout_s, rule);
       }},
      {"--body-min-rate-bytes-per-s", "SWEETSPOT_BODY_MIN_RATE_BYTES_PER_S",
       "a body of N bytes must arrive within header-timeout-s + N / this many s; else 408 "
       "and the connection is closed (default 32768)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 1LL << 34, &n, rule)) return false;
         c->body_min_rate_bytes_per_s = static_cast<double>(n);
         return true;
       }},
      {"--read-timeout-s", "SWEETSPOT_READ_TIMEOUT_S",
       "longest silence inside a request (head or body) in s; else 408 and the connection is "
       "closed (default 10)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->read_timeout_s, rule);
       }},
      {"--write-timeout-s", "SWEETSPOT_WRITE_TIMEOUT_S", "socket write timeout in s (default 10)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->write_timeout_s, rule);
       }},
      {"--keep-alive-timeout-s", "SWEETSPOT_KEEP_ALIVE_TIMEOUT_S",
       "idle keep-alive timeout in s (default 5)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->keep_alive_timeout_s, rule);
       }},
      {"--keep-alive-max-requests", "SWEETSPOT_KEEP_ALIVE_MAX_REQUESTS",
       "requests per keep-alive connection (default 10000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 1000000000, &n, rule)) return false;
         c->keep_alive_max_requests = static_cast<int>(n);
         return true;
       }},
      {"--max-json-depth", "SWEETSPOT_MAX_JSON_DEPTH",
       "deepest JSON nesting in a body (default 32)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 2, 512, &n, rule)) return false;
         c->limits.max_json_depth = static_cast<int>(n);
         return true;
       }},
      {"--max-array-length", "SWEETSPOT_MAX_ARRAY_LENGTH",
       "longest array anywhere in a body (default 4096)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_array_length, v, rule);
       }},
      {"--max-string-length", "SWEETSPOT_MAX_STRING_LENGTH",
       "longest string value or key in a body, bytes (default 256)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_string_length, v, rule);
       }},
      {"--max-knots", "SWEETSPOT_MAX_KNOTS", "knots of a profile (default 256)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_knots, v, rule);
       }},
      {"--max-variants", "SWEETSPOT_MAX_VARIANTS", "variants in /v1/compare (default 64)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_variants, v, rule);
       }},
      {"--max-launches", "SWEETSPOT_MAX_LAUNCHES", "launches in one /v1/flight request (default 4096)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_launches, v, rule);
       }},
      {"--max-jobs-page", "SWEETSPOT_MAX_JOBS_PAGE",
       "jobs on one page of GET /v1/jobs: the largest `limit` (default 1000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_jobs_page, v, rule);
       }},
      {"--max-curve-samples", "SWEETSPOT_MAX_CURVE_SAMPLES",
       "points of an exit-speed curve (default 10000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_curve_samples, v, rule);
       }},
      {"--max-samples", "SWEETSPOT_MAX_SAMPLES",
       "designs in one /v1/explore request (default 100000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_samples, v, rule);
       }},
      {"--max-batch-samples", "SWEETSPOT_MAX_BATCH_SAMPLES",
       "designs in one /v1/explore run as a job, whose rows go to its result (default "
       "1000000; synchronous requests keep --max-samples)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_batch_samples, v, rule);
       }},
      {"--max-response-bytes", "SWEETSPOT_MAX_RESPONSE_BYTES",
       "estimated bytes of an answer built in memory (a synchronous /v1/explore in JSON: rows "
       "x bytes per row); beyond it 413 before the first design (default 67108864)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1024, 1LL << 40, &n, rule)) return false;
         c->limits.max_response_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--max-job-cpu-s", "SWEETSPOT_MAX_JOB_CPU_S",
       "a job's estimated CPU time (designs x its models' cost per design), s; beyond it "
       "POST /v1/jobs answers 413 (default 3600)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSecondsUpTo(v, 1e7, &c->limits.max_job_cpu_s, rule);
       }},
      {"--max-design-variables", "SWEETSPOT_MAX_DESIGN_VARIABLES",
       "variables of one /v1/optimize design (default 200, the optimiser's ceiling)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->limits.max_design_variables, v, rule);
       }},
      {"--max-iterations", "SWEETSPOT_MAX_ITERATIONS",
       "solver iterations a request may ask for (default 10000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 100000000, &n, rule)) return false;
         c->limits.max_iterations = static_cast<int>(n);
         return true;
       }},
      {"--max-integration-steps", "SWEETSPOT_MAX_INTEGRATION_STEPS",
       "ODE steps one impact may take (hertz, flexible; default 10000000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseLong(v, 10, 1000000000, &c->limits.max_integration_steps, rule);
       }},
      {"--max-time-s", "SWEETSPOT_MAX_TIME_S",
       "solver wall time a request may ask for, s (default 60)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->limits.max_time_s, rule);
       }},
      {"--job-workers", "SWEETSPOT_JOB_WORKERS", "threads running jobs (default 2)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1, 64, &n, rule)) return false;
         c->jobs.workers = static_cast<int>(n);
         return true;
       }},
      {"--job-queue", "SWEETSPOT_JOB_QUEUE", "queued jobs before 429 (default 64)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->jobs.max_queued, v, rule);
       }},
      {"--jobs-kept", "SWEETSPOT_JOBS_KEPT", "finished jobs kept (default 1000)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return SetSize(&c->jobs.max_kept, v, rule);
       }},
      {"--job-keep-s", "SWEETSPOT_JOB_KEEP_S",
       "how long a finished job's result is kept, s (default 3600)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseSeconds(v, &c->jobs.keep_results_s, rule);
       }},
      {"--job-max-resumes", "SWEETSPOT_JOB_MAX_RESUMES",
       "times a job the server died under (crash, SIGKILL) is run again (at start-up, or with "
       "PostgreSQL by another replica once its lease expires) before it is marked failed "
       "(default 2)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 0, 100, &n, rule)) return false;
         c->jobs.max_resumes = static_cast<int>(n);
         return true;
       }},
      {"--job-lease-s", "SWEETSPOT_JOB_LEASE_S",
       "PostgreSQL: how long a running job's claim lasts unrenewed before another replica "
       "may run it, s (default 10)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         double s = 0;
         if (!ParseSeconds(v, &s, rule)) return false;
         if (s < 1 || s > 3600) {
           *rule = "must be in [1, 3600] s";
           return false;
         }
         c->jobs.lease_s = s;
         return true;
       }},
      {"--job-max-result-bytes", "SWEETSPOT_JOB_MAX_RESULT_BYTES",
       "the largest job result kept (any jobs database); a larger one fails the job (413 "
       "TooBig) with its size, never truncated (default 268435456)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1024, 1000000000, &n, rule)) return false;
         c->jobs.max_result_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--job-results-memory-bytes", "SWEETSPOT_JOB_RESULTS_MEMORY_BYTES",
       "finished jobs' results held in memory in total, bytes: with a SQLite jobs database, "
       "results over 65536 bytes stay in the database only and the oldest small ones leave "
       "memory beyond this; with --jobs-db none, the oldest finished jobs are dropped beyond "
       "it and a larger result fails its job (default 268435456)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 1024, 1000000000000LL, &n, rule)) return false;
         c->jobs.max_results_memory_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--job-max-time-s", "SWEETSPOT_JOB_MAX_TIME_S",
       "the longest a job may run, s; then it is stopped and failed (408 Timeout) "
       "(default 600)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         char* end = nullptr;
         const double value = std::strtod(v.c_str(), &end);
         if (v.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) || value <= 0 ||
             value > 1e6) {
           *rule = "must be a number of seconds in (0, 1000000]";
           return false;
         }
         c->jobs.max_time_s = value;
         return true;
       }},
      {"--jobs-db-max-bytes", "SWEETSPOT_JOBS_DB_MAX_BYTES",
       "SQLite: the largest the jobs database file may grow, bytes; past it saves fail as on a "
       "full disk (submits answer 503, a job whose result cannot be saved fails); 0 = no limit "
       "but the disk's (default 4294967296)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         long long n = 0;
         if (!ParseLong(v, 0, 1000000000000000LL, &n, rule)) return false;
         if (n != 0 && n < 65536) {
           *rule = "must be 0 (no limit) or at least 65536";
           return false;
         }
         c->jobs_db_max_bytes = static_cast<std::size_t>(n);
         return true;
       }},
      {"--jobs-db", "SWEETSPOT_JOBS_DB",
       "where jobs and their results are kept: a SQLite file (default sweetspot-jobs.db in "
       "the working directory), a postgresql://user@host:port/db URI shared by every replica "
       "(one store and one queue), or none = memory only",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         if (v.empty()) {
           *rule = "must be a file path, a postgresql:// URI, or none for no persistence";
           return false;
         }
         c->jobs_db = v;
         return true;
       }},
      {"--shutdown-grace-s", "SWEETSPOT_SHUTDOWN_GRACE_S",
       "on SIGTERM, how long running jobs may finish before they are interrupted and kept "
       "for the next start, s (default 8; 0 = interrupt at once)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         char* end = nullptr;
         const double value = std::strtod(v.c_str(), &end);
         if (v.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) || value < 0 ||
             value > 3600) {
           *rule = "must be a number of seconds in [0, 3600]";
           return false;
         }
         c->shutdown_grace_s = value;
         return true;
       }},
      {"--web-root", "SWEETSPOT_WEB_ROOT",
       "folder of the design explorer's static files, served at / without a token (default: "
       "the folder web next to the executable; a missing folder answers 404 at /)",
       true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         if (v.empty()) {
           *rule = "must be a folder path";
           return false;
         }
         c->web_root = v;
         return true;
       }},
      {"--access-log", "SWEETSPOT_ACCESS_LOG",
       "one JSON line per request on stderr, 1 or 0 (default 1)", true,
       [](ServerConfig* c, const std::string& v, std::string* rule) {
         return ParseBool(v, &c->access_log, rule);
       }},
  };
  return options;
}

}  // namespace

bool ServerConfig::Validate(core::Refusal* refusal) const {
  using core::IntegerRefusal;
  using core::NumberRefusal;
  auto fail = [refusal](core::Refusal why) { return core::Refuse(refusal, std::move(why)); };
  if (host.empty()) return fail(core::QuotedRefusal("host", "\"\"", "must not be empty"));
  if (port < 0 || port > 65535) return fail(IntegerRefusal("port", port, "must be in [0, 65535]"));
  if (threads < 1 || threads > 1024) {
    return fail(IntegerRefusal("threads", threads, "must be in [1, 1024]"));
  }
  if (compute_threads < 0 || compute_threads > 1024) {
    return fail(IntegerRefusal("compute_threads", compute_threads,
                               "must be in [0, 1024] (0 = one per core)"));
  }
  if (explore_threads < 0 || explore_threads > 1024) {
    return fail(IntegerRefusal("explore_threads", explore_threads,
                               "must be in [0, 1024] (0 = one per core)"));
  }
  if (max_head_bytes < 256) {
    return fail(IntegerRefusal("max_head_bytes", static_cast<long long>(max_head_bytes),
                               "must be at least 256"));
  }
  if (!std::isfinite(body_min_rate_bytes_per_s) || body_min_rate_bytes_per_s < 1) {
    return fail(NumberRefusal("body_min_rate_bytes_per_s", body_min_rate_bytes_per_s,
                              "must be at least 1"));
  }
  if (max_connections < 1) {
    return fail(IntegerRefusal("max_connections", static_cast<long long>(max_connections),
                               "must be at least 1"));
  }
  if (max_connections_per_client < 1) {
    return fail(IntegerRefusal("max_connections_per_client",
                               static_cast<long long>(max_connections_per_client),
                               "must be at least 1"));
  }
  if (!auth_token.empty() && auth_token.size() < 16) {
    return fail(core::TextRefusal("auth_token", "must have at least 16 characters"));
  }
  if (max_body_bytes < 1) return fail(IntegerRefusal("max_body_bytes", 0, "must be at least 1"));
  for (const auto& [name, value] :
       {std::pair{"header_timeout_s", header_timeout_s},
        std::pair{"read_timeout_s", read_timeout_s}, std::pair{"write_timeout_s", write_timeout_s},
        std::pair{"keep_alive_timeout_s", keep_alive_timeout_s},
        std::pair{"first_byte_timeout_s", first_byte_timeout_s},
        std::pair{"max_request_time_s", max_request_time_s}}) {
    if (!std::isfinite(value) || value <= 0 || value > 3600) {
      return fail(NumberRefusal(name, value, "must be in (0, 3600]"));
    }
  }
  if (core::Refusal why; !limits.Validate(&why)) return fail(core::Prefixed("limits.", why));
  if (core::Refusal why; !jobs.Validate(&why)) return fail(core::Prefixed("jobs.", why));
  if (jobs_db.empty()) {
    return fail(core::QuotedRefusal("jobs_db", "\"\"",
                                    "must be a file path, a postgresql:// URI, or \"" +
                                        std::string(kNoJobsDb) + "\" for no persistence"));
  }
  if (jobs_db_max_bytes != 0 &&
      (jobs_db_max_bytes < 65536 || jobs_db_max_bytes > 1000000000000000ULL)) {
    return fail(core::QuotedRefusal("jobs_db_max_bytes", std::to_string(jobs_db_max_bytes),
                                    "must be 0 (no limit) or in [65536, 1e15]"));
  }
  if (!std::isfinite(shutdown_grace_s) || shutdown_grace_s < 0 || shutdown_grace_s > 3600) {
    return fail(NumberRefusal("shutdown_grace_s", shutdown_grace_s, "must be in [0, 3600]"));
  }
  if (keep_alive_max_requests < 1) {
    return fail(IntegerRefusal("keep_alive_max_requests",
                               static_cast<long long>(keep_alive_max_requests),
                               "must be at least 1"));
  }
  return true;
}

ParsedCommandLine ParseCommandLine(
    const std::vector<std::string>& args,
    const std::function<std::optional<std::string>(const std::string&)>& getenv) {
  ParsedCommandLine out;
  std::string rule;
  if (auto token = getenv("SWEETSPOT_AUTH_TOKEN")) out.config.auth_token = *token;
  for (const Option& option : Options()) {
    if (auto value = getenv(option.env)) {
      if (!option.set(&out.config, *value, &rule)) {
        out.error = std::string("environment ") + option.env + " = \"" + *value + "\": " + rule;
        return out;
      }
    }
  }
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (arg == "--help" || arg == "-h") {
      out.show_help = true;
      continue;
    }
    std::string name = arg;
    std::optional<std::string> value;
    if (const auto eq = arg.find('='); eq != std::string::npos) {
      name = arg.substr(0, eq);
      value = arg.substr(eq + 1);
    }
    if (name == "--no-access-log" && !value) {
      out.config.access_log = false;
      continue;
    }
    const Option* match = nullptr;
    for (const Option& option : Options()) {
      if (name == option.flag) match = &option;
    }
    if (match == nullptr) {
      out.error = "unknown option " + arg + " (see --help)";
      return out;
    }
    if (!value) {
      if (i + 1 >= args.size()) {
        out.error = "option " + name + " needs a value";
        return out;
      }
      value = args[++i];
    }
    if (!match->set(&out.config, *value, &rule)) {
      out.error = "option " + name + " = \"" + *value + "\": " + rule;
      return out;
    }
  }
  // One flag per job limit: the api's check at submit reads the job runner's limits.
  out.config.limits.max_job_time_s = out.config.jobs.max_time_s;
  out.config.limits.max_job_result_bytes = out.config.jobs.max_result_bytes;
  if (core::Refusal why; !out.config.Validate(&why)) out.error = why.Message();
  return out;
}

std::string Usage(const std::string& program) {
  std::ostringstream text;
  text << "Usage: " << program << " [OPTIONS]\n"
       << "Serves the sweetspot HTTP JSON API in the foreground; logs to stderr;\n"
       << "stops cleanly on SIGTERM or SIGINT. Flags override environment variables.\n\n"
       << "Options:\n";
  for (const Option& option : Options()) {
    text << "  " << option.flag << " VALUE\n      " << option.help << "\n      env: " << option.env
         << "\n";
  }
  text << "  --no-access-log\n      same as --access-log 0\n"
       << "  -h, --help\n      this text\n";
  return text.str();
}

}  // namespace sweetspot::server
