// The server's connection pool: a fixed number of worker threads serve
// connections (one keep-alive connection holds one worker while it is open);
// at most max_connections connections are active or waiting. Connections
// beyond that are handed to a small reject pool whose threads mark them, so
// the server answers their first request 503 TooBusy and closes them, while
// the connections already admitted are served as usual.
#pragma once

#include <httplib.h>

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace sweetspot::server {

/// A cpp-httplib task queue with an admission limit. Thread-safe.
class ConnectionPool : public httplib::TaskQueue {
 public:
  /// `workers` threads serve up to `max_connections` admitted connections
  /// (active + waiting); `reject_workers` threads answer the others 503.
  ConnectionPool(std::size_t workers, std::size_t max_connections, std::size_t reject_workers = 2);
  ~ConnectionPool() override;

  /// Admits `fn` (one connection's whole life) or hands it to the reject pool.
  void enqueue(std::function<void()> fn) override;
  /// Finishes queued connections and joins every thread.
  void shutdown() override;

  /// True on a reject-pool thread: the connection being handled is over the limit.
  static bool CurrentConnectionRejected();

 private:
  struct Queue {
    std::deque<std::function<void()>> tasks;
    std::vector<std::thread> threads;
  };
  void Work(Queue* queue, bool reject);

  const std::size_t max_connections_;
  std::mutex mutex_;
  std::condition_variable cv_;
  Queue admitted_;
  Queue rejected_;
  std::size_t admitted_count_ = 0;  // active + waiting admitted connections
  bool shutdown_ = false;
};

}  // namespace sweetspot::server
