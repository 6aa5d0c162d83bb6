// A refusal: why core's validation refused an input, as data (the field in core's own names,
// the value, the rule) rather than as text: every validator is `bool Validate(Refusal*) const`.
// Message() writes it the one way users see it ("field = value: rule"); the api maps `field`
// to the request's path with one function (api/json_reader.hpp: CoreRefusal) instead of
// reading the text back.
#pragma once

#include <limits>
#include <string>
#include <string_view>

namespace sweetspot::core {

/// Why an input was refused: "field = shown: rule" as data.
struct Refusal {
  /// The refused field in core's names ("wall_thickness_m", "knots[2].x_m", "ball.mass_kg",
  /// "fill.material.density_kg_m3"); "" when the refusal is about no one field.
  std::string field;
  /// The refused value (problem units); NaN when the refusal quotes no number.
  double value = std::numeric_limits<double>::quiet_NaN();
  /// The value as the message writes it ("0.05", "3", "second-order"); "" when the message
  /// quotes no value ("bat: missing ...").
  std::string shown;
  /// What the field must satisfy ("must be non-negative (0 = solid)").
  std::string rule;

  /// True when the message quotes the field's value ("field = shown: rule").
  bool QuotesValue() const { return !shown.empty(); }
  /// "field = shown: rule"; "field: rule" when no value is quoted; "rule" without a field.
  std::string Message() const;
};

/// A refusal of `field` = `value` (written with FormatNumber, the shortest exact decimal).
Refusal NumberRefusal(std::string_view field, double value, std::string_view rule);
/// A refusal of `field` = `value` written with 17 significant digits (FormatNumber17), as the
/// scene's messages write their numbers.
Refusal Number17Refusal(std::string_view field, double value, std::string_view rule);
/// A refusal of the integer `field` = `value` (written as an integer: "4096", not "4096.0").
Refusal IntegerRefusal(std::string_view field, long long value, std::string_view rule);
/// A refusal quoting a value that is no number, as written (`shown`: a path, a name, "0 and
/// ..."): "field = shown: rule"; value NaN.
Refusal QuotedRefusal(std::string_view field, std::string_view shown, std::string_view rule);
/// A refusal that quotes no value: "field: rule" ("bat: missing ...").
Refusal TextRefusal(std::string_view field, std::string_view rule);

/// `inner` moved under `prefix` ("material." + "density_kg_m3"): the field and so the message
/// gain the prefix; the value and the rule are kept.
Refusal Prefixed(std::string_view prefix, Refusal inner);

/// `inner` with `note` appended to its rule, so that its message ends with the note
/// ("... (model = flexible)"); the field and the value are kept.
Refusal Noted(Refusal inner, std::string_view note);

/// A range's rule written from its bounds, the one way every range is written: "must be in
/// [lo, hi]", or "must be in (lo, hi]" when `lo_open` (the lower bound itself is refused).
std::string RangeRule(double lo, double hi, bool lo_open = false);
/// True when `value` is finite and in [lo, hi] ((lo, hi] when `lo_open`); otherwise refuses
/// `field` = value (NumberRefusal) with RangeRule(lo, hi, lo_open) followed by `note`
/// (" (0 = solid)"), and returns false.
bool CheckInRange(Refusal* out, std::string_view field, double value, double lo, double hi,
                  bool lo_open = false, std::string_view note = {});
/// CheckInRange for an integer: "field = 21: must be in [1, 20]" (IntegerRefusal).
bool CheckIntegerInRange(Refusal* out, std::string_view field, long long value, long long lo,
                         long long hi);

/// Stores `refusal` in *out (if non-null) and returns false: the one way core's validators
/// refuse (`return Refuse(out, NumberRefusal("length_m", length_m, "must be positive"));`).
bool Refuse(Refusal* out, Refusal refusal);
/// Refuse(out, NumberRefusal(field, value, rule)) without formatting when `out` is null.
bool Refuse(Refusal* out, std::string_view field, double value, std::string_view rule);
/// `validate(Refusal*)` run with its refusal's Message() in *why (nothing is formatted when
/// `why` is null): for a caller that shows the refusal as text. Validators themselves have
/// one form, `bool Validate(Refusal*) const`; none writes a string.
template <typename Validate>
bool ExplainRefusal(std::string* why, Validate&& validate) {
  if (why == nullptr) return validate(nullptr);
  Refusal refusal;
  if (validate(&refusal)) return true;
  *why = refusal.Message();
  return false;
}

}  // namespace sweetspot::core
