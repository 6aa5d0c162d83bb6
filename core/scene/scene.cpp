#include "core/scene/scene.hpp"

#include <cmath>

#include "core/geometry_format.hpp"
#include "core/refusal.hpp"

namespace sweetspot::core {
namespace {

// The refusal of `field` = `value` as the scene writes it (17 significant digits).
bool Refuse17(Refusal* out, std::string_view field, double value, std::string_view rule) {
  return out == nullptr ? false : Refuse(out, Number17Refusal(field, value, rule));
}

// True when `value` is finite and in [lo, hi]; otherwise the refusal of `field` with the
// rule "must be in [lo, hi]", written from the bounds themselves.
bool CheckRange(Refusal* out, std::string_view field, double value, double lo, double hi) {
  if (std::isfinite(value) && value >= lo && value <= hi) return true;
  return Refuse17(out, field, value,
                  "must be in [" + FormatNumber(lo) + ", " + FormatNumber(hi) + "]");
}

}  // namespace

bool Ball::Validate(Refusal* why) const {
  // Floors of 1 mg and 1 µm: smaller values are not balls, and a subnormal
  // mass made 1/m infinite in the free-bat and Hertz models (found by fuzzing).
  if (!CheckRange(why, "ball.mass_kg", mass_kg, kMinBallMassKg, kMaxBallMassKg)) return false;
  if (!CheckRange(why, "ball.radius_m", radius_m, kMinBallRadiusM, kMaxBallRadiusM)) return false;
  if (!CheckRange(why, "ball.speed_mps", speed_mps, 0.0, kMaxBallSpeedMps)) return false;
  if (!(std::isfinite(stiffness) && stiffness > 0.0 && stiffness <= kMaxBallStiffness))
    return Refuse17(why, "ball.stiffness", stiffness,
                    "must be in (0, " + FormatNumber(kMaxBallStiffness) + "]");
  if (!(std::isfinite(stiffness_exponent) && stiffness_exponent >= 1.0 &&
        stiffness_exponent <= 3.0))
    return Refuse17(why, "ball.stiffness_exponent", stiffness_exponent, "must be in [1, 3]");
  if (!CheckRange(why, "ball.descent_angle_deg", descent_angle_deg, -kMaxPathAngleDeg,
                  kMaxPathAngleDeg) ||
      !CheckRange(why, "ball.spin_rpm", spin_rpm, -kMaxPitchSpinRpm, kMaxPitchSpinRpm)) {
    return false;
  }
  return !cor_law.has_value() || cor_law->Validate(why);
}

void ApplyBallPreset(const BallPreset& preset, Ball* ball) {
  ball->mass_kg = preset.mass_kg;
  ball->radius_m = preset.radius_m;
  ball->stiffness = preset.stiffness;
  ball->stiffness_exponent = preset.stiffness_exponent;
  ball->preset = preset.name;
  ball->cor_law = preset.cor_law;
}

bool Swing::Validate(Refusal* why) const {
  return CheckRange(why, "swing.angular_speed_rad_s", angular_speed_rad_s, 0.0,
                    kMaxSwingAngularSpeedRadS) &&
         CheckRange(why, "swing.pivot_from_knob_m", pivot_from_knob_m, -kMaxSwingOffsetM,
                    kMaxSwingOffsetM) &&
         CheckRange(why, "swing.hands_from_knob_m", hands_from_knob_m, -kMaxSwingOffsetM,
                    kMaxSwingOffsetM) &&
         (!bat_speed_mps.has_value() ||
          CheckRange(why, "swing.bat_speed_mps", *bat_speed_mps, 0.0, kMaxBatSpeedMps)) &&
         CheckRange(why, "swing.bat_speed_from_tip_m", bat_speed_from_tip_m, 0.0,
                    kMaxSwingOffsetM) &&
         CheckRange(why, "swing.attack_angle_deg", attack_angle_deg, -kMaxPathAngleDeg,
                    kMaxPathAngleDeg) &&
         ValidateSpeedModel(why);
}

bool Swing::ValidateSpeedModel(Refusal* why) const {
  if (reference_moi_kg_m2.has_value() &&
      !(std::isfinite(*reference_moi_kg_m2) && *reference_moi_kg_m2 > 0.0 &&
        *reference_moi_kg_m2 <= kMaxSwingMoiKgM2)) {
    return Refuse17(why, "swing.reference_moi_kg_m2", *reference_moi_kg_m2,
                    "must be in (0, " + FormatNumber(kMaxSwingMoiKgM2) + "]");
  }
  if (!CheckRange(why, "swing.swing_weight_exponent", swing_weight_exponent, 0.0,
                  kMaxSwingWeightExponent)) {
    return false;
  }
  if (bat_speed_point == BatSpeedPoint::kSweetSpot && !bat_speed_mps.has_value()) {
    return why == nullptr ? false
                          : Refuse(why, QuotedRefusal("swing.bat_speed_from_tip_m", "sweet_spot",
                                                      "needs swing.bat_speed_mps (the speed "
                                                      "measured at the sweet spot)"));
  }
  if (speed_model == SwingSpeedModel::kSwingWeight && !bat_speed_mps.has_value()) {
    return why == nullptr ? false
                          : Refuse(why, QuotedRefusal("swing.speed_model", "swing_weight",
                                                      "needs swing.bat_speed_mps (the reference "
                                                      "bat's speed)"));
  }
  if (speed_model != SwingSpeedModel::kSwingWeight) {
    // Settings of the swing-weight model without it would have no effect.
    if (reference_moi_kg_m2.has_value()) {
      return Refuse17(why, "swing.reference_moi_kg_m2", *reference_moi_kg_m2,
                      "applies only with swing.speed_model = swing_weight");
    }
    if (swing_weight_exponent != kSwingWeightExponent) {
      return Refuse17(why, "swing.swing_weight_exponent", swing_weight_exponent,
                      "applies only with swing.speed_model = swing_weight");
    }
  }
  return true;
}

const char* BatSpeedPointName(BatSpeedPoint point) {
  return point == BatSpeedPoint::kSweetSpot ? "sweet_spot" : "distance";
}

const char* SwingSpeedModelName(SwingSpeedModel model) {
  return model == SwingSpeedModel::kSwingWeight ? "swing_weight" : "fixed";
}

std::optional<SwingSpeedModel> ParseSwingSpeedModel(std::string_view name) {
  for (SwingSpeedModel m : {SwingSpeedModel::kFixed, SwingSpeedModel::kSwingWeight}) {
    if (name == SwingSpeedModelName(m)) return m;
  }
  return std::nullopt;
}

bool Contact::Validate(Refusal* why) const {
  return CheckRange(why, "contact.undercut_m", undercut_m, -kMaxUndercutM, kMaxUndercutM);
}

bool ResolveSwing(const Swing& swing, double length_m, Swing* resolved, Refusal* refusal) {
  *resolved = swing;
  if (!swing.bat_speed_mps.has_value()) return true;
  const double from_tip = swing.bat_speed_from_tip_m;
  if (!(from_tip <= length_m)) {
    return Refuse17(refusal, "swing.bat_speed_from_tip_m", from_tip,
                    "the bat-speed point must be on the bat: at most its length " +
                        FormatNumber17(length_m) + " m from the tip");
  }
  const double x = length_m - from_tip;  // the bat-speed point, m from the knob
  const double arm = x - swing.pivot_from_knob_m;
  if (!(arm > 0.0)) {
    return Refuse17(refusal, "swing.bat_speed_from_tip_m", from_tip,
                    "the bat-speed point (" + FormatNumber17(x) +
                        " m from the knob) must lie beyond the pivot (swing.pivot_from_knob_m = " +
                        FormatNumber17(swing.pivot_from_knob_m) + ")");
  }
  const double omega = *swing.bat_speed_mps / arm;
  if (!(omega <= kMaxSwingAngularSpeedRadS)) {
    return Refuse17(refusal, "swing.bat_speed_mps", *swing.bat_speed_mps,
                    "gives angular_speed_rad_s = " + FormatNumber17(omega) + " over " +
                        FormatNumber17(kMaxSwingAngularSpeedRadS) + " (the point is " +
                        FormatNumber17(arm) + " m from the pivot)");
  }
  resolved->angular_speed_rad_s = omega;
  return true;
}

bool Scene::Validate(Refusal* why) const {
  if (!bat.has_value() && !mass_properties.has_value())
    return Refuse(why, TextRefusal("bat", "missing (give a bat or precomputed mass_properties)"));
  if (bat.has_value()) {
    // "bat: knots[1].x_m = ...: ...": the refusal names "bat" and quotes the bat's own
    // refusal as its rule.
    Refusal inner;
    if (!bat->Validate(why == nullptr ? nullptr : &inner)) {
      return Refuse(why, TextRefusal("bat", inner.Message()));
    }
  } else if (!(std::isfinite(length_m) && length_m > 0.0)) {
    return Refuse17(why, "length_m", length_m,
                    "must be finite and > 0 when only mass_properties are given");
  }
  if (mass_properties.has_value()) {
    const MassProperties& mp = *mass_properties;
    if (!(std::isfinite(mp.mass_kg) && mp.mass_kg > 0.0))
      return Refuse17(why, "mass_properties.mass_kg", mp.mass_kg, "must be finite and > 0");
    if (!std::isfinite(mp.balance_point_m))
      return Refuse17(why, "mass_properties.balance_point_m", mp.balance_point_m, "must be finite");
    if (!(std::isfinite(mp.moi_centroid_kg_m2) && mp.moi_centroid_kg_m2 > 0.0))
      return Refuse17(why, "mass_properties.moi_centroid_kg_m2", mp.moi_centroid_kg_m2,
                      "must be finite and > 0");
    if (!std::isfinite(mp.moi_knob_kg_m2))
      return Refuse17(why, "mass_properties.moi_knob_kg_m2", mp.moi_knob_kg_m2, "must be finite");
  }
  if (!ball.Validate(why) || !swing.Validate(why) || !contact.Validate(why)) return false;
  // The flight's own validators, their fields under the scene's objects ("environment.").
  if (Refusal inner; !environment.Validate(why == nullptr ? nullptr : &inner))
    return why == nullptr ? false : Refuse(why, Prefixed("environment.", std::move(inner)));
  if (Refusal inner; !aero.Validate(why == nullptr ? nullptr : &inner))
    return why == nullptr ? false : Refuse(why, Prefixed("aero.", std::move(inner)));
  if (!ValidateCor(why)) return false;
  if (outputs.empty())
    return Refuse(why, TextRefusal("outputs", "empty: name at least one output"));
  return true;
}

bool Scene::ValidateCor(Refusal* why) const {
  if (cor.has_value() && !(std::isfinite(*cor) && *cor >= 0.0 && *cor <= 1.0))
    return Refuse17(why, "cor", *cor, "must be in [0, 1]");
  return true;
}

bool SceneOptions::Validate(Refusal* why) const {
  if (!nlopt.Validate(why)) return false;
  // Named by its unit, as a request names it.
  const bool percent = sweet_zone_unit == ToleranceUnit::kPercent;
  if (!CheckRange(why, percent ? "sweet_zone_tolerance_percent" : "sweet_zone_tolerance_mps",
                  sweet_zone_tolerance, 0.0, percent ? 100.0 : 1e3))
    return false;
  if (max_curve_points < 2)
    return Refuse(why, IntegerRefusal("max_curve_points", max_curve_points, "must be >= 2"));
  if (curve_positions_from_knob_m.empty() &&
      (curve_samples < 2 || curve_samples > max_curve_points))
    return Refuse(why, IntegerRefusal("curve_samples", curve_samples,
                                      "must be in [2, " + std::to_string(max_curve_points) + "]"));
  if (curve_positions_from_knob_m.size() > static_cast<size_t>(max_curve_points))
    return Refuse(
        why, TextRefusal("curve_positions_from_knob_m",
                         std::to_string(curve_positions_from_knob_m.size()) +
                             " positions: must be at most " + std::to_string(max_curve_points)));
  for (size_t i = 0; i < curve_positions_from_knob_m.size(); ++i) {
    if (!std::isfinite(curve_positions_from_knob_m[i]))
      return Refuse17(why, "curve_positions_from_knob_m[" + std::to_string(i) + "]",
                      curve_positions_from_knob_m[i], "must be finite");
  }
  if (!hertz.Validate(why)) return false;
  if (!distance.Validate(why)) return false;
  if (Refusal barrel_why; !barrel.Validate(&barrel_why))
    return Refuse(why, TextRefusal("barrel", barrel_why.Message()));
  return flexible.Validate(why);
}

bool DistanceOptions::Validate(Refusal* why) const {
  for (const auto* bound : {&position_min_from_knob_m, &position_max_from_knob_m}) {
    if (bound->has_value() && !(std::isfinite(**bound) && std::abs(**bound) <= kMaxSwingOffsetM)) {
      return Refuse17(why,
                      bound == &position_min_from_knob_m ? "distance.position_min_from_knob_m"
                                                         : "distance.position_max_from_knob_m",
                      **bound, "must be finite and within the bat");
    }
  }
  if (position_min_from_knob_m.has_value() && position_max_from_knob_m.has_value() &&
      !(*position_min_from_knob_m < *position_max_from_knob_m)) {
    return Refuse17(why, "distance.position_max_from_knob_m", *position_max_from_knob_m,
                    "must be greater than distance.position_min_from_knob_m = " +
                        FormatNumber17(*position_min_from_knob_m));
  }
  if (!CheckRange(why, "distance.undercut_min_m", undercut_min_m, -kMaxUndercutM, kMaxUndercutM) ||
      !CheckRange(why, "distance.undercut_max_m", undercut_max_m, -kMaxUndercutM, kMaxUndercutM))
    return false;
  if (!(undercut_min_m < undercut_max_m))
    return Refuse17(
        why, "distance.undercut_max_m", undercut_max_m,
        "must be greater than distance.undercut_min_m = " + FormatNumber17(undercut_min_m));
  const struct {
    const char* field;
    int value, lo, hi;
  } counts[] = {{"distance.coarse_positions", coarse_positions, 2, 201},
                {"distance.coarse_undercuts", coarse_undercuts, 2, 201},
                {"distance.max_evaluations", max_evaluations, 10, 100000},
                {"distance.map_positions", map_positions, 2, 401},
                {"distance.map_undercuts", map_undercuts, 2, 401},
                {"distance.normal_table_speeds", normal_table_speeds, 2, 16},
                {"distance.normal_table_positions", normal_table_positions, 3, 401}};
  for (const auto& c : counts) {
    if (!CheckIntegerInRange(why, c.field, c.value, c.lo, c.hi)) return false;
  }
  return CheckRange(why, "distance.position_tolerance_m", position_tolerance_m, 1e-7, 0.01) &&
         CheckRange(why, "distance.undercut_tolerance_m", undercut_tolerance_m, 1e-8, 0.01);
}

bool FlexibleOptions::Validate(Refusal* why) const {
  if (!(std::isfinite(frequency_tolerance) && frequency_tolerance >= 1e-9 &&
        frequency_tolerance <= 0.1))
    return Refuse17(why, "flexible.frequency_tolerance", frequency_tolerance,
                    "must be in [1e-9, 0.1]");
  if (max_elements < 2 || max_elements > 4096)
    return Refuse(why,
                  IntegerRefusal("flexible.max_elements", max_elements, "must be in [2, 4096]"));
  if (sting_samples < 3 || sting_samples > 1001)
    return Refuse(why,
                  IntegerRefusal("flexible.sting_samples", sting_samples, "must be in [3, 1001]"));
  if (!(std::isfinite(sting_zone_fraction) && sting_zone_fraction > 0.0 &&
        sting_zone_fraction <= 1.0))
    return Refuse17(why, "flexible.sting_zone_fraction", sting_zone_fraction, "must be in (0, 1]");
  if (!search.Validate(why)) {
    if (why != nullptr) *why = Prefixed("flexible.search.", std::move(*why));
    return false;
  }
  return impact.Validate(why);
}

BeamModesOptions FlexibleOptions::VibrationModes() const {
  BeamModesOptions o;
  o.theory = theory;
  o.num_modes = 2;
  o.relative_tolerance = frequency_tolerance;
  o.max_elements = max_elements;
  return o;
}

BeamModesOptions FlexibleOptions::ImpactModes() const {
  BeamModesOptions o;
  o.theory = theory;
  o.num_modes = impact.max_modes;
  o.relative_tolerance = impact.frequency_tolerance;
  o.max_elements = max_elements;
  return o;
}

const char* CollisionModelName(CollisionModel model) {
  switch (model) {
    case CollisionModel::kAuto:
      return "auto";
    case CollisionModel::kRigidPivot:
      return "rigid_pivot";
    case CollisionModel::kFreeBat:
      return "free_bat";
    case CollisionModel::kHertz:
      return "hertz";
    case CollisionModel::kFlexible:
      return "flexible";
  }
  return "auto";
}

CollisionModel ResolveExitModel(CollisionModel requested, const Scene& scene, std::string* reason) {
  if (requested != CollisionModel::kAuto) {
    *reason = "requested";
    return requested;
  }
  if (scene.paper_bat) {
    *reason =
        "auto: rigid_pivot, the paper's model (the bat pinned at the pivot), for the paper's bat; "
        "options.model = free_bat gives the free bat";
    return CollisionModel::kRigidPivot;
  }
  *reason =
      "auto: free_bat, the bat free during the ~1 ms contact and hit in the swing's velocity "
      "field (closed form); rigid_pivot is the paper's pinned bat, flexible adds bending";
  return CollisionModel::kFreeBat;
}

std::optional<CollisionModel> ParseCollisionModel(std::string_view name) {
  for (CollisionModel m :
       {CollisionModel::kAuto, CollisionModel::kRigidPivot, CollisionModel::kFreeBat,
        CollisionModel::kHertz, CollisionModel::kFlexible}) {
    if (name == CollisionModelName(m)) return m;
  }
  return std::nullopt;
}

}  // namespace sweetspot::core
