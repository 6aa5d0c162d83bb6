// Typed endpoints: a POST endpoint is a parse function (JSON body -> request
// struct, never throws), a core call and a render function (core result ->
// JSON), run by one driver, ServeEndpoint, which owns what every endpoint
// shares: the clock (timing_s), the body's parsing (ParseObjectBody), the
// mapping of a parse error to its response, the failure check before
// rendering, the summary block, the provenance and the 422 "closest" answer.
// An exception is not caught here: it reaches Dispatch, the one place it
// becomes a 500 InternalError.
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "api/error_code.hpp"
#include "api/handlers/handlers.hpp"
#include "api/json_reader.hpp"
#include "api/json_writer.hpp"
#include "api/response.hpp"
#include "api/router.hpp"
#include "api/trade_units.hpp"
#include "core/summary.hpp"

namespace sweetspot::api {

/// What a result's provenance records besides the request body (which it hashes).
struct ProvenanceInputs {
  nlohmann::json options = nlohmann::json::object();  ///< The options the answer used.
  std::optional<unsigned long long> seed;             ///< The random seed, if one was used.
};

/// The provenance inputs most endpoints give: the body's "options" object (or {}), `seed`.
ProvenanceInputs BodyOptions(const nlohmann::json& body,
                             std::optional<unsigned long long> seed = std::nullopt);

/// A usable result that does not meet what was asked (no bat of the family meets the
/// targets): answered 422 {code, message, field, "closest": the rendered answer}.
struct Unmet {
  ErrorCode code = ErrorCode::kInfeasible;  ///< Infeasible or Timeout.
  std::string message;                      ///< Why the targets were not met.
  std::string field;                        ///< The request field that could not be met.
};

/// One typed endpoint: `Req` is the parsed request, `Result` what the core call returns.
/// parse, run and render are required; the others are optional (empty = not used).
template <class Req, class Result>
struct Endpoint {
  /// The body (a JSON object) -> the request; nullopt with *error set on a refusal.
  /// Must not throw (ObjectReader does not).
  std::function<std::optional<Req>(const nlohmann::json& body, const Context& context,
                                   ApiError* error)>
      parse;
  /// The core call(s). Reached only with a parsed request.
  std::function<Result(const Req& request, const Context& context)> run;
  /// The error answer for a result that cannot be rendered (a refusal, a model that
  /// failed, a cancelled run), or nullopt when it can.
  std::function<std::optional<Response>(const Req& request, const Result& result)> failure;
  /// The result as the answer's JSON object (without summary, provenance and timing_s).
  std::function<nlohmann::json(const Req& request, const Result& result)> render;
  /// The same answer written as text (Context::answer_text): the members `render` gives, with
  /// `warnings` after the result's own in "warnings" (as AppendWarnings adds them to render's
  /// tree), written to `out`. Optional: empty = the tree's text.
  std::function<void(const Req& request, const Result& result,
                     const std::vector<std::string>& warnings, TextObject& out)>
      write;
  /// The summary to render as "summary" (SummaryToJson); empty when render writes its own
  /// or the endpoint has none.
  std::function<const core::Summary&(const Result& result)> summary;
  /// The provenance's options and seed; empty = the answer carries no provenance.
  std::function<ProvenanceInputs(const Req& request, const nlohmann::json& body)> provenance;
  /// Whether a rendered result misses its targets (422 with it as "closest").
  std::function<std::optional<Unmet>(const Req& request, const Result& result)> unmet;
  /// Notes on inputs no real bat, ball or swing has (core::SanityWarnings, from the mass
  /// properties the result carries: computed once), appended to the answer's "warnings";
  /// empty = none.
  std::function<std::vector<std::string>(const Req& request, const Result& result)> warnings;
  /// The bat's length, m, for "report_units": "imperial" where the answer states none
  /// (AddImperial's distances from the tip, "*_from_tip_in"); empty = the answer's own.
  std::function<std::optional<double>(const Req& request, const Result& result)> length_m;
};

namespace endpoint_detail {

/// Adds "summary" (when `summary` is set), "provenance" (when `provenance` is set) and
/// "timing_s" (seconds since `start`) to `out`, and answers 200, or 422 with `out` as
/// "closest" when `unmet` is set.
Response Answer(nlohmann::json out, const core::Summary* summary,
                const std::optional<ProvenanceInputs>& provenance, const nlohmann::json& body,
                std::chrono::steady_clock::time_point start, const std::optional<Unmet>& unmet);

/// Adds "summary", "provenance" and "timing_s" to `out` as Answer does.
void AnswerTail(const core::Summary* summary, const std::optional<ProvenanceInputs>& provenance,
                const nlohmann::json& body, std::chrono::steady_clock::time_point start,
                TextObject& out);

}  // namespace endpoint_detail

/// The answer of a request that passed validation under Context::validate_only:
/// 200 {"valid": true}.
inline Response ValidRequest() { return {200, nlohmann::json{{"valid", true}}}; }

/// Parses `request`'s body as a JSON object and then with `parse` (the Endpoint::parse
/// signature); on a refusal nullopt with the error's response in *failure. For handlers
/// that keep their own flow after parsing and whose answer has no quantity to report in
/// other units (/v1/jobs: the job's own request takes "report_units"), so
/// "report_units": "imperial" is refused.
template <class Req, class Parse>
std::optional<Req> ParseRequest(const Request& request, const Context& context, const Parse& parse,
                                Response* failure) {
  std::optional<nlohmann::json> body = ParseObjectBody(request, context, failure);
  if (!body) return std::nullopt;
  ApiError error;
  ReportUnits units = ReportUnits::kSi;
  if (!TakeReportUnits(&*body, &units, &error)) {
    *failure = ToResponse(error);
    return std::nullopt;
  }
  if (units == ReportUnits::kImperial) {
    SetError(&error, ErrorCode::kInvalidValue, "report_units", nullptr,
             "\"imperial\" is not offered by " + request.path +
                 " (its answer has no quantity with a unit; give report_units in the request "
                 "it runs)");
    *failure = ToResponse(error);
    return std::nullopt;
  }
  std::optional<Req> parsed = parse(*body, context, &error);
  if (!parsed) {
    *failure = ToResponse(error);
    ErrorAsWritten(*body, failure);  // a field given in a trade form: named as written
  }
  return parsed;
}

/// Runs `endpoint` on `request`: the body is parsed (400/413 on a refusal, before any core
/// call), the core called, a failure answered as `failure` maps it, and a usable result
/// rendered with its summary, provenance and timing_s (200, or 422 "closest" when unmet).
template <class Req, class Result>
Response ServeEndpoint(const Endpoint<Req, Result>& endpoint, const Request& request,
                       const Context& context) {
  const auto start = std::chrono::steady_clock::now();
  Response refused;
  std::optional<nlohmann::json> body = ParseObjectBody(request, context, &refused);
  if (!body) return refused;
  ApiError error;
  ReportUnits units = ReportUnits::kSi;
  if (!TakeReportUnits(&*body, &units, &error)) return ToResponse(error);
  const std::optional<Req> parsed = endpoint.parse(*body, context, &error);
  if (!parsed) {
    // A field given in a trade form is named as written, with the value as written.
    Response answer = ToResponse(error);
    ErrorAsWritten(*body, &answer);
    return answer;
  }
  if (context.validate_only) return ValidRequest();
  const Result result = endpoint.run(*parsed, context);
  if (endpoint.failure) {
    if (std::optional<Response> failed = endpoint.failure(*parsed, result)) {
      ErrorAsWritten(*body, &*failed);
      return std::move(*failed);
    }
  }
  const core::Summary* summary = endpoint.summary ? &endpoint.summary(result) : nullptr;
  std::optional<ProvenanceInputs> provenance;
  if (endpoint.provenance) provenance = endpoint.provenance(*parsed, *body);
  std::optional<Unmet> unmet;
  if (endpoint.unmet) unmet = endpoint.unmet(*parsed, result);
  std::vector<std::string> warnings;
  if (endpoint.warnings) warnings = endpoint.warnings(*parsed, result);
  if (context.answer_text && endpoint.write && units == ReportUnits::kSi && !unmet) {
    Response answer(200, nullptr);
    static thread_local std::size_t last_bytes = 1024;  // this thread's last text answer's
    answer.json_text.reserve(last_bytes + last_bytes / 4);
    {
      JsonWriter writer(&answer.json_text);
      TextObject out(&writer);
      endpoint.write(*parsed, result, warnings, out);
      endpoint_detail::AnswerTail(summary, provenance, *body, start, out);
    }  // the object closed, its members sorted
    last_bytes = std::min<std::size_t>(answer.json_text.size(), std::size_t{1} << 20);
    return answer;
  }
  nlohmann::json out = endpoint.render(*parsed, result);
  AppendWarnings(warnings, &out);
  if (units == ReportUnits::kImperial) {
    AddImperial(&out, endpoint.length_m ? endpoint.length_m(*parsed, result) : std::nullopt);
  }
  return endpoint_detail::Answer(std::move(out), summary, provenance, *body, start, unmet);
}

}  // namespace sweetspot::api
