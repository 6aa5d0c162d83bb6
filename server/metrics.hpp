// Request metrics in the Prometheus text exposition format (version 0.0.4).
#pragma once

#include <array>
#include <atomic>
#include <map>
#include <mutex>
#include <string>
#include <string_view>
#include <tuple>

namespace sweetspot::server {

/// Counts requests by route pattern, method and status, a latency histogram
/// by route, and requests in flight. Thread-safe.
class Metrics {
 public:
  /// Upper bounds of the latency histogram's buckets, s (+Inf is implicit).
  static constexpr std::array<double, 14> kBucketsS = {0.0005, 0.001, 0.0025, 0.005, 0.01,
                                                       0.025,  0.05,  0.1,    0.25,  0.5,
                                                       1.0,    2.5,   5.0,    10.0};

  /// A request started.
  void Begin() { in_flight_.fetch_add(1, std::memory_order_relaxed); }
  /// The method's label: one of the nine HTTP methods, else "other" (a request the
  /// loop refused may carry any bytes as its method: the label set stays bounded).
  static const char* MethodLabel(std::string_view method);
  /// A request ended: its route pattern (not the raw path, so the label set
  /// stays bounded), method (as MethodLabel), HTTP status and duration in s.
  void End(const std::string& route, const std::string& method, int status, double duration_s);
  /// The exposition text; `jobs_by_state` adds sweetspot_jobs{state=...}.
  std::string Render(const std::map<std::string, int>& jobs_by_state) const;

 private:
  struct Histogram {
    std::array<unsigned long long, kBucketsS.size()> buckets{};  // non-cumulative
    unsigned long long count = 0;
    double sum_s = 0.0;
  };
  mutable std::mutex mutex_;
  std::map<std::tuple<std::string, std::string, int>, unsigned long long> requests_;
  std::map<std::string, Histogram> latency_;
  std::atomic<long long> in_flight_{0};
};

}  // namespace sweetspot::server
