// The parsers the option tables share, and the serving options (server/config_options.hpp).
#include "server/config_options.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>

#include "core/geometry_format.hpp"

namespace sweetspot::server::config_options {

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

// A number of seconds in [0, 3600] (0 = none).
bool ParseSecondsOrZero(const std::string& text, double* out, std::string* rule) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end == nullptr || *end != '\0' || !std::isfinite(value) || value < 0 ||
      value > 3600) {
    *rule = "must be a number of seconds in [0, 3600]";
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

// Listening and threads.
const std::vector<Option>& ServingOptions() {
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
  };
  return options;
}

// Connections: how many, from one address, unread answers; the first byte's and a
// computation's deadlines; the token; CORS.
const std::vector<Option>& ConnectionOptions() {
  static const std::vector<Option> options = {
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
       "file holding a bearer token required on every path but /health and /ready (default: "
       "none; SWEETSPOT_AUTH_TOKEN may hold the token itself)",
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
  };
  return options;
}

// What a request may take of a connection: sizes and deadlines of heads and bodies, answers'
// writes, keep-alive.
const std::vector<Option>& RequestReadingOptions() {
  static const std::vector<Option> options = {
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
  };
  return options;
}

}  // namespace sweetspot::server::config_options
