// Strict JSON reading: a depth-limited parser that never throws, and a field
// reader that checks types, ranges, required and unknown fields, and reports
// the first problem as an ApiError naming the field, the value and the rule.
#pragma once

#include <boost/container/small_vector.hpp>
#include <nlohmann/json.hpp>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "api/error_code.hpp"
#include "api/limits.hpp"
#include "api/response.hpp"
#include "core/refusal.hpp"
#include "core/summary.hpp"

namespace sweetspot::api {

/// A client error (or, with status 500, an internal one) in the contract's envelope.
struct ApiError {
  int status = 400;               ///< HTTP status (usually ErrorCodeStatus(*code)).
  std::optional<ErrorCode> code;  ///< The error's code; nullopt = no error recorded yet.
  std::string message;            ///< Names the field, the value and the rule.
  std::string field;              ///< Dotted path of the field ("" = none).
};

/// The envelope {"code", "message", "field"} with the error's status.
Response ToResponse(const ApiError& error);

/// Parses `body` as one JSON value. Refuses (never throws): invalid JSON
/// (InvalidJson, with the parser's position), nesting deeper than
/// limits.max_json_depth (TooBig), arrays longer than max_array_length and
/// strings longer than max_string_length (TooBig), numbers out of double range
/// (InvalidValue). An empty body is read as {}. A body in JSON's plain subset is read by
/// ReadPlainBody, anything else by nlohmann's parser (ParseBodyWithNlohmann): the same tree.
std::optional<nlohmann::json> ParseBody(std::string_view body, const ApiLimits& limits,
                                        ApiError* error);

/// ParseBody with nlohmann's parser alone: the reference ReadPlainBody is tested against (and
/// what ParseBody falls back to).
std::optional<nlohmann::json> ParseBodyWithNlohmann(std::string_view body, const ApiLimits& limits,
                                                    ApiError* error);

/// `body` read into *out without nlohmann's lexer when it keeps to JSON's plain subset:
/// strings of printable ASCII without escapes, numbers a 64-bit integer or a finite double
/// holds, within `limits`' depth, array and string lengths. True with *out the tree nlohmann's
/// parser builds; false (*out untouched) for anything else, valid or not
/// (api/json_plain_body.cpp).
bool ReadPlainBody(std::string_view body, const ApiLimits& limits, nlohmann::json* out);

/// A numeric rule: the closed or open interval a value must lie in.
struct NumberRule {
  double min = -1e300;         ///< Lower bound.
  double max = 1e300;          ///< Upper bound.
  bool min_exclusive = false;  ///< True: value must be > min.
  bool max_exclusive = false;  ///< True: value must be < max.
  bool integer = false;        ///< True: value must be an integer.

  /// "must be > 0", "must be in [0, 1]", ... ; empty when unbounded.
  std::string Describe() const;
  /// True when `value` satisfies the rule.
  bool Accepts(double value) const;
};

/// Any finite number: the type only, for a field whose range core checks.
NumberRule AnyNumber();
/// A value > 0 with an optional upper bound.
NumberRule Positive(double max = 1e300);
/// A value >= 0 with an optional upper bound.
NumberRule NonNegative(double max = 1e300);
/// A value in [min, max].
NumberRule Between(double min, double max);
/// An integer in [min, max].
NumberRule IntegerBetween(double min, double max);

/// Formats a JSON value for an error message (compact, strings quoted, long values cut).
std::string Show(const nlohmann::json& value);
/// Joins a parent path and a key: ("bat", "material") -> "bat.material".
std::string JoinPath(std::string_view parent, std::string_view key);

/// The name of `names` that `written` is one typo away from (two for names of 6 characters
/// or more; a typo: a character added, dropped, changed, or two neighbours swapped), or ""
/// when none is: the "did you mean" of an unknown field.
std::string NearestName(std::string_view written, const std::vector<std::string>& names);

/// Reads one JSON object field by field. The first problem is recorded in
/// *error; later calls then do nothing and return false/nullopt. Finish()
/// refuses any field that was not read (a typo must not fall back silently).
class ObjectReader {
 public:
  /// `path` is where `value` sits in the request ("" for the body itself).
  ObjectReader(const nlohmann::json& value, std::string path, ApiError* error);

  /// True while no error has been recorded (by this reader or another).
  bool ok() const { return !error_->code.has_value(); }
  /// The error this reader records into (share it with sub-readers).
  ApiError* error() const { return error_; }
  /// The path of `key` in this object.
  std::string PathOf(std::string_view key) const { return JoinPath(path_, key); }
  /// True when the object has `key` (marks it as known).
  bool Has(std::string_view key);
  /// The raw value of `key` (marks it as known), or nullptr.
  const nlohmann::json* Get(std::string_view key);

  /// The value of SI field `key` or of one of its trade spellings (TradeForms: "length_in",
  /// "barrel_diameter_in", "mass_oz", ...; marks the one given as known), with the name it was
  /// given as (a view of `key` or of the object's own key: valid while both are) and the
  /// factor to SI; nullptr when none is given, or (recording the error) when two forms are.
  const nlohmann::json* GetInUnits(std::string_view key, std::string_view* given_as, double* to_si);
  /// True when `key` or one of its trade spellings is given.
  bool HasInUnits(std::string_view key) const;
  /// A required number obeying `rule` (in SI; `key` may be given in a trade unit, see
  /// GetInUnits).
  bool Number(std::string_view key, const NumberRule& rule, double* out);
  /// An optional number obeying `rule` (in SI; `key` may be given in a trade unit, converted
  /// here); `*out` untouched when absent.
  bool OptionalNumber(std::string_view key, const NumberRule& rule, double* out);
  /// An optional number; nullopt when absent or invalid (check ok()).
  std::optional<double> MaybeNumber(std::string_view key, const NumberRule& rule);
  /// An optional integer in [min, max]; `*out` untouched when absent.
  bool OptionalInteger(std::string_view key, long long min, long long max, long long* out);
  /// An optional integer that fits an int, for a field whose range core checks; `*out`
  /// untouched when absent.
  bool OptionalInt(std::string_view key, int* out);
  /// A required string; if `allowed` is non-empty it must be one of them.
  bool String(std::string_view key, std::string* out, const std::vector<std::string>& allowed = {});
  /// An optional string; `*out` untouched when absent.
  bool OptionalString(std::string_view key, std::string* out,
                      const std::vector<std::string>& allowed = {});
  /// An optional boolean; `*out` untouched when absent.
  bool OptionalBool(std::string_view key, bool* out);
  /// Marks `key` as read without reading it (the caller reads it itself).
  void Skip(std::string_view key) { Mark(key); }
  /// Records an error about `key` with `rule`, quoting its value.
  bool Fail(std::string_view key, const std::string& rule,
            ErrorCode code = ErrorCode::kInvalidValue);
  /// Records MissingField for `key`.
  bool Missing(std::string_view key);
  /// Refuses unread fields (UnknownField, listing the known ones). Returns ok().
  bool Finish();

 private:
  const nlohmann::json* value_;
  std::string path_;
  ApiError* error_;
  // The object's members in its (sorted) order, each with whether a call has asked for it:
  // Finish refuses the rest. Built once, so that a field is found by a short scan of the few
  // keys given instead of a map lookup, and asking for an absent field allocates nothing.
  struct Member {
    std::string_view key;         // the member's name (the object's own string)
    const nlohmann::json* value;  // its value
    bool asked = false;           // a call asked for it
  };
  // In the reader itself for up to 12 members (a request's objects have a few): reading a
  // request allocates nothing for them.
  boost::container::small_vector<Member, 12> members_;
  // Every name asked for, each followed by '\0', in the order asked (repeats included): the
  // "known" list and the "did you mean" of an unknown-field error, sorted and made unique only
  // then. One buffer instead of a set node per name, in the reader itself while the names fit
  // (a scene object asks for some 20).
  boost::container::small_vector<char, 448> asked_;
  // Records that `key` was asked for: appends it to asked_, marks its member and returns it
  // (nullptr when the object has none).
  const Member* Mark(std::string_view key);
  // The member named `key`, or nullptr.
  const Member* Find(std::string_view key) const;
  // The names in asked_, sorted and unique.
  std::vector<std::string> AskedNames() const;
  // Whether some key of the object is a trade spelling (SiFormsOf): -1 until first needed.
  // Without one, no field's TradeForms need be built and looked up.
  mutable int has_trade_spelling_ = -1;
  bool HasTradeSpelling() const;
};

/// The request's name of a core field: core's name except where the request names it
/// otherwise (the one table: "hertz.paper.k3" -> "hertz.paper_constants.k3").
std::string RequestName(std::string_view core_field);

/// The request path of a core refusal's field under `prefix` (e.g. "bat"):
/// prefix.RequestName(field) ("bat.wall_thickness_m"), or `prefix` itself when the refusal
/// names no field.
std::string RequestField(const core::Refusal& refusal, std::string_view prefix);

/// The message of a core refusal in the request's names: Message() with the field renamed
/// by RequestName (no prefix added).
std::string RequestMessage(const core::Refusal& refusal);

/// Records a core refusal as an InvalidValue error (400): the field is RequestField(refusal,
/// prefix), the message core's Message() under `prefix` ("bat.wall_thickness_m = -1: ...";
/// "options: <message>" when the refusal names no field). The one mapping from core's field
/// names to the request's. Returns false.
bool CoreRefusal(const core::Refusal& refusal, const std::string& prefix, ApiError* error);

/// CoreRefusal for a solve that refused its input: the summary's refusal (core::Summary::
/// refusal); a summary without one is reported with its message under `prefix`, the field
/// `prefix`.
bool CoreRefusal(const core::Summary& summary, const std::string& prefix, ApiError* error);

/// True when a core refusal's field names a part of the scene (bat, ball, swing, cor, outputs,
/// inertia_model) rather than of the computation's options: such fields sit at the top level
/// of a request, the others under its "options" object.
bool IsSceneField(std::string_view core_field);

/// Records an error at `path` ("field = value: rule") unless one is recorded,
/// with the code's status (ErrorCodeStatus).
bool SetError(ApiError* error, ErrorCode code, const std::string& path, const nlohmann::json* value,
              const std::string& rule);

}  // namespace sweetspot::api
