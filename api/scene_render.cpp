// Renders core's scene results as JSON: the Summary, /v1/collision's result, and the blocks the
// outputs' declarations render (api/outputs/: vibration node, least sting, barrel, BBCOR; the
// reading side is scene_json.cpp).
#include <cmath>
#include <cstddef>

#include "api/scene_json.hpp"

namespace sweetspot::api {
namespace {

using Json = nlohmann::json;

}  // namespace

template <class Out>
void WriteSwing(const core::Swing& swing, Out& out) {
  out.Set("angular_speed_rad_s", swing.angular_speed_rad_s);  // the three in key order
  out.Set("hands_from_knob_m", swing.hands_from_knob_m);
  out.Set("pivot_from_knob_m", swing.pivot_from_knob_m);
  if (swing.bat_speed_mps.has_value()) {
    out.Set("bat_speed_mps", *swing.bat_speed_mps);
    out.Set("bat_speed_from_tip_m", swing.bat_speed_from_tip_m);
    // A resolved swing that is not the plain fixed speed at a distance says how it was
    // resolved (an answer's swing without these is a fixed speed at bat_speed_from_tip_m).
    const core::SwingResolution* how =
        swing.resolution.has_value() ? &*swing.resolution : nullptr;
    if (swing.bat_speed_point == core::BatSpeedPoint::kSweetSpot) {
      out.Set("bat_speed_point", core::BatSpeedPointName(swing.bat_speed_point));
      if (how != nullptr) {
        out.Set("bat_speed_point_model", how->point_model);
        if (how->iterations > 0) {  // hertz, flexible: iterated to the model's own maximum
          out.Set("bat_speed_point_iterations", how->iterations);
          out.Set("bat_speed_point_error_mps", how->speed_error_mps);
        }
      }
    }
    if (swing.speed_model == core::SwingSpeedModel::kSwingWeight) {
      out.Set("speed_model", core::SwingSpeedModelName(swing.speed_model));
      if (how != nullptr) {
        out.Object("swing_weight", [&](Out& weight) {
          weight.Set("given_bat_speed_mps", how->given_bat_speed_mps);
          weight.Set("moi_hands_kg_m2", how->moi_hands_kg_m2);
          weight.Set("reference_moi_kg_m2", how->reference_moi_kg_m2);
          weight.Set("exponent", swing.swing_weight_exponent);
          weight.Set("factor", how->swing_weight_factor);
          weight.Set("source", core::kSwingWeightSource);
          if (!swing.reference_moi_kg_m2.has_value()) {
            weight.Set("reference_bat", core::kSwingWeightReferenceBat);
          }
        });
      }
    }
  }
}
template void WriteSwing(const core::Swing&, TreeObject&);
template void WriteSwing(const core::Swing&, TextObject&);

Json SwingToJson(const core::Swing& swing) {
  return TreeOf([&](TreeObject& out) { WriteSwing(swing, out); });
}

template <class Out>
void WriteSummary(const core::Summary& s, Out& out) {
  // In key order (the text writer then only checks it).
  out.Set("backend", s.backend);
  out.Set("error_estimate", s.error_estimate);
  out.Set("evaluations", s.evaluations);
  out.Set("iterations", s.iterations);
  out.Set("message", s.message);
  out.Set("models_used", s.models_used);
  out.Set("raw_status", s.raw_status);
  out.Set("solve_time_s", s.solve_time_s);
  out.Set("termination", core::TerminationName(s.termination));
  out.Set("warnings", s.warnings);
}
template void WriteSummary(const core::Summary&, TreeObject&);
template void WriteSummary(const core::Summary&, TextObject&);

Json SummaryToJson(const core::Summary& s) {
  return TreeOf([&](TreeObject& out) { WriteSummary(s, out); });
}

Json BarrelOutputToJson(const core::BarrelOutput& b) {
  // A solid bat has no hoop mode: those fields are null on purpose (not a failed number).
  auto hollow_only = [&](double v) { return b.hollow ? Json(v) : Json(nullptr); };
  Json curve = Json::array();
  for (const auto& p : b.effective_cor_curve) {
    curve.push_back({{"position_from_knob_m", p.position_from_knob_m},
                     {"approach_speed_mps", p.approach_speed_mps},
                     {"ball_cor", p.ball_cor},
                     {"effective_cor", p.effective_cor}});
  }
  return {{"hollow", b.hollow},
          {"method", b.method},
          {"position_from_knob_m", b.position_from_knob_m},
          {"hoop_frequency_hz", hollow_only(b.wall.hoop_frequency_hz)},
          {"barrel_stiffness_n_m", hollow_only(b.wall.stiffness_n_m)},
          {"ring_stiffness_n_m", hollow_only(b.wall.ring_stiffness_n_m)},
          {"modal_mass_kg", hollow_only(b.wall.modal_mass_kg)},
          {"effective_length_m", hollow_only(b.wall.effective_length_m)},
          {"mid_radius_m", hollow_only(b.wall.mid_radius_m)},
          {"wall_thickness_m", hollow_only(b.wall.thickness_m)},
          {"shell_factor", hollow_only(b.shell_factor)},
          {"barrel_loss", hollow_only(b.wall.barrel_loss)},
          {"barrel_energy_fraction", b.barrel_energy_fraction},
          {"effective_cor", b.effective_cor},
          {"effective_cor_curve", std::move(curve)}};
}

Json BbcorToJson(const core::BbcorResult& b) {
  const bool certified = b.method == core::kCertifiedBbcorMethod;
  if (!certified) {  // the fixed-point estimate alone
    const bool hollow = b.method != "rigid";
    return {{"value", b.value},
            {"ball", b.ball},
            {"ball_speed_mps", b.ball_speed_mps},
            {"ball_cor", b.ball_cor},
            {"impact_from_knob_m", b.impact_from_knob_m},
            {"pivot_from_knob_m", b.pivot_from_knob_m},
            {"method", b.method},
            {"hoop_frequency_hz", hollow ? Json(b.hoop_frequency_hz) : Json(nullptr)},
            {"barrel_stiffness_n_m", hollow ? Json(b.barrel_stiffness_n_m) : Json(nullptr)},
            {"protocol",
             "NCAA BBCOR fast estimate: the bat at rest on a pivot 6 in from the knob, the ball "
             "fired at 136 mph at 6 in from the barrel end; BBCOR = e_A (1 + r) + r, "
             "r = m z^2 / I_pivot"}};
  }
  const bool hollow = b.barrel_stiffness_n_m > 0.0;
  return {{"value", b.value},
          {"method", b.method},
          {"impact_from_knob_m", b.impact_from_knob_m},
          {"impact_from_tip_m", b.impact_from_tip_m},
          {"refinement", b.refinement},
          {"ball", b.ball},
          {"ball_speed_mps", b.ball_speed_mps},
          {"ball_cor", b.ball_cor},
          {"pivot_from_knob_m", b.pivot_from_knob_m},
          {"barrel_stiffness_n_m", hollow ? Json(b.barrel_stiffness_n_m) : Json(nullptr)},
          {"estimate",
           {{"value", b.estimate_value},
            {"method", b.estimate_method},
            {"impact_from_tip_m", b.estimate_from_tip_m},
            {"error", b.estimate_error}}},
          {"protocol",
           "NCAA BBCOR at the maximum-BBCOR location: the bat at rest on a pivot 6 in from the "
           "knob, the ball fired at 136 mph; e_A = rebound / incoming speed of the flexible "
           "free-free bat, BBCOR = e_A (1 + r) + r, r = m z^2 / I_pivot; the maximum over 4.0 to "
           "8.0 in from the barrel end (every 0.5 in, then polished on the model). estimate: the "
           "fast fixed-point approximation (rigid pivoted bat 6 in from the tip), error = "
           "estimate - value"}};
}

Json BbcorScanToJson(const core::BbcorScan& s) {
  Json points = Json::array();
  for (const auto& p : s.points) {
    points.push_back({{"position_from_tip_m", p.position_from_tip_m},
                      {"position_from_knob_m", p.position_from_knob_m},
                      {"apparent_cor", p.apparent_cor},
                      {"value", p.value},
                      {"rigid_value", p.rigid_value},
                      {"barrel_stiffness_n_m", p.barrel_stiffness_n_m},
                      {"modes_used", p.modes_used}});
  }
  return {{"max_value", s.max_value},
          {"max_from_tip_m", s.max_from_tip_m},
          {"max_from_knob_m", s.max_from_knob_m},
          {"refinement", s.refinement},
          {"polish_impacts", s.polish_impacts},
          {"fixed_point_value", s.fixed_point_value},
          {"fixed_point_from_tip_m", s.fixed_point_from_tip_m},
          {"fixed_point_method", s.fixed_point_method},
          {"points", std::move(points)},
          {"ball", s.ball},
          {"ball_speed_mps", s.ball_speed_mps},
          {"ball_cor", s.ball_cor},
          {"pivot_from_knob_m", s.pivot_from_knob_m},
          {"method", s.method},
          {"elements", s.elements},
          {"protocol",
           "NCAA BBCOR at every point of the scan range (4.0 to 8.0 in from the barrel end every "
           "0.5 in: this service's choice): the ball fired at 136 mph onto the bat at rest, e_A "
           "from the flexible free-free bat (barrel spring in series for a hollow bat), BBCOR = "
           "e_A (1 + r) + r, r = m z^2 / I_pivot about the 6-in pivot; the maximum polished on the "
           "model by successive parabolic interpolation"}};
}

Json CollisionResultToJson(const core::CollisionResult& r) {
  Json out{{"model", core::CollisionModelName(r.model)},
           {"model_reason", r.model_reason},
           {"impact_from_knob_m", r.impact_from_knob_m},
           {"approach_speed_mps", r.approach_speed_mps},
           {"exit_speed_mps", r.exit_speed_mps},
           {"error_estimate", {{"exit_speed_mps", r.error_estimate_mps}}},
           {"cor", r.cor},
           {"cor_source", r.cor_source},
           {"models_used", r.summary.models_used}};
  if (r.cor_impact_speed_mps) out["cor_impact_speed_mps"] = *r.cor_impact_speed_mps;
  out["swing"] = SwingToJson(r.swing);
  if (r.rigid_pivot) {
    const auto& p = *r.rigid_pivot;
    out["rigid_pivot"] = {{"x_from_pivot_m", p.x_from_pivot_m},
                          {"bat_speed_at_impact_mps", p.bat_speed_at_impact_mps},
                          {"collision_efficiency", p.collision_efficiency},
                          {"ball_impulse_n_s", p.ball_impulse_n_s},
                          {"pivot_impulse_n_s", p.pivot_impulse_n_s},
                          {"angular_speed_after_rad_s", p.angular_speed_after_rad_s}};
  }
  if (r.free_bat) {
    const auto& f = *r.free_bat;
    out["free_bat"] = {{"recoil_factor", f.recoil_factor},
                       {"collision_efficiency", f.collision_efficiency},
                       {"bat_speed_at_impact_mps", f.bat_speed_at_impact_mps},
                       {"ball_impulse_n_s", f.ball_impulse_n_s},
                       {"hands_velocity_change_mps", f.hands_velocity_change_mps}};
    Json bbcor{{"applies", f.bbcor.applies}};
    if (f.bbcor.applies) {
      bbcor["pivot_from_knob_m"] = f.bbcor.pivot_from_knob_m;
      bbcor["moi_pivot_kg_m2"] = f.bbcor.moi_pivot_kg_m2;
      bbcor["recoil_factor"] = f.bbcor.recoil_factor;
      bbcor["apparent_cor"] = f.bbcor.apparent_cor;
      bbcor["bbcor"] = f.bbcor.bbcor;
      bbcor["besr"] = f.bbcor.besr;
    }
    out["free_bat"]["bbcor_style"] = std::move(bbcor);
  }
  if (r.hertz) {
    const auto& h = *r.hertz;
    const auto& p = h.problem;
    out["hertz"] = {{"contact_time_s", h.contact_time_s},
                    {"max_compression_m", h.max_compression_m},
                    {"peak_force_n", h.peak_force_n},
                    {"ball_impulse_n_s", h.ball_impulse_n_s},
                    {"hands_impulse_n_s", h.hands_impulse_n_s},
                    {"separation_speed_mps", h.separation_speed_mps},
                    {"apparent_cor", h.apparent_cor},
                    {"steps", h.steps},
                    {"error_estimate",
                     {{"contact_time_s", h.error_estimate_contact_time_s},
                      {"exit_speed_mps", h.error_estimate_exit_speed_mps},
                      {"peak_force_n", h.error_estimate_peak_force_n}}},
                    {"parameters",
                     {{"law", core::ContactLawName(p.law)},
                      {"approach_speed_mps", p.approach_speed_mps},
                      {"ball_mass_kg", p.ball_mass_kg},
                      {"ball_stiffness_n_m_p", p.ball_stiffness},
                      {"ball_exponent", p.ball_exponent},
                      {"surface_stiffness_n_m1_5", p.surface_stiffness},
                      {"cor", p.cor},
                      {"hands_stiffness_n_m", p.hands_stiffness_n_m},
                      {"hands_damping_n_s_m", p.hands_damping_n_s_m},
                      {"c11_per_kg", p.c11_per_kg},
                      {"c12_per_kg", p.c12_per_kg},
                      {"c22_per_kg", p.c22_per_kg}}},
                    {"summary", SummaryToJson(h.summary)}};
    if (p.law == core::ContactLaw::kPaperConstants) {
      out["hertz"]["parameters"]["paper_constants"] = {
          {"k1", p.paper.k1}, {"k2", p.paper.k2}, {"k3", p.paper.k3}};
    }
  }
  if (r.flexible) {
    out["flexible"] = FlexibleImpactToJson(*r.flexible);
    out["flexible"]["cache_hit"] = r.modes_cache_hit;
  }
  Json timings = Json::array();
  for (const auto& t : r.timings) {
    timings.push_back({{"model", t.model}, {"time_s", t.time_s}, {"calls", t.calls}});
  }
  out["timings"] = std::move(timings);
  return out;
}

Json VibrationNodeToJson(const core::VibrationNodeResult& v) {
  return {{"position_from_knob_m", v.position_from_knob_m},
          {"frequency_hz", v.frequency_hz},
          {"other_node_from_knob_m", v.other_node_from_knob_m},
          {"second_mode",
           {{"frequency_hz", v.second_mode_frequency_hz},
            {"nodes_from_knob_m", v.second_mode_nodes_from_knob_m}}},
          {"theory", v.theory},
          {"method", "fem:" + v.theory},
          {"elements", v.elements},
          {"refinement_elements", v.refinement_elements},
          {"relative_tolerance", v.relative_tolerance},
          {"cache_hit", v.cache_hit},
          {"termination", core::TerminationName(v.summary.termination)}};
}

Json LeastStingZoneToJson(const core::LeastStingZoneResult& z) {
  Json curve = Json::array();
  for (const auto& p : z.curve) {
    curve.push_back({{"position_from_knob_m", p.position_from_knob_m},
                     {"exit_speed_mps", p.exit_speed_mps},
                     {"rigid_exit_speed_mps", p.rigid_exit_speed_mps},
                     {"vibration_energy_j", p.vibration_energy_j},
                     {"hands_vibration_energy_j", p.hands_vibration_energy_j},
                     {"hands_peak_shear_force_n", p.hands_peak_shear_force_n},
                     {"hands_peak_bending_moment_n_m", p.hands_peak_bending_moment_n_m},
                     {"contact_time_s", p.contact_time_s}});
  }
  return {{"from_knob_m", z.from_knob_m},
          {"to_knob_m", z.to_knob_m},
          {"min_position_from_knob_m", z.min_position_from_knob_m},
          {"min_hands_energy_j", z.min_hands_energy_j},
          {"max_hands_energy_j", z.max_hands_energy_j},
          {"threshold_j", z.threshold_j},
          {"fraction", z.fraction},
          {"exit_speed_at_min_mps", z.exit_speed_at_min_mps},
          {"clipped_at_hands", z.clipped_at_hands},
          {"clipped_at_tip", z.clipped_at_tip},
          {"modes_used", z.modes_used},
          {"elements", z.elements},
          {"theory", z.theory},
          {"metric",
           "hands_vibration_energy_j: vibration energy left in the grip segment at the "
           "hands after the impact"},
          {"curve", std::move(curve)}};
}

Json FlexibleImpactToJson(const core::FlexibleImpactResult& f) {
  Json modes = Json::array();
  for (std::size_t i = 0; i < f.modal_energies_j.size(); ++i) {
    modes.push_back({{"mode", i + 1},
                     {"frequency_hz", f.mode_frequencies_hz[i]},
                     {"energy_j", f.modal_energies_j[i]}});
  }
  return {{"exit_speed_mps", f.exit_speed_mps},
          {"rigid_exit_speed_mps", f.rigid_exit_speed_mps},
          {"vibration_energy_j", f.vibration_energy_j},
          {"hands",
           {{"vibration_energy_j", f.hands_vibration_energy_j},
            {"peak_shear_force_n", f.hands_peak_shear_force_n},
            {"peak_bending_moment_n_m", f.hands_peak_bending_moment_n_m}}},
          {"contact_time_s", f.contact_time_s},
          {"contact_time_estimate_s", f.contact_time_estimate_s},
          {"contacts", f.contacts},
          {"peak_force_n", f.peak_force_n},
          {"max_compression_m", f.max_compression_m},
          {"ball_impulse_n_s", f.ball_impulse_n_s},
          {"energy",
           {{"initial_j", f.initial_energy_j},
            {"ball_j", f.ball_energy_j},
            {"bat_rigid_body_j", f.rigid_body_energy_j},
            {"vibration_j", f.vibration_energy_j},
            {"contact_loss_j", f.contact_loss_j},
            {"balance_error_j", f.energy_balance_error_j}}},
          {"modes_used", f.modes_used},
          {"modes", std::move(modes)},
          {"cutoff_hz", f.cutoff_hz},
          {"residual_compliance_m_n", f.residual_compliance_m_n},
          {"elements", f.elements},
          {"theory", core::BeamTheoryName(f.theory)},
          {"steps", f.steps},
          {"error_estimate",
           {{"exit_speed_mps", f.error_estimate_exit_speed_mps},
            {"integration_exit_speed_mps", f.integration_error_exit_speed_mps},
            {"truncation_exit_speed_mps", f.truncation_error_exit_speed_mps},
            {"vibration_energy_j", f.error_estimate_vibration_energy_j},
            {"hands_vibration_energy_j", f.error_estimate_hands_energy_j}}},
          {"summary", SummaryToJson(f.summary)}};
}

}  // namespace sweetspot::api
