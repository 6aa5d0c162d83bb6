// The time spent per model within one request, and the models_used list it implies; the
// frame of a timed solve (its wall time, and no exception leaving it).
#pragma once

#include <chrono>
#include <string>
#include <utility>
#include <vector>

#include "core/summary.hpp"

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

/// Runs one solve: `body(out)` fills a fresh `Result` (a struct with a `Summary summary`),
/// whose termination starts as invalid input; what `body` throws becomes an internal error
/// (CatchInternalError); summary.solve_time_s is the wall time of it all, s.
template <class Result, class Body>
Result TimedSolve(Body&& body) {
  const auto t0 = std::chrono::steady_clock::now();
  Result out;
  out.summary.termination = Termination::kInvalidInput;
  CatchInternalError(&out.summary, [&] { body(out); });
  out.summary.solve_time_s = SecondsSince(t0);
  return out;
}

/// Runs one request as TimedSolve does, with `backend` as the summary's backend and a fresh
/// TimingBook for `body(out, book)`: the result's `timings` and summary.models_used are the
/// book's, however the request ended.
template <class Result, class Body>
Result TimedRequest(const char* backend, Body&& body) {
  TimingBook book;
  Result out = TimedSolve<Result>([&](Result& r) {
    r.summary.backend = backend;
    body(r, book);
  });
  out.timings = book.timings();
  out.summary.models_used = book.Models();
  return out;
}

}  // namespace sweetspot::core
