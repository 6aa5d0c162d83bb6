// What every api handler returns: an HTTP-style status and a JSON body (or,
// for /metrics, a text body). The api layer is pure functions (body ->
// Response); it never includes httplib.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <string_view>
#include <utility>

namespace sweetspot::api {

/// Receives one chunk of a streamed body; false when the receiver is gone
/// (e.g. the client disconnected) and the producer should stop.
using ChunkSink = std::function<bool(std::string_view)>;

/// A handler's answer: HTTP status code and body.
struct Response {
  Response() = default;
  /// A JSON answer.
  Response(int status_code, nlohmann::json json_body)
      : status(status_code), body(std::move(json_body)) {}
  /// A text answer (e.g. Prometheus metrics).
  static Response Text(int status_code, std::string text_body, std::string type) {
    Response out(status_code, nullptr);
    out.text = std::move(text_body);
    out.content_type = std::move(type);
    return out;
  }

  int status = 200;          ///< HTTP status code.
  nlohmann::json body;       ///< JSON body (never contains NaN or Infinity).
  std::string text;          ///< A non-JSON body, used when content_type is set.
  std::string content_type;  ///< Empty = application/json with `body`.
  /// When set, the body (of `content_type`) is produced by calling this with a
  /// sink, chunk by chunk, after the status has been sent; it returns false
  /// when it stopped early. It must not throw and owns everything it uses.
  /// Only Dispatch(..., allow_stream = true) returns one; every other caller
  /// gets the chunks collected into `text`.
  std::function<bool(const ChunkSink&)> stream;
  /// What the top-level handler caught when it answered 500 InternalError
  /// (the exception's what()); empty otherwise. Never sent to the client:
  /// the server and the CLI write it to their stderr log.
  std::string internal_error;
};

/// GET /health: {"status": "ok"}.
Response HandleHealth();

}  // namespace sweetspot::api
