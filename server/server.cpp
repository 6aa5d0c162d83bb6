#include "server/server.hpp"

#include <httplib.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <mutex>

#include "api/jobs.hpp"
#include "api/router.hpp"
#include "server/metrics.hpp"

namespace sweetspot::server {
namespace {

// Writes one JSON body: never throws on invalid UTF-8 (replaced instead).
std::string Serialize(const nlohmann::json& body) {
  return body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void WriteApiResponse(const api::Response& response, httplib::Response& res) {
  res.status = response.status;
  if (!response.content_type.empty()) {
    res.set_content(response.text, response.content_type.c_str());
  } else {
    res.set_content(Serialize(response.body) + "\n", "application/json");
  }
}

// The code of the error envelope for an HTTP status httplib produced itself.
const char* CodeForStatus(int status) {
  switch (status) {
    case 400:
      return "InvalidValue";
    case 404:
      return "NotFound";
    case 405:
      return "MethodNotAllowed";
    case 408:
      return "Timeout";
    case 413:
      return "TooBig";
    case 414:
      return "TooBig";
    default:
      return status >= 500 ? "InternalError" : "InvalidValue";
  }
}

time_t WholeSeconds(double s) { return static_cast<time_t>(s < 1.0 ? 1.0 : s); }

}  // namespace

struct Server::Impl {
  httplib::Server http;
  api::Context context;
  Metrics metrics;
  std::unique_ptr<api::JobManager> jobs;
  std::mutex log_mutex;
};

namespace {
// Set by the route handler on its worker thread, read by the logger that
// httplib calls on the same thread right after: requests httplib answered
// itself (413, 411, malformed) are counted there.
thread_local bool request_was_routed = false;
}  // namespace

Server::Server(ServerConfig config) : config_(std::move(config)), impl_(std::make_unique<Impl>()) {
  httplib::Server& http = impl_->http;
  const int threads = config_.threads;
  http.new_task_queue = [threads] { return new httplib::ThreadPool(static_cast<size_t>(threads)); };
  // httplib's default also sets SO_REUSEPORT, which lets a second server bind
  // the same port silently and split the traffic: keep SO_REUSEADDR only.
  http.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  http.set_tcp_nodelay(true);  // Nagle's delay costs ~100x keep-alive throughput (pitfalls.md)
  http.set_payload_max_length(config_.max_body_bytes);
  http.set_read_timeout(WholeSeconds(config_.read_timeout_s));
  http.set_write_timeout(WholeSeconds(config_.write_timeout_s));
  http.set_keep_alive_timeout(WholeSeconds(config_.keep_alive_timeout_s));
  http.set_keep_alive_max_count(static_cast<size_t>(config_.keep_alive_max_requests));

  // A chunked body bypasses the payload limit in 0.11.4 (pitfalls.md): refuse it.
  http.set_pre_routing_handler([](const httplib::Request& req, httplib::Response& res) {
    if (req.has_header("Transfer-Encoding")) {
      WriteApiResponse(api::ErrorResponse(411, "InvalidValue",
                                          "header Transfer-Encoding = \"" +
                                              req.get_header_value("Transfer-Encoding") +
                                              "\": chunked bodies are not accepted; send "
                                              "Content-Length",
                                          "Transfer-Encoding"),
                       res);
      return httplib::Server::HandlerResponse::Handled;
    }
    return httplib::Server::HandlerResponse::Unhandled;
  });

  impl_->context.limits = config_.limits;
  // Jobs run the same router with the job's cancel flag and progress.
  impl_->jobs = std::make_unique<api::JobManager>(
      config_.jobs, [impl = impl_.get()](const api::Request& inner, core::Progress* progress) {
        api::Context context = impl->context;
        context.progress = progress;
        return api::Dispatch(inner, context);
      });
  impl_->context.jobs = impl_->jobs.get();
  impl_->context.metrics_text = [impl = impl_.get()] {
    return impl->metrics.Render(impl->jobs->CountsByState());
  };

  auto handle = [this](const httplib::Request& req, httplib::Response& res) {
    const auto start = std::chrono::steady_clock::now();
    impl_->metrics.Begin();
    std::string route;
    const api::Response response =
        api::Dispatch({req.method, req.path, req.body}, impl_->context, &route);
    WriteApiResponse(response, res);
    const double duration_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    impl_->metrics.End(route, req.method, response.status, duration_s);
    request_was_routed = true;
    if (config_.access_log) {
      const nlohmann::json line{{"method", req.method},   {"path", req.path},
                                {"route", route},         {"status", response.status},
                                {"duration_s", duration_s}, {"bytes_in", req.body.size()}};
      std::lock_guard<std::mutex> lock(impl_->log_mutex);
      std::cerr << Serialize(line) << "\n";
    }
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
  http.set_error_handler(httplib::Server::HandlerWithResponse([](const httplib::Request&,
                                                                 httplib::Response& res) {
    if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
    std::string message = "HTTP status " + std::to_string(res.status);
    if (res.status == 413) message = "request body exceeds the configured max_body_bytes";
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
  // Never send an exception's text to the client (pitfalls.md).
  http.set_exception_handler(
      [](const httplib::Request&, httplib::Response& res, std::exception_ptr) {
        WriteApiResponse(api::ErrorResponse(500, "InternalError", "internal error"), res);
      });
}

Server::~Server() {
  Stop();
  impl_->jobs->Shutdown();
}

bool Server::Bind(std::string* error) {
  const int bound = config_.port == 0 ? impl_->http.bind_to_any_port(config_.host)
                                      : (impl_->http.bind_to_port(config_.host, config_.port)
                                             ? config_.port
                                             : -1);
  if (bound < 0) {
    if (error != nullptr) {
      *error = "cannot bind " + config_.host + ":" + std::to_string(config_.port) +
               " (address in use, not local, or not permitted)";
    }
    return false;
  }
  port_ = bound;
  return true;
}

bool Server::Run() { return impl_->http.listen_after_bind(); }

void Server::Stop() { impl_->http.stop(); }

}  // namespace sweetspot::server
