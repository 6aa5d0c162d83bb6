// The api's half of batted_ball (core's: core/scene/outputs_batted_ball.cpp).
#include <iterator>

#include "api/outputs/scene_outputs.hpp"

namespace sweetspot::api {
namespace outputs_batted_ball_api {
namespace {

using Json = nlohmann::json;

void RenderBattedBall(const core::SceneResult& r, Json* out, Json* errors) {
  const core::BattedBallResult& b = *r.batted_ball;
  const core::ObliqueImpactResult& i = b.impact;
  const core::flight::FlightResult& f = b.flight;
  (*out)["batted_ball"] = {
      {"exit_speed_mps", i.exit_speed_mps},
      {"launch_angle_deg", i.launch_angle_deg},
      {"backspin_rpm", i.backspin_rpm + 0.0},  // + 0.0: head-on writes 0, not -0
      {"sidespin_rpm", 0.0},
      {"spin_source", "oblique_impact"},
      {"distance_m", f.distance_m},
      {"hang_time_s", f.hang_time_s},
      {"apex_m", f.apex_m},
      {"landing", {{"x_m", f.landing_x_m}, {"y_m", f.landing_y_m}}},
      {"impact_from_knob_m", b.impact_from_knob_m},
      {"undercut_m", b.undercut_m},
      {"impact",
       {{"bat_speed_at_impact_mps", b.bat_speed_at_impact_mps},
        {"bat_radius_m", b.bat_radius_m},
        {"bat_effective_mass_kg", b.bat_effective_mass_kg},
        {"normal_cor", b.normal_cor},
        {"incidence_angle_deg", i.incidence_angle_deg},
        {"tangential_regime", core::TangentialRegimeName(i.regime)},
        {"tangential_cor", core::kDefaultTangentialCor},
        {"friction_coefficient", core::kDefaultBallBatFriction}}},
      {"flight",
       {{"aero_model", core::flight::AeroModelName(b.aero_model)},
        {"environment", b.default_environment ? "default" : "scene"},
        {"air_density_kg_m3", f.air_density_kg_m3}}},
  };
  // hertz and flexible: the normal impulse is the model's own at the normal approach speed.
  if (b.normal_model != nullptr) {
    (*out)["batted_ball"]["impact"]["normal_model"] = b.normal_model;
  }
  (*errors)["batted_ball"] = {{"distance_m", f.error_estimate_m}};
}

void ProbeBattedBall(core::SceneResult* r) { r->batted_ball.emplace(); }

// batted_ball's numbers a sweep reads without rendering (its explore columns).
template <typename F>
DirectValue FromBall(const OutputView& v, F number) {
  return v.result != nullptr && v.result->batted_ball ? number(*v.result->batted_ball)
                                                      : DirectValue{};
}

const DirectField kBattedBallFields[] = {
    {"exit_speed_mps", true,
     [](const OutputView& v) {
       return FromBall(v, [](const auto& b) { return Number(b.impact.exit_speed_mps); });
     }},
    {"launch_angle_deg", true,
     [](const OutputView& v) {
       return FromBall(v, [](const auto& b) { return Number(b.impact.launch_angle_deg); });
     }},
    {"backspin_rpm", true,
     [](const OutputView& v) {
       return FromBall(v, [](const auto& b) { return Number(b.impact.backspin_rpm + 0.0); });
     }},
    {"distance_m", true,
     [](const OutputView& v) {
       return FromBall(v, [](const auto& b) { return Number(b.flight.distance_m); });
     }},
    {"hang_time_s", true,
     [](const OutputView& v) {
       return FromBall(v, [](const auto& b) { return Number(b.flight.hang_time_s); });
     }},
    {"apex_m", true,
     [](const OutputView& v) {
       return FromBall(v, [](const auto& b) { return Number(b.flight.apex_m); });
     }},
};

}  // namespace
}  // namespace outputs_batted_ball_api

namespace obb = outputs_batted_ball_api;

extern const ApiOutputDecl kBattedBallApi{core::SceneOutput::kBattedBall, obb::RenderBattedBall,
                                          obb::ProbeBattedBall, std::begin(obb::kBattedBallFields),
                                          std::end(obb::kBattedBallFields)};

}  // namespace sweetspot::api
