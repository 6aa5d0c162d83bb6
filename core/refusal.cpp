#include "core/refusal.hpp"

#include <cmath>
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

std::string RangeRule(double lo, double hi, bool lo_open) {
  return std::string("must be in ") + (lo_open ? "(" : "[") + FormatNumber(lo) + ", " +
         FormatNumber(hi) + "]";
}

bool CheckInRange(Refusal* out, std::string_view field, double value, double lo, double hi,
                  bool lo_open, std::string_view note) {
  if (std::isfinite(value) && (lo_open ? value > lo : value >= lo) && value <= hi) return true;
  if (out == nullptr) return false;
  return Refuse(out, NumberRefusal(field, value, RangeRule(lo, hi, lo_open) + std::string(note)));
}

bool CheckIntegerInRange(Refusal* out, std::string_view field, long long value, long long lo,
                         long long hi) {
  if (value >= lo && value <= hi) return true;
  if (out == nullptr) return false;
  return Refuse(
      out, IntegerRefusal(field, value,
                          "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]"));
}

bool Refuse(Refusal* out, Refusal refusal) {
  if (out != nullptr) *out = std::move(refusal);
  return false;
}

bool Refuse(Refusal* out, std::string_view field, double value, std::string_view rule) {
  if (out != nullptr) *out = NumberRefusal(field, value, rule);
  return false;
}

}  // namespace sweetspot::core
