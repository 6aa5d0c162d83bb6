#include "server/server.hpp"

// Before httplib.h: it pulls in <resolv.h>, whose `_res` macro breaks Eigen.
#include "api/thread_budget.hpp"
#include "core/flexible/modes_cache.hpp"

#include <httplib.h>

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <iostream>
#include <mutex>
#include <optional>
#include <string_view>
#include <thread>

#include "server/jobs/job_manager.hpp"
#include "api/router.hpp"
#include "server/access_log.hpp"
#include "core/geometry_format.hpp"
#include "server/connection_loop.hpp"
#include "server/metrics.hpp"
#include "server/request_head.hpp"
#include "server/request_stream.hpp"
#include "server/jobs/postgres_job_service.hpp"
#include "server/jobs/sqlite_job_store.hpp"
#include "server/static_files.hpp"

namespace sweetspot::server {
namespace {

// Writes one JSON body: never throws on invalid UTF-8 (replaced instead).
std::string Serialize(const nlohmann::json& body) {
  return body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// Serialize(body) appended to *out (the serializer nlohmann::json::dump uses, on a string
// the caller sized).
void SerializeInto(const nlohmann::json& body, std::string* out) {
  nlohmann::detail::serializer<nlohmann::json> serializer(
      nlohmann::detail::output_adapter<char, std::string>(*out), ' ',
      nlohmann::json::error_handler_t::replace);
  serializer.dump(body, /*pretty_print=*/false, /*ensure_ascii=*/false, /*indent_step=*/0);
}

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
        try {
          producer([&](std::string_view chunk) {
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

void WriteApiResponse(const api::Response& response, httplib::Response& res) {
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
    bool same = true;
    for (std::size_t i = 0; i < name.size() && same; ++i) {
      const auto lower = [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c + 32) : c; };
      same = lower(line[i]) == lower(name[i]);
    }
    if (!same) continue;
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

// The route label of static files in metrics and the access log (one label
// for every file keeps the label set bounded).
constexpr const char* kStaticRoute = "static";

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

}  // namespace

namespace {
// The message of the 413 for a body over max_body_bytes (httplib's and the lean path's).
constexpr const char* kBodyTooLargeMessage = "request body exceeds the configured max_body_bytes";

// How the pre-routing hook answers a request: on httplib's own path (kHttplib), or itself,
// with the body the loop received (kWithBody: the methods whose body httplib reads) or
// without one (kWithoutBody: GET, HEAD, OPTIONS; httplib ignores their body).
enum class LeanPath { kHttplib, kWithBody, kWithoutBody };

LeanPath LeanPathOf(const httplib::Request& req, const RequestStream* stream) {
  if (stream == nullptr || !stream->framed()) return LeanPath::kHttplib;
  const std::string& m = req.method;
  const bool with_body = m == "POST" || m == "PUT" || m == "PATCH" || m == "DELETE";
  if (!with_body && m != "GET" && m != "HEAD" && m != "OPTIONS") {
    return LeanPath::kHttplib;  // httplib answers 400 (or reads the body first: 413)
  }
  if (!with_body) return LeanPath::kWithoutBody;
  // Bodies httplib transforms before a handler sees them: multipart forms (parsed into
  // files), compressed bodies (decoded, or 415).
  if (req.has_header("Content-Encoding") || req.is_multipart_form_data()) {
    return LeanPath::kHttplib;
  }
  return LeanPath::kWithBody;
}
}  // namespace

namespace {
// httplib's request handling (parsing, routing, our handlers, writing the
// answer) for one request the connection loop has read completely.
class HttpServer : public httplib::Server {
 public:
  // httplib stops a streamed answer between two chunks once its listening
  // socket is gone (svr_sock_ invalid); the connection loop owns the socket,
  // so tell httplib whether the server is serving.
  void SetServing(int listen_fd) { svr_sock_ = listen_fd; }
  void SetStopping() { svr_sock_ = INVALID_SOCKET; }

  bool ServeOne(httplib::Stream& stream, bool close_connection, bool* connection_closed) {
    bool closed = false;
    const bool ok = process_request(stream, close_connection, closed, PrepareRequest);
    *connection_closed = closed;
    return ok;
  }
};

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

// The compute pool's size: the configured count, or (0) the cores.
int ComputeWorkers(int configured) {
  if (configured > 0) return configured;
  const unsigned cores = std::thread::hardware_concurrency();
  return cores == 0 ? 1 : static_cast<int>(cores);
}
}  // namespace

struct Server::Impl {
  HttpServer http;
  std::atomic<bool> stop_requested{false};
  api::Context context;
  Metrics metrics;
  core::ModesCache modes_cache;               // bending modes kept across requests (bounded LRU)
  // The compute pool's threads: a compute worker holds one while it answers, a sweep takes
  // idle ones for its extra threads (--explore-threads), so model work never runs on more
  // threads than the pool has.
  std::unique_ptr<api::ThreadBudget> compute_budget;
  std::unique_ptr<SqliteJobStore> job_store;  // A SQLite --jobs-db only; outlives `jobs`.
  std::unique_ptr<ServerJobService> jobs;     // Never null after the constructor.
  std::unique_ptr<StaticFiles> static_files;  // The explorer's files (web root); never null.
  std::string startup_error;  // Why the jobs database cannot be used; Bind() reports it.
  std::mutex log_mutex;
  // Created by Bind(); owns the listening socket. Last: its workers use the members above.
  std::unique_ptr<ConnectionLoop> loop;
};

namespace {
// Set by the route handler on its worker thread, read by the logger that
// httplib calls on the same thread right after: requests httplib answered
// itself (413, 411, malformed) are counted there.
thread_local bool request_was_routed = false;
}  // namespace

Server::Server(ServerConfig config) : config_(std::move(config)), impl_(std::make_unique<Impl>()) {
  httplib::Server& http = impl_->http;
  // What httplib still applies itself: the body limit (413 from the head alone)
  // and the values of the Keep-Alive answer header. Reading, timeouts and the
  // connection limit belong to the connection loop (it hands over complete requests).
  http.set_payload_max_length(config_.max_body_bytes);
  http.set_keep_alive_timeout(WholeSeconds(config_.keep_alive_timeout_s));
  http.set_keep_alive_max_count(static_cast<size_t>(config_.keep_alive_max_requests));

  impl_->static_files =
      std::make_unique<StaticFiles>(config_.web_root.empty() ? DefaultWebRoot() : config_.web_root);
  impl_->context.limits = config_.limits;
  // A job's limits at submit (api/explore_estimate) are the job runner's (--job-max-time-s,
  // --job-max-result-bytes): one flag each.
  impl_->context.limits.max_job_time_s = config_.jobs.max_time_s;
  impl_->context.limits.max_job_result_bytes = config_.jobs.max_result_bytes;
  impl_->context.modes_cache = &impl_->modes_cache;
  impl_->compute_budget =
      std::make_unique<api::ThreadBudget>(ComputeWorkers(config_.compute_threads));
  impl_->context.thread_budget = impl_->compute_budget.get();
  impl_->context.explore_threads = ComputeWorkers(config_.explore_threads);
  // Jobs run the same router with the job's cancel flag and progress, on a
  // copy of the context taken now: loaded jobs may start before this
  // constructor returns, and jobbable requests need neither jobs nor metrics.
  const JobRunner runner = [context = impl_->context, impl = impl_.get()](
                               const api::Request& inner, core::Progress* progress) {
    api::Context job_context = context;
    job_context.progress = progress;
    job_context.batch = true;  // the rows go to the job's result: --max-batch-samples
    job_context.stream_json = true;  // a sweep's rows go to the store as they are made
    // Streamed answers (CSV, NDJSON sweeps) are collected by the job service, which stops
    // them at its result limit.
    api::Response response = api::Dispatch(inner, job_context, nullptr, /*allow_stream=*/true);
    if (!response.internal_error.empty()) {
      // A job's 500 is logged like a request's: the job's path and the caught text.
      const std::string line = AccessLogLine({inner.method, inner.path, "job", response.status,
                                              0.0, inner.body.size(), response.internal_error});
      std::lock_guard<std::mutex> lock(impl->log_mutex);
      std::cerr << line << "\n";
    }
    return response;
  };
  auto log_store_error = [impl = impl_.get()](const std::string& message) {
    std::lock_guard<std::mutex> lock(impl->log_mutex);
    std::cerr << "sweetspot-server: jobs database: " << message << std::endl;
  };
  if (IsPostgresUri(config_.jobs_db)) {
    std::string error;
    impl_->jobs =
        PostgresJobService::Open(config_.jobs_db, config_.jobs, runner, log_store_error, &error);
    if (!impl_->jobs) impl_->startup_error = error;
  } else if (config_.jobs_db != kNoJobsDb) {
    std::string error;
    SqliteJobStoreOptions store_options;
    store_options.max_bytes = config_.jobs_db_max_bytes;
    impl_->job_store = SqliteJobStore::Open(config_.jobs_db, &error, store_options);
    if (!impl_->job_store) impl_->startup_error = error;
  }
  if (impl_->job_store) {
    JobPersistence persistence;
    persistence.store = impl_->job_store.get();
    persistence.on_store_error = log_store_error;
    try {
      impl_->jobs = std::make_unique<JobManager>(config_.jobs, runner, persistence);
    } catch (const std::runtime_error& load_error) {
      impl_->startup_error = "jobs database \"" + config_.jobs_db + "\": " + load_error.what();
    }
  }
  // Memory only: with --jobs-db none, or (never serving: Bind fails) when the database failed.
  if (!impl_->jobs) impl_->jobs = std::make_unique<JobManager>(config_.jobs, runner);
  impl_->context.jobs = impl_->jobs.get();
  impl_->context.metrics_text = [impl = impl_.get()] {
    std::string text = impl->metrics.Render(impl->jobs->CountsByState());
    if (impl->loop) text += impl->loop->MetricsText();
    return text;
  };

  // Answers a request for the API or the static files; `body` is the request's body (the
  // bytes the connection loop received, or what httplib read on its own path).
  auto answer = [this](const httplib::Request& req, std::string_view body,
                       httplib::Response& res) {
    const auto start = std::chrono::steady_clock::now();
    impl_->metrics.Begin();
    std::string route;
    std::string internal_error;
    if (IsStaticRequest(req, *impl_->static_files)) {
      route = kStaticRoute;
      WriteStaticResponse(req, *impl_->static_files, res);
    } else {
      // A request of the compute pool carries the loop's cancel flag (client gone, time up,
      // shutdown): its models poll it through the context.
      RequestStream* stream = RequestStream::Current();
      RequestCancel* cancel = stream != nullptr ? stream->cancel() : nullptr;
      std::optional<api::Context> with_cancel;
      if (cancel != nullptr) {
        with_cancel.emplace(impl_->context);
        with_cancel->progress = &cancel->progress;
      }
      api::Request request{req.method, req.path, std::string(body), req.params};
      // The body the choice of pool parsed already (a scene naming an iterative model).
      if (stream != nullptr) request.parsed_body = stream->parsed_body();
      api::Response response = api::Dispatch(
          request, with_cancel ? *with_cancel : impl_->context, &route, /*allow_stream=*/true);
      if (cancel != nullptr && !response.stream) StoppedAnswer(*cancel, config_.max_request_time_s, &response);
      internal_error = std::move(response.internal_error);
      WriteApiResponse(response, res);
    }
    const double duration_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    impl_->metrics.End(route, req.method, res.status, duration_s);
    request_was_routed = true;
    // A caught exception is always logged, also with the access log off.
    if (config_.access_log || !internal_error.empty()) {
      const std::string line = AccessLogLine({req.method, req.path, route, res.status, duration_s,
                                              body.size(), std::move(internal_error)});
      std::lock_guard<std::mutex> lock(impl_->log_mutex);
      std::cerr << line << "\n";
    }
  };

  // Every request the connection loop framed is answered here, before httplib's routing:
  // no regex match against the path, and the body is not read into a second string (the
  // loop holds the request's bytes). What httplib did after this hook is done here with
  // the same answers: 413 for a Content-Length over max_body_bytes (from the head alone).
  // Requests this does not answer (a method httplib does not route, a multipart or
  // Content-Encoding body httplib decodes, no loop framing) take httplib's own path to
  // the same handler, as before.
  http.set_pre_routing_handler([this, answer](const httplib::Request& req,
                                              httplib::Response& res) {
    RequestStream* stream = RequestStream::Current();
    if (!config_.cors_origin.empty()) {
      const std::string origin = req.get_header_value("Origin");
      if (config_.cors_origin == "*" || origin == config_.cors_origin) {
        res.set_header("Access-Control-Allow-Origin", config_.cors_origin == "*" ? "*" : origin);
        res.set_header("Vary", "Origin");
        if (req.method == "OPTIONS" && req.has_header("Access-Control-Request-Method")) {
          res.status = 204;
          res.set_header("Access-Control-Allow-Methods", "GET, POST, DELETE, OPTIONS");
          res.set_header("Access-Control-Allow-Headers", "Content-Type, Authorization");
          res.set_header("Access-Control-Max-Age", "600");
          return httplib::Server::HandlerResponse::Handled;
        }
      }
    }
    // Static files carry no data: the page itself asks for the token.
    if (!config_.auth_token.empty() && req.path != "/health" &&
        !IsStaticRequest(req, *impl_->static_files) &&
        !TokenMatches(RawHeaderValue("Authorization"), config_.auth_token)) {
      WriteApiResponse(api::ErrorResponse(401, api::ErrorCode::kUnauthorized,
                                          "header Authorization: must be \"Bearer <token>\" "
                                          "with the server's token (everything but /health "
                                          "and the explorer's static files needs it)",
                                          "Authorization"),
                       res);
      res.set_header("WWW-Authenticate", "Bearer");
      return httplib::Server::HandlerResponse::Handled;
    }
    // A chunked body bypasses the payload limit in 0.11.4 (pitfalls.md): refuse it.
    if (req.has_header("Transfer-Encoding")) {
      WriteApiResponse(api::ErrorResponse(411, api::ErrorCode::kInvalidValue,
                                          "header Transfer-Encoding = \"" +
                                              req.get_header_value("Transfer-Encoding") +
                                              "\": chunked bodies are not accepted; send "
                                              "Content-Length",
                                          "Transfer-Encoding"),
                       res);
      return httplib::Server::HandlerResponse::Handled;
    }
    const LeanPath path = LeanPathOf(req, stream);
    if (path == LeanPath::kHttplib) return httplib::Server::HandlerResponse::Unhandled;
    std::string_view body;
    if (path == LeanPath::kWithBody) {
      // httplib's payload limit, from the head alone (the loop did not read such a body).
      if (stream->content_length() > config_.max_body_bytes) {
        WriteApiResponse(api::ErrorResponse(413, CodeForStatus(413), kBodyTooLargeMessage), res);
        return httplib::Server::HandlerResponse::Handled;  // logged "unrouted", as before
      }
      body = stream->body();
    }
    answer(req, body, res);
    return httplib::Server::HandlerResponse::Handled;
  });

  // httplib's own path (see above): its regex routing, the body it read.
  auto handle = [answer](const httplib::Request& req, httplib::Response& res) {
    answer(req, req.body, res);
  };
  for (const char* pattern : {".*"}) {
    http.Get(pattern, handle);
    http.Post(pattern, handle);
    http.Put(pattern, handle);
    http.Patch(pattern, handle);
    http.Delete(pattern, handle);
    http.Options(pattern, handle);
  }

  // Statuses httplib produces itself (413, 400 on a malformed request line,
  // ...) get the JSON error envelope; bodies our handlers wrote are kept.
  http.set_error_handler(
      httplib::Server::HandlerWithResponse([](const httplib::Request&, httplib::Response& res) {
        if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
        std::string message = "HTTP status " + std::to_string(res.status);
        if (res.status == 413) message = kBodyTooLargeMessage;
        if (res.status == 400) {
          message =
              "the request could not be read: malformed, or its body did not arrive within "
              "the read timeout";
        }
        WriteApiResponse(api::ErrorResponse(res.status, CodeForStatus(res.status), message), res);
        return httplib::Server::HandlerResponse::Handled;
      }));
  http.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
    if (request_was_routed) {
      request_was_routed = false;
      return;
    }
    impl_->metrics.Begin();
    impl_->metrics.End("unrouted", req.method, res.status, 0.0);
    if (config_.access_log) {
      const nlohmann::json line{{"method", req.method}, {"path", req.path},
                                {"route", "unrouted"},  {"status", res.status},
                                {"duration_s", 0.0},    {"bytes_in", req.body.size()}};
      std::lock_guard<std::mutex> lock(impl_->log_mutex);
      std::cerr << Serialize(line) << "\n";
    }
  });
  // Never send an exception's text to the client (pitfalls.md); log it.
  http.set_exception_handler([this](const httplib::Request& req, httplib::Response& res,
                                    std::exception_ptr caught) {
    WriteApiResponse(api::ErrorResponse(500, api::ErrorCode::kInternalError, "internal error"),
                     res);
    const std::string line = AccessLogLine(
        {req.method, req.path, "unrouted", 500, 0.0, req.body.size(), WhatOf(caught)});
    std::lock_guard<std::mutex> lock(impl_->log_mutex);
    std::cerr << line << "\n";
  });
}

Server::~Server() {
  Stop();
  impl_->jobs->Shutdown(0.0);  // No grace (a no-op after Shutdown()).
}

void Server::Shutdown() {
  Stop();
  const auto counts = impl_->jobs->CountsByState();
  const int running = counts.count("running") != 0 ? counts.at("running") : 0;
  if (running > 0) {
    std::lock_guard<std::mutex> lock(impl_->log_mutex);
    std::cerr << "sweetspot-server: waiting up to " << config_.shutdown_grace_s << " s for "
              << running << " running job(s) to finish" << std::endl;
  }
  impl_->jobs->Shutdown(config_.shutdown_grace_s);
  const auto after = impl_->jobs->CountsByState();
  const int queued = after.count("queued") != 0 ? after.at("queued") : 0;
  if (queued > 0 && impl_->job_store) {
    std::lock_guard<std::mutex> lock(impl_->log_mutex);
    std::cerr << "sweetspot-server: " << queued << " unfinished job(s) kept in \""
              << config_.jobs_db << "\" for the next start" << std::endl;
  } else if (queued > 0 && IsPostgresUri(config_.jobs_db)) {
    std::lock_guard<std::mutex> lock(impl_->log_mutex);
    std::cerr << "sweetspot-server: " << queued
              << " queued job(s) left in the shared PostgreSQL queue for the other replicas"
              << std::endl;
  }
}

void Server::EndShutdownGrace() {
  if (impl_->loop) impl_->loop->EndGrace();
  impl_->jobs->EndGrace();
}

bool Server::Bind(std::string* error) {
  if (!impl_->startup_error.empty()) {
    if (error != nullptr) *error = impl_->startup_error;
    return false;
  }
  int bound = -1;
  const int listen_fd = Listen(config_.host, config_.port, &bound);
  if (listen_fd < 0) {
    if (error != nullptr) {
      *error = "cannot bind " + config_.host + ":" + std::to_string(config_.port) +
               " (address in use, not local, or not permitted)";
    }
    return false;
  }
  port_ = bound;
  ConnectionLoopOptions options;
  options.max_connections = config_.max_connections;
  options.max_connections_per_client = config_.max_connections_per_client;
  options.first_byte_timeout_s = config_.first_byte_timeout_s;
  options.max_unsent_bytes_per_client = config_.max_unsent_bytes_per_client;
  options.max_request_time_s = config_.max_request_time_s;
  options.shutdown_grace_s = config_.shutdown_grace_s;
  options.max_head_bytes = config_.max_head_bytes;
  options.max_body_bytes = config_.max_body_bytes;
  options.header_timeout_s = config_.header_timeout_s;
  options.body_min_rate_bytes_per_s = config_.body_min_rate_bytes_per_s;
  options.read_timeout_s = config_.read_timeout_s;
  options.write_timeout_s = config_.write_timeout_s;
  options.keep_alive_timeout_s = config_.keep_alive_timeout_s;
  options.keep_alive_max_requests = config_.keep_alive_max_requests;
  options.light_workers = config_.threads;
  options.compute_workers = ComputeWorkers(config_.compute_threads);
  options.compute_budget = impl_->compute_budget.get();
  ConnectionLoopHooks hooks;
  hooks.serve = [impl = impl_.get()](RequestStream& stream, bool close_connection, bool* closed) {
    return impl->http.ServeOne(stream, close_connection, closed);
  };
  hooks.classify = [impl = impl_.get()](std::string_view method, std::string_view path,
                                        std::string_view body,
                                        std::shared_ptr<nlohmann::json>* parsed) {
    // The router sees the path percent-decoded (httplib decodes it): so must the choice of
    // pool, or "/v1/%65xplore" would run a sweep on a light worker.
    std::string decoded;
    if (path.find('%') != std::string_view::npos) {
      decoded = PercentDecoded(path);
      path = decoded;
    }
    // A scene body parsed to decide is handed on to its handler (parsed once).
    return api::ClassifyWorkload(method, path, body, impl->context, parsed) ==
                   api::Workload::kCompute
               ? Pool::kCompute
               : Pool::kLight;
  };
  hooks.error_body = [](int status, api::ErrorCode code, const std::string& message) {
    return Serialize(api::ErrorResponse(status, code, message).body) + "\n";
  };
  hooks.refused = [this](int status, api::ErrorCode /*code*/, const std::string& method,
                         const std::string& path) {
    impl_->metrics.Begin();
    impl_->metrics.End("unrouted", method, status, 0.0);
    if (config_.access_log) {
      // A refused request's method and path may be any bytes, up to the head limit: the log
      // line keeps their first 64 and 512 bytes.
      const nlohmann::json line{{"method", method.substr(0, 64)},
                                {"path", path.substr(0, 512)},
                                {"route", "unrouted"},
                                {"status", status},
                                {"duration_s", 0.0},
                                {"bytes_in", 0}};
      std::lock_guard<std::mutex> lock(impl_->log_mutex);
      std::cerr << Serialize(line) << "\n";
    }
  };
  impl_->http.SetServing(listen_fd);
  impl_->loop = std::make_unique<ConnectionLoop>(listen_fd, options, std::move(hooks));
  {
    std::lock_guard<std::mutex> lock(impl_->log_mutex);
    const StaticFiles& files = *impl_->static_files;
    if (files.Installed()) {
      std::cerr << "sweetspot-server: design explorer at / from \"" << files.root() << "\""
                << std::endl;
    } else {
      std::cerr << "sweetspot-server: design explorer not installed (no index.html in \""
                << files.root() << "\"); / answers 404, the API is unaffected" << std::endl;
    }
  }
  return true;
}

int Server::compute_threads() const { return ComputeWorkers(config_.compute_threads); }

bool Server::Run() {
  if (!impl_->loop) return false;
  if (impl_->stop_requested.load()) impl_->loop->Stop();
  return impl_->loop->Run();
}

void Server::Stop() {
  impl_->stop_requested.store(true);
  impl_->http.SetStopping();  // streamed answers end at their next chunk, as before
  if (impl_->loop) impl_->loop->Stop();
}

}  // namespace sweetspot::server
