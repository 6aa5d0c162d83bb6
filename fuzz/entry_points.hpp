// The fuzzing entry points, shared by the libFuzzer targets (fuzz/fuzzer.cpp)
// and by the regression test that replays fuzz/regressions/ in the normal
// build (tests/api/fuzz_regressions_test.cpp). Header-only so that the test
// links nothing from fuzz/.
//
// Each Run...() feeds one input to the api layer and checks the contract on
// what comes back, returning a Verdict: a broken rule (always a bug), or a
// note (a handler answered a deliberate 500: a bug in strict mode). A crash, a
// sanitizer report or an escaping exception is reported by the caller
// (libFuzzer, or the test).
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include "api/bat_json.hpp"
#include "api/json_reader.hpp"
#include "api/limits.hpp"
#include "api/router.hpp"
#include "core/bat/mass_properties.hpp"

namespace sweetspot::fuzz {

/// Request limits that keep the work of one input to milliseconds: few
/// samples, variants, iterations and little solver time.
inline api::ApiLimits FuzzLimits() {
  api::ApiLimits limits;
  limits.max_json_depth = 16;
  limits.max_array_length = 256;
  limits.max_string_length = 128;
  limits.max_knots = 32;
  limits.max_variants = 3;
  limits.max_curve_samples = 64;
  limits.max_samples = 8;
  limits.max_iterations = 200;
  limits.max_time_s = 0.05;
  limits.max_integration_steps = 200000;
  limits.max_launches = 8;
  return limits;
}

/// The context the handlers see while fuzzing: FuzzLimits(), and no server
/// (no job manager, no metrics: those routes answer 501).
inline api::Context FuzzContext() {
  api::Context context;
  context.limits = FuzzLimits();
  return context;
}

/// A POST endpoint the dispatch target reaches, with the input byte that selects it.
struct FuzzRoute {
  char key;          ///< First input byte that selects the route.
  const char* path;  ///< The endpoint (method POST).
};

/// The POST endpoints of the dispatch target, by selector byte. A test checks
/// that every POST route of api::Routes() is here.
inline const std::vector<FuzzRoute>& PostRoutes() {
  static const std::vector<FuzzRoute> routes = {
      {'p', "/v1/bat/properties"}, {'f', "/v1/bat/fit"}, {'s', "/v1/sweet-spot"},
      {'c', "/v1/collision"},      {'m', "/v1/compare"}, {'o', "/v1/optimize"},
      {'x', "/v1/explore"},        {'j', "/v1/jobs"},    {'b', "/v1/bat/modes"},
      {'l', "/v1/flight"},
  };
  return routes;
}

/// The selector byte of the dispatch target's "raw" mode: the input then reads
/// "METHOD PATH\nBODY", which reaches every route (GET, DELETE, unknown paths).
inline constexpr char kRawKey = 'r';

/// The Hertz step budget above which an input is skipped: api::ApiLimits does
/// not bound "max_steps" (up to 1e7 per impact), so one input could run for
/// minutes. Remove once the limits bound it.
inline constexpr double kMaxHertzSteps = 5000;

/// What one input did.
struct Verdict {
  std::string problem;  ///< A broken contract rule ("" = none): always a bug.
  std::string note;     ///< A handler's deliberate 500 ("" = none): a bug in strict mode.

  /// True when neither a problem nor a note was recorded.
  bool Clean() const { return problem.empty() && note.empty(); }
};

namespace internal {

// "" when no number in `value` is NaN or infinite; else the JSON pointer of one.
inline std::string FindNonFinite(const nlohmann::json& value, const std::string& where) {
  if (value.is_number_float()) {
    return std::isfinite(value.get<double>()) ? std::string() : (where.empty() ? "/" : where);
  }
  if (value.is_object()) {
    for (const auto& [key, item] : value.items()) {
      std::string found = FindNonFinite(item, where + "/" + key);
      if (!found.empty()) return found;
    }
  } else if (value.is_array()) {
    for (std::size_t i = 0; i < value.size(); ++i) {
      std::string found = FindNonFinite(value[i], where + "/" + std::to_string(i));
      if (!found.empty()) return found;
    }
  }
  return {};
}

// Deepest nesting of arrays and objects in `value` (a scalar is 0).
inline int Depth(const nlohmann::json& value) {
  int deepest = 0;
  if (value.is_structured()) {
    for (const auto& item : value) deepest = std::max(deepest, Depth(item));
    return deepest + 1;
  }
  return 0;
}

// True when `a` and `b` have the same types throughout (nlohmann's == takes 1, 1u and 1.0 as
// equal; the tree's types reach the answer's bytes).
inline bool SameTypes(const nlohmann::json& a, const nlohmann::json& b) {
  if (a.type() != b.type()) return false;
  if (a.is_object()) {
    for (auto it = a.begin(), jt = b.begin(); it != a.end(); ++it, ++jt) {
      if (it.key() != jt.key() || !SameTypes(*it, *jt)) return false;
    }
  } else if (a.is_array()) {
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (!SameTypes(a[i], b[i])) return false;
    }
  }
  return true;
}

// Compact text of `value` for a problem report (cut to 300 bytes).
inline std::string Excerpt(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > 300) text = text.substr(0, 300) + "...";
  return text;
}

// True when `value` holds a "max_steps" over kMaxHertzSteps at any depth.
inline bool HasManySteps(const nlohmann::json& value) {
  if (value.is_object()) {
    for (auto it = value.begin(); it != value.end(); ++it) {
      if (it.key() == "max_steps" && it->is_number() && it->get<double>() > kMaxHertzSteps) {
        return true;
      }
      if (HasManySteps(*it)) return true;
    }
  } else if (value.is_array()) {
    for (const auto& item : value) {
      if (HasManySteps(item)) return true;
    }
  }
  return false;
}

// True when `body` asks for more Hertz steps than kMaxHertzSteps anywhere.
inline bool OverStepBudget(std::string_view body) {
  if (body.find("max_steps") == std::string_view::npos &&
      body.find("\\u") == std::string_view::npos) {  // a key may be written with \u escapes
    return false;
  }
  api::ApiError error;
  const auto value = api::ParseBody(body, FuzzLimits(), &error);  // depth-limited
  return value.has_value() && HasManySteps(*value);
}

}  // namespace internal

/// Checks a handler's answer against the contract: a 2xx, 4xx or 501 status,
/// a JSON object body without NaN or Infinity that serialises, and for errors
/// the envelope {"code", "message", "field"}. A 500 the handler chose (a core
/// failure) is a note; any other status is a problem.
inline Verdict CheckResponse(const api::Response& response) {
  const std::string status = "status " + std::to_string(response.status);
  if (response.status < 200 || response.status > 501) {
    return {status + " (contract: 2xx, 4xx or 501): " + internal::Excerpt(response.body), ""};
  }
  if (!response.content_type.empty()) return {};  // text (Prometheus, NDJSON): no JSON rules
  if (!response.body.is_object()) {
    return {status + ": the body is not a JSON object: " + internal::Excerpt(response.body), ""};
  }
  if (const std::string where = internal::FindNonFinite(response.body, ""); !where.empty()) {
    return {status + ": NaN or Infinity at " + where +
                " (would be sent as null): " + internal::Excerpt(response.body),
            ""};
  }
  // The server sends dump(..., replace); that must never throw.
  (void)response.body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (response.status >= 400) {
    const auto& body = response.body;
    const bool envelope = body.contains("code") && body["code"].is_string() &&
                          !body["code"].get<std::string>().empty() && body.contains("message") &&
                          body["message"].is_string() && body.contains("field") &&
                          (body["field"].is_null() || body["field"].is_string());
    if (!envelope) {
      return {
          status + ": not the error envelope {code, message, field}: " + internal::Excerpt(body),
          ""};
    }
  }
  if (response.status == 500) {
    return {"", status + " (a client's input must get a 4xx): " + internal::Excerpt(response.body)};
  }
  return {};
}

/// Target parse_body: api::ParseBody on the raw input. Checks that it either
/// refuses with a 400/413 error or returns a value within the limits that
/// survives dump() and parses back to itself.
inline Verdict RunParseBody(std::string_view input) {
  const api::ApiLimits limits = FuzzLimits();
  api::ApiError error;
  const auto value = api::ParseBody(input, limits, &error);
  // ParseBody's plain reader (api/json_plain_body.cpp) answers as nlohmann's parser alone does.
  api::ApiError reference_error;
  const auto reference = api::ParseBodyWithNlohmann(input, limits, &reference_error);
  if (value.has_value() != reference.has_value() ||
      (value && (*value != *reference || !internal::SameTypes(*value, *reference))) ||
      (!value &&
       (error.message != reference_error.message || error.status != reference_error.status))) {
    return {"ParseBody and ParseBodyWithNlohmann differ", ""};
  }
  if (!value) {
    if (!error.code) return {"ParseBody refused without an error code", ""};
    if (error.status != 400 && error.status != 413) {
      return {"ParseBody refused with status " + std::to_string(error.status), ""};
    }
    return {};
  }
  if (error.code) {
    return {
        "ParseBody returned a value and the error " + std::string(api::ErrorCodeName(*error.code)),
        ""};
  }
  if (internal::Depth(*value) > limits.max_json_depth) {
    return {"ParseBody accepted depth " + std::to_string(internal::Depth(*value)) +
                " over max_json_depth = " + std::to_string(limits.max_json_depth),
            ""};
  }
  if (const std::string where = internal::FindNonFinite(*value, ""); !where.empty()) {
    return {"ParseBody accepted a non-finite number at " + where, ""};
  }
  // The parser validates UTF-8, so a strict dump() must work and round-trip.
  const std::string text = value->dump();
  api::ApiError again_error;
  const auto again = api::ParseBody(text, limits, &again_error);
  if (!again) {
    return {"ParseBody refused its own dump() (" + again_error.message + "): " + text, ""};
  }
  if (*again != *value) return {"dump() did not round-trip: " + text, ""};
  return {};
}

/// Target parse_bat: the input is a JSON bat object (the value of "bat");
/// api::ParseBat either refuses it or returns a valid bat whose mass
/// properties are finite and physical (mass > 0, balance point on the bat).
inline Verdict RunParseBat(std::string_view input) {
  const api::ApiLimits limits = FuzzLimits();
  api::ApiError error;
  const auto value = api::ParseBody(input, limits, &error);
  if (!value) return {};
  const auto spec = api::ParseBat(*value, "bat", limits, &error);
  if (!spec) {
    if (!error.code) return {"ParseBat refused without an error code", ""};
    if (error.status != 400 && error.status != 413) {
      return {"ParseBat refused with status " + std::to_string(error.status), ""};
    }
    return {};
  }
  if (error.code) {
    return {"ParseBat returned a bat and the error " + std::string(api::ErrorCodeName(*error.code)),
            ""};
  }
  if (core::Refusal why; !spec->bat.Validate(&why))
    return {"ParseBat returned an invalid bat: " + why.Message(), ""};
  const double length = spec->bat.LengthM();
  for (const core::InertiaModel model :
       {core::InertiaModel::kRigidBody, core::InertiaModel::kSlenderRod}) {
    const core::MassProperties p = core::ComputeMassProperties(spec->bat, model);
    const nlohmann::json json = api::PropertiesToJson(p, length, 0.1524);
    const std::string where = internal::FindNonFinite(json, "");
    if (!where.empty() || !(p.mass_kg > 0) || !(p.volume_m3 > 0) || !(p.moi_centroid_kg_m2 >= 0) ||
        !(p.balance_point_m >= 0) || !(p.balance_point_m <= length * (1 + 1e-9))) {
      return {"a valid bat has non-finite or unphysical mass properties " +
                  internal::Excerpt(json) + " for " + internal::Excerpt(*value),
              ""};
    }
  }
  (void)api::BatToJson(spec->bat).dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return {};
}

/// Classifies {method, path, body} as the server does, then sends it to the
/// route that matches, calling its handler
/// directly (so an unexpected exception escapes to the caller with its
/// origin) or, for no route, api::Dispatch (404/405); checks the answer.
/// Skips (clean verdict) bodies over the fuzzing budget (kMaxHertzSteps).
inline Verdict RunRequest(const api::Request& request) {
  if (internal::OverStepBudget(request.body)) return {};
  const api::Context context = FuzzContext();
  // The server classifies every request before a handler sees it: it must
  // take any bytes (ClassifyWorkload never throws; a crash is reported).
  (void)api::ClassifyWorkload(request.method, request.path, request.body, context);
  api::Response response;
  bool routed = false;
  for (const api::Route* route : api::MatchRoutes(request.path)) {
    if (route->method != request.method) continue;
    response = route->handler(request, context);
    routed = true;
    break;
  }
  if (!routed) response = api::Dispatch(request, context);
  Verdict verdict = CheckResponse(response);
  const std::string where = request.method + " " + request.path + ": ";
  if (!verdict.problem.empty()) verdict.problem = where + verdict.problem;
  if (!verdict.note.empty()) verdict.note = where + verdict.note;
  return verdict;
}

/// Target <endpoint> (sweet_spot, collision, ...): the input is the body of a
/// POST to `path`.
inline Verdict RunPost(std::string_view path, std::string_view input) {
  return RunRequest({"POST", std::string(path), std::string(input)});
}

/// Target dispatch: the first byte selects a POST endpoint (PostRoutes(); any
/// other byte by its value modulo the count) or the raw mode (kRawKey: "METHOD
/// PATH\n" then the body); the rest is the body.
inline Verdict RunDispatch(std::string_view input) {
  if (input.empty()) return {};
  const auto& routes = PostRoutes();
  const char key = input.front();
  input.remove_prefix(1);
  std::size_t index = routes.size();
  for (std::size_t i = 0; i < routes.size(); ++i) {
    if (routes[i].key == key) index = i;
  }
  if (index == routes.size() && key != kRawKey) {
    index = static_cast<unsigned char>(key) % (routes.size() + 1);
  }
  if (index < routes.size()) return RunPost(routes[index].path, input);
  // Raw mode: "METHOD PATH\nBODY" (no newline: all of it is the request line).
  const std::string_view line = input.substr(0, input.find('\n'));
  const std::string_view body =
      line.size() < input.size() ? input.substr(line.size() + 1) : std::string_view();
  const auto space = line.find(' ');
  const std::string_view method = space == std::string_view::npos ? line : line.substr(0, space);
  const std::string_view path =
      space == std::string_view::npos ? std::string_view() : line.substr(space + 1);
  return RunRequest({std::string(method), std::string(path), std::string(body)});
}

/// A fuzz target: its name, as fuzz/corpus/<name> and fuzz/regressions/<name>
/// name it, and its entry point.
struct Target {
  const char* name;                  ///< Directory name under fuzz/corpus, fuzz/regressions.
  Verdict (*run)(std::string_view);  ///< Its entry point.
};

/// Every target, in a stable order: parse_body, parse_bat, dispatch, and one
/// per heavy endpoint.
inline const std::vector<Target>& Targets() {
  static const std::vector<Target> targets = {
      {"parse_body", RunParseBody},
      {"parse_bat", RunParseBat},
      {"dispatch", RunDispatch},
      {"bat_fit", [](std::string_view in) { return RunPost("/v1/bat/fit", in); }},
      {"sweet_spot", [](std::string_view in) { return RunPost("/v1/sweet-spot", in); }},
      {"collision", [](std::string_view in) { return RunPost("/v1/collision", in); }},
      {"compare", [](std::string_view in) { return RunPost("/v1/compare", in); }},
      {"explore", [](std::string_view in) { return RunPost("/v1/explore", in); }},
      {"flight", [](std::string_view in) { return RunPost("/v1/flight", in); }},
  };
  return targets;
}

}  // namespace sweetspot::fuzz
