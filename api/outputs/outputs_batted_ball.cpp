// The api's half of batted_ball (core's: core/scene/outputs_batted_ball.cpp).
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
       {{"aero_model", core::flight::AeroModelName(core::flight::AeroOptions{}.model)},
        {"environment", "default"},
        {"air_density_kg_m3", f.air_density_kg_m3}}},
  };
  (*errors)["batted_ball"] = {{"distance_m", f.error_estimate_m}};
}

void ProbeBattedBall(core::SceneResult* r) { r->batted_ball.emplace(); }

}  // namespace
}  // namespace outputs_batted_ball_api

extern const ApiOutputDecl kBattedBallApi{core::SceneOutput::kBattedBall,
                                          outputs_batted_ball_api::RenderBattedBall,
                                          outputs_batted_ball_api::ProbeBattedBall};

}  // namespace sweetspot::api
