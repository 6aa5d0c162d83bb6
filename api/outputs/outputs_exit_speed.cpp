// The api's half of max_exit_speed, sweet_zone and exit_speed_curve (core's:
// core/scene/outputs_exit_speed.cpp).
#include "api/outputs/scene_outputs.hpp"
#include "api/scene_json.hpp"

namespace sweetspot::api {
namespace outputs_exit_speed_api {
namespace {

using Json = nlohmann::json;

template <class Out>
void WriteMaxExitSpeed(const core::SceneResult& r, Out& out, Out& errors) {
  const auto& m = *r.max_exit_speed;
  // In key order (the text writer then only checks it).
  out.Object("max_exit_speed", [&](Out& block) {
    block.Set("exit_speed_mps", m.exit_speed_mps);
    block.Set("method", m.method);
    block.Set("model", m.model);
    block.Set("placement", core::PlacementName(m.placement));
    block.Set("position_from_knob_m", m.position_from_knob_m);
    if (m.method != "closed_form") {
      block.Object("summary", [&](Out& summary) { WriteSummary(m.summary, summary); });
    }
    block.Set("unconstrained_position_from_knob_m", m.unconstrained_position_from_knob_m);
  });
  errors.Object("max_exit_speed", [&](Out& error) {
    error.Set("exit_speed_mps", m.error_estimate_mps);
    error.Set("position_m", m.error_estimate_m);
  });
}

void ProbeMaxExitSpeed(core::SceneResult* r) {
  r->max_exit_speed.emplace();  // method "" != closed_form: its summary is shown too
}

// `number(max)` of the design's max_exit_speed, full or lean (the same fields, the same names).
template <typename F>
DirectValue FromMax(const OutputView& v, F number) {
  if (v.result != nullptr) {
    return v.result->max_exit_speed ? number(*v.result->max_exit_speed) : DirectValue{};
  }
  return v.lean != nullptr ? number(v.lean->max_exit_speed) : DirectValue{};
}

const DirectField kMaxExitSpeedFields[] = {
    {"position_from_knob_m", true,
     [](const OutputView& v) {
       return FromMax(v, [](const auto& m) { return Number(m.position_from_knob_m); });
     }},
    {"exit_speed_mps", true,
     [](const OutputView& v) {
       return FromMax(v, [](const auto& m) { return Number(m.exit_speed_mps); });
     }},
    {"unconstrained_position_from_knob_m", true,
     [](const OutputView& v) {
       return FromMax(v,
                      [](const auto& m) { return Number(m.unconstrained_position_from_knob_m); });
     }},
    {"placement", false,
     [](const OutputView& v) {
       return FromMax(v, [](const auto& m) { return Text(core::PlacementName(m.placement)); });
     }},
    {"model", false,
     [](const OutputView& v) {
       if (v.result != nullptr) {
         return v.result->max_exit_speed ? Text(v.result->max_exit_speed->model) : DirectValue{};
       }
       return v.lean != nullptr ? Text(v.lean_model) : DirectValue{};
     }},
    {"method", false,
     [](const OutputView& v) {
       if (v.result != nullptr) {
         return v.result->max_exit_speed ? Text(v.result->max_exit_speed->method) : DirectValue{};
       }
       return v.lean != nullptr ? Text("closed_form") : DirectValue{};  // ClosedFormMaxExitSpeed's
     }},
};

void RenderSweetZone(const core::SceneResult& r, Json* out, Json* errors) {
  const auto& z = *r.sweet_zone;
  (*out)["sweet_zone"] = {{"from_knob_m", z.from_knob_m},
                          {"to_knob_m", z.to_knob_m},
                          {"tolerance_mps", z.tolerance_mps},
                          {"threshold_mps", z.threshold_mps},
                          {"clipped_at_knob", z.clipped_at_knob},
                          {"clipped_at_tip", z.clipped_at_tip},
                          {"method", z.method}};
  (*errors)["sweet_zone"] = {{"ends_m", z.error_estimate_m}};
}

void ProbeSweetZone(core::SceneResult* r) { r->sweet_zone.emplace(); }

void RenderExitSpeedCurve(const core::SceneResult& r, Json* out, Json* errors) {
  Json points = Json::array();
  for (const auto& p : r.exit_speed_curve->points) {
    points.push_back(
        {{"position_from_knob_m", p.position_from_knob_m}, {"exit_speed_mps", p.exit_speed_mps}});
  }
  (*out)["exit_speed_curve"] = std::move(points);
  (*errors)["exit_speed_curve"] = {{"exit_speed_mps", r.exit_speed_curve->error_estimate_mps}};
}

void ProbeExitSpeedCurve(core::SceneResult* r) {
  r->exit_speed_curve.emplace();
  r->exit_speed_curve->points.emplace_back();
}

}  // namespace
}  // namespace outputs_exit_speed_api

namespace oes = outputs_exit_speed_api;

extern const ApiOutputDecl kMaxExitSpeedApi{core::SceneOutput::kMaxExitSpeed,
                                            RenderTree<oes::WriteMaxExitSpeed<TreeObject>>,
                                            oes::ProbeMaxExitSpeed,
                                            std::begin(oes::kMaxExitSpeedFields),
                                            std::end(oes::kMaxExitSpeedFields),
                                            oes::WriteMaxExitSpeed<TextObject>};

extern const ApiOutputDecl kSweetZoneApi{core::SceneOutput::kSweetZone, oes::RenderSweetZone,
                                         oes::ProbeSweetZone};

extern const ApiOutputDecl kExitSpeedCurveApi{core::SceneOutput::kExitSpeedCurve,
                                              oes::RenderExitSpeedCurve, oes::ProbeExitSpeedCurve};

}  // namespace sweetspot::api
