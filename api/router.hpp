// The routing table shared by the HTTP server and the CLI: (method, path) ->
// pure handler. HTTP-agnostic: the server and the CLI both call Dispatch().
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "api/error_code.hpp"
#include "api/limits.hpp"
#include "api/response.hpp"
#include "core/progress.hpp"

namespace sweetspot::core {
class ModesCache;
}  // namespace sweetspot::core

namespace sweetspot::api {

class JobService;
class ThreadBudget;

/// A request as the handlers see it.
struct Request {
  std::string method;  ///< "GET", "POST", "DELETE".
  std::string path;    ///< Path without query, e.g. "/v1/bat/properties".
  std::string body;    ///< Raw body (JSON for POST).
  /// The query string's parameters, decoded (GET /v1/jobs?state=running); empty for most routes.
  std::multimap<std::string, std::string> query{};
  /// The body already parsed into a JSON object (by ClassifyWorkload, for the server's choice
  /// of pool), or null. ParseObjectBody takes it (moving it out, leaving null JSON) instead of
  /// parsing `body` again; a second ParseObjectBody of the same request parses `body`.
  std::shared_ptr<nlohmann::json> parsed_body{};
};

/// What handlers may use besides the request: limits, and what only a
/// running server has (jobs, metrics). Null members mean "not available here".
struct Context {
  ApiLimits limits;                           ///< Request limits (configuration).
  JobService* jobs = nullptr;                 ///< The jobs (server only; server/jobs/).
  std::function<std::string()> metrics_text;  ///< Prometheus text (server only).
  /// True while the server drains before it stops (SIGTERM, --drain-s): GET /ready answers 503.
  /// Null: never (the CLI).
  std::function<bool()> draining;
  core::Progress* progress = nullptr;         ///< Cancel flag and progress (inside a job).
  core::ModesCache* modes_cache = nullptr;    ///< Bending modes kept across requests (server only).
  /// True when the answer goes to a job's result or the CLI's output rather than to a waiting
  /// HTTP client: /v1/explore then allows limits.max_batch_samples designs, not max_samples.
  bool batch = false;
  /// Threads one /v1/explore sweep may evaluate its designs on (>= 1; the rows' order and
  /// bytes do not depend on it): the server's and the CLI's --explore-threads.
  int explore_threads = 1;
  /// Where a sweep's threads beyond its first come from, without waiting (null: no bound).
  /// The server's is its compute pool's (server/connection_loop.hpp).
  ThreadBudget* thread_budget = nullptr;
  /// True when only the request's validation runs (POST /v1/jobs checks a job's inner request
  /// before queueing it): a typed endpoint answers its 4xx, or 200 {"valid": true} once its
  /// body parsed, without calling core.
  bool validate_only = false;
  /// True when the request is a job's inner request checked at POST /v1/jobs: /v1/explore
  /// then refuses (413) a sweep whose estimated CPU time, wall time or result is over
  /// limits.max_job_cpu_s, max_job_time_s or max_job_result_bytes (api/explore/estimate.hpp).
  bool job = false;
  /// True when the answer is a job's result, collected by the job service: /v1/explore then
  /// streams a "json" answer too (Response::stream, content type application/json: the
  /// compact text the server would send, a row at a time) instead of building it in memory,
  /// so that the job service can write it to its store as it is produced.
  bool stream_json = false;
  /// True when the answer is sent as text at once (the server's HTTP answers): a typed
  /// endpoint with a text writer (Endpoint::write) answers 200 with Response::json_text
  /// instead of a tree. False: every answer is a tree (the CLI, jobs, the tests).
  bool answer_text = false;
};

/// What answering a request costs, for the server's choice of worker pool.
enum class Workload {
  kLight,    ///< Well under a millisecond: catalogue, closed-form scenes, jobs, health.
  kCompute,  ///< Runs an ODE, finite elements or an optimiser: the bounded compute pool.
};

/// How a route's workload is known.
enum class RouteWorkload {
  kLight,    ///< Always Workload::kLight.
  kCompute,  ///< Always Workload::kCompute (explore, optimize, fit, modes).
  kScene,    ///< Workload::kCompute when the body's outputs or model need a model
             ///< other than the closed forms (hertz, flexible); see ClassifyWorkload.
};

/// One endpoint: method, path pattern and handler. A pattern segment "{id}"
/// matches any one path segment.
struct Route {
  std::string method;   ///< HTTP method.
  std::string path;     ///< Path pattern.
  std::string summary;  ///< One line for --help and OpenAPI.
  std::function<Response(const Request&, const Context&)> handler;  ///< The handler.
  bool jobbable = false;                           ///< True when POST /v1/jobs may run it.
  RouteWorkload workload = RouteWorkload::kLight;  ///< What answering it costs.
};

/// Every route the service answers, in a stable order.
const std::vector<Route>& Routes();

/// The route for `method` on `path`, or null (unknown path, or another method).
const Route* FindRoute(std::string_view method, std::string_view path);

/// The routes whose pattern matches `path` (any method), in table order.
std::vector<const Route*> MatchRoutes(std::string_view path);

/// The path segment that "{id}" matched in `path` for `pattern` ("" if none).
std::string PathParameter(std::string_view pattern, std::string_view path);

/// Routes `request`: 404 NotFound for an unknown path, 405 MethodNotAllowed
/// for a known path with another method. `route_pattern`, if non-null, gets
/// the matched pattern (or "unmatched") for metrics and logs. Never throws:
/// an escaping exception becomes a 500 InternalError without details in the
/// body and its what() in Response::internal_error (for the log). With
/// `allow_stream`, a handler may answer with Response::stream (the server
/// writes it chunked); otherwise streamed bodies are collected into `text`.
Response Dispatch(const Request& request, const Context& context,
                  std::string* route_pattern = nullptr, bool allow_stream = false);

/// Calls `route`'s handler as Dispatch does once the route matched: an escaping exception
/// becomes a 500 InternalError without details in the body (its what() in
/// Response::internal_error), and without `allow_stream` a streamed body is collected into
/// `text`. Never throws.
Response CallRoute(const Route& route, const Request& request, const Context& context,
                   bool allow_stream = false);

/// The workload of `request`: kCompute for routes that always run models
/// (explore, optimize, fit, modes) and for scene routes (sweet-spot, collision,
/// compare) whose outputs or model need the hertz or flexible models
/// (core::ModelsFor); kLight otherwise, also for unknown paths and bodies that
/// do not parse (they are refused at once). Cost: path matching, plus one JSON
/// parse of the body for scene routes. Never throws.
/// Takes views so that a server can classify the bytes it received without copying them.
/// When it parsed the body (a scene body naming an iterative model or output) and
/// `parsed` is non-null, the parsed object goes to *parsed, for Request::parsed_body: the
/// handler then does not parse the body a second time.
Workload ClassifyWorkload(std::string_view method, std::string_view path, std::string_view body,
                          const Context& context,
                          std::shared_ptr<nlohmann::json>* parsed = nullptr);

/// The error envelope {"code", "message", "field"} with `status` (pass
/// ErrorCodeStatus(code) unless a documented exception applies).
Response ErrorResponse(int status, ErrorCode code, std::string message, std::string field = {});

}  // namespace sweetspot::api
