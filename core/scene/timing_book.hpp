// The time spent per model within one request, and the models_used list it implies.
#pragma once

#include <chrono>
#include <string>
#include <vector>

namespace sweetspot::core {

/// Seconds elapsed on the steady clock since `start`.
inline double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Time spent in one model during a request.
struct ModelTiming {
  std::string model;    ///< e.g. "mass_properties", "rigid_pivot", "hertz".
  double time_s = 0.0;  ///< Wall time, s.
  int calls = 0;        ///< Evaluations.
};

/// Time and calls per model, in first-use order; one per request (not shared across threads).
class TimingBook {
 public:
  /// Adds `time_s` seconds and `calls` evaluations to `model` (listed on first use).
  void Add(const std::string& model, double time_s, int calls) {
    for (auto& t : timings_) {
      if (t.model == model) {
        t.time_s += time_s;
        t.calls += calls;
        return;
      }
    }
    timings_.push_back({model, time_s, calls});
  }
  /// The timings, in first-use order.
  const std::vector<ModelTiming>& timings() const { return timings_; }
  /// The models used, in first-use order (a result's models_used).
  std::vector<std::string> Models() const {
    std::vector<std::string> out;
    for (const auto& t : timings_) out.push_back(t.model);
    return out;
  }

 private:
  std::vector<ModelTiming> timings_;
};

}  // namespace sweetspot::core
