// The HTTP service: cpp-httplib wired to the api layer's router.
#pragma once

#include <atomic>
#include <memory>
#include <string>

#include "server/config.hpp"

namespace sweetspot::server {

/// An HTTP server bound to config.host:config.port that answers every route
/// of api::Routes(). Thread-safe: Stop() may be called from any thread.
class Server {
 public:
  /// Prepares a server; nothing is bound until Bind().
  explicit Server(ServerConfig config);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  /// Binds the listening socket. On failure returns false and says why.
  bool Bind(std::string* error);
  /// The bound port (useful with port 0); -1 before Bind().
  int port() const { return port_; }
  /// Serves until Stop(); returns false if the listen loop failed.
  bool Run();
  /// Stops accepting and makes Run() return (in-flight requests finish).
  void Stop();

 private:
  struct Impl;
  ServerConfig config_;
  std::unique_ptr<Impl> impl_;
  int port_ = -1;
};

}  // namespace sweetspot::server
