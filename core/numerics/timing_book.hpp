// The time spent per model within one request, and the models_used list it implies; the
// frame of a timed solve (its wall time, and no exception leaving it).
#pragma once

#include <chrono>
#include <string>
#include <string_view>
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
  /// A book that reads the clock (`timed`, the default) or one that lists the models and their
  /// calls with 0 s and never reads it (a sweep that reports no timings: the clock is a tenth of
  /// a closed-form design's time).
  explicit TimingBook(bool timed = true) : timed_(timed) {}
  /// Now, or the epoch when not timed.
  std::chrono::steady_clock::time_point Now() const {
    return timed_ ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
  }
  /// Seconds since `start` (from Now()), or 0 when not timed.
  double Since(std::chrono::steady_clock::time_point start) const {
    return timed_ ? SecondsSince(start) : 0.0;
  }
  /// True when the book reads the clock.
  bool timed() const { return timed_; }
  /// Adds `time_s` seconds and `calls` evaluations to `model` (listed on first use).
  void Add(std::string_view model, double time_s, int calls) {
    for (auto& t : timings_) {
      if (t.model == model) {
        t.time_s += time_s;
        t.calls += calls;
        return;
      }
    }
    timings_.push_back({std::string(model), time_s, calls});
  }
  /// The timings, in first-use order.
  const std::vector<ModelTiming>& timings() const { return timings_; }
  /// The timings, moved out (the book is left empty).
  std::vector<ModelTiming> TakeTimings() { return std::move(timings_); }
  /// Forgets every model, keeping the buffers; `timed` as the constructor's.
  void Reset(bool timed) {
    timings_.clear();
    timed_ = timed;
  }
  /// The models used, in first-use order, into *out (its buffers reused).
  void ModelsInto(std::vector<std::string>* out) const {
    out->resize(timings_.size());
    for (std::size_t i = 0; i < timings_.size(); ++i) (*out)[i] = timings_[i].model;
  }
  /// The models used, in first-use order (a result's models_used).
  std::vector<std::string> Models() const {
    std::vector<std::string> out;
    out.reserve(timings_.size());
    for (const auto& t : timings_) out.push_back(t.model);
    return out;
  }

 private:
  std::vector<ModelTiming> timings_;
  bool timed_ = true;
};

/// Runs one solve: `body(out)` fills a fresh `Result` (a struct with a `Summary summary`),
/// whose termination starts as invalid input; what `body` throws becomes an internal error
/// (CatchInternalError); summary.solve_time_s is the wall time of it all, s (0 and no clock
/// read when not `timed`).
template <class Result, class Body>
Result TimedSolve(Body&& body, bool timed = true) {
  const auto t0 =
      timed ? std::chrono::steady_clock::now() : std::chrono::steady_clock::time_point{};
  Result out;
  out.summary.termination = Termination::kInvalidInput;
  CatchInternalError(&out.summary, [&] { body(out); });
  if (timed) out.summary.solve_time_s = SecondsSince(t0);
  return out;
}

template <class Result, class Body>
Result TimedRequest(const char* backend, bool timed, Body&& body) {
  TimingBook book(timed);
  Result out = TimedSolve<Result>(
      [&](Result& r) {
        r.summary.backend = backend;
        body(r, book);
      },
      timed);
  out.summary.models_used = book.Models();
  out.timings = book.TakeTimings();
  return out;
}

/// TimedRequest with the clock read (timed = true).
template <class Result, class Body>
Result TimedRequest(const char* backend, Body&& body) {
  return TimedRequest<Result>(backend, true, std::forward<Body>(body));
}

}  // namespace sweetspot::core
