// POST /v1/bat/modes: parse -> validate -> core::CachedBatModes -> render.
#include "api/handlers/modes.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "api/bat_json.hpp"
#include "api/handlers/endpoint.hpp"
#include "api/handlers/handlers.hpp"
#include "api/scene_json.hpp"
#include "core/flexible/modes_cache.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

// The most modes one answer lists (core computes up to 50 for the flexible impact).
constexpr long long kMaxListedModes = 20;
// The most positions one mode's shape is sampled at in the answer.
constexpr long long kMaxShapeSamples = 1001;

// One mode: frequency, nodes and the shape sampled at `samples` evenly spaced positions,
// scaled so that the largest |displacement| is 1 (tip positive).
Json ModeToJson(const core::BatModes& modes, std::size_t k, int samples) {
  const core::BeamMode& mode = modes.modes[k];
  const double length = modes.length_m;
  std::vector<double> xs, ws;
  double peak = 0.0;
  for (int i = 0; i < samples; ++i) {
    const double x = i + 1 == samples ? length : length * i / (samples - 1);
    const double w = modes.Displacement(mode.vector, x);
    xs.push_back(x);
    ws.push_back(w);
    peak = std::max(peak, std::abs(w));
  }
  // The largest |w| over the mesh nodes too, so the scale does not depend on the sampling.
  for (double x : modes.nodes_m)
    peak = std::max(peak, std::abs(modes.Displacement(mode.vector, x)));
  const double scale = peak > 0.0 ? peak : 1.0;
  Json shape = Json::array();
  for (std::size_t i = 0; i < xs.size(); ++i) {
    shape.push_back({{"position_from_knob_m", xs[i]}, {"displacement", ws[i] / scale}});
  }
  return {{"mode", k + 1},
          {"frequency_hz", mode.frequency_hz},
          {"error_estimate_hz", mode.error_estimate_hz},
          {"observed_order", mode.observed_order},
          {"nodes_from_knob_m", mode.nodes_from_knob_m},
          {"nodes_error_estimate_m", mode.nodes_error_estimate_m},
          {"displacement_scale_per_sqrt_kg", scale},
          {"shape", std::move(shape)}};
}

// A parsed /v1/bat/modes request: the bat, the modes' options and the shape's samples.
struct ModesRequest {
  BatSpec spec;
  core::BeamModesOptions options;
  int shape_samples = 41;
};

// What the modes' core call returns: the modes (shared with the cache) and whether the
// cache had them.
struct ModesResult {
  std::shared_ptr<const core::BatModes> modes;
  bool cache_hit = false;
};

std::optional<ModesRequest> ParseModes(const Json& body, const Context& context, ApiError* error) {
  ObjectReader reader(body, "", error);
  const Json* bat_json = reader.Get("bat");
  if (bat_json == nullptr) {
    reader.Missing("bat");
    return std::nullopt;
  }
  auto spec = ParseBat(*bat_json, "bat", context.limits, error);
  if (!spec) return std::nullopt;
  ModesRequest request{std::move(*spec), {}, 41};
  core::BeamModesOptions& options = request.options;
  std::string theory = "timoshenko";
  reader.OptionalString("theory", &theory, {"timoshenko", "euler_bernoulli"});
  options.theory = core::ParseBeamTheory(theory).value_or(core::BeamTheory::kTimoshenko);
  // The answer's size, the api's to cap: at most kMaxListedModes modes (core computes up to
  // 50 for the flexible impact), each sampled at 2 to kMaxShapeSamples positions (the
  // sampling is the api's rendering, ModeToJson).
  long long modes = 4;
  reader.OptionalInteger("modes", 1, kMaxListedModes, &modes);
  options.num_modes = static_cast<int>(modes);
  long long samples = 41;
  reader.OptionalInteger("shape_samples", 2, kMaxShapeSamples, &samples);
  request.shape_samples = static_cast<int>(samples);
  // The solver's ranges are core's (BeamModesOptions::Validate).
  reader.OptionalNumber("tolerance", AnyNumber(), &options.relative_tolerance);
  reader.OptionalInt("max_elements", &options.max_elements);
  if (!reader.Finish()) return std::nullopt;
  if (core::Refusal refusal; !options.Validate(&refusal)) {
    // Core's names of this request's fields; no other request has them bare, so they are
    // renamed here rather than in RequestName's table.
    if (refusal.field == "relative_tolerance") refusal.field = "tolerance";
    if (refusal.field == "num_modes") refusal.field = "modes";
    CoreRefusal(refusal, "", error);
    return std::nullopt;
  }
  return request;
}

Json RenderModes(const ModesRequest& request, const ModesResult& modes) {
  const core::BatModes& result = *modes.modes;
  Json out = Json::object();
  Json frequencies = Json::array(), errors = Json::array(), list = Json::array();
  for (std::size_t k = 0; k < result.modes.size(); ++k) {
    frequencies.push_back(result.modes[k].frequency_hz);
    errors.push_back(result.modes[k].error_estimate_hz);
    list.push_back(ModeToJson(result, k, request.shape_samples));
  }
  out["theory"] = core::BeamTheoryName(result.theory);
  out["boundary_conditions"] = "free-free";
  out["frequencies_hz"] = std::move(frequencies);
  out["modes"] = std::move(list);
  const core::BeamMode& first = result.modes.front();
  if (!first.nodes_from_knob_m.empty()) {
    out["vibration_node"] = {{"position_from_knob_m", first.nodes_from_knob_m.back()},
                             {"frequency_hz", first.frequency_hz},
                             {"other_node_from_knob_m", first.nodes_from_knob_m.front()}};
  }
  out["elements"] = result.Elements();
  out["refinement_elements"] = result.refinement_elements;
  out["tolerance"] = result.tolerance;
  out["error_estimate"] = {{"frequency_relative", result.max_relative_error},
                           {"frequencies_hz", std::move(errors)}};
  out["rigid_body"] = {{"mass_kg", result.mass_kg},
                       {"balance_point_m", result.balance_point_m},
                       {"moi_centroid_kg_m2", result.moi_centroid_kg_m2}};
  out["models_used"] = {core::kFlexibleBeamModel};
  out["cache_hit"] = modes.cache_hit;
  return out;
}

const Endpoint<ModesRequest, ModesResult>& ModesEndpoint() {
  static const auto endpoint = [] {
    Endpoint<ModesRequest, ModesResult> e;
    e.parse = ParseModes;
    e.run = [](const ModesRequest& request, const Context& context) {
      ModesResult result;
      result.modes = core::CachedBatModes(request.spec.bat, request.options, context.modes_cache,
                                          &result.cache_hit);
      return result;
    };
    e.failure = [](const ModesRequest&, const ModesResult& result) -> std::optional<Response> {
      const core::Summary& s = result.modes->summary;
      if (s.IsSolutionUsable()) return std::nullopt;
      return CoreFailure(s, "", "bat");
    };
    e.render = RenderModes;
    e.summary = [](const ModesResult& result) -> const core::Summary& {
      return result.modes->summary;
    };
    e.provenance = [](const ModesRequest&, const Json&) { return ProvenanceInputs{}; };
    // The answer states no length: the nodes' and the shape's distances from the tip need it.
    e.length_m = [](const ModesRequest&, const ModesResult& result) -> std::optional<double> {
      return result.modes->length_m;
    };
    return e;
  }();
  return endpoint;
}

}  // namespace

Response HandleBatModes(const Request& request, const Context& context) {
  return ServeEndpoint(ModesEndpoint(), request, context);
}

}  // namespace sweetspot::api
