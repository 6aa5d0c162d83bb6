// /v1/optimize's answer for one design (ResultToJson): the bat in the request's own form, the
// variables as written, the properties, the objective, the sweet spot and the summary with its
// active constraints, certificate and spread. Shared by the single design and the frontier's rows.
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "api/bat_json.hpp"
#include "api/handlers/optimize_request.hpp"
#include "api/json_path.hpp"
#include "api/scene_json.hpp"
#include "api/trade_units.hpp"

namespace sweetspot::api::optimize_detail {
namespace {

using Json = nlohmann::json;

// The answer's bat in the request's own form: each variable written back at
// its path; where the request's form lacks the path's parent (a preset), the
// shape or material block is written out whole.
// True when the object at `steps`' parent in `bat` gives the field in any form (SI or trade).
bool GivesField(const Json& bat, const std::vector<PathStep>& steps) {
  std::string why;
  if (NumberAtPath(bat, steps, &why)) return true;
  std::vector<PathStep> form = steps;
  for (const TradeForm& trade : TradeForms(std::get<std::string>(steps.back()))) {
    form.back() = trade.key;
    if (NumberAtPath(bat, form, &why)) return true;
  }
  return false;
}

Json BatInRequestForm(const Json& request_bat, const core::DesignResult& r,
                      const VariableNames& names) {
  Json bat = request_bat;
  for (const core::DesignValue& v : r.variables) {
    if (v.scale_factor) continue;  // a factor: its fields follow it in the list
    std::string why;
    const auto steps = ParseJsonPath(v.path, &why);
    // A field the bat does not give (a preset's wall), of a variable written in a trade form:
    // written in that form ("wall_thickness_in"), so the bat stays in the request's units.
    const WrittenVariable* written = names.Find(v.path);
    if (steps && written != nullptr && !GivesField(bat, *steps)) {
      if (const auto written_steps = ParseJsonPath(written->written, &why);
          written_steps &&
          SetNumberAtPath(&bat, *written_steps, v.value / written->to_si, &why)) {
        continue;
      }
    }
    // In the request's own units: "taper_start_in" stays inches.
    if (steps && SetNumberInRequestForm(&bat, *steps, v.value, &why)) continue;
    // The request's form lacks the block (a preset): written out whole, in the trade's form
    // when the variable was written in it ("profile.knots[3].diameter_in": every knot in
    // inches, each radius as a diameter), so the bat is in the units the request used.
    const char* block = nullptr;
    if (v.path.rfind("three_segment.", 0) == 0 && r.three_segment) {
      const auto& s = *r.three_segment;
      bat["three_segment"] = {{"length_m", s.length_m},
                              {"handle_radius_m", s.handle_radius_m},
                              {"barrel_radius_m", s.barrel_radius_m},
                              {"taper_start_m", s.taper_start_m},
                              {"taper_end_m", s.taper_end_m}};
      block = "three_segment";
    } else if (v.path.rfind("profile.", 0) == 0) {
      bat["profile"] = BatToJson(r.bat)["profile"];
      block = "profile";
    } else if (v.path.rfind("material.", 0) == 0) {
      bat["material"] = MaterialInRequestForm(r.bat.material);
    } else if (v.path.rfind("fill.", 0) == 0 || v.path == "wall_thickness_m") {
      const Json built = BatToJson(r.bat);
      if (built.contains("fill")) bat["fill"] = built["fill"];
      // The wall in the form the request gave it, if it gave one ("wall_thickness_in").
      if (built.contains("wall_thickness_m")) {
        const std::vector<PathStep> wall{std::string("wall_thickness_m")};
        SetNumberInRequestForm(&bat, wall, built["wall_thickness_m"].get<double>(), &why);
      }
      block = "fill";
    }
    if (block != nullptr && written != nullptr && bat.contains(block)) {
      ToTradeForm(&bat[block]);
    }
  }
  return bat;
}

}  // namespace

Json Finite(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// A material written out whole, as a request gives one (no source or density range; no
// null cor).
Json MaterialInRequestForm(const core::Material& m) {
  Json material = MaterialToJson(m);
  material.erase("source");
  material.erase("density_range_kg_m3");
  if (material["cor"].is_null()) material.erase("cor");
  return material;
}

namespace {

// The active constraints of a design, each a variable's bound as the request wrote the
// variable ("three_segment.barrel_diameter_in.max": its value and bound in inches, the
// multiplier per inch); any other constraint in its own unit.
Json DesignActiveConstraintsJson(const core::DesignResult& r, const VariableNames& names) {
  Json active = Json::array();
  for (const auto& a : r.active_constraints) {
    const std::size_t dot = a.name.rfind('.');
    const WrittenVariable* written =
        dot == std::string::npos ? nullptr : names.Find(a.name.substr(0, dot));
    const double f = written != nullptr ? written->to_si : 1.0;
    active.push_back(
        {{"name", written != nullptr ? written->written + a.name.substr(dot) : a.name},
         {"unit", written != nullptr && written->written.size() > 3 &&
                          written->written.compare(written->written.size() - 3, 3, "_in") == 0
                      ? std::string("in")
                      : a.unit},
         {"value", a.value / f},
         {"bound", a.bound / f},
         {"multiplier", Finite(a.multiplier * f)},  // null for min_sting
         {"satisfied", a.satisfied},
         {"tolerance", a.tolerance / f}});
  }
  return active;
}

// The multistart's spread: how many starts converged and were feasible, the objective's range
// (in the objective's unit) and each run.
Json DesignSpreadJson(const core::DesignResult& r) {
  Json runs = Json::array();
  for (const auto& s : r.spread.runs) {
    runs.push_back({{"index", s.index},
                    {"termination", core::TerminationName(s.termination)},
                    {"raw_status", s.raw_status},
                    {"iterations", s.iterations},
                    {"objective", Finite(s.objective)},
                    {"constraint_violation", Finite(s.constraint_violation)}});
  }
  return {{"starts", r.spread.starts},
          {"converged", r.spread.converged},
          {"feasible", r.spread.feasible},
          {"best_start", r.spread.best_start},
          {"objective_min", Finite(r.spread.objective_min)},
          {"objective_max", Finite(r.spread.objective_max)},
          {"objective_median", Finite(r.spread.objective_median)},
          {"runs", std::move(runs)}};
}

// The service's own first-order check of the answer (core/optimize/certificate.hpp): its
// residuals and tolerances (dimensionless, scaled as the certificate scales them).
Json DesignCertificateJson(const core::DesignCertificate& cert) {
  return {{"checked", cert.checked},
          {"certified", cert.certified},
          {"stationarity", Finite(cert.stationarity)},
          {"feasibility", Finite(cert.feasibility)},
          {"complementarity", Finite(cert.complementarity)},
          {"stationarity_tolerance", cert.stationarity_tolerance},
          {"feasibility_tolerance", cert.feasibility_tolerance},
          {"complementarity_tolerance", cert.complementarity_tolerance},
          {"multipliers_unique", cert.multipliers_unique},
          {"active", cert.active},
          {"failed", cert.failed}};
}

// The design's summary: the solve's Summary with its constraint violation, error estimate,
// active constraints, spread, certificate, merged constraints and derivative check.
Json DesignSummaryJson(const core::DesignResult& r, const VariableNames& names) {
  Json summary = SummaryToJson(r.summary);
  summary["constraint_violation"] = Finite(r.summary.constraint_violation);
  summary["error_estimate"] = Finite(r.summary.error_estimate);  // null for min_sting
  summary["active_constraints"] = DesignActiveConstraintsJson(r, names);
  summary["spread"] = DesignSpreadJson(r);
  summary["certificate"] = DesignCertificateJson(r.certificate);
  if (!r.merged_constraints.empty()) {
    Json merged = Json::array();
    for (const core::MergedConstraint& m : r.merged_constraints) {
      merged.push_back({{"name", m.name}, {"into", m.into}, {"message", m.message}});
    }
    summary["merged_constraints"] = std::move(merged);
  }
  if (r.derivative_check_errors >= 0) {
    summary["derivative_check"] = {{"errors", r.derivative_check_errors},
                                   {"report", r.derivative_check_report}};
  }
  return summary;
}

// The constraints that could not all be met: each group's requested and achievable ranges
// (in the group's `unit`) and the shortfall.
Json DesignConflictsJson(const core::DesignResult& r) {
  Json conflicts = Json::array();
  for (const auto& c : r.conflicts) {
    conflicts.push_back({{"constraints", c.constraints},
                         {"unit", c.unit},
                         {"requested_min", Finite(c.requested_min)},
                         {"requested_max", Finite(c.requested_max)},
                         {"achievable_min", Finite(c.achievable_min)},
                         {"achievable_max", Finite(c.achievable_max)},
                         {"shortfall", Finite(c.shortfall)},
                         {"message", c.message}});
  }
  return conflicts;
}

// max_distance: the answer's distance sweet spot (SI), as /v1/sweet-spot's
// distance_sweet_spot gives it for the returned bat in the same scene.
Json DesignDistanceSweetSpotJson(const core::DistanceSweetSpotResult& d) {
  return {{"position_from_knob_m", d.position_from_knob_m},
          {"undercut_m", d.undercut_m},
          {"distance_m", d.distance_m},
          {"exit_speed_mps", d.exit_speed_mps},
          {"launch_angle_deg", d.launch_angle_deg},
          {"backspin_rpm", d.backspin_rpm + 0.0},
          {"hang_time_s", d.ball.flight.hang_time_s},
          {"apex_m", d.ball.flight.apex_m},
          {"bat_speed_at_impact_mps", d.ball.bat_speed_at_impact_mps},
          {"aero_model", core::flight::AeroModelName(d.ball.aero_model)},
          {"air_density_kg_m3", d.ball.flight.air_density_kg_m3},
          {"distance_error_estimate_m", Finite(d.ball.flight.error_estimate_m)},
          {"at_position_bound", d.at_position_bound},
          {"at_undercut_bound", d.at_undercut_bound},
          {"evaluations", d.evaluations}};
}

// The outputs a design has only when its objective or constraints asked for them (SI), added
// to *out: the barrel COR's impact, the BBCOR, the first bending mode, the sting and the
// distance sweet spot.
void AddDesignOptionalOutputs(const core::DesignResult& r, Json* out) {
  if (std::isfinite(r.cor_impact_from_knob_m)) {
    // The design's own barrel COR (cor_from_barrel): where and at what speed it was taken.
    (*out)["cor_impact_from_knob_m"] = r.cor_impact_from_knob_m;
    (*out)["cor_impact_speed_mps"] = Finite(r.cor_impact_speed_mps);
    (*out)["cor_ball"] = Finite(r.cor_ball);
  }
  if (r.bbcor) {
    (*out)["bbcor"] = BbcorToJson(*r.bbcor);
    // The certification rounds (core/optimize/bbcor_constraint.hpp).
    (*out)["bbcor"]["rounds"] = r.bbcor_rounds;
    (*out)["bbcor"]["estimate_offset"] = r.bbcor_estimate_offset;
  }
  if (r.first_bending_mode) {
    const core::DesignFrequency& f = *r.first_bending_mode;
    (*out)["first_bending_mode"] = {{"frequency_hz", Finite(f.frequency_hz)},
                                    {"error_estimate_hz", Finite(f.error_estimate_hz)},
                                    {"elements", f.elements},
                                    {"model_frequency_hz", Finite(f.model_frequency_hz)},
                                    {"model_elements", f.model_elements}};
  }
  if (r.sting) {
    (*out)["sting"] = {{"position_from_knob_m", r.sting->impact_from_knob_m},
                       {"hands_vibration_energy_j", r.sting->hands_vibration_energy_j},
                       {"error_estimate_j", r.sting->error_estimate_j},
                       {"flexible", FlexibleImpactToJson(r.sting->impact)}};
  }
  if (r.distance_sweet_spot) {
    (*out)["distance_sweet_spot"] = DesignDistanceSweetSpotJson(*r.distance_sweet_spot);
  }
}

}  // namespace

Json ResultToJson(const core::DesignResult& r, const Json& request_bat,
                  const VariableNames& names) {
  // Each variable as the request wrote it, in its unit ("wall_thickness_in": inches).
  Json variables = names.ValuesAsWritten(r.variables);
  Json summary = DesignSummaryJson(r, names);
  Json conflicts = DesignConflictsJson(r);
  Json out{{"bat", BatInRequestForm(request_bat, r, names)},
           {"variables", std::move(variables)},
           {"properties", PropertiesToJson(r.properties, r.bat.LengthM())},
           {"objective_value", Finite(r.objective_value)},
           {"objective_unit", r.objective_unit},
           {"cor", r.cor},
           {"sweet_spot",
            {{"position_from_knob_m", Finite(r.sweet_spot_from_knob_m)},
             {"placement", core::PlacementName(r.sweet_spot_placement)},
             {"exit_speed_mps", Finite(r.max_exit_speed_mps)},
             {"angular_speed_rad_s", Finite(r.angular_speed_rad_s)}}},
           {"summary", std::move(summary)}};
  if (!conflicts.empty()) out["conflicts"] = std::move(conflicts);
  AddDesignOptionalOutputs(r, &out);
  return out;
}

}  // namespace sweetspot::api::optimize_detail
