// Parsing a flight sweep (flight_sweep_internal.hpp): the template, a list of launches or the
// swept paths, and the checks every flight sweep shares.
#include "api/explore/flight_sweep_internal.hpp"

#include <string>
#include <utility>

#include "api/error_code.hpp"

namespace sweetspot::api::flight_sweep {
namespace {

using Json = nlohmann::json;

// Prefixes an error of the template's parser with "flight.": an error naming a field states it
// first (SetError and CoreRefusal write "field = value: rule"), so both gain the prefix.
void PrefixFlight(ApiError* error) {
  if (error->field.empty()) return;
  error->message = "flight." + error->message;
  error->field = "flight." + error->field;
}

bool ParseSweptTemplate(ObjectReader& reader, std::size_t limit, const char* limit_name,
                        FlightSweep* out, std::string* format, ApiError* error);
std::optional<FlightSweep> Finish(FlightSweep sweep, const Context& context,
                                  const std::string& format, ApiError* error);

// The "parameters", "sampling", "samples", "seed" and "format" of a swept template.
bool ParseSweptTemplate(ObjectReader& reader, std::size_t limit, const char* limit_name,
                        FlightSweep* out, std::string* format, ApiError* error) {
  FlightSweep& sweep = *out;
  std::string sampling = "grid";
  reader.OptionalString("sampling", &sampling, {"grid", "lhs", "sobol"});
  if (!reader.ok()) return false;
  sweep.plan.method = *core::ParseSamplingMethod(sampling);
  long long samples = 0, seed = 0;
  reader.OptionalInteger(
      "samples", 1, static_cast<long long>(std::min<std::size_t>(limit, 1ULL << 53)), &samples);
  reader.OptionalInteger("seed", 0, 1LL << 53, &seed);
  sweep.plan.samples = static_cast<std::uint64_t>(samples);
  sweep.plan.seed = static_cast<std::uint64_t>(seed);
  if (reader.ok() && sweep.plan.method != core::SamplingMethod::kGrid && samples == 0) {
    reader.Missing("samples");
  }
  *format = "json";  // as a bat sweep's
  reader.OptionalString("format", format, {"json", "csv"});
  const Json* params = reader.Get("parameters");
  if (reader.ok() && params == nullptr) reader.Missing("parameters");
  if (!reader.ok()) return false;
  if (!params->is_array() || params->empty() || params->size() > 32) {
    reader.Fail("parameters", "must be an array of 1 to 32 {\"path\", \"min\", \"max\"}");
    return false;
  }
  bool swept[12] = {};
  for (std::size_t i = 0; i < params->size(); ++i) {
    const std::string where = "parameters[" + std::to_string(i) + "]";
    if (!(*params)[i].is_object()) {
      SetError(error, ErrorCode::kInvalidValue, where, &(*params)[i],
               "must be an object {\"path\", \"min\", \"max\"}");
      return false;
    }
    ObjectReader p((*params)[i], where, error);
    std::string path;
    core::SweepDimension dimension;
    NumberRule finite;
    finite.min = -1e12;
    finite.max = 1e12;
    p.String("path", &path);
    p.Number("min", finite, &dimension.min);
    p.Number("max", finite, &dimension.max);
    long long count = sweep.plan.method == core::SamplingMethod::kGrid ? 2 : 1;
    p.OptionalInteger("count", 1, 1000000000, &count);  // the total is checked below
    dimension.count = static_cast<int>(count);
    if (!p.Finish()) return false;
    const PathSpec* spec = FindPath(path);
    if (spec == nullptr) {
      std::string known;
      for (const PathSpec& s : kPaths) known += (known.empty() ? "" : ", ") + std::string(s.path);
      SetError(error, ErrorCode::kInvalidValue, where + ".path", &(*params)[i]["path"],
               "is not a field a flight sweep can sweep (one of: " + known + ")");
      return false;
    }
    if (swept[static_cast<int>(spec->target)]) {
      SetError(error, ErrorCode::kInvalidValue, where + ".path", &(*params)[i]["path"],
               "sweeps a quantity another parameter already sweeps");
      return false;
    }
    swept[static_cast<int>(spec->target)] = true;
    if (dimension.max < dimension.min) {
      SetError(error, ErrorCode::kInvalidValue, where + ".max", &(*params)[i]["max"],
               "must be >= min");
      return false;
    }
    sweep.paths.push_back(path);
    sweep.specs.push_back(spec);
    sweep.plan.dimensions.push_back(dimension);
  }
  // Both spins or neither (Launch::Validate): one swept spin needs the other in the template.
  const bool back = swept[static_cast<int>(Target::kBackspin)];
  const bool side = swept[static_cast<int>(Target::kSidespin)];
  if (back != side && !sweep.base.launches.front().backspin_rpm) {
    SetError(error, ErrorCode::kInvalidValue, "flight.launch", nullptr,
             std::string("gives no spin, and the sweep sets only ") +
                 (back ? "backspin_rpm" : "sidespin_rpm") +
                 ": give both spins in the launch, or sweep both");
    return false;
  }
  if (!reader.Finish()) return false;
  if (core::Refusal refusal; !sweep.plan.Validate(&refusal)) {
    CoreRefusal(refusal, "", error);
    return false;
  }
  sweep.total = sweep.plan.DesignCount();
  if (sweep.total > limit) {
    SetError(error, ErrorCode::kTooBig, "parameters", nullptr,
             "describe " + std::to_string(sweep.total) + " launches, over the limit " + limit_name +
                 " = " + std::to_string(limit));
    return false;
  }
  return true;
}

// The checks and settings every flight sweep shares: the size of a JSON answer, the threads.
std::optional<FlightSweep> Finish(FlightSweep sweep, const Context& context,
                                  const std::string& format, ApiError* error) {
  // A JSON answer is built in memory (a CSV one streams): a row is about 1 kB (the /v1/flight
  // answer with its parameters; 0.7 kB compact), so its size is bounded like a bat sweep's.
  constexpr std::uint64_t kJsonRowBytes = 1000;
  if (format == "json" && sweep.total > context.limits.max_response_bytes / kJsonRowBytes) {
    SetError(error, ErrorCode::kTooBig, "format", nullptr,
             "\"json\" for " + std::to_string(sweep.total) + " launches is about " +
                 std::to_string(sweep.total * kJsonRowBytes / 1000000) +
                 " MB in memory, over max_response_bytes = " +
                 std::to_string(context.limits.max_response_bytes) +
                 "; ask for \"format\": \"csv\" (streamed)");
    return std::nullopt;
  }
  sweep.threads = std::max(1, context.explore_threads);
  sweep.budget = context.thread_budget;
  sweep.progress = context.progress;
  return sweep;
}

}  // namespace

std::optional<FlightSweep> Parse(const Json& body, const Context& context, std::string* format,
                                 ApiError* error) {
  ObjectReader reader(body, "", error);
  const Json* template_json = reader.Get("flight");
  if (!reader.ok()) return std::nullopt;
  if (!template_json->is_object()) {
    reader.Fail("flight", "must be an object: a /v1/flight request with one \"launch\"");
    return std::nullopt;
  }
  const std::size_t limit =
      context.batch ? context.limits.max_batch_samples : context.limits.max_samples;
  const char* limit_name = context.batch ? "max_batch_samples" : "max_samples";
  FlightSweep sweep;
  // "launches": a list flown as given (a season's batted balls), up to the sweep's limit.
  sweep.list = template_json->contains("launches");
  {
    ApiError inner;
    ApiLimits limits = context.limits;
    if (sweep.list) limits.max_launches = limit;
    std::optional<FlightRequest> request = ParseFlight(*template_json, limits, &inner);
    if (!request) {
      *error = std::move(inner);
      PrefixFlight(error);
      if (sweep.list && error->code == ErrorCode::kTooBig && error->field == "flight.launches") {
        error->message = "flight.launches: has " +
                         std::to_string(template_json->at("launches").size()) +
                         " launches, over the limit " + limit_name + " = " + std::to_string(limit);
      }
      return std::nullopt;
    }
    if (request->trajectory) {
      SetError(error, ErrorCode::kInvalidValue, "flight.outputs", nullptr,
               "a sweep's rows carry no trajectory (POST /v1/flight gives one)");
      return std::nullopt;
    }
    sweep.base = std::move(*request);
  }

  if (sweep.list) {
    for (const char* key : {"parameters", "sampling", "samples", "seed"}) {
      if (reader.Has(key)) {
        reader.Fail(key,
                    "applies to a swept \"launch\"; a list of \"launches\" is flown as "
                    "given");
        return std::nullopt;
      }
    }
    *format = "json";  // as a bat sweep's
    reader.OptionalString("format", format, {"json", "csv"});
    if (!reader.Finish()) return std::nullopt;
    sweep.total = sweep.base.launches.size();  // <= limit: ParseFlight's max_launches
  } else if (!ParseSweptTemplate(reader, limit, limit_name, &sweep, format, error)) {
    return std::nullopt;
  }
  return Finish(std::move(sweep), context, *format, error);
}

}  // namespace sweetspot::api::flight_sweep
