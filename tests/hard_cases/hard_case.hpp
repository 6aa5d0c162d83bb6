// The hard-case tables: each row is {name, input, expected behaviour}. A core row runs a core
// function and reports an Outcome; an endpoint row is a request body sent through the api
// router's Dispatch. Expected behaviours (docs/hard-cases.md):
//   - an exact value (closed form) with a tolerance justified next to the row,
//   - a bounded error against a reference (closed form, long double, or a refined solution),
//   - a bounded range (the model gives no closed form, but the answer must lie in an interval),
//   - a named refusal: core `Validate` false or a Summary termination, with a phrase of the
//     message; api: HTTP status + error `code` + `field`.
// Every endpoint row also checks the invariants of the service: never a 500, never a NaN or an
// infinity anywhere in the body, and a refusal always carries code, message and field.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/summary.hpp"

namespace sweetspot::hard_cases {

inline constexpr long double kNaN = std::numeric_limits<long double>::quiet_NaN();
/// Double-precision unit round-off (2^-52).
inline constexpr double kEps = std::numeric_limits<double>::epsilon();

// ------------------------------------------------------------------------------------ core rows

/// What a core row produced.
struct Outcome {
  /// "converged", "no_convergence", "infeasible", "failure", "invalid_input" (the last also
  /// for a `Validate` that returned false).
  std::string termination;
  std::string message;       ///< The summary's message or the refusal's Message().
  long double value = kNaN;  ///< The quantity under test (NaN when not computed).
};

/// A value computed without a Summary (closed forms): termination "converged".
Outcome Value(long double value);
/// A value with the Summary of the solve that produced it.
Outcome FromSummary(const core::Summary& summary, long double value);
/// A `Validate` refusal: termination "invalid_input", message = its Message().
Outcome Invalid(std::string why);

/// What a core row must produce.
struct Expected {
  enum class Kind { kValue, kRange, kRefusal };
  Kind kind = Kind::kValue;
  /// kValue: the reference value (evaluated when the row runs).
  std::function<long double()> reference;
  long double abs_tolerance = 0;  ///< kValue: |value - reference| <= max(abs, rel |reference|).
  long double rel_tolerance = 0;
  long double lo = 0, hi = 0;  ///< kRange: lo <= value <= hi.
  /// The termination required: a name, or "usable" for converged or no_convergence.
  std::string termination = "converged";
  std::string phrase;  ///< kRefusal: text the message must contain.

  /// The same expectation with another required termination.
  Expected With(std::string required) const;
};

/// An exact (closed-form) value, |value - exact| <= abs_tolerance.
Expected Exactly(long double exact, long double abs_tolerance);
/// A bounded error against a reference evaluated when the row runs:
/// |value - ref| <= max(abs_tolerance, rel_tolerance |ref|).
Expected Reference(std::function<long double()> reference, long double rel_tolerance,
                   long double abs_tolerance = 0);
/// A value in [lo, hi].
Expected Within(long double lo, long double hi);
/// A named refusal: the termination and a phrase of the message.
Expected Refused(std::string termination, std::string phrase);

/// One row of a core table.
struct CoreCase {
  std::string name;              ///< CamelCase, unique in its table (the ctest name).
  std::function<Outcome()> run;  ///< Calls core.
  Expected expected;             ///< What it must produce.
};

/// Asserts that `c` behaves as expected (gtest failures name the row).
void CheckCoreCase(const CoreCase& c);
/// gtest prints rows by name.
void PrintTo(const CoreCase& c, std::ostream* os);

// -------------------------------------------------------------------------------- endpoint rows

/// A check of one number (or string) of a 200 body, by JSON pointer ("/max_exit_speed/...").
struct JsonCheck {
  std::string pointer;
  long double lo = 0, hi = 0;         ///< The number must lie in [lo, hi].
  std::optional<std::string> equals;  ///< Or: the value must be this string.
};
/// |value - expected| <= tolerance.
JsonCheck Near(std::string pointer, long double expected, long double tolerance);
/// lo <= value <= hi.
JsonCheck Between(std::string pointer, long double lo, long double hi);
/// The value is the string `text`.
JsonCheck Is(std::string pointer, std::string text);

/// One row of an endpoint table.
struct ApiCase {
  std::string name;               ///< CamelCase, unique in its table.
  std::string path;               ///< e.g. "/v1/sweet-spot".
  std::string body;               ///< The request body (JSON text).
  int status = 200;               ///< Expected HTTP status.
  std::string code;               ///< Refusals: the error code.
  std::string field;              ///< Refusals: the error field.
  std::vector<JsonCheck> checks;  ///< 2xx: numbers in bounded ranges, strings.
  bool as_job = false;  ///< Also run through POST /v1/jobs: the job's result must be the same.
};

/// A 200 with these checks.
ApiCase Ok(std::string name, std::string path, std::string body, std::vector<JsonCheck> checks);
/// A refusal: status, code and field.
ApiCase Refusal(std::string name, std::string path, std::string body, int status, std::string code,
                std::string field);
/// The same row, also run as a job.
ApiCase AsJob(ApiCase c);

/// Sends `c` through the router (and, for as_job rows, through a job) and asserts its expected
/// behaviour and the invariants (no 500, no NaN/Inf, refusal envelope).
void CheckApiCase(const ApiCase& c);
/// gtest prints rows by name.
void PrintTo(const ApiCase& c, std::ostream* os);

/// Every number in `json` is finite; otherwise false with the path of the first offender.
bool AllFinite(const nlohmann::json& json, std::string* where);

/// A row name as gtest accepts it: '-' (as in 1e-9) becomes "Minus", '.' becomes 'p', any other
/// character that is not a letter, a digit or '_' becomes '_'.
std::string SafeName(const std::string& name);

/// The name gtest shows for a row.
template <typename Row>
std::string RowName(const testing::TestParamInfo<Row>& info) {
  return SafeName(info.param.name);
}

}  // namespace sweetspot::hard_cases
