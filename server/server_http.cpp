// The httplib side of Server (server/server_http.hpp): writing answers (JSON, streamed,
// sourced, static files), reading the raw request head, the listening socket.
#include "server/server_http.hpp"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <chrono>
#include <exception>
#include <memory>
#include <thread>

#include "api/router.hpp"
#include "core/geometry_format.hpp"
#include "server/cpu_quota.hpp"

namespace sweetspot::server::http {

// Writes one JSON body: never throws on invalid UTF-8 (replaced instead).
std::string Serialize(const nlohmann::json& body) {
  return body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

namespace {

// Serialize(body) appended to *out, on a string the caller sized.
void SerializeInto(const nlohmann::json& body, std::string* out) { api::AppendJson(body, out); }

}  // namespace

// The text of a caught exception, for the log.
std::string WhatOf(const std::exception_ptr& caught) {
  try {
    if (caught) std::rethrow_exception(caught);
  } catch (const std::exception& e) {
    return e.what();
  } catch (...) {
    return "an exception not derived from std::exception";
  }
  return "no exception";
}

namespace {

// A streamed body is sent with chunked transfer encoding, in chunks of about
// 16 KiB or whatever was produced in 0.1 s, whichever comes first.
void WriteStreamedResponse(const api::Response& response, httplib::Response& res) {
  res.status = response.status;
  // The chunks must reach the client as they are produced, not when the answer
  // ends: here, and in a proxy in front (nginx buffers answers unless told not to).
  if (RequestStream* stream = RequestStream::Current()) stream->WriteThrough();
  res.set_header("X-Accel-Buffering", "no");
  auto producer = response.stream;
  res.set_chunked_content_provider(
      response.content_type, [producer](std::size_t /*offset*/, httplib::DataSink& sink) {
        constexpr std::size_t kChunkBytes = 16 * 1024;
        constexpr auto kChunkTime = std::chrono::milliseconds(100);
        std::string buffer;
        auto last_flush = std::chrono::steady_clock::now();
        bool writable = true;
        const auto flush = [&] {
          if (!buffer.empty() && writable) writable = sink.write(buffer.data(), buffer.size());
          buffer.clear();
          last_flush = std::chrono::steady_clock::now();
          return writable;
        };
        bool finished = false;
        try {
          finished = producer([&](std::string_view chunk) {
            buffer.append(chunk);
            if (buffer.size() >= kChunkBytes ||
                std::chrono::steady_clock::now() - last_flush >= kChunkTime) {
              return flush();
            }
            return true;
          });
        } catch (...) {
          return false;  // closes the connection: the client sees a truncated stream
        }
        if (!flush()) return false;
        // A stream that did not finish (a sweep stopped by the deadline or a shutdown; its
        // NDJSON already ends with an {"error"} line) ends without the chunked body's last
        // chunk: the client sees an incomplete body, never a complete-looking one.
        if (!finished) return false;
        sink.done();
        return true;
      });
}

// A body read from where it is kept (a stored job result), with Content-Length: the
// connection loop sends it as the client takes it, a piece at a time, holding no worker
// (RequestStream::DeferBody); without the loop's stream, piece by piece here.
void WriteSourcedResponse(const api::Response& response, httplib::Response& res) {
  res.status = response.status;
  std::shared_ptr<const api::BodySource> source = response.source;
  res.set_content_provider(
      static_cast<std::size_t>(source->bytes), response.content_type,
      [source](std::size_t offset, std::size_t length, httplib::DataSink& sink) {
        if (RequestStream* stream = RequestStream::Current();
            stream != nullptr && stream->DeferBody(source, offset)) {
          static const char kCounted = 0;  // never read: the stream counts the length only
          return sink.write(&kCounted, length);
        }
        std::string piece;
        if (!source->read(offset, std::min<std::size_t>(length, 64 * 1024), &piece) ||
            piece.empty()) {
          return false;
        }
        return sink.write(piece.data(), piece.size());
      });
}

// The Content-Type of `res`, as Response::set_content sets it (one header, replaced).
void SetContentType(httplib::Response& res, const char* type) {
  const auto range = res.headers.equal_range("Content-Type");
  res.headers.erase(range.first, range.second);
  res.set_header("Content-Type", type);
}

}  // namespace

void WriteApiResponse(api::Response response, httplib::Response& res) {
  if (response.stream) {
    WriteStreamedResponse(response, res);
    return;
  }
  if (response.source) {
    WriteSourcedResponse(response, res);
    return;
  }
  res.status = response.status;
  // Too busy, shutting down or the jobs database away: worth retrying soon.
  if (response.status == 429 || response.status == 503) res.set_header("Retry-After", "1");
  if (!response.content_type.empty()) {
    res.set_content(response.text, response.content_type.c_str());
  } else if (!response.json_text.empty()) {  // written as text by the endpoint already
    res.body = std::move(response.json_text);
    res.body.push_back('\n');
    SetContentType(res, "application/json");
  } else {
    // Serialised straight into the answer's body (set_content would copy it once more),
    // with room reserved for the size of this thread's previous answer: the serializer
    // appends a character at a time, and growing the string showed in the profile.
    thread_local std::size_t last_bytes = 1024;
    res.body.clear();
    res.body.reserve(last_bytes + last_bytes / 4);
    SerializeInto(response.body, &res.body);
    res.body.push_back('\n');
    last_bytes = std::min<std::size_t>(res.body.size(), 1u << 20);
    SetContentType(res, "application/json");
  }
}

// The code of the error envelope for an HTTP status httplib produced itself.
api::ErrorCode CodeForStatus(int status) {
  switch (status) {
    case 400:
      return api::ErrorCode::kInvalidValue;
    case 404:
      return api::ErrorCode::kNotFound;
    case 405:
      return api::ErrorCode::kMethodNotAllowed;
    case 408:
      return api::ErrorCode::kTimeout;
    case 413:
      return api::ErrorCode::kTooBig;
    case 414:
      return api::ErrorCode::kTooBig;
    default:
      return status >= 500 ? api::ErrorCode::kInternalError : api::ErrorCode::kInvalidValue;
  }
}

// The answer of a request the connection loop stopped (its cancel flag set while it
// computed), in place of the handler's: 503 with Retry-After for the time budget and for
// a shutdown; the handler's own for a client that left (nobody reads it).
void StoppedAnswer(const RequestCancel& cancel, double max_request_time_s,
                   api::Response* response) {
  switch (cancel.Reason()) {
    case CancelReason::kDeadline:
      *response = api::ErrorResponse(
          503, api::ErrorCode::kTimeout,
          "the request computed for longer than max_request_time_s = " +
              core::FormatNumber(max_request_time_s) +
              " s and was stopped; run it as a job (POST /v1/jobs), which has its own time "
              "limit");
      break;
    case CancelReason::kShutdown:
      *response = api::ErrorResponse(503, api::ErrorCode::kTooBusy,
                                     "the server is shutting down and stopped this request; "
                                     "retry on another replica or later");
      break;
    case CancelReason::kNone:
    case CancelReason::kClientGone:
      break;
  }
}

time_t WholeSeconds(double s) { return static_cast<time_t>(s < 1.0 ? 1.0 : s); }

// "Bearer <token>" against the configured token, in time independent of
// where the first difference is (no timing oracle for the token). The scheme's
// name is case-insensitive (RFC 9110, 11.1); the token is compared byte for byte.
bool TokenMatches(std::string_view header, const std::string& token) {
  constexpr std::string_view prefix = "bearer ";
  if (header.size() != prefix.size() + token.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    const char c = header[i];
    if ((c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c) != prefix[i]) return false;
  }
  unsigned char diff = 0;
  for (std::size_t i = 0; i < token.size(); ++i) {
    diff |= static_cast<unsigned char>(header[prefix.size() + i] ^ token[i]);
  }
  return diff == 0;
}

namespace {

char AsciiLower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

// httplib's order of header names (detail::ci: tolower, byte by byte; the C locale's tolower
// is ASCII's).
bool NameLess(std::string_view a, std::string_view b) {
  return std::lexicographical_compare(a.begin(), a.end(), b.begin(), b.end(), [](char x, char y) {
    return static_cast<unsigned char>(AsciiLower(x)) < static_cast<unsigned char>(AsciiLower(y));
  });
}

// Header names equal as httplib's map takes them.
bool SameName(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (AsciiLower(a[i]) != AsciiLower(b[i])) return false;
  }
  return true;
}

}  // namespace

// The value of header `name` as the client sent it (httplib percent-decodes the values it
// parses: "Bearer%20x" would become "Bearer x"), from the raw head of the request the
// calling thread answers; "" when absent. Names compare case-insensitively.
std::string_view RawHeaderValue(std::string_view name) {
  const RequestStream* stream = RequestStream::Current();
  if (stream == nullptr) return {};
  const std::string_view bytes = stream->request();
  const std::size_t head_end = bytes.find("\r\n\r\n");
  if (head_end == std::string_view::npos) return {};
  std::size_t at = bytes.find("\r\n");  // past the request line
  while (at < head_end) {
    const std::size_t begin = at + 2;
    const std::size_t end = bytes.find("\r\n", begin);
    const std::string_view line = bytes.substr(begin, end - begin);
    at = end;
    if (line.size() <= name.size() || line[name.size()] != ':') continue;
    if (!SameName(line.substr(0, name.size()), name)) continue;
    std::string_view value = line.substr(name.size() + 1);
    while (!value.empty() && (value.front() == ' ' || value.front() == '\t')) value.remove_prefix(1);
    while (!value.empty() && (value.back() == ' ' || value.back() == '\t')) value.remove_suffix(1);
    return value;
  }
  return {};
}

// What httplib must not do with a request, undone before routing (its setup hook):
// a form-encoded body (the Content-Type of `curl -d` and urllib) is capped at 8192 bytes
// in 0.11.4 and parsed into query parameters: the API reads every body as JSON, so that
// Content-Type is dropped and max_body_bytes alone applies.
void PrepareRequest(httplib::Request& req) {
  const auto type = req.headers.find("Content-Type");
  if (type != req.headers.end() &&
      type->second.rfind("application/x-www-form-urlencoded", 0) == 0) {
    req.headers.erase(type);
  }
}

// True for requests the design explorer's static files answer: GET or HEAD
// of "/" (also when the explorer is not installed: then a 404 envelope), or
// of an existing file under the web root at a path no API route matches.
// The API's paths always win; /v1/ is the API's alone.
bool IsStaticRequest(const httplib::Request& req, const StaticFiles& files) {
  if (req.method != "GET" && req.method != "HEAD") return false;
  if (req.path == "/") return true;
  if (req.path.rfind("/v1/", 0) == 0 || !api::MatchRoutes(req.path).empty()) return false;
  return files.Find(req.path).has_value();
}

// Answers a static request: the file with its Content-Type, Cache-Control
// and ETag (304 when If-None-Match has it), or a 404 envelope.
void WriteStaticResponse(const httplib::Request& req, const StaticFiles& files,
                         httplib::Response& res) {
  const std::optional<std::string> found = files.Find(req.path);
  const std::optional<StaticFile> file = found ? files.Read(*found) : std::nullopt;
  if (!file) {
    std::string message = "no file at path " + req.path;
    if (req.path == "/") {
      message = "the design explorer is not installed: no index.html in the web root \"" +
                files.root() +
                "\" (build with -DSWEETSPOT_BUILD_WEB=ON, or set --web-root); the API under /v1/ "
                "is unaffected";
    }
    WriteApiResponse(api::ErrorResponse(404, api::ErrorCode::kNotFound, message), res);
    return;
  }
  res.set_header("Cache-Control", file->cache_control);
  res.set_header("ETag", file->etag);
  res.set_header("X-Content-Type-Options", "nosniff");
  if (file->content_type.rfind("text/html", 0) == 0) {
    // The page loads its own bundle and calls its own origin's API only.
    res.set_header("Content-Security-Policy",
                   "default-src 'self'; style-src 'self' 'unsafe-inline'; img-src 'self' data:; "
                   "object-src 'none'; base-uri 'none'; form-action 'none'; "
                   "frame-ancestors 'none'");
    res.set_header("Referrer-Policy", "no-referrer");
  }
  if (req.get_header_value("If-None-Match") == file->etag) {
    res.status = 304;
    return;
  }
  res.status = 200;
  res.set_content(file->body, file->content_type.c_str());
}

const char* StatusText(int status) {
  switch (status) {
    case 200: return "OK";
    case 201: return "Created";
    case 202: return "Accepted";
    case 204: return "No Content";
    case 304: return "Not Modified";
    case 400: return "Bad Request";
    case 401: return "Unauthorized";
    case 403: return "Forbidden";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 406: return "Not Acceptable";
    case 408: return "Request Timeout";
    case 409: return "Conflict";
    case 410: return "Gone";
    case 411: return "Length Required";
    case 412: return "Precondition Failed";
    case 413: return "Payload Too Large";
    case 414: return "URI Too Long";
    case 415: return "Unsupported Media Type";
    case 422: return "Unprocessable Entity";
    case 429: return "Too Many Requests";
    case 500: return "Internal Server Error";
    case 501: return "Not Implemented";
    case 502: return "Bad Gateway";
    case 503: return "Service Unavailable";
    case 504: return "Gateway Timeout";
    default: return nullptr;
  }
}

namespace {

bool IsSpaceOrTab(char c) { return c == ' ' || c == '\t'; }

std::string Decoded(std::string_view text) {
  std::string s(text);
  return text.find('%') == std::string_view::npos ? s : httplib::detail::decode_url(s, false);
}

}  // namespace

bool ParseFramedHead(std::string_view head, httplib::Request* req, FramedHeaders* noted) {
  // The request line: httplib's pattern is "(METHOD) (([^? ]+)(?:\\?([^ ]*?))?) (HTTP/1\\.[01])";
  // only a plain line of a method this service routes is parsed here.
  const std::size_t line_end = head.find("\r\n");
  if (line_end == std::string_view::npos) return false;
  const std::string_view line = head.substr(0, line_end);
  const std::size_t sp1 = line.find(' ');
  if (sp1 == std::string_view::npos) return false;
  const std::size_t sp2 = line.find(' ', sp1 + 1);
  if (sp2 == std::string_view::npos) return false;
  const std::string_view method = line.substr(0, sp1);
  const std::string_view target = line.substr(sp1 + 1, sp2 - sp1 - 1);
  const std::string_view version = line.substr(sp2 + 1);
  if (version != "HTTP/1.1" && version != "HTTP/1.0") return false;
  if (method != "GET" && method != "POST" && method != "HEAD" && method != "OPTIONS" &&
      method != "PUT" && method != "DELETE" && method != "PATCH") {
    return false;
  }
  if (target.empty() || target.front() == '?') return false;
  for (const char c : target) {
    const auto u = static_cast<unsigned char>(c);
    if (u <= 0x20 || u >= 0x7f) return false;
  }
  req->method = std::string(method);
  req->version = std::string(version);
  req->target = std::string(target);
  const std::size_t query = target.find('?');
  req->path = Decoded(target.substr(0, query));
  if (query != std::string_view::npos && query + 1 < target.size()) {
    httplib::detail::parse_query_text(std::string(target.substr(query + 1)), req->params);
  }
  // The headers, as httplib's parse_header reads a line: the name up to the first ':', the
  // value without the spaces and tabs around it, percent-decoded.
  std::size_t at = line_end + 2;
  for (;;) {
    const std::size_t end = head.find("\r\n", at);
    if (end == std::string_view::npos) return false;
    if (end == at) break;  // the blank line
    std::string_view header = head.substr(at, end - at);
    at = end + 2;
    while (!header.empty() && IsSpaceOrTab(header.back())) header.remove_suffix(1);
    const std::size_t colon = header.find(':');
    if (colon == std::string_view::npos || colon == 0) return false;
    std::string_view value = header.substr(colon + 1);
    while (!value.empty() && IsSpaceOrTab(value.front())) value.remove_prefix(1);
    if (value.empty()) return false;
    const std::string_view name = header.substr(0, colon);
    const auto added = req->headers.emplace(std::string(name), Decoded(value));
    if (noted == nullptr) continue;
    if (SameName(name, "Accept-Encoding")) noted->accept_encoding = true;
    if (SameName(name, "Content-Encoding")) noted->content_encoding = true;
    if (SameName(name, "Transfer-Encoding")) noted->transfer_encoding = true;
    if (SameName(name, "Connection") && noted->connection.empty()) {
      noted->connection = added->second;  // the first, as get_header_value gives it
    }
    if (SameName(name, "Content-Type") && noted->content_type.empty()) {
      noted->content_type = added->second;
    }
  }
  return true;
}

std::string ResponseHead(const httplib::Response& res, const char* status_text) {
  return ResponseHead(res, status_text, {});
}

std::string ResponseHead(const httplib::Response& res, const char* status_text,
                         std::initializer_list<AddedHeader> added) {
  std::string head;
  head.reserve(256);
  head += "HTTP/1.1 ";
  head += std::to_string(res.status);
  head += ' ';
  head += status_text;
  head += "\r\n";
  auto line = [&head](std::string_view name, std::string_view value) {
    head += name;
    head += ": ";
    head += value;
    head += "\r\n";
  };
  const AddedHeader* next = added.begin();
  for (const auto& [name, value] : res.headers) {
    // An added header goes before the first of res's headers whose name sorts after it.
    for (; next != added.end() && NameLess(next->name, name); ++next) line(next->name, next->value);
    line(name.c_str(), value.c_str());  // httplib writes them with "%s": up to a NUL
  }
  for (; next != added.end(); ++next) line(next->name, next->value);
  head += "\r\n";
  return head;
}

std::string UsualAnswerHead(const httplib::Response& res, const char* status_text,
                            bool keep_alive, std::string_view keep_alive_value) {
  // In httplib's order of names: Connection < Content-Length < Keep-Alive.
  const std::string length = std::to_string(res.body.size());
  return keep_alive ? ResponseHead(res, status_text,
                                   {{"Content-Length", length}, {"Keep-Alive", keep_alive_value}})
                    : ResponseHead(res, status_text,
                                   {{"Connection", "close"}, {"Content-Length", length}});
}

LeanPath LeanPathOf(const httplib::Request& req, const RequestStream* stream,
                    const FramedHeaders* headers) {
  if (stream == nullptr || !stream->framed()) return LeanPath::kHttplib;
  const std::string& m = req.method;
  const bool with_body = m == "POST" || m == "PUT" || m == "PATCH" || m == "DELETE";
  if (!with_body && m != "GET" && m != "HEAD" && m != "OPTIONS") {
    return LeanPath::kHttplib;  // httplib answers 400 (or reads the body first: 413)
  }
  if (!with_body) return LeanPath::kWithoutBody;
  // Bodies httplib transforms before a handler sees them: multipart forms (parsed into
  // files), compressed bodies (decoded, or 415).
  // is_multipart_form_data: the first Content-Type starts with "multipart/form-data".
  const bool transformed =
      headers != nullptr ? headers->content_encoding ||
                               headers->content_type.rfind("multipart/form-data", 0) == 0
                         : req.has_header("Content-Encoding") || req.is_multipart_form_data();
  if (transformed) return LeanPath::kHttplib;
  return LeanPath::kWithBody;
}

// A listening TCP socket on host:port (port 0: any free port), with
// SO_REUSEADDR only (httplib's default also sets SO_REUSEPORT, which lets a
// second server bind the same port silently and split the traffic), and the
// kernel's largest backlog. Returns the socket or -1; *bound_port gets the port.
int Listen(const std::string& host, int port, int* bound_port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE | AI_NUMERICSERV;
  addrinfo* found = nullptr;
  if (getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found) != 0) return -1;
  int fd = -1;
  for (addrinfo* a = found; a != nullptr && fd < 0; a = a->ai_next) {
    fd = ::socket(a->ai_family, a->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, a->ai_protocol);
    if (fd < 0) continue;
    const int yes = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    if (::bind(fd, a->ai_addr, a->ai_addrlen) != 0 || ::listen(fd, SOMAXCONN) != 0) {
      ::close(fd);
      fd = -1;
    }
  }
  freeaddrinfo(found);
  if (fd < 0) return -1;
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  *bound_port = addr.ss_family == AF_INET6
                    ? ntohs(reinterpret_cast<const sockaddr_in6*>(&addr)->sin6_port)
                    : ntohs(reinterpret_cast<const sockaddr_in*>(&addr)->sin_port);
  return fd;
}

// The compute pool's size: the configured count, or (0) the CPUs this process may use (its
// affinity mask and cgroup CPU quota, server/cpu_quota.hpp), not the node's cores.
int ComputeWorkers(int configured) {
  if (configured > 0) return configured;
  return DefaultThreadCount();
}

}  // namespace sweetspot::server::http
