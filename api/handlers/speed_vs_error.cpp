// GET /v1/speed-vs-error: the speed-versus-error report (docs/speed-vs-error.json, written by
// scripts/speed-vs-error.sh and embedded at build time), and its date for /v1/version.
#include "api/handlers/handlers.hpp"
#include "api/speed_vs_error_document.hpp"

namespace sweetspot::api {
namespace {

// The embedded report, parsed once (CMake checked that it is JSON; a placeholder when the file
// was missing at build time).
const nlohmann::json& SpeedVsErrorReport() {
  static const nlohmann::json report =
      nlohmann::json::parse(SpeedVsErrorDocumentText(), nullptr, /*allow_exceptions=*/false);
  return report;
}

}  // namespace

Response HandleSpeedVsError(const Request&, const Context&) { return {200, SpeedVsErrorReport()}; }

nlohmann::json SpeedVsErrorGenerated() {
  const nlohmann::json& report = SpeedVsErrorReport();
  if (!report.is_object() || !report.contains("metadata")) return nullptr;
  const nlohmann::json& metadata = report["metadata"];
  if (!metadata.is_object() || !metadata.contains("generated")) return nullptr;
  const nlohmann::json& generated = metadata["generated"];
  return generated.is_string() ? generated : nlohmann::json(nullptr);
}

}  // namespace sweetspot::api
