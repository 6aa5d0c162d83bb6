// The routing table shared by the HTTP server and the CLI: (method, path) ->
// pure handler. HTTP-agnostic: the server and the CLI both call Dispatch().
#pragma once

#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "api/response.hpp"

namespace sweetspot::api {

/// A request as the handlers see it.
struct Request {
  std::string method;  ///< "GET", "POST", "DELETE".
  std::string path;    ///< Path without query, e.g. "/v1/bat/properties".
  std::string body;    ///< Raw body (JSON for POST).
};

/// One endpoint: method, path pattern and handler. A pattern segment "{id}"
/// matches any one path segment.
struct Route {
  std::string method;                                   ///< HTTP method.
  std::string path;                                     ///< Path pattern.
  std::string summary;                                  ///< One line for --help and OpenAPI.
  std::function<Response(const Request&)> handler;      ///< The handler.
};

/// Every route the service answers, in a stable order.
const std::vector<Route>& Routes();

/// The routes whose pattern matches `path` (any method), in table order.
std::vector<const Route*> MatchRoutes(std::string_view path);

/// Routes `request`: 404 NotFound for an unknown path, 405 MethodNotAllowed
/// for a known path with another method. `route_pattern`, if non-null, gets
/// the matched pattern (or "unmatched") for metrics and logs.
Response Dispatch(const Request& request, std::string* route_pattern = nullptr);

/// The error envelope {"code", "message", "field"} with `status`.
Response ErrorResponse(int status, std::string_view code, std::string message,
                       std::string field = {});

}  // namespace sweetspot::api
