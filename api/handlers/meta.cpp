// Handlers that describe the service: health, version, OpenAPI, metrics,
// and the shared request plumbing (body parsing, provenance).
#include <cstdint>
#include <cstdio>

#include "api/handlers/handlers.hpp"
#include "api/openapi_document.hpp"
#include "core/version.hpp"

namespace sweetspot::api {

Response HandleHealth() { return {200, nlohmann::json{{"status", "ok"}}}; }

Response HandleReady(bool draining) {
  if (!draining) return {200, nlohmann::json{{"status", "ready"}}};
  return ErrorResponse(503, ErrorCode::kUnavailable,
                       "draining: the server is stopping; it still answers until its drain "
                       "period (--drain-s) ends, then stops accepting connections");
}

Response HandleOpenApi(const Request&, const Context&) {
  static const nlohmann::json document = nlohmann::json::parse(OpenApiDocumentText());
  return {200, document};
}

Response HandleMetrics(const Request&, const Context& context) {
  if (!context.metrics_text) {
    return ErrorResponse(501, ErrorCode::kNotImplemented,
                         "metrics are kept by the running server (sweetspot-server), not the CLI");
  }
  return Response::Text(200, context.metrics_text(), "text/plain; version=0.0.4; charset=utf-8");
}

Response HandleVersion(const Request&, const Context&) {
  return {
      200,
      {{"sweetspot", core::SweetspotVersion()},
       {"eigen", core::EigenVersion()},
       {"nlopt", core::NloptVersion()},
       {"ipopt", core::IpoptVersion()},
       {"nlohmann_json", std::to_string(NLOHMANN_JSON_VERSION_MAJOR) + "." +
                             std::to_string(NLOHMANN_JSON_VERSION_MINOR) + "." +
                             std::to_string(NLOHMANN_JSON_VERSION_PATCH)},
       {"compiler", __VERSION__},
       {"speed_vs_error_generated", SpeedVsErrorGenerated()}},
  };
}

std::string InputHash(const nlohmann::json& canonical_input) {
  // FNV-1a 64 over the compact dump (nlohmann objects keep keys sorted, so the
  // dump is canonical). An identity key for reproduction, not a security hash.
  const std::string text =
      canonical_input.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  std::uint64_t hash = 1469598103934665603ULL;
  for (const unsigned char c : text) {
    hash ^= c;
    hash *= 1099511628211ULL;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
  return std::string("fnv1a64:") + hex;
}

nlohmann::json Provenance(const nlohmann::json& input, const nlohmann::json& options,
                          std::optional<unsigned long long> seed) {
  nlohmann::json out{{"sweetspot_version", core::SweetspotVersion()},
                     {"libraries",
                      {{"eigen", core::EigenVersion()},
                       {"nlopt", core::NloptVersion()},
                       {"ipopt", core::IpoptVersion()}}},
                     {"input_hash", InputHash(input)},
                     {"options", options}};
  out["seed"] = seed ? nlohmann::json(*seed) : nlohmann::json(nullptr);
  return out;
}

std::optional<nlohmann::json> ParseObjectBody(const Request& request, const Context& context,
                                              Response* error_response) {
  // Parsed already (ClassifyWorkload): taken once, so the body is parsed once.
  if (request.parsed_body && request.parsed_body->is_object()) {
    return std::move(*request.parsed_body);
  }
  ApiError error;
  std::optional<nlohmann::json> body = ParseBody(request.body, context.limits, &error);
  if (body.has_value() && body->is_object()) return body;
  if (body.has_value())
    SetError(&error, ErrorCode::kInvalidValue, "", &*body, "must be a JSON object");
  *error_response = ToResponse(error);
  return std::nullopt;
}

}  // namespace sweetspot::api
