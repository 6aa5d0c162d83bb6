#include "api/outputs/scene_outputs.hpp"

#include <array>
#include <stdexcept>

#include "api/scene_json.hpp"
#include "core/scene/output_registry.hpp"

namespace sweetspot::api {

using Json = nlohmann::json;

// Each output's api declaration (api/outputs/outputs_*.cpp).
extern const ApiOutputDecl kMaxExitSpeedApi, kSweetZoneApi, kExitSpeedCurveApi,
    kCenterOfPercussionApi, kVibrationNodeApi, kLeastStingZoneApi, kBarrelApi, kBbcorApi,
    kBbcorScanApi, kBattedBallApi, kDistanceSweetSpotApi, kCarryMapApi;

namespace {

// The api declarations by id; every id of core's table has exactly one (checked once).
const std::array<const ApiOutputDecl*, core::kSceneOutputCount>& ApiById() {
  static const std::array<const ApiOutputDecl*, core::kSceneOutputCount> by_id = [] {
    std::array<const ApiOutputDecl*, core::kSceneOutputCount> out{};
    // The api's rows: one per output (any order: core's table orders them).
    for (const ApiOutputDecl* d :
         {&kMaxExitSpeedApi, &kSweetZoneApi, &kExitSpeedCurveApi, &kCenterOfPercussionApi,
          &kVibrationNodeApi, &kLeastStingZoneApi, &kBarrelApi, &kBbcorApi, &kBbcorScanApi,
          &kBattedBallApi, &kDistanceSweetSpotApi, &kCarryMapApi}) {
      const auto i = static_cast<std::size_t>(d->id);
      if (i >= out.size() || out[i] != nullptr) {
        throw std::logic_error("api output table: a duplicate or out-of-range id");
      }
      out[i] = d;
    }
    for (const ApiOutputDecl* d : out) {
      if (d == nullptr) throw std::logic_error("api output table: an output without its api part");
    }
    return out;
  }();
  return by_id;
}

}  // namespace

DirectValue Number(double v) {
  DirectValue d;
  d.kind = DirectValue::kNumber;
  d.number = v;
  return d;
}

DirectValue Text(std::string_view v) {
  DirectValue d;
  d.kind = DirectValue::kString;
  d.text = v;
  return d;
}

const std::vector<const ApiOutputDecl*>& ApiOutputTable() {
  static const std::vector<const ApiOutputDecl*> table = [] {
    std::vector<const ApiOutputDecl*> out;
    for (const core::SceneOutputDecl* d : core::SceneOutputTable()) {
      out.push_back(ApiById()[static_cast<std::size_t>(d->id)]);
    }
    return out;
  }();
  return table;
}

const ApiOutputDecl& ApiOutputDeclaration(core::SceneOutput id) {
  return *ApiById()[static_cast<std::size_t>(id)];
}

Json SceneResultToJson(const core::SceneResult& r) {
  Json out = Json::object();
  Json errors = Json::object();
  for (const core::SceneOutputDecl* d : core::SceneOutputTable()) {
    if (d->present(r)) ApiOutputDeclaration(d->id).render(r, &out, &errors);
  }
  out["error_estimate"] = std::move(errors);
  out["models_used"] = r.summary.models_used;
  out["exit_speed_model"] = r.exit_speed_model.empty() ? Json(nullptr) : Json(r.exit_speed_model);
  if (!r.model_reason.empty()) out["model_reason"] = r.model_reason;
  if (r.cor.has_value()) {  // absent when no requested output uses a COR
    out["cor"] = *r.cor;
    out["cor_source"] = r.cor_source;
    if (r.cor_impact_speed_mps) out["cor_impact_speed_mps"] = *r.cor_impact_speed_mps;
  }
  Json timings = Json::array();
  for (const auto& t : r.timings) {
    Json timing = Json::object();  // member by member: no initializer list's arrays
    timing.emplace("model", t.model);
    timing.emplace("time_s", t.time_s);
    timing.emplace("calls", t.calls);
    timings.push_back(std::move(timing));
  }
  out["timings"] = std::move(timings);
  if (!r.summary.warnings.empty()) out["warnings"] = r.summary.warnings;
  return out;
}

core::SceneResult ProbeResult(const std::vector<core::SceneOutput>& outputs) {
  core::SceneResult r;
  for (const core::SceneOutput output : outputs) ApiOutputDeclaration(output).probe(&r);
  return r;
}

}  // namespace sweetspot::api
