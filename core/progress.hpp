// Cooperative cancellation and progress reporting for long computations
// (sweeps, multi-start optimisation, jobs). Core code polls Cancelled() at
// natural boundaries (per design, per start, per iteration callback).
#pragma once

#include <atomic>

namespace sweetspot::core {

/// A cancel flag and a progress fraction shared between a computation and its
/// owner. Thread-safe; lives as long as the computation.
class Progress {
 public:
  /// Asks the computation to stop at its next check.
  void Cancel() { cancelled_.store(true, std::memory_order_relaxed); }
  /// True once Cancel() was called.
  bool Cancelled() const { return cancelled_.load(std::memory_order_relaxed); }
  /// Records progress in [0, 1] (clamped; never decreases).
  void Report(double fraction) {
    if (!(fraction >= 0.0)) fraction = 0.0;
    if (fraction > 1.0) fraction = 1.0;
    double current = fraction_.load(std::memory_order_relaxed);
    while (fraction > current &&
           !fraction_.compare_exchange_weak(current, fraction, std::memory_order_relaxed)) {
    }
  }
  /// The last reported fraction in [0, 1].
  double Fraction() const { return fraction_.load(std::memory_order_relaxed); }

 private:
  std::atomic<bool> cancelled_{false};
  std::atomic<double> fraction_{0.0};
};

/// True when `progress` is non-null and cancelled (null = never cancelled).
inline bool IsCancelled(const Progress* progress) {
  return progress != nullptr && progress->Cancelled();
}

}  // namespace sweetspot::core
