// POST /v1/jobs, GET /v1/jobs, GET /v1/jobs/{id}, GET /v1/jobs/{id}/result,
// DELETE /v1/jobs/{id}: any long POST endpoint run as a job (api/job_service.hpp
// has the states and JSON; the server implements the service).
#include <algorithm>
#include <iterator>

#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"
#include "api/job_service.hpp"

namespace sweetspot::api {
namespace {

// The largest offset GET /v1/jobs accepts (far beyond any kept job count: JobConfig::max_kept
// is at most 1e6).
constexpr std::size_t kMaxJobListOffset = 1000000000;

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

constexpr const char* kJobStates[] = {"queued", "running", "done", "failed", "cancelled"};

// A query parameter of GET /v1/jobs as a whole number in [min, max]; false with the error
// (field = the parameter's name) otherwise.
bool JobListNumber(const std::string& name, const std::string& text, std::size_t min,
                   std::size_t max, std::size_t* out, ApiError* error) {
  const std::string rule =
      "must be a whole number in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  const bool digits = !text.empty() && text.size() <= 19 &&
                      text.find_first_not_of("0123456789") == std::string::npos;
  const unsigned long long value = digits ? std::stoull(text) : 0;
  if (!digits || value < min || value > max) {
    const nlohmann::json shown(text);
    SetError(error, ErrorCode::kInvalidValue, name, &shown, rule);
    return false;
  }
  *out = static_cast<std::size_t>(value);
  return true;
}

// GET /v1/jobs's query string: state (one of the five), limit (1..max_jobs_page, default
// JobListQuery's), offset (0..); each at most once, nothing else.
std::optional<JobListQuery> ParseJobListQuery(const Request& request, const ApiLimits& limits,
                                              ApiError* error) {
  JobListQuery query;
  query.limit = std::min(query.limit, limits.max_jobs_page);
  for (const auto& [name, value] : request.query) {
    const nlohmann::json shown(value);
    if (request.query.count(name) > 1) {
      SetError(error, ErrorCode::kInvalidValue, name, &shown, "may be given once");
      return std::nullopt;
    }
    if (name == "state") {
      const auto* end = std::end(kJobStates);
      if (std::find(std::begin(kJobStates), end, value) == end) {
        SetError(error, ErrorCode::kInvalidValue, "state", &shown,
                 "must be one of queued, running, done, failed, cancelled");
        return std::nullopt;
      }
      query.state = value;
    } else if (name == "limit") {
      if (!JobListNumber(name, value, 1, limits.max_jobs_page, &query.limit, error)) {
        return std::nullopt;
      }
    } else if (name == "offset") {
      if (!JobListNumber(name, value, 0, kMaxJobListOffset, &query.offset, error)) {
        return std::nullopt;
      }
    } else {
      SetError(error, ErrorCode::kUnknownField, name, &shown,
               "is not a parameter of GET /v1/jobs (state, limit, offset)");
      return std::nullopt;
    }
  }
  return query;
}

}  // namespace

nlohmann::json JobErrorObject(int status, const nlohmann::json& body, const std::string& message) {
  if (body.is_object() && body.contains("code") && body["code"].is_string() &&
      body.contains("message") && body["message"].is_string()) {
    return nlohmann::json{{"code", body["code"]},
                          {"message", body["message"]},
                          {"field", body.value("field", nlohmann::json())}};
  }
  // The codes the contract pairs with the statuses a job fails with.
  ErrorCode code = ErrorCode::kInternalError;
  if (status == 413) code = ErrorCode::kTooBig;
  if (status == 422) code = ErrorCode::kInfeasible;
  if (status == 503) code = ErrorCode::kInterrupted;
  if (status >= 400 && status < 500 && status != 413 && status != 422) {
    code = ErrorCode::kInvalidValue;
  }
  return nlohmann::json{{"code", ErrorCodeName(code)}, {"message", message}, {"field", nullptr}};
}

// A job's answer is its state (202), not a typed endpoint's result: only the parsing is
// shared (ParseRequest). The inner request is validated first, as its own endpoint does
// (Context::validate_only: parsed, no core call), so that a refused one is answered at once
// and never becomes a job.
Response HandleJobSubmit(const Request& request, const Context& context) {
  if (context.jobs == nullptr) return NoJobs();
  Response failure;
  const auto job = ParseRequest<JobRequest>(request, context, ParseJob, &failure);
  if (!job) return failure;
  const Request inner{job->target->method, job->target->path, job->body};
  Context check = context;
  check.validate_only = true;
  check.batch = true;  // as the job will run (server/server.cpp's runner)
  check.job = true;    // its estimated cost against the job limits (max_job_cpu_s, ...)
  check.progress = nullptr;
  Response checked = CallRoute(*job->target, inner, check);
  if (checked.status < 200 || checked.status >= 300) return checked;
  return context.jobs->Submit(inner);
}

Response HandleJobList(const Request& request, const Context& context) {
  if (context.jobs == nullptr) return NoJobs();
  ApiError error;
  const std::optional<JobListQuery> query = ParseJobListQuery(request, context.limits, &error);
  if (!query) return ToResponse(error);
  return context.jobs->List(*query);
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
