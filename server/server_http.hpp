// The httplib side of Server, shared by server.cpp and server_http.cpp: how answers are
// written (the JSON envelope, streamed and sourced bodies, the design explorer's static
// files), what is read from a request before routing (the token from the raw head, which
// path the pre-routing hook takes), httplib's request handling for one request, and the
// listening socket. Included after Eigen's headers where both are (<httplib.h> pulls in
// <resolv.h>, whose `_res` macro breaks Eigen: server.cpp).
#pragma once

#include <httplib.h>

#include <ctime>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "api/error_code.hpp"
#include "api/json_text.hpp"
#include "api/response.hpp"
#include "server/request_stream.hpp"
#include "server/static_files.hpp"

namespace sweetspot::server::http {

/// One JSON body: never throws on invalid UTF-8 (replaced instead).
std::string Serialize(const nlohmann::json& body);

/// `value` appended to *out exactly as Serialize writes it (api/json_text.hpp).
using api::AppendJson;

/// The text of a caught exception, for the log.
std::string WhatOf(const std::exception_ptr& caught);

/// Writes an api answer into httplib's: a streamed body chunked (and passed through a proxy's
/// buffer), a sourced one with Content-Length a piece at a time, a JSON body serialised in
/// place, one the endpoint wrote as text moved in; Retry-After: 1 on 429 and 503.
void WriteApiResponse(api::Response response, httplib::Response& res);

/// The code of the error envelope for an HTTP status httplib produced itself.
api::ErrorCode CodeForStatus(int status);

/// The answer of a request the connection loop stopped (its cancel flag set while it
/// computed), in place of the handler's: 503 for the time budget and for a shutdown; the
/// handler's own for a client that left.
void StoppedAnswer(const RequestCancel& cancel, double max_request_time_s, api::Response* response);

/// Seconds rounded down to whole ones, at least 1 (httplib's keep-alive header).
time_t WholeSeconds(double s);

/// "Bearer <token>" against the configured token, in constant time; the scheme's name is
/// case-insensitive, the token compared byte for byte.
bool TokenMatches(std::string_view header, const std::string& token);

/// The value of header `name` as the client sent it (not percent-decoded), from the raw head
/// of the request the calling thread answers; "" when absent.
std::string_view RawHeaderValue(std::string_view name);

/// httplib's setup hook: drops a form-encoded Content-Type (the API reads bodies as JSON).
void PrepareRequest(httplib::Request& req);

/// The route label of static files in metrics and the access log.
inline constexpr const char* kStaticRoute = "static";

/// True for requests the design explorer's static files answer (GET or HEAD of "/", or of
/// an existing file at a path no API route matches).
bool IsStaticRequest(const httplib::Request& req, const StaticFiles& files);

/// Answers a static request: the file with its headers (304 on a matching If-None-Match), or
/// a 404 envelope.
void WriteStaticResponse(const httplib::Request& req, const StaticFiles& files,
                         httplib::Response& res);

/// The message of the 413 for a body over max_body_bytes (httplib's and the lean path's): the
/// limit's value, bytes, and the flag and variable that set it.
inline std::string BodyTooLargeMessage(std::size_t max_body_bytes) {
  return "the request body is larger than the limit max_body_bytes = " +
         std::to_string(max_body_bytes) +
         " bytes: send a smaller body, or raise the limit with --max-body-bytes "
         "(SWEETSPOT_MAX_BODY_BYTES)";
}

/// How the pre-routing hook answers a request: on httplib's own path (kHttplib), or itself,
/// with the body the loop received (kWithBody: the methods whose body httplib reads) or
/// without one (kWithoutBody: GET, HEAD, OPTIONS; httplib ignores their body).
enum class LeanPath { kHttplib, kWithBody, kWithoutBody };

/// What the lean path asks of a framed request's headers, noted by ParseFramedHead as it reads
/// them (names compared as httplib compares them, ignoring ASCII case), so that it looks
/// nothing up in httplib's header map. The values are views of the request's own header
/// values: valid while that httplib::Request is.
struct FramedHeaders {
  bool accept_encoding = false;    ///< An Accept-Encoding header is given.
  bool content_encoding = false;   ///< A Content-Encoding header is given.
  bool transfer_encoding = false;  ///< A Transfer-Encoding header is given.
  std::string_view connection;     ///< The first Connection header's value ("" when none).
  std::string_view content_type;   ///< The first Content-Type header's value ("" when none).
};

/// The path `req` takes (kHttplib without the loop's framing); `headers`, when given, are
/// req's as ParseFramedHead noted them (else they are looked up in req's).
LeanPath LeanPathOf(const httplib::Request& req, const RequestStream* stream,
                    const FramedHeaders* headers = nullptr);

/// The reason phrase httplib 0.11.4 writes after `status` in its status line, for the
/// statuses this service answers; null for the others (httplib then writes the answer).
const char* StatusText(int status);

/// The request line and headers of a head the connection loop framed (`head`: up to and
/// with its blank line), parsed as httplib parses them into *req: method, target, version,
/// the path percent-decoded, the query's parameters, the headers (values percent-decoded).
/// False, *req partly filled, for any head where httplib's parsing might differ or fail
/// (an unusual request line, a method it does not route, a header line without a value):
/// those take httplib's own path.
/// With `noted`, what FramedHeaders holds of them is noted there too.
bool ParseFramedHead(std::string_view head, httplib::Request* req, FramedHeaders* noted = nullptr);

/// httplib's status line and headers for `res` (headers in its order), blank line included.
std::string ResponseHead(const httplib::Response& res, const char* status_text);

/// A header ResponseHead writes as if res.set_header had added it.
struct AddedHeader {
  std::string_view name;   ///< Its name.
  std::string_view value;  ///< Its value.
};

/// ResponseHead of `res` with `added` set on it (each after res's headers of the same name,
/// as set_header inserts them), without inserting them into res's map. `added` must be in
/// httplib's order of names (ASCII case ignored), e.g. Connection, Content-Length, Keep-Alive.
std::string ResponseHead(const httplib::Response& res, const char* status_text,
                         std::initializer_list<AddedHeader> added);

/// The head of the usual answer (a body with its Content-Type, not for HEAD): res's headers
/// with Content-Length and Keep-Alive (`keep_alive_value`) or Connection: close added, as
/// httplib's set_header would add them, without inserting them into res's map.
std::string UsualAnswerHead(const httplib::Response& res, const char* status_text, bool keep_alive,
                            std::string_view keep_alive_value);

/// httplib's request handling (parsing, routing, our handlers, writing the answer) for one
/// request the connection loop has read completely.
class HttpServer : public httplib::Server {
 public:
  /// httplib stops a streamed answer between two chunks once its listening socket is gone
  /// (svr_sock_ invalid); the connection loop owns the socket, so tell httplib whether the
  /// server is serving.
  void SetServing(int listen_fd) { svr_sock_ = listen_fd; }
  void SetStopping() { svr_sock_ = INVALID_SOCKET; }
  /// The value of the Keep-Alive answer header, as httplib writes it.
  std::string KeepAliveValue() const {
    return "timeout=" + std::to_string(keep_alive_timeout_sec_) +
           ", max=" + std::to_string(keep_alive_max_count_);
  }

  bool ServeOne(httplib::Stream& stream, bool close_connection, bool* connection_closed) {
    bool closed = false;
    const bool ok = process_request(stream, close_connection, closed, PrepareRequest);
    *connection_closed = closed;
    return ok;
  }
};

/// A listening TCP socket on host:port (port 0: any free port), SO_REUSEADDR only, the
/// kernel's largest backlog. Returns the socket or -1; *bound_port gets the port.
int Listen(const std::string& host, int port, int* bound_port);

/// The compute pool's size: the configured count, or (0) the CPUs this process may use
/// (DefaultThreadCount, server/cpu_quota.hpp).
int ComputeWorkers(int configured);

}  // namespace sweetspot::server::http
