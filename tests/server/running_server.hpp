// An in-process Server for the server tests: bound to 127.0.0.1 on an
// ephemeral port, run on its own thread, stopped and joined on destruction.
#pragma once

#include <httplib.h>

#include <string>
#include <thread>
#include <utility>

#include "server/server.hpp"

namespace sweetspot::server {

/// A Server with `config` (port 0, no access log, jobs in memory), running on its own thread.
class RunningServer {
 public:
  /// Binds and starts; bound() says whether the bind worked.
  explicit RunningServer(ServerConfig config) : server_(Prepare(std::move(config))) {
    std::string error;
    bound_ = server_.Bind(&error);
    if (bound_) thread_ = std::thread([this] { server_.Run(); });
  }
  ~RunningServer() {
    server_.Stop();
    if (thread_.joinable()) thread_.join();
  }
  RunningServer(const RunningServer&) = delete;
  RunningServer& operator=(const RunningServer&) = delete;

  /// True when the server bound its port.
  bool bound() const { return bound_; }
  /// The port it listens on.
  int port() const { return server_.port(); }
  /// A client for it on 127.0.0.1.
  httplib::Client Client() const { return httplib::Client("127.0.0.1", server_.port()); }

 private:
  static ServerConfig Prepare(ServerConfig config) {
    config.port = 0;
    config.access_log = false;
    config.jobs_db = kNoJobsDb;  // Jobs in memory: a shared default file would couple tests.
    return config;
  }
  Server server_;
  bool bound_ = false;
  std::thread thread_;
};

}  // namespace sweetspot::server
