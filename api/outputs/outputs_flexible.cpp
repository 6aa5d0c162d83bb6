// The api's half of vibration_node and least_sting_zone (core's: core/scene/outputs_flexible.cpp;
// their blocks: VibrationNodeToJson and LeastStingZoneToJson, api/scene_render.cpp).
#include <algorithm>

#include "api/outputs/scene_outputs.hpp"
#include "api/scene_json.hpp"

namespace sweetspot::api {
namespace outputs_flexible_api {
namespace {

using Json = nlohmann::json;

void RenderVibrationNode(const core::SceneResult& r, Json* out, Json* errors) {
  const auto& v = *r.vibration_node;
  (*out)["vibration_node"] = VibrationNodeToJson(v);
  (*errors)["vibration_node"] = {{"position_m", v.error_estimate_m},
                                 {"frequency_hz", v.error_estimate_hz},
                                 {"second_mode_frequency_hz", v.second_mode_error_estimate_hz}};
}

void ProbeVibrationNode(core::SceneResult* r) {
  r->vibration_node.emplace();
  r->vibration_node->second_mode_nodes_from_knob_m = {0.0};
  r->vibration_node->refinement_elements = {0};
}

void RenderLeastStingZone(const core::SceneResult& r, Json* out, Json* errors) {
  const auto& z = *r.least_sting_zone;
  (*out)["least_sting_zone"] = LeastStingZoneToJson(z);
  double speed_err = 0.0, energy_err = 0.0;
  for (const auto& p : z.curve) {
    speed_err = std::max(speed_err, p.error_estimate_exit_speed_mps);
    energy_err = std::max(energy_err, p.error_estimate_hands_energy_j);
  }
  (*errors)["least_sting_zone"] = {{"ends_m", z.error_estimate_m},
                                   {"exit_speed_mps", speed_err},
                                   {"hands_energy_j", energy_err}};
}

void ProbeLeastStingZone(core::SceneResult* r) {
  r->least_sting_zone.emplace();
  r->least_sting_zone->curve.emplace_back();
}

}  // namespace
}  // namespace outputs_flexible_api

extern const ApiOutputDecl kVibrationNodeApi{core::SceneOutput::kVibrationNode,
                                             outputs_flexible_api::RenderVibrationNode,
                                             outputs_flexible_api::ProbeVibrationNode};

extern const ApiOutputDecl kLeastStingZoneApi{core::SceneOutput::kLeastStingZone,
                                              outputs_flexible_api::RenderLeastStingZone,
                                              outputs_flexible_api::ProbeLeastStingZone};

}  // namespace sweetspot::api
