// The HTTP service: cpp-httplib wired to the api layer's router.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "server/config.hpp"

namespace sweetspot::server {

/// An HTTP server bound to config.host:config.port that answers every route
/// of api::Routes(). One thread (Run's) owns the connections and reads whole
/// requests under deadlines; complete requests are answered by a pool of
/// config.threads workers, or, when they run models, by a pool of
/// config.compute_threads (server/connection_loop.hpp). Thread-safe: Stop()
/// may be called from any thread.
class Server {
 public:
  /// Prepares a server; nothing is bound until Bind(). Opens the jobs
  /// database and loads its jobs (unfinished ones start running at once).
  explicit Server(ServerConfig config);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Binds the listening socket. On failure returns false and says why; also
  /// when the jobs database (config.jobs_db) could not be opened or loaded.
  bool Bind(std::string* error);
  /// The bound port (useful with port 0); -1 before Bind().
  int port() const { return port_; }
  /// Worker threads for requests that run models (config.compute_threads, or the cores).
  int compute_threads() const;
  /// Serves until Stop(); returns false if the listen loop failed.
  bool Run();
  /// Starts the drain that precedes Stop(): GET /ready answers 503 and every answer carries
  /// "Connection: close", while the server keeps accepting and answering. Any thread.
  void BeginDrain();
  /// Stops accepting and makes Run() return: in-flight requests finish within
  /// config.shutdown_grace_s, then their models are stopped (503).
  void Stop();
  /// After Run() returned: Stop(), then stops the jobs: no new ones, running
  /// ones get config.shutdown_grace_s seconds to finish, the rest are
  /// interrupted and (with a jobs database) kept queued for the next start.
  /// Logs to stderr what it waits for and what it keeps. Idempotent.
  void Shutdown();
  /// Ends the grace periods of Stop() and Shutdown() now (from another thread, e.g. on a
  /// second signal): requests and jobs still computing are stopped.
  void EndShutdownGrace();

 private:
  struct Impl;
  ServerConfig config_;
  std::unique_ptr<Impl> impl_;
  int port_ = -1;
};

}  // namespace sweetspot::server
