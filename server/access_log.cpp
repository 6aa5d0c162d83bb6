#include "server/access_log.hpp"

#include <nlohmann/json.hpp>

namespace sweetspot::server {

std::string AccessLogLine(const AccessLogEntry& entry) {
  nlohmann::json line{{"method", entry.method},         {"path", entry.path},
                      {"route", entry.route},           {"status", entry.status},
                      {"duration_s", entry.duration_s}, {"bytes_in", entry.bytes_in}};
  if (!entry.error.empty()) line["error"] = entry.error;
  return line.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

}  // namespace sweetspot::server
