// What every api handler returns: an HTTP-style status and a JSON body.
// The api layer is pure functions (body -> Response); it never includes httplib.
#pragma once

#include <nlohmann/json.hpp>

namespace sweetspot::api {

/// A handler's answer: HTTP status code and JSON body.
struct Response {
  int status = 200;     ///< HTTP status code.
  nlohmann::json body;  ///< JSON body (never contains NaN or Infinity).
};

/// GET /health: {"status": "ok"}.
Response HandleHealth();

}  // namespace sweetspot::api
