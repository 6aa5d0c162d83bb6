// POST /v1/jobs, GET /v1/jobs, GET /v1/jobs/{id}, GET /v1/jobs/{id}/result,
// DELETE /v1/jobs/{id}: any long POST endpoint run as a job (api/job_service.hpp
// has the states and JSON; the server implements the service).
#include "api/endpoint.hpp"
#include "api/handlers.hpp"
#include "api/job_service.hpp"

namespace sweetspot::api {
namespace {

Response NoJobs() {
  return ErrorResponse(501, ErrorCode::kNotImplemented,
                       "jobs run inside the server (sweetspot-server); the CLI answers "
                       "requests directly, so send the inner request to its own path");
}

// A parsed POST /v1/jobs request: the endpoint to run and the request it gets.
struct JobRequest {
  const Route* target = nullptr;
  std::string body;  // the inner request, as JSON text
};

std::optional<JobRequest> ParseJob(const nlohmann::json& body, const Context&, ApiError* error) {
  ObjectReader reader(body, "", error);
  std::string path;
  reader.String("path", &path);
  const nlohmann::json* inner_body = reader.Get("body");
  if (reader.ok() && inner_body == nullptr) reader.Missing("body");
  if (!reader.Finish()) return std::nullopt;
  if (path.rfind("/", 0) != 0) path = "/v1/" + path;  // "sweet-spot" -> "/v1/sweet-spot"
  std::string jobbable;
  const Route* target = nullptr;
  for (const Route& route : Routes()) {
    if (route.jobbable) jobbable += (jobbable.empty() ? "" : ", ") + route.path;
    if (route.jobbable && route.path == path) target = &route;
  }
  if (target == nullptr) {
    SetError(error, ErrorCode::kInvalidValue, "path", &body["path"],
             "must name an endpoint that can run as a job: " + jobbable);
    return std::nullopt;
  }
  if (!inner_body->is_object()) {
    SetError(error, ErrorCode::kInvalidValue, "body", inner_body,
             "must be the endpoint's request object");
    return std::nullopt;
  }
  return JobRequest{target, inner_body->dump()};
}

}  // namespace

// A job's answer is its state (202), not a typed endpoint's result: only the parsing is
// shared (ParseRequest).
Response HandleJobSubmit(const Request& request, const Context& context) {
  if (context.jobs == nullptr) return NoJobs();
  Response failure;
  const auto job = ParseRequest<JobRequest>(request, context, ParseJob, &failure);
  if (!job) return failure;
  return context.jobs->Submit({job->target->method, job->target->path, job->body});
}

Response HandleJobList(const Request&, const Context& context) {
  if (context.jobs == nullptr) return NoJobs();
  return context.jobs->List();
}

Response HandleJobStatus(const Request& request, const Context& context) {
  if (context.jobs == nullptr) return NoJobs();
  return context.jobs->Status(PathParameter("/v1/jobs/{id}", request.path));
}

Response HandleJobResult(const Request& request, const Context& context) {
  if (context.jobs == nullptr) return NoJobs();
  return context.jobs->Result(PathParameter("/v1/jobs/{id}/result", request.path));
}

Response HandleJobCancel(const Request& request, const Context& context) {
  if (context.jobs == nullptr) return NoJobs();
  return context.jobs->Cancel(PathParameter("/v1/jobs/{id}", request.path));
}

}  // namespace sweetspot::api
