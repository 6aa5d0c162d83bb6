#include "api/router.hpp"

#include <utility>

namespace sweetspot::api {
namespace {

// True when `path` matches `pattern` segment by segment ("{x}" matches one segment).
bool PathMatches(std::string_view pattern, std::string_view path) {
  while (!pattern.empty() || !path.empty()) {
    if (pattern.empty() || path.empty()) return false;
    if (pattern.front() != '/' || path.front() != '/') return false;
    pattern.remove_prefix(1);
    path.remove_prefix(1);
    const auto pattern_end = pattern.find('/');
    const auto path_end = path.find('/');
    const std::string_view pattern_seg = pattern.substr(0, pattern_end);
    const std::string_view path_seg = path.substr(0, path_end);
    const bool wildcard = pattern_seg.size() >= 2 && pattern_seg.front() == '{' &&
                          pattern_seg.back() == '}';
    if (wildcard ? path_seg.empty() : pattern_seg != path_seg) return false;
    pattern.remove_prefix(pattern_seg.size());
    path.remove_prefix(path_seg.size());
  }
  return true;
}

}  // namespace

const std::vector<Route>& Routes() {
  static const std::vector<Route> routes = {
      {"GET", "/health", "Liveness: {\"status\": \"ok\"}.",
       [](const Request&) { return HandleHealth(); }},
  };
  return routes;
}

std::vector<const Route*> MatchRoutes(std::string_view path) {
  std::vector<const Route*> matches;
  for (const Route& route : Routes()) {
    if (PathMatches(route.path, path)) matches.push_back(&route);
  }
  return matches;
}

Response Dispatch(const Request& request, std::string* route_pattern) {
  bool path_known = false;
  for (const Route& route : Routes()) {
    if (!PathMatches(route.path, request.path)) continue;
    path_known = true;
    if (route.method != request.method) continue;
    if (route_pattern != nullptr) *route_pattern = route.path;
    return route.handler(request);
  }
  if (route_pattern != nullptr) *route_pattern = "unmatched";
  if (path_known) {
    return ErrorResponse(405, "MethodNotAllowed",
                         "method " + request.method + " is not allowed on " + request.path);
  }
  return ErrorResponse(404, "NotFound", "no endpoint at path " + request.path);
}

Response ErrorResponse(int status, std::string_view code, std::string message,
                       std::string field) {
  nlohmann::json body{{"code", code}, {"message", std::move(message)}};
  body["field"] = field.empty() ? nlohmann::json(nullptr) : nlohmann::json(std::move(field));
  return {status, std::move(body)};
}

}  // namespace sweetspot::api
