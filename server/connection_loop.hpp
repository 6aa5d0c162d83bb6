// The server's connection loop: one thread owns every connection with epoll,
// reads each request's whole head and body under deadlines, and only then hands
// the complete request to a worker; idle keep-alive connections and slow
// clients hold no worker. Requests are served first come, first served across
// connections (one request per turn), so many keep-alive clients share the
// workers fairly. Two pools: `light_workers` threads for cheap requests and
// `compute_workers` threads (sized to the cores) for requests that run models,
// so a burst of solver work never delays /health or a closed-form answer.
//
// What the loop answers itself, then closes the connection:
//   503 TooBusy   a connection past max_connections, at once (Retry-After: 1);
//   408 Timeout   a head not complete within header_timeout_s of its first byte
//                 (of the accept, for a new connection), a body slower than
//                 body_min_rate_bytes_per_s, or read_timeout_s without a byte;
//   431 TooBig    a head over max_head_bytes;
//   400           a Content-Length that is not one decimal number.
// A closed connection is first drained for up to linger_s (so that the client
// reads the answer instead of a reset), without counting against the limit.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "server/request_stream.hpp"

namespace sweetspot::server {

/// The loop's limits and pool sizes (ServerConfig supplies them).
struct ConnectionLoopOptions {
  int max_connections = 256;             ///< Open connections admitted; beyond: 503.
  std::size_t max_head_bytes = 65536;    ///< Largest request head, bytes; beyond: 431.
  std::size_t max_body_bytes = 1 << 20;  ///< Larger bodies are not read (httplib answers 413).
  double header_timeout_s = 10.0;        ///< Whole request head, s, from its first byte.
  double body_min_rate_bytes_per_s = 32768;  ///< A body of N bytes gets header_timeout_s + N / rate.
  double read_timeout_s = 10.0;          ///< Longest silence inside a request, s.
  double write_timeout_s = 10.0;         ///< Longest wait for the socket to take more of an answer, s.
  double keep_alive_timeout_s = 5.0;     ///< Idle keep-alive connection closed after this, s.
  int keep_alive_max_requests = 10000;   ///< Requests per connection; the last says Connection: close.
  int light_workers = 8;                 ///< Threads for cheap requests.
  int compute_workers = 2;               ///< Threads for requests that run models.
  double linger_s = 1.0;                 ///< How long a closed connection is drained, s.
};

/// The worker pool a request is served in.
enum class Pool { kLight, kCompute };

/// What the loop needs from the HTTP layer.
struct ConnectionLoopHooks {
  /// Answers one request read from `stream` (httplib's request handling);
  /// `close_connection` asks for "Connection: close". Returns false when the
  /// connection cannot be used again; sets *closed when the client asked to close.
  std::function<bool(RequestStream& stream, bool close_connection, bool* closed)> serve;
  /// Which pool a complete request belongs in (called on a light worker).
  std::function<Pool(std::string_view method, std::string_view path, std::string_view body)>
      classify;
  /// The JSON error envelope (with its trailing newline) for an answer the loop gives itself.
  std::function<std::string(int status, const char* code, const std::string& message)>
      error_body;
  /// Called after the loop answered a request itself: status, code, the
  /// request's method and path when known ("" otherwise). May be empty.
  std::function<void(int status, const char* code, const std::string& method,
                     const std::string& path)>
      refused;
};

/// The loop. Run() on one thread; Stop() and MetricsText() from any thread.
class ConnectionLoop {
 public:
  /// Takes ownership of `listen_fd` (bound and listening). Starts the workers.
  ConnectionLoop(int listen_fd, ConnectionLoopOptions options, ConnectionLoopHooks hooks);
  ~ConnectionLoop();
  ConnectionLoop(const ConnectionLoop&) = delete;
  ConnectionLoop& operator=(const ConnectionLoop&) = delete;

  /// Serves until Stop(); then closes the listening socket and idle
  /// connections, answers the requests already read (with Connection: close)
  /// and returns. Returns false if the loop could not start (epoll failed).
  bool Run();
  /// Makes Run() return (after the in-flight requests); idempotent, any thread.
  void Stop();

  /// Prometheus text of the loop's gauges and counters (connections by state,
  /// refusals by reason, each pool's busy workers, their peak and queue).
  std::string MetricsText() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sweetspot::server
