#include "core/refusal.hpp"

#include <charconv>
#include <utility>

#include "core/geometry_format.hpp"

namespace sweetspot::core {

std::string Refusal::Message() const {
  std::string out = field;
  if (QuotesValue()) {
    out += " = ";
    out += shown;
  }
  if (!rule.empty()) {
    if (!out.empty()) out += ": ";
    out += rule;
  }
  return out;
}

Refusal NumberRefusal(std::string_view field, double value, std::string_view rule) {
  return Refusal{std::string(field), value, FormatNumber(value), std::string(rule)};
}

Refusal Number17Refusal(std::string_view field, double value, std::string_view rule) {
  return Refusal{std::string(field), value, FormatNumber17(value), std::string(rule)};
}

Refusal IntegerRefusal(std::string_view field, long long value, std::string_view rule) {
  return Refusal{std::string(field), static_cast<double>(value), std::to_string(value),
                 std::string(rule)};
}

Refusal QuotedRefusal(std::string_view field, std::string_view shown, std::string_view rule) {
  Refusal out;
  out.field = field;
  out.shown = shown;
  out.rule = rule;
  return out;
}

Refusal TextRefusal(std::string_view field, std::string_view rule) {
  Refusal out;
  out.field = field;
  out.rule = rule;
  return out;
}

Refusal Prefixed(std::string_view prefix, Refusal inner) {
  inner.field.insert(0, prefix);
  return inner;
}

Refusal Noted(Refusal inner, std::string_view note) {
  inner.rule += note;
  return inner;
}

bool Refuse(Refusal* out, Refusal refusal) {
  if (out != nullptr) *out = std::move(refusal);
  return false;
}

bool Refuse(Refusal* out, std::string_view field, double value, std::string_view rule) {
  if (out != nullptr) *out = NumberRefusal(field, value, rule);
  return false;
}

bool RefuseMessage(std::string* why, const Refusal& refusal) {
  if (why != nullptr) *why = refusal.Message();
  return false;
}

bool RefuseMessage(std::string* why, std::string_view field, double value,
                   std::string_view rule) {
  if (why != nullptr) *why = NumberRefusal(field, value, rule).Message();
  return false;
}

bool RefuseMessage(std::string* why, std::string message) {
  if (why != nullptr) *why = std::move(message);
  return false;
}

Refusal RefusalFromMessage(std::string_view message) {
  Refusal out;
  const auto eq = message.find(" = ");
  if (eq == std::string_view::npos) {
    out.rule = message;
    return out;
  }
  out.field = message.substr(0, eq);
  const std::string_view rest = message.substr(eq + 3);
  const auto colon = rest.find(": ");
  out.shown = rest.substr(0, colon);
  double value = 0.0;
  const char* end = out.shown.data() + out.shown.size();
  const auto parsed = std::from_chars(out.shown.data(), end, value);
  if (parsed.ec == std::errc() && parsed.ptr == end) out.value = value;
  if (colon != std::string_view::npos) out.rule = rest.substr(colon + 2);
  return out;
}

}  // namespace sweetspot::core
