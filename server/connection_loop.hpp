// The server's connection handling: every connection lives in one epoll set
// that the light workers wait on together; a worker that is woken for a
// connection reads what arrived without blocking, and only when a request's
// whole head and body are in does it answer the request (or pass it to the
// compute pool), then puts the connection back into the set. So a connection
// holds a worker only while a complete request of it is being answered: idle
// keep-alive connections and slow clients hold none, and many keep-alive
// clients take turns one request at a time (each connection is re-armed after
// each request, behind those already waiting). Two pools: `light_workers`
// threads for cheap requests and `compute_workers` threads (sized to the
// cores) for requests that run models, so that a burst of solver work never
// delays /health or a closed-form answer. The thread that calls Run() keeps the
// deadlines.
//
// What is answered without a handler, then the connection is closed:
//   503 TooBusy   a connection past max_connections, or past max_connections_per_client
//                 from one address, at once (Retry-After: 1); a queued compute request
//                 once the server is stopping;
//   408 Timeout   a head not complete within header_timeout_s of its first byte
//                 (of the accept, for a new connection), a body slower than
//                 body_min_rate_bytes_per_s, or read_timeout_s without a byte;
//   431 TooBig    a head over max_head_bytes, or a header line over 8192 bytes;
//   414 TooBig    a request line over 8192 bytes;
//   400           a Content-Length that is not one decimal number, or a line that ends
//                 in a bare LF.
// A connection that sends no byte within first_byte_timeout_s is closed without an
// answer; one whose unread answer would take its address past
// max_unsent_bytes_per_client is closed with the answer cut. Range headers are
// dropped before httplib sees the request: every answer is whole. A request of the compute pool
// carries a cancel flag (RequestCancel) that the deadline keeper sets when its client closes the
// connection, when it has computed for max_request_time_s, or shutdown_grace_s after the server
// began to stop; a queued request whose client left is dropped without computing, and one still
// queued when the grace ends is refused 503. A closed connection is first half-closed and drained
// for up to linger_s (so that the client reads the answer instead of a reset), without counting
// against the limit.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

#include "api/error_code.hpp"
#include "server/request_stream.hpp"

namespace sweetspot::api {
class ThreadBudget;
}  // namespace sweetspot::api

namespace sweetspot::server {

/// The loop's limits and pool sizes (ServerConfig supplies them).
struct ConnectionLoopOptions {
  /// Open connections admitted; beyond: 503.
  int max_connections = 256;
  /// Open connections admitted from one client address; beyond: 503.
  int max_connections_per_client = 128;
  /// Answer bytes one client address's connections may leave unread (held until the client
  /// reads them); an answer whose rest would exceed it is cut (the connection closed).
  std::size_t max_unsent_bytes_per_client = 64u << 20;
  /// A new connection's first byte must arrive within this, s; else closed silently.
  double first_byte_timeout_s = 2.0;
  /// A compute-pool request is cancelled (CancelReason::kDeadline) after computing this long, s.
  double max_request_time_s = 120.0;
  /// After Stop(), how long requests being answered (and queued compute requests) may still
  /// finish, s; then they are cancelled (CancelReason::kShutdown) and queued ones refused.
  double shutdown_grace_s = 8.0;
  /// Largest request head, bytes; beyond: 431.
  std::size_t max_head_bytes = 65536;
  /// Larger bodies are not read (httplib answers 413).
  std::size_t max_body_bytes = 1 << 20;
  /// Whole request head, s, from its first byte.
  double header_timeout_s = 10.0;
  /// A body of N bytes gets header_timeout_s + N / this, s.
  double body_min_rate_bytes_per_s = 32768;
  /// Longest silence inside a request, s.
  double read_timeout_s = 10.0;
  /// Longest wait for the client to take more of an answer, s.
  double write_timeout_s = 10.0;
  /// An idle keep-alive connection is closed after this, s.
  double keep_alive_timeout_s = 5.0;
  /// Requests per connection; the last is answered with Connection: close.
  int keep_alive_max_requests = 10000;
  /// Threads for cheap requests (they also accept and read).
  int light_workers = 8;
  /// Threads for requests that run models.
  int compute_workers = 2;
  /// The compute pool's threads as a budget (null: none): a compute worker takes one while it
  /// answers, waiting when sweeps have borrowed them all (api/explore/engine.hpp).
  api::ThreadBudget* compute_budget = nullptr;
  /// How long a closed connection is drained, s.
  double linger_s = 1.0;
};

/// The worker pool a request is served in.
enum class Pool { kLight, kCompute };

/// What the loop needs from the HTTP layer.
struct ConnectionLoopHooks {
  /// Answers one request read from `stream` (httplib's request handling);
  /// `close_connection` asks for "Connection: close". Returns false when the
  /// connection cannot be used again; sets *closed when the client asked to close.
  std::function<bool(RequestStream& stream, bool close_connection, bool* closed)> serve;
  /// Which pool a complete request belongs in (called on a light worker). When it had to
  /// parse the body to decide, it may leave the parsed body in *parsed: the request's
  /// RequestStream carries it to the answer (RequestStream::parsed_body), so a body is
  /// parsed once.
  std::function<Pool(std::string_view method, std::string_view path, std::string_view body,
                     std::shared_ptr<nlohmann::json>* parsed)>
      classify;
  /// The JSON error envelope (with its trailing newline) for an answer the loop gives itself.
  std::function<std::string(int status, api::ErrorCode code, const std::string& message)>
      error_body;
  /// Called after the loop answered a request itself: status, code, the
  /// request's method and path when known ("" otherwise). May be empty.
  std::function<void(int status, api::ErrorCode code, const std::string& method,
                     const std::string& path)>
      refused;
};

/// The connections. Run() on one thread; Stop() and MetricsText() from any thread.
class ConnectionLoop {
 public:
  /// Takes ownership of `listen_fd` (bound and listening). Nothing runs before Run().
  ConnectionLoop(int listen_fd, ConnectionLoopOptions options, ConnectionLoopHooks hooks);
  ~ConnectionLoop();
  ConnectionLoop(const ConnectionLoop&) = delete;
  ConnectionLoop& operator=(const ConnectionLoop&) = delete;

  /// Starts the workers and serves until Stop(); then closes the listening
  /// socket and the connections that wait for a request, lets the requests
  /// being answered finish (with Connection: close) and returns. Returns false
  /// if it could not start (epoll failed).
  bool Run();
  /// Makes Run() return (after the in-flight requests, within shutdown_grace_s); idempotent,
  /// any thread.
  void Stop();
  /// The drain before Stop(): every answer from now on carries "Connection: close", so that
  /// keep-alive clients reconnect (through their load balancer, to another replica) while this
  /// one still accepts. Any thread.
  void BeginDrain();
  /// Ends the shutdown grace at once: the requests still computing are cancelled. Any thread.
  void EndGrace();

  /// Prometheus text of the loop's gauges and counters (connections by state,
  /// refusals by reason, each pool's busy workers, their peak and queue).
  std::string MetricsText() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sweetspot::server
