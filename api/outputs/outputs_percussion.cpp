// The api's half of center_of_percussion (core's: core/scene/outputs_percussion.cpp).
#include "api/outputs/scene_outputs.hpp"

namespace sweetspot::api {
namespace outputs_percussion_api {
namespace {

using Json = nlohmann::json;

void RenderCenterOfPercussion(const core::SceneResult& r, Json* out, Json* errors) {
  const auto& c = *r.center_of_percussion;
  (*out)["center_of_percussion"] = {{"position_from_knob_m", c.position_from_knob_m},
                                    {"hands_from_knob_m", c.hands_from_knob_m},
                                    {"moi_hands_kg_m2", c.moi_hands_kg_m2},
                                    {"placement", core::PlacementName(c.placement)}};
  (*errors)["center_of_percussion"] = {{"position_m", c.error_estimate_m}};
}

void ProbeCenterOfPercussion(core::SceneResult* r) { r->center_of_percussion.emplace(); }

// `value(cop)` of the design's center_of_percussion (the lean path has none).
template <typename F>
DirectValue FromCop(const OutputView& v, F value) {
  return v.result != nullptr && v.result->center_of_percussion
             ? value(*v.result->center_of_percussion)
             : DirectValue{};
}

const DirectField kCenterOfPercussionFields[] = {
    {"position_from_knob_m", true,
     [](const OutputView& v) {
       return FromCop(v, [](const auto& c) { return Number(c.position_from_knob_m); });
     }},
    {"hands_from_knob_m", true,
     [](const OutputView& v) {
       return FromCop(v, [](const auto& c) { return Number(c.hands_from_knob_m); });
     }},
    {"moi_hands_kg_m2", true,
     [](const OutputView& v) {
       return FromCop(v, [](const auto& c) { return Number(c.moi_hands_kg_m2); });
     }},
    {"placement", false,
     [](const OutputView& v) {
       return FromCop(v, [](const auto& c) { return Text(core::PlacementName(c.placement)); });
     }},
};

}  // namespace
}  // namespace outputs_percussion_api

extern const ApiOutputDecl kCenterOfPercussionApi{
    core::SceneOutput::kCenterOfPercussion, outputs_percussion_api::RenderCenterOfPercussion,
    outputs_percussion_api::ProbeCenterOfPercussion,
    std::begin(outputs_percussion_api::kCenterOfPercussionFields),
    std::end(outputs_percussion_api::kCenterOfPercussionFields)};

}  // namespace sweetspot::api
