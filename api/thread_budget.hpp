// ThreadBudget: the threads a process lends to /v1/explore sweeps beyond each sweep's own
// (the server's compute pool; api/explore/engine.hpp takes from it).
#pragma once

#include <memory>

namespace sweetspot::api {

/// Threads a process lends to sweeps beyond each sweep's own: a counting budget that a
/// sweep takes from without waiting and gives back when it ends. Thread-safe.
class ThreadBudget {
 public:
  /// A budget of `threads` (>= 0) threads.
  explicit ThreadBudget(int threads);
  ~ThreadBudget();
  /// Takes up to `wanted` threads (fewer when fewer are free, maybe 0); never waits.
  int TryTake(int wanted);
  /// Takes one thread, waiting until one is free.
  void TakeOne();
  /// Gives back `threads` taken before.
  void Give(int threads);
  /// Threads taken now.
  int taken() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sweetspot::api
