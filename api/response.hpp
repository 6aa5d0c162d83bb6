// What every api handler returns: an HTTP-style status and a JSON body (or,
// for /metrics, a text body). The api layer is pure functions (body ->
// Response); it never includes httplib.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

namespace sweetspot::api {

/// Receives one chunk of a streamed body; false when the receiver is gone
/// (e.g. the client disconnected) and the producer should stop.
using ChunkSink = std::function<bool(std::string_view)>;

/// A body read piece by piece from where it is kept (a job's stored result), so that it is
/// never whole in memory: `bytes` in all; `read` appends at most `max` bytes from `offset` to
/// *out, false when it cannot (the source is gone: the answer is cut). Must not throw;
/// thread-safe; everything it uses outlives the answer (the server's job store does).
struct BodySource {
  std::uint64_t bytes = 0;  ///< The body's length, bytes.
  std::function<bool(std::uint64_t offset, std::size_t max, std::string* out)> read;  ///< A piece.
};

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
  std::string content_type;  ///< Empty = application/json with `body` (or `json_text`).
  /// The JSON answer already written as compact text (api/json_writer.hpp), in place of
  /// `body` (null then): the bytes AppendJson would write for the tree. Only a caller that
  /// sets Context::answer_text gets one (the server); content_type stays empty.
  std::string json_text;
  /// When set, the body (of `content_type`) is produced by calling this with a
  /// sink, chunk by chunk, after the status has been sent; it returns false
  /// when it stopped early. It must not throw and owns everything it uses.
  /// Only Dispatch(..., allow_stream = true) returns one; every other caller
  /// gets the chunks collected into `text`.
  std::function<bool(const ChunkSink&)> stream;
  /// When set, the body (of `content_type`, source->bytes long) is read from here as the client
  /// takes it (the server sends it with Content-Length, holding no worker and a piece of it
  /// at a time). Only Dispatch(..., allow_stream = true) returns one; every other caller gets
  /// the body read into `text`.
  std::shared_ptr<const BodySource> source;
  /// What the top-level handler caught when it answered 500 InternalError
  /// (the exception's what()); empty otherwise. Never sent to the client:
  /// the server and the CLI write it to their stderr log.
  std::string internal_error;
};

/// GET /health: {"status": "ok"}.
Response HandleHealth();

/// GET /ready: 200 {"status": "ready"}, or, while the server drains before it stops, 503
/// Unavailable (a load balancer's readiness probe then takes it out of rotation).
Response HandleReady(bool draining);

}  // namespace sweetspot::api
