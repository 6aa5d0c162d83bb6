#include "core/geometry_format.hpp"

#include <charconv>
#include <cmath>
#include <sstream>

#include "core/refusal.hpp"

namespace sweetspot::core {

std::string FormatNumber(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::string FormatNumber17(double value) {
  std::ostringstream s;
  s.precision(17);
  s << value;
  return s.str();
}

std::string RefusalMessage(std::string_view field, double value, std::string_view rule) {
  return NumberRefusal(field, value, rule).Message();
}

std::string IndexedField(std::string_view prefix, std::size_t index, std::string_view member) {
  std::string out(prefix);
  out += '[';
  out += std::to_string(index);
  out += "].";
  out += member;
  return out;
}

}  // namespace sweetspot::core
