// POST /v1/jobs, GET /v1/jobs, GET /v1/jobs/{id}, GET /v1/jobs/{id}/result,
// DELETE /v1/jobs/{id}: any long POST endpoint run as a job (api/job_service.hpp
// has the states and JSON; the server implements the service).
#include "api/handlers.hpp"
#include "api/job_service.hpp"

namespace sweetspot::api {
namespace {

Response NoJobs() {
  return ErrorResponse(501, ErrorCode::kNotImplemented,
                       "jobs run inside the server (sweetspot-server); the CLI answers "
                       "requests directly, so send the inner request to its own path");
}

}  // namespace

Response HandleJobSubmit(const Request& request, const Context& context) {
  if (context.jobs == nullptr) return NoJobs();
  Response failure;
  const auto body = ParseObjectBody(request, context, &failure);
  if (!body) return failure;
  ApiError error;
  ObjectReader reader(*body, "", &error);
  std::string path;
  reader.String("path", &path);
  const nlohmann::json* inner_body = reader.Get("body");
  if (reader.ok() && inner_body == nullptr) reader.Missing("body");
  if (!reader.Finish()) return ToResponse(error);
  if (path.rfind("/", 0) != 0) path = "/v1/" + path;  // "sweet-spot" -> "/v1/sweet-spot"
  std::string jobbable;
  const Route* target = nullptr;
  for (const Route& route : Routes()) {
    if (route.jobbable) jobbable += (jobbable.empty() ? "" : ", ") + route.path;
    if (route.jobbable && route.path == path) target = &route;
  }
  if (target == nullptr) {
    SetError(&error, ErrorCode::kInvalidValue, "path", &(*body)["path"],
             "must name an endpoint that can run as a job: " + jobbable);
    return ToResponse(error);
  }
  if (!inner_body->is_object()) {
    SetError(&error, ErrorCode::kInvalidValue, "body", inner_body,
             "must be the endpoint's request object");
    return ToResponse(error);
  }
  return context.jobs->Submit({target->method, target->path, inner_body->dump()});
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
