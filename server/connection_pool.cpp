#include "server/connection_pool.hpp"

namespace sweetspot::server {
namespace {
thread_local bool current_connection_rejected = false;
}  // namespace

ConnectionPool::ConnectionPool(std::size_t workers, std::size_t max_connections,
                               std::size_t reject_workers)
    : max_connections_(max_connections) {
  for (std::size_t i = 0; i < workers; ++i) {
    admitted_.threads.emplace_back([this] { Work(&admitted_, false); });
  }
  for (std::size_t i = 0; i < reject_workers; ++i) {
    rejected_.threads.emplace_back([this] { Work(&rejected_, true); });
  }
}

ConnectionPool::~ConnectionPool() { shutdown(); }

bool ConnectionPool::CurrentConnectionRejected() { return current_connection_rejected; }

void ConnectionPool::enqueue(std::function<void()> fn) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (admitted_count_ < max_connections_) {
      ++admitted_count_;
      admitted_.tasks.push_back(std::move(fn));
    } else {
      rejected_.tasks.push_back(std::move(fn));
    }
  }
  cv_.notify_all();
}

void ConnectionPool::shutdown() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutdown_) return;
    shutdown_ = true;
  }
  cv_.notify_all();
  for (Queue* queue : {&admitted_, &rejected_}) {
    for (auto& thread : queue->threads) {
      if (thread.joinable()) thread.join();
    }
  }
}

void ConnectionPool::Work(Queue* queue, bool reject) {
  current_connection_rejected = reject;
  for (;;) {
    std::function<void()> task;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [&] { return shutdown_ || !queue->tasks.empty(); });
      if (queue->tasks.empty()) return;  // shutdown with nothing left
      task = std::move(queue->tasks.front());
      queue->tasks.pop_front();
    }
    task();  // httplib's connection handler: never throws (its own try/catch)
    if (!reject) {
      std::lock_guard<std::mutex> lock(mutex_);
      --admitted_count_;
    }
  }
}

}  // namespace sweetspot::server
