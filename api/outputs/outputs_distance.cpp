// The api's half of distance_sweet_spot and carry_map (core's: core/scene/outputs_distance.cpp).
#include <cmath>
#include <iterator>

#include "api/outputs/scene_outputs.hpp"
#include "api/scene_json.hpp"

namespace sweetspot::api {
namespace outputs_distance_api {
namespace {

using Json = nlohmann::json;

void RenderDistanceSweetSpot(const core::SceneResult& r, Json* out, Json* errors) {
  const core::DistanceSweetSpotResult& d = *r.distance_sweet_spot;
  const core::flight::FlightResult& f = d.ball.flight;
  Json search = {
      {"method", "coarse scan, then LN_BOBYQA within one coarse cell"},
      {"position_min_from_knob_m", d.position_min_from_knob_m},
      {"position_max_from_knob_m", d.position_max_from_knob_m},
      {"undercut_min_m", d.undercut_min_m},
      {"undercut_max_m", d.undercut_max_m},
      {"coarse_positions", d.coarse_positions},
      {"coarse_undercuts", d.coarse_undercuts},
      {"position_tolerance_m", d.position_tolerance_m},
      {"undercut_tolerance_m", d.undercut_tolerance_m},
      {"at_position_bound", d.at_position_bound},
      {"at_undercut_bound", d.at_undercut_bound},
      {"evaluations", d.evaluations},
      {"normal_law", d.normal_law},
      {"termination", core::TerminationName(d.summary.termination)},
  };
  if (d.normal_law == "tabulated") {
    search["normal_table_positions"] = d.normal_table_positions;
    search["normal_table_speeds"] = d.normal_table_speeds;
    search["normal_table_error_m"] = d.normal_table_error_m;
  }
  (*out)["distance_sweet_spot"] = {
      {"position_from_knob_m", d.position_from_knob_m},
      {"undercut_m", d.undercut_m},
      {"distance_m", d.distance_m},
      {"exit_speed_mps", d.exit_speed_mps},
      {"launch_angle_deg", d.launch_angle_deg},
      {"backspin_rpm", d.backspin_rpm + 0.0},
      {"hang_time_s", f.hang_time_s},
      {"apex_m", f.apex_m},
      {"bat_speed_at_impact_mps", d.ball.bat_speed_at_impact_mps},
      {"aero_model", core::flight::AeroModelName(d.ball.aero_model)},
      {"air_density_kg_m3", f.air_density_kg_m3},
      {"search", std::move(search)},
  };
  (*errors)["distance_sweet_spot"] = {{"position_m", d.position_tolerance_m},
                                      {"undercut_m", d.undercut_tolerance_m},
                                      {"distance_m", f.error_estimate_m}};
}

void ProbeDistanceSweetSpot(core::SceneResult* r) {
  r->distance_sweet_spot.emplace();
  r->distance_sweet_spot->normal_law = "tabulated";  // its table's fields shown too
}

template <typename F>
DirectValue FromSpot(const OutputView& v, F number) {
  return v.result != nullptr && v.result->distance_sweet_spot
             ? number(*v.result->distance_sweet_spot)
             : DirectValue{};
}

const DirectField kDistanceSweetSpotFields[] = {
    {"position_from_knob_m", true,
     [](const OutputView& v) {
       return FromSpot(v, [](const auto& d) { return Number(d.position_from_knob_m); });
     }},
    {"undercut_m", true,
     [](const OutputView& v) {
       return FromSpot(v, [](const auto& d) { return Number(d.undercut_m); });
     }},
    {"distance_m", true,
     [](const OutputView& v) {
       return FromSpot(v, [](const auto& d) { return Number(d.distance_m); });
     }},
    {"exit_speed_mps", true,
     [](const OutputView& v) {
       return FromSpot(v, [](const auto& d) { return Number(d.exit_speed_mps); });
     }},
    {"launch_angle_deg", true,
     [](const OutputView& v) {
       return FromSpot(v, [](const auto& d) { return Number(d.launch_angle_deg); });
     }},
    {"backspin_rpm", true,
     [](const OutputView& v) {
       return FromSpot(v, [](const auto& d) { return Number(d.backspin_rpm + 0.0); });
     }},
};

void RenderCarryMap(const core::SceneResult& r, Json* out, Json*) {
  const core::CarryMapResult& m = *r.carry_map;
  const std::size_t nu = m.undercuts_m.size();
  // One row per position: its carries over the undercuts (null: no carry).
  Json positions = Json::array();
  for (std::size_t i = 0; i < m.positions_from_knob_m.size(); ++i) {
    Json distances = Json::array();
    for (std::size_t j = 0; j < nu; ++j) {
      const double c = m.distance_m[i * nu + j];
      distances.push_back(std::isfinite(c) ? Json(c) : Json(nullptr));
    }
    positions.push_back({{"position_from_knob_m", m.positions_from_knob_m[i]},
                         {"distance_m", std::move(distances)}});
  }
  Json block = {{"undercuts_m", m.undercuts_m},
                {"positions", std::move(positions)},
                {"best",
                 {{"position_from_knob_m", m.best_position_from_knob_m},
                  {"undercut_m", m.best_undercut_m},
                  {"distance_m", m.best_distance_m}}},
                {"normal_law", m.normal_law}};
  if (m.normal_law == "tabulated") block["normal_table_speeds"] = m.normal_table_speeds;
  (*out)["carry_map"] = std::move(block);
}

void ProbeCarryMap(core::SceneResult* r) {
  r->carry_map.emplace();
  r->carry_map->positions_from_knob_m = {0.0};
  r->carry_map->undercuts_m = {0.0};
  r->carry_map->distance_m = {0.0};
  r->carry_map->normal_law = "tabulated";
}

}  // namespace
}  // namespace outputs_distance_api

namespace oda = outputs_distance_api;

extern const ApiOutputDecl kDistanceSweetSpotApi{
    core::SceneOutput::kDistanceSweetSpot, oda::RenderDistanceSweetSpot,
    oda::ProbeDistanceSweetSpot, std::begin(oda::kDistanceSweetSpotFields),
    std::end(oda::kDistanceSweetSpotFields)};

extern const ApiOutputDecl kCarryMapApi{core::SceneOutput::kCarryMap, oda::RenderCarryMap,
                                        oda::ProbeCarryMap};

}  // namespace sweetspot::api
