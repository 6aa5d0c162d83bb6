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

namespace {

// One output's block and error estimates.
void WriteOutput(const ApiOutputDecl& decl, const core::SceneResult& r, TreeObject& out,
                 TreeObject& errors) {
  decl.render(r, out.json(), errors.json());
}

void WriteOutput(const ApiOutputDecl& decl, const core::SceneResult& r, TextObject& out,
                 TextObject& errors) {
  if (decl.write != nullptr) {
    decl.write(r, out, errors);
    return;
  }
  Json block = Json::object();
  Json error = Json::object();
  decl.render(r, &block, &error);
  for (const auto& [key, value] : block.items()) out.Set(key, value);
  for (const auto& [key, value] : error.items()) errors.Set(key, value);
}

}  // namespace

template <class Out>
void WriteSceneResult(const core::SceneResult& r, const std::vector<std::string>& warnings,
                      Out& out) {
  {
    typename Out::Detached errors;
    for (const core::SceneOutputDecl* d : core::SceneOutputTable()) {
      if (d->present(r)) WriteOutput(ApiOutputDeclaration(d->id), r, out, errors.out());
    }
    out.Attach("error_estimate", errors);
  }
  out.Set("models_used", r.summary.models_used);
  if (r.exit_speed_model.empty()) {
    out.Set("exit_speed_model", nullptr);
  } else {
    out.Set("exit_speed_model", r.exit_speed_model);
  }
  if (!r.model_reason.empty()) out.Set("model_reason", r.model_reason);
  if (r.cor.has_value()) {  // absent when no requested output uses a COR
    out.Set("cor", *r.cor);
    out.Set("cor_source", r.cor_source);
    if (r.cor_impact_speed_mps) out.Set("cor_impact_speed_mps", *r.cor_impact_speed_mps);
  }
  out.Objects("timings", r.timings.size(), [&](std::size_t i, Out& timing) {
    timing.Set("calls", r.timings[i].calls);  // in key order
    timing.Set("model", r.timings[i].model);
    timing.Set("time_s", r.timings[i].time_s);
  });
  if (warnings.empty()) {
    if (!r.summary.warnings.empty()) out.Set("warnings", r.summary.warnings);
  } else {
    std::vector<std::string> all = r.summary.warnings;
    all.insert(all.end(), warnings.begin(), warnings.end());
    out.Set("warnings", all);
  }
}
template void WriteSceneResult(const core::SceneResult&, const std::vector<std::string>&,
                               TreeObject&);
template void WriteSceneResult(const core::SceneResult&, const std::vector<std::string>&,
                               TextObject&);

Json SceneResultToJson(const core::SceneResult& r) {
  return TreeOf([&](TreeObject& out) { WriteSceneResult(r, {}, out); });
}

core::SceneResult ProbeResult(const std::vector<core::SceneOutput>& outputs) {
  core::SceneResult r;
  for (const core::SceneOutput output : outputs) ApiOutputDeclaration(output).probe(&r);
  return r;
}

}  // namespace sweetspot::api
