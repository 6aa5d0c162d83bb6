// JSON text without nlohmann's character-at-a-time output: a value written exactly as
// nlohmann's compact dump writes it (dump(-1, ' ', false, replace)), appended to a string or
// hashed (FNV-1a 64) as it is written. Used for every answer's text (server/) and for the
// provenance's input hash (api/handlers/meta.cpp).
#pragma once

#include <cstdint>
#include <string>

#include <nlohmann/json.hpp>

namespace sweetspot::api {

/// `value` appended to *out exactly as nlohmann's dump(-1, ' ', false, replace) writes it
/// (invalid UTF-8 replaced): objects, arrays, numbers and printable ASCII strings are written
/// here through a small buffer, other strings by nlohmann's escaping.
void AppendJson(const nlohmann::json& value, std::string* out);

/// FNV-1a 64 of the bytes AppendJson writes for `value` (the string is never held whole).
std::uint64_t JsonFnv1a64(const nlohmann::json& value);

}  // namespace sweetspot::api
