#include "api/router.hpp"

#include <exception>
#include <utility>

#include "api/handlers/handlers.hpp"
#include "api/handlers/modes.hpp"

namespace sweetspot::api {
namespace {

// True when `path` matches `pattern` segment by segment ("{x}" matches one
// non-empty segment). If `parameter` is non-null it gets the "{x}" segment.
bool PathMatches(std::string_view pattern, std::string_view path,
                 std::string* parameter = nullptr) {
  while (!pattern.empty() || !path.empty()) {
    if (pattern.empty() || path.empty()) return false;
    if (pattern.front() != '/' || path.front() != '/') return false;
    pattern.remove_prefix(1);
    path.remove_prefix(1);
    const std::string_view pattern_seg = pattern.substr(0, pattern.find('/'));
    const std::string_view path_seg = path.substr(0, path.find('/'));
    const bool wildcard =
        pattern_seg.size() >= 2 && pattern_seg.front() == '{' && pattern_seg.back() == '}';
    if (wildcard ? path_seg.empty() : pattern_seg != path_seg) return false;
    if (wildcard && parameter != nullptr) *parameter = std::string(path_seg);
    pattern.remove_prefix(pattern_seg.size());
    path.remove_prefix(path_seg.size());
  }
  return true;
}

}  // namespace

const std::vector<Route>& Routes() {
  static const std::vector<Route> routes = {
      {"GET", "/health", "Liveness: {\"status\": \"ok\"}.",
       [](const Request&, const Context&) { return HandleHealth(); }},
      {"GET", "/ready",
       "Readiness: {\"status\": \"ready\"}, or 503 while the server drains before it stops.",
       [](const Request&, const Context& context) {
         return HandleReady(context.draining && context.draining());
       }},
      {"GET", "/openapi.json", "The OpenAPI 3 document of every endpoint.", HandleOpenApi},
      {"GET", "/metrics", "Prometheus text: requests by route and status, latency, jobs.",
       HandleMetrics},
      {"GET", "/v1/version", "Versions of sweetspot and of the libraries it was built with.",
       HandleVersion},
      {"GET", "/v1/speed-vs-error",
       "Time per evaluation against error for every model and numeric setting "
       "(docs/speed-vs-error.md); the service's defaults are marked is_auto.",
       HandleSpeedVsError},
      {"GET", "/v1/materials", "The material catalogue with properties and sources.",
       HandleMaterials},
      {"GET", "/v1/presets", "The preset bats with their properties and sources.", HandlePresets},
      {"GET", "/v1/balls",
       "The ball catalogue: mass, radius, COR and its speed law, contact stiffness, sources.",
       HandleBalls},
      {"POST", "/v1/bat/properties",
       "Exact mass properties: mass, balance point, moments of inertia, volume.",
       HandleBatProperties, true},
      {"POST", "/v1/bat/modes",
       "The free-free bending modes: frequencies, mode shapes, nodes, with error estimates.",
       HandleBatModes, true, RouteWorkload::kCompute},
      {"POST", "/v1/bat/fit",
       "Solve unknown dimensions from a target mass and balance point (422 with the closest bat).",
       HandleBatFit, true, RouteWorkload::kCompute},
      {"POST", "/v1/sweet-spot",
       "The sweet spot(s) of a scene: max exit speed, centre of percussion, sweet zone, curve.",
       HandleSweetSpot, true, RouteWorkload::kScene},
      {"POST", "/v1/collision",
       "One impact with a chosen model (auto, rigid_pivot, free_bat, hertz).", HandleCollision,
       true, RouteWorkload::kScene},
      {"POST", "/v1/flight",
       "Batted-ball flight (Nathan's calculator): distance, hang time, apex, landing point, "
       "Statcast labels, for one launch or many.",
       HandleFlight, true},
      {"POST", "/v1/compare", "A baseline bat against variants: properties, sweet spot, deltas.",
       HandleCompare, true, RouteWorkload::kScene},
      {"POST", "/v1/optimize",
       "Ipopt design of a bat's profile and material under length, mass, balance-point, MOI, "
       "diameter, taper and league-rule constraints.",
       HandleOptimize, true, RouteWorkload::kCompute},
      {"POST", "/v1/explore",
       "Design sweeps: grid, Latin hypercube or Sobol samples, shards, a Pareto front.",
       HandleExplore, true, RouteWorkload::kCompute},
      {"POST", "/v1/jobs", "Run a long request as a job: {\"path\", \"body\"} -> 202 with its id.",
       HandleJobSubmit},
      {"GET", "/v1/jobs",
       "The jobs the server keeps, newest first: {\"jobs\": [...], \"total\", \"next_offset\"} "
       "(?state=, ?limit=, ?offset=).",
       HandleJobList},
      {"GET", "/v1/jobs/{id}", "A job's state and progress (0-1).", HandleJobStatus},
      {"GET", "/v1/jobs/{id}/result", "A finished job's result.", HandleJobResult},
      {"DELETE", "/v1/jobs/{id}", "Cancel a job (or forget a finished one).", HandleJobCancel},
  };
  return routes;
}

const Route* FindRoute(std::string_view method, std::string_view path) {
  for (const Route& route : Routes()) {
    if (route.method == method && PathMatches(route.path, path)) return &route;
  }
  return nullptr;
}

std::vector<const Route*> MatchRoutes(std::string_view path) {
  std::vector<const Route*> matches;
  for (const Route& route : Routes()) {
    if (PathMatches(route.path, path)) matches.push_back(&route);
  }
  return matches;
}

std::string PathParameter(std::string_view pattern, std::string_view path) {
  std::string parameter;
  PathMatches(pattern, path, &parameter);
  return parameter;
}

namespace {

// 500 InternalError without details; `what` goes to Response::internal_error.
Response InternalErrorResponse(std::string what) {
  Response response = ErrorResponse(500, ErrorCode::kInternalError, "internal error");
  response.internal_error = what.empty() ? "an exception with an empty what()" : std::move(what);
  return response;
}

}  // namespace

Response CallRoute(const Route& route, const Request& request, const Context& context,
                   bool allow_stream) {
  try {
    Response response = route.handler(request, context);
    if (response.stream && !allow_stream) {
      std::string text;
      response.stream([&text](std::string_view chunk) {
        text.append(chunk);
        return true;
      });
      response.text = std::move(text);
      response.stream = nullptr;
    }
    if (response.source && !allow_stream) {
      std::string text;
      constexpr std::size_t kPiece = 1 << 20;
      for (std::uint64_t at = 0; at < response.source->bytes;) {
        const std::size_t before = text.size();
        if (!response.source->read(at, kPiece, &text) || text.size() == before) break;
        at += text.size() - before;
      }
      response.text = std::move(text);
      response.source = nullptr;
    }
    return response;
  } catch (const std::exception& caught) {
    // The one place an unexpected exception becomes a 500: no details in
    // the body, the text kept for the log.
    return InternalErrorResponse(caught.what());
  } catch (...) {
    return InternalErrorResponse("an exception not derived from std::exception");
  }
}

Response Dispatch(const Request& request, const Context& context, std::string* route_pattern,
                  bool allow_stream) {
  bool path_known = false;
  std::string allowed;
  for (const Route& route : Routes()) {
    if (!PathMatches(route.path, request.path)) continue;
    path_known = true;
    allowed += (allowed.empty() ? "" : ", ") + route.method;
    if (route.method != request.method) continue;
    if (route_pattern != nullptr) *route_pattern = route.path;
    return CallRoute(route, request, context, allow_stream);
  }
  if (route_pattern != nullptr) *route_pattern = path_known ? "method_not_allowed" : "unmatched";
  if (path_known) {
    return ErrorResponse(405, ErrorCode::kMethodNotAllowed,
                         "method " + request.method + " is not allowed on " + request.path +
                             " (allowed: " + allowed + ")");
  }
  return ErrorResponse(404, ErrorCode::kNotFound, "no endpoint at path " + request.path);
}

Response ErrorResponse(int status, ErrorCode code, std::string message, std::string field) {
  nlohmann::json body{{"code", ErrorCodeName(code)}, {"message", std::move(message)}};
  body["field"] = field.empty() ? nlohmann::json(nullptr) : nlohmann::json(std::move(field));
  return {status, std::move(body)};
}

}  // namespace sweetspot::api
