// The OpenAPI 3 document of the service: docs/openapi.json, embedded at build
// time (api/CMakeLists.txt), so the served document is the documented one.
#pragma once

#include <string_view>

namespace sweetspot::api {

/// The text of docs/openapi.json.
std::string_view OpenApiDocumentText();

}  // namespace sweetspot::api
