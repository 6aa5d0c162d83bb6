// The access log: one JSON line on stderr per request the server answered.
#pragma once

#include <cstddef>
#include <string>

namespace sweetspot::server {

/// One request and how it was answered.
struct AccessLogEntry {
  std::string method;       ///< HTTP method ("" when the request line was unreadable).
  std::string path;         ///< Request path.
  std::string route;        ///< The matched route pattern, "unrouted" or the static route.
  int status = 0;           ///< HTTP status sent.
  double duration_s = 0.0;  ///< Time from the complete request to the answer, in seconds.
  std::size_t bytes_in = 0; ///< Body bytes received.
  /// What the top-level handler caught when it answered 500 (the exception's
  /// what()); empty otherwise. Logged, never sent to the client.
  std::string error;
};

/// The entry as one compact JSON object without a newline: {"method", "path",
/// "route", "status", "duration_s", "bytes_in"}, plus "error" when it is set.
/// Invalid UTF-8 is replaced, so the line is always valid JSON.
std::string AccessLogLine(const AccessLogEntry& entry);

}  // namespace sweetspot::server
