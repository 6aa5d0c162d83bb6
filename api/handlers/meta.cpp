// Handlers that describe the service: health, version, OpenAPI, metrics,
// and the shared request plumbing (body parsing, provenance).
#include <cstddef>
#include <cstdint>

#include "api/handlers/handlers.hpp"
#include "api/json_text.hpp"
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
  // dump is canonical): dump(-1, ' ', false, replace)'s bytes, hashed as they are written
  // (api/json_text.hpp). An identity key for reproduction, not a security hash.
  std::uint64_t hash = JsonFnv1a64(canonical_input);
  std::string out = "fnv1a64:0000000000000000";  // 16 hex digits, most significant first
  static constexpr char kHex[] = "0123456789abcdef";
  for (std::size_t i = out.size(); hash != 0; hash >>= 4) out[--i] = kHex[hash & 0xf];
  return out;
}

template <class Out>
void WriteProvenance(const nlohmann::json& input, const nlohmann::json& options,
                     std::optional<unsigned long long> seed, Out& out) {
  // The versions are the process's, read once.
  static const std::string sweetspot = core::SweetspotVersion();
  static const std::string eigen = core::EigenVersion();
  static const std::string nlopt = core::NloptVersion();
  static const std::string ipopt = core::IpoptVersion();
  // In key order (the text writer then only checks it).
  out.Set("input_hash", InputHash(input));
  out.Object("libraries", [&](Out& libraries) {
    libraries.Set("eigen", eigen);
    libraries.Set("ipopt", ipopt);
    libraries.Set("nlopt", nlopt);
  });
  out.Set("options", options);
  if (seed) {
    out.Set("seed", *seed);
  } else {
    out.Set("seed", nullptr);
  }
  out.Set("sweetspot_version", sweetspot);
}
template void WriteProvenance(const nlohmann::json&, const nlohmann::json&,
                              std::optional<unsigned long long>, TreeObject&);
template void WriteProvenance(const nlohmann::json&, const nlohmann::json&,
                              std::optional<unsigned long long>, TextObject&);

nlohmann::json Provenance(const nlohmann::json& input, const nlohmann::json& options,
                          std::optional<unsigned long long> seed) {
  return TreeOf([&](TreeObject& out) { WriteProvenance(input, options, seed, out); });
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
