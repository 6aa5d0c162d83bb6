// The speed-versus-error report: docs/speed-vs-error.json (written by
// scripts/speed-vs-error.sh), embedded at build time (api/CMakeLists.txt), so the
// served data is the committed report.
#pragma once

#include <string_view>

namespace sweetspot::api {

/// The text of docs/speed-vs-error.json: {"metadata", "models", "rows", "skipped"}; each row's
/// time_per_eval_s is in s, error in its error_unit, relative_error dimensionless.
std::string_view SpeedVsErrorDocumentText();

}  // namespace sweetspot::api
