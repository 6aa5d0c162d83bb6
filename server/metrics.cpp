#include "server/metrics.hpp"

#include <sstream>

namespace sweetspot::server {
namespace {

// Prometheus label values escape backslash, double quote and newline.
std::string Label(const std::string& value) {
  std::string out;
  for (const char c : value) {
    if (c == '\\' || c == '"') {
      out += '\\';
      out += c;
    } else if (c == '\n') {
      out += "\\n";
    } else {
      out += c;
    }
  }
  return out;
}

}  // namespace

const char* Metrics::MethodLabel(std::string_view method) {
  static constexpr std::array<const char*, 9> kKnown = {
      "GET", "HEAD", "POST", "PUT", "DELETE", "PATCH", "OPTIONS", "CONNECT", "TRACE"};
  for (const char* known : kKnown) {
    if (method == known) return known;
  }
  return "other";
}

void Metrics::End(const std::string& route, const std::string& method, int status,
                  double duration_s) {
  in_flight_.fetch_sub(1, std::memory_order_relaxed);
  std::lock_guard<std::mutex> lock(mutex_);
  ++requests_[{route, MethodLabel(method), status}];
  Histogram& h = latency_[route];
  for (std::size_t i = 0; i < kBucketsS.size(); ++i) {
    if (duration_s <= kBucketsS[i]) {
      ++h.buckets[i];
      break;
    }
  }
  ++h.count;
  h.sum_s += duration_s;
}

std::string Metrics::Render(const std::map<std::string, int>& jobs_by_state) const {
  std::ostringstream out;
  out.precision(9);
  std::lock_guard<std::mutex> lock(mutex_);
  out << "# HELP sweetspot_requests_total HTTP requests by route pattern, method and status.\n"
      << "# TYPE sweetspot_requests_total counter\n";
  for (const auto& [key, count] : requests_) {
    const auto& [route, method, status] = key;
    out << "sweetspot_requests_total{route=\"" << Label(route) << "\",method=\"" << Label(method)
        << "\",status=\"" << status << "\"} " << count << "\n";
  }
  out << "# HELP sweetspot_request_duration_seconds Request latency by route pattern.\n"
      << "# TYPE sweetspot_request_duration_seconds histogram\n";
  for (const auto& [route, h] : latency_) {
    unsigned long long cumulative = 0;
    for (std::size_t i = 0; i < kBucketsS.size(); ++i) {
      cumulative += h.buckets[i];
      out << "sweetspot_request_duration_seconds_bucket{route=\"" << Label(route) << "\",le=\""
          << kBucketsS[i] << "\"} " << cumulative << "\n";
    }
    out << "sweetspot_request_duration_seconds_bucket{route=\"" << Label(route)
        << "\",le=\"+Inf\"} " << h.count << "\n"
        << "sweetspot_request_duration_seconds_sum{route=\"" << Label(route) << "\"} " << h.sum_s
        << "\n"
        << "sweetspot_request_duration_seconds_count{route=\"" << Label(route) << "\"} "
        << h.count << "\n";
  }
  out << "# HELP sweetspot_requests_in_flight Requests being handled now.\n"
      << "# TYPE sweetspot_requests_in_flight gauge\n"
      << "sweetspot_requests_in_flight " << in_flight_.load(std::memory_order_relaxed) << "\n";
  out << "# HELP sweetspot_jobs Jobs by state.\n# TYPE sweetspot_jobs gauge\n";
  for (const auto& [state, count] : jobs_by_state) {
    out << "sweetspot_jobs{state=\"" << Label(state) << "\"} " << count << "\n";
  }
  return out.str();
}

}  // namespace sweetspot::server
