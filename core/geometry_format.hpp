// Internal helpers for the refusal messages of core's geometry and mass
// properties ("field = value: rule"). Not part of the public API.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace sweetspot::core {

/// Shortest decimal text that reads back as exactly `value` ("0.05", "1e-12",
/// "nan", "inf", "-inf").
std::string FormatNumber(double value);

/// `value` with 17 significant digits ("0.85499999999999998"), as the scene's and the sweet
/// spots' messages write numbers.
std::string FormatNumber17(double value);

/// "field = value: rule", the message format of every IsValid in core: the Message() of
/// NumberRefusal(field, value, rule) (core/refusal.hpp).
std::string RefusalMessage(std::string_view field, double value, std::string_view rule);

/// "prefix[index].member", e.g. IndexedField("knots", 3, "x_m") == "knots[3].x_m".
std::string IndexedField(std::string_view prefix, std::size_t index, std::string_view member);

}  // namespace sweetspot::core
