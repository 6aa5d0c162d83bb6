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
#include "server/server_http.hpp"
#include "server/static_files.hpp"

namespace sweetspot::server {

// The httplib side (server_http.hpp); this file is compiled alone (server/CMakeLists.txt).
using namespace http;  // NOLINT(build/namespaces)

struct Server::Impl {
  explicit Impl(const ServerConfig& server_config) : config(server_config) {}

  /// Called once by the constructor, in this order.
  void Configure();
  /// Opens the job store of config.jobs_db (or keeps jobs in memory); a failure is kept in
  /// startup_error for Bind().
  void OpenJobs();
  void InstallHandlers();

  /// Answers a request for the API or the static files; `body` is the request's body (the
  /// bytes the connection loop received, or what httplib read on its own path).
  void Answer(const httplib::Request& req, std::string_view body, httplib::Response& res);
  /// The pre-routing hook's work: CORS, the token, refusals, then Answer() with the loop's
  /// bytes; `path` is LeanPathOf(req, the stream), found once by the caller; `headers`, when
  /// given, are what ParseFramedHead noted of req's (else they are looked up).
  httplib::Server::HandlerResponse PreRoute(const httplib::Request& req, httplib::Response& res,
                                            LeanPath path, const FramedHeaders* headers = nullptr);
  /// Serves one request the connection loop framed: parsed from the loop's bytes, answered
  /// by PreRoute, its head and body written here as httplib would write them; httplib's
  /// own request handling for what this leaves to it (ServeDirect's comment).
  bool ServeDirect(RequestStream& stream, bool close_connection, bool* connection_closed);
  /// httplib's error handler: the JSON envelope of a status >= 400 with no body.
  httplib::Server::HandlerResponse ErrorEnvelope(httplib::Response& res);
  /// httplib's logger: requests no route answered, counted and logged "unrouted".
  void LogUnrouted(const httplib::Request& req, const httplib::Response& res);
  /// httplib's exception handler: a JSON 500, the exception's text in the log only.
  void OnException(const httplib::Request& req, httplib::Response& res,
                   const std::exception_ptr& caught);

  const ServerConfig& config;  // the Server's, which outlives this
  HttpServer http;
  std::atomic<bool> stop_requested{false};
  std::atomic<bool> draining{false};  // BeginDrain() was called: GET /ready answers 503
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
  std::string keep_alive_value;  // the Keep-Alive answer header's value (Configure)
  // Created by Bind(); owns the listening socket. Last: its workers use the members above.
  std::unique_ptr<ConnectionLoop> loop;
};

namespace {
// Set by the route handler on its worker thread, read by the logger that
// httplib calls on the same thread right after: requests httplib answered
// itself (413, 411, malformed) are counted there.
thread_local bool request_was_routed = false;
// An answer ServeDirect computed but leaves httplib to write (a body from a provider, a
// status whose reason phrase it does not know): PreRoute hands it to httplib as it is.
thread_local httplib::Response* computed_answer = nullptr;
}  // namespace

// httplib's settings that still apply, the static files, and the context every request
// and job gets.
void Server::Impl::Configure() {
  // What httplib still applies itself: the body limit (413 from the head alone)
  // and the values of the Keep-Alive answer header. Reading, timeouts and the
  // connection limit belong to the connection loop (it hands over complete requests).
  http.set_payload_max_length(config.max_body_bytes);
  http.set_keep_alive_timeout(WholeSeconds(config.keep_alive_timeout_s));
  http.set_keep_alive_max_count(static_cast<size_t>(config.keep_alive_max_requests));
  keep_alive_value = http.KeepAliveValue();

  static_files =
      std::make_unique<StaticFiles>(config.web_root.empty() ? DefaultWebRoot() : config.web_root);
  context.limits = config.limits;
  // A job's limits at submit (api/explore_estimate) are the job runner's (--job-max-time-s,
  // --job-max-result-bytes): one flag each.
  context.limits.max_job_time_s = config.jobs.max_time_s;
  context.limits.max_job_result_bytes = config.jobs.max_result_bytes;
  context.modes_cache = &modes_cache;
  context.answer_text = true;  // HTTP answers are sent as text at once (Response::json_text)
  context.draining = [this] { return draining.load(); };
  compute_budget =
      std::make_unique<api::ThreadBudget>(ComputeWorkers(config.compute_threads));
  context.thread_budget = compute_budget.get();
  context.explore_threads = ComputeWorkers(config.explore_threads);
}

void Server::Impl::OpenJobs() {
  // Jobs run the same router with the job's cancel flag and progress, on a
  // copy of the context taken now: loaded jobs may start before this
  // constructor returns, and jobbable requests need neither jobs nor metrics.
  const JobRunner runner = [context = context, this](
                               const api::Request& inner, core::Progress* progress) {
    api::Context job_context = context;
    job_context.progress = progress;
    job_context.answer_text = false;  // the job service stores the tree (response_json)
    job_context.batch = true;  // the rows go to the job's result: --max-batch-samples
    job_context.stream_json = true;  // a sweep's rows go to the store as they are made
    // Streamed answers (CSV, NDJSON sweeps) are collected by the job service, which stops
    // them at its result limit.
    api::Response response = api::Dispatch(inner, job_context, nullptr, /*allow_stream=*/true);
    if (!response.internal_error.empty()) {
      // A job's 500 is logged like a request's: the job's path and the caught text.
      const std::string line = AccessLogLine({inner.method, inner.path, "job", response.status,
                                              0.0, inner.body.size(), response.internal_error});
      std::lock_guard<std::mutex> lock(log_mutex);
      std::cerr << line << "\n";
    }
    return response;
  };
  auto log_store_error = [this](const std::string& message) {
    std::lock_guard<std::mutex> lock(log_mutex);
    std::cerr << "sweetspot-server: jobs database: " << message << std::endl;
  };
  if (IsPostgresUri(config.jobs_db)) {
    std::string error;
    jobs =
        PostgresJobService::Open(config.jobs_db, config.jobs, runner, log_store_error, &error);
    if (!jobs) startup_error = error;
  } else if (config.jobs_db != kNoJobsDb) {
    std::string error;
    SqliteJobStoreOptions store_options;
    store_options.max_bytes = config.jobs_db_max_bytes;
    job_store = SqliteJobStore::Open(config.jobs_db, &error, store_options);
    if (!job_store) startup_error = error;
  }
  if (job_store) {
    JobPersistence persistence;
    persistence.store = job_store.get();
    persistence.on_store_error = log_store_error;
    try {
      jobs = std::make_unique<JobManager>(config.jobs, runner, persistence);
    } catch (const std::runtime_error& load_error) {
      startup_error = "jobs database \"" + config.jobs_db + "\": " + load_error.what();
    }
  }
  // Memory only: with --jobs-db none, or (never serving: Bind fails) when the database failed.
  if (!jobs) jobs = std::make_unique<JobManager>(config.jobs, runner);
}

  // Answers a request for the API or the static files; `body` is the request's body (the
  // bytes the connection loop received, or what httplib read on its own path).
void Server::Impl::Answer(const httplib::Request& req, std::string_view body,
                          httplib::Response& res) {
  const auto start = std::chrono::steady_clock::now();
  metrics.Begin();
  std::string route;
  std::string internal_error;
  if (IsStaticRequest(req, *static_files)) {
    route = kStaticRoute;
    WriteStaticResponse(req, *static_files, res);
  } else {
    // A request of the compute pool carries the loop's cancel flag (client gone, time up,
    // shutdown): its models poll it through the context.
    RequestStream* stream = RequestStream::Current();
    RequestCancel* cancel = stream != nullptr ? stream->cancel() : nullptr;
    std::optional<api::Context> with_cancel;
    if (cancel != nullptr) {
      with_cancel.emplace(context);
      with_cancel->progress = &cancel->progress;
    }
    api::Request request{req.method, req.path, std::string(body), req.params};
    // The body the choice of pool parsed already (a scene naming an iterative model).
    if (stream != nullptr) request.parsed_body = stream->parsed_body();
    api::Response response = api::Dispatch(
        request, with_cancel ? *with_cancel : context, &route, /*allow_stream=*/true);
    if (cancel != nullptr && !response.stream) StoppedAnswer(*cancel, config.max_request_time_s, &response);
    internal_error = std::move(response.internal_error);
    WriteApiResponse(std::move(response), res);
  }
  const double duration_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  metrics.End(route, req.method, res.status, duration_s);
  request_was_routed = true;
  // A caught exception is always logged, also with the access log off.
  if (config.access_log || !internal_error.empty()) {
    const std::string line = AccessLogLine({req.method, req.path, route, res.status, duration_s,
                                            body.size(), std::move(internal_error)});
    std::lock_guard<std::mutex> lock(log_mutex);
    std::cerr << line << "\n";
  }
}

  // Every request the connection loop framed is answered here, before httplib's routing:
  // no regex match against the path, and the body is not read into a second string (the
  // loop holds the request's bytes). What httplib did after this hook is done here with
  // the same answers: 413 for a Content-Length over max_body_bytes (from the head alone).
  // Requests this does not answer (a method httplib does not route, a multipart or
  // Content-Encoding body httplib decodes, no loop framing) take httplib's own path to
  // the same handler, as before.
httplib::Server::HandlerResponse Server::Impl::PreRoute(const httplib::Request& req,
                                                      httplib::Response& res, LeanPath path,
                                                      const FramedHeaders* headers) {
  if (!config.cors_origin.empty()) {
    const std::string origin = req.get_header_value("Origin");
    if (config.cors_origin == "*" || origin == config.cors_origin) {
      res.set_header("Access-Control-Allow-Origin", config.cors_origin == "*" ? "*" : origin);
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
  // Static files carry no data: the page itself asks for the token. Nor do the probes.
  if (!config.auth_token.empty() && req.path != "/health" && req.path != "/ready" &&
      !IsStaticRequest(req, *static_files) &&
      !TokenMatches(RawHeaderValue("Authorization"), config.auth_token)) {
    WriteApiResponse(api::ErrorResponse(401, api::ErrorCode::kUnauthorized,
                                        "header Authorization: must be \"Bearer <token>\" "
                                        "with the server's token (everything but /health, "
                                        "/ready and the explorer's static files needs it)",
                                        "Authorization"),
                     res);
    res.set_header("WWW-Authenticate", "Bearer");
    return httplib::Server::HandlerResponse::Handled;
  }
  // A chunked body bypasses the payload limit in 0.11.4 (pitfalls.md): refuse it.
  if (headers != nullptr ? headers->transfer_encoding : req.has_header("Transfer-Encoding")) {
    WriteApiResponse(api::ErrorResponse(411, api::ErrorCode::kInvalidValue,
                                        "header Transfer-Encoding = \"" +
                                            req.get_header_value("Transfer-Encoding") +
                                            "\": chunked bodies are not accepted; send "
                                            "Content-Length",
                                        "Transfer-Encoding"),
                     res);
    return httplib::Server::HandlerResponse::Handled;
  }
  if (path == LeanPath::kHttplib) return httplib::Server::HandlerResponse::Unhandled;
  const RequestStream* stream = RequestStream::Current();
  std::string_view body;
  if (path == LeanPath::kWithBody) {
    // httplib's payload limit, from the head alone (the loop did not read such a body).
    if (stream->content_length() > config.max_body_bytes) {
      WriteApiResponse(
          api::ErrorResponse(413, CodeForStatus(413), BodyTooLargeMessage(config.max_body_bytes)),
          res);
      return httplib::Server::HandlerResponse::Handled;  // logged "unrouted", as before
    }
    body = stream->body();
  }
  Answer(req, body, res);
  return httplib::Server::HandlerResponse::Handled;
}

// httplib's hooks: the pre-routing hook (PreRoute), its own routing for what that leaves to
// it, the envelope of the statuses it produces itself, its logger and exception handler.
void Server::Impl::InstallHandlers() {
  http.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    if (computed_answer != nullptr) {  // ServeDirect's answer, for httplib to write
      res = std::move(*computed_answer);
      computed_answer = nullptr;
      return httplib::Server::HandlerResponse::Handled;
    }
    return PreRoute(req, res, LeanPathOf(req, RequestStream::Current()));
  });

  // httplib's own path (see above): its regex routing, the body it read.
  auto handle = [this](const httplib::Request& req, httplib::Response& res) {
    Answer(req, req.body, res);
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
      httplib::Server::HandlerWithResponse([this](const httplib::Request&, httplib::Response& res) {
        return ErrorEnvelope(res);
      }));
  http.set_logger([this](const httplib::Request& req, const httplib::Response& res) {
    LogUnrouted(req, res);
  });
  // Never send an exception's text to the client (pitfalls.md); log it.
  http.set_exception_handler([this](const httplib::Request& req, httplib::Response& res,
                                    std::exception_ptr caught) {
    OnException(req, res, caught);
  });
}

// Statuses httplib produces itself (413, 400 on a malformed request line,
// ...) get the JSON error envelope; bodies our handlers wrote are kept.
httplib::Server::HandlerResponse Server::Impl::ErrorEnvelope(httplib::Response& res) {
  if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
  std::string message = "HTTP status " + std::to_string(res.status);
  if (res.status == 413) message = BodyTooLargeMessage(config.max_body_bytes);
  if (res.status == 400) {
    message =
        "the request could not be read: malformed, or its body did not arrive within "
        "the read timeout";
  }
  WriteApiResponse(api::ErrorResponse(res.status, CodeForStatus(res.status), message), res);
  return httplib::Server::HandlerResponse::Handled;
}

void Server::Impl::LogUnrouted(const httplib::Request& req, const httplib::Response& res) {
  if (request_was_routed) {
    request_was_routed = false;
    return;
  }
  metrics.Begin();
  metrics.End("unrouted", req.method, res.status, 0.0);
  if (config.access_log) {
    const nlohmann::json line{{"method", req.method}, {"path", req.path},
                              {"route", "unrouted"},  {"status", res.status},
                              {"duration_s", 0.0},    {"bytes_in", req.body.size()}};
    std::lock_guard<std::mutex> lock(log_mutex);
    std::cerr << Serialize(line) << "\n";
  }
}

void Server::Impl::OnException(const httplib::Request& req, httplib::Response& res,
                               const std::exception_ptr& caught) {
  WriteApiResponse(api::ErrorResponse(500, api::ErrorCode::kInternalError, "internal error"),
                   res);
  const std::string line = AccessLogLine(
      {req.method, req.path, "unrouted", 500, 0.0, req.body.size(), WhatOf(caught)});
  std::lock_guard<std::mutex> lock(log_mutex);
  std::cerr << line << "\n";
}

// A request the loop framed, answered without httplib's request handling: the head is parsed
// from the loop's bytes (no regex, no line reader), PreRoute answers it, and the answer's
// head is built here with httplib 0.11.4's rules (write_response_core: the error envelope,
// Content-Length of the body, Connection: close or Keep-Alive, Content-Type text/plain for
// an untyped body, Content-Length: 0 for none, Accept-Ranges for HEAD; headers in httplib's
// order) and handed to the stream with the body, which the loop sends with one writev.
// httplib's own path stays for what this does not parse (ParseFramedHead), what PreRoute
// leaves to httplib (LeanPathOf), a client that accepts compressed answers (httplib may
// compress), and answers it must write itself: a body from a provider (streamed, sourced)
// or a status without a reason phrase here (then with the answer computed here).
bool Server::Impl::ServeDirect(RequestStream& stream, bool close_connection,
                               bool* connection_closed) {
  httplib::Request req;
  FramedHeaders headers;  // what this asks of them, noted as they are parsed
  if (!ParseFramedHead(stream.request().substr(0, stream.head_bytes()), &req, &headers) ||
      headers.accept_encoding) {
    return http.ServeOne(stream, close_connection, connection_closed);
  }
  const LeanPath path = LeanPathOf(req, &stream, &headers);
  if (path == LeanPath::kHttplib) return http.ServeOne(stream, close_connection, connection_closed);
  const std::string_view connection = headers.connection;
  const bool closed =
      connection == "close" || (req.version == "HTTP/1.0" && connection != "Keep-Alive");
  if (headers.content_type.rfind("application/x-www-form-urlencoded", 0) == 0) {
    PrepareRequest(req);  // erases that header, of which content_type was a view
    headers.content_type = {};
  }
  httplib::Response res;
  res.version = "HTTP/1.1";
  try {
    PreRoute(req, res, path, &headers);
  } catch (...) {
    OnException(req, res, std::current_exception());
  }
  if (res.status == -1) res.status = 200;
  if (res.status >= 400) ErrorEnvelope(res);
  const char* status_text = StatusText(res.status);
  if (res.content_provider_ || status_text == nullptr) {
    computed_answer = &res;
    const bool ok = http.ServeOne(stream, close_connection, connection_closed);
    computed_answer = nullptr;
    return ok;
  }
  const bool head_only = req.method == "HEAD";
  const bool keep_alive = !(close_connection || connection == "close");
  std::string head;
  if (!res.body.empty() && !head_only && res.has_header("Content-Type")) {
    head = UsualAnswerHead(res, status_text, keep_alive, keep_alive_value);  // no map insert
  } else {
    if (!res.body.empty()) res.set_header("Content-Length", std::to_string(res.body.size()));
    res.set_header(keep_alive ? "Keep-Alive" : "Connection",
                   keep_alive ? keep_alive_value.c_str() : "close");
    if (!res.body.empty() && !res.has_header("Content-Type")) {
      res.set_header("Content-Type", "text/plain");
    }
    if (res.body.empty() && !res.has_header("Content-Length")) {
      res.set_header("Content-Length", "0");
    }
    if (head_only && !res.has_header("Accept-Ranges")) res.set_header("Accept-Ranges", "bytes");
    head = ResponseHead(res, status_text);
  }
  stream.SetAnswer(std::move(head), head_only ? std::string() : std::move(res.body));
  LogUnrouted(req, res);
  *connection_closed = closed;
  return stream.healthy();
}

Server::Server(ServerConfig config)
    : config_(std::move(config)), impl_(std::make_unique<Impl>(config_)) {
  impl_->Configure();
  impl_->OpenJobs();
  impl_->context.jobs = impl_->jobs.get();
  impl_->context.metrics_text = [impl = impl_.get()] {
    std::string text = impl->metrics.Render(impl->jobs->CountsByState());
    if (impl->loop) text += impl->loop->MetricsText();
    return text;
  };
  impl_->InstallHandlers();
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
    return impl->ServeDirect(stream, close_connection, closed);
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

void Server::BeginDrain() {
  // The loop first: once /ready says 503, every answer carries Connection: close.
  if (impl_->loop) impl_->loop->BeginDrain();
  impl_->draining.store(true);
}

void Server::Stop() {
  impl_->stop_requested.store(true);
  impl_->http.SetStopping();  // streamed answers end at their next chunk, as before
  if (impl_->loop) impl_->loop->Stop();
}

}  // namespace sweetspot::server
