#include "core/scene/scene.hpp"

#include <cmath>

#include "core/geometry_format.hpp"

namespace sweetspot::core {
namespace {


bool Fail(std::string* why, const std::string& m) {
  if (why != nullptr) *why = m;
  return false;
}

}  // namespace

bool Ball::IsValid(std::string* why) const {
  // Floors of 1 mg and 1 µm: smaller values are not balls, and a subnormal
  // mass made 1/m infinite in the free-bat and Hertz models (found by fuzzing).
  if (!(std::isfinite(mass_kg) && mass_kg >= kMinBallMassKg))
    return Fail(why, "ball.mass_kg = " + FormatNumber17(mass_kg) + ": must be finite and >= 1e-06");
  if (!(std::isfinite(radius_m) && radius_m >= kMinBallRadiusM))
    return Fail(why,
                "ball.radius_m = " + FormatNumber17(radius_m) + ": must be finite and >= 1e-06");
  if (!(std::isfinite(speed_mps) && speed_mps >= 0.0))
    return Fail(why, "ball.speed_mps = " + FormatNumber17(speed_mps) + ": must be >= 0");
  if (!(std::isfinite(stiffness) && stiffness > 0.0))
    return Fail(why, "ball.stiffness = " + FormatNumber17(stiffness) + ": must be finite and > 0");
  if (!(std::isfinite(stiffness_exponent) && stiffness_exponent >= 1.0 &&
        stiffness_exponent <= 3.0))
    return Fail(why, "ball.stiffness_exponent = " + FormatNumber17(stiffness_exponent) +
                         ": must be in [1, 3]");
  return true;
}

bool Swing::IsValid(std::string* why) const {
  if (!(std::isfinite(angular_speed_rad_s) && angular_speed_rad_s >= 0.0))
    return Fail(why, "swing.angular_speed_rad_s = " + FormatNumber17(angular_speed_rad_s) +
                         ": must be >= 0");
  if (!std::isfinite(pivot_from_knob_m))
    return Fail(
        why, "swing.pivot_from_knob_m = " + FormatNumber17(pivot_from_knob_m) + ": must be finite");
  if (!std::isfinite(hands_from_knob_m))
    return Fail(
        why, "swing.hands_from_knob_m = " + FormatNumber17(hands_from_knob_m) + ": must be finite");
  return true;
}

bool Scene::IsValid(std::string* why) const {
  if (!bat.has_value() && !mass_properties.has_value())
    return Fail(why, "bat: missing (give a bat or precomputed mass_properties)");
  if (bat.has_value()) {
    std::string inner;
    if (!bat->IsValid(&inner)) return Fail(why, "bat: " + inner);
  } else if (!(std::isfinite(length_m) && length_m > 0.0)) {
    return Fail(why, "length_m = " + FormatNumber17(length_m) +
                         ": must be finite and > 0 when only mass_properties are given");
  }
  if (mass_properties.has_value()) {
    const MassProperties& mp = *mass_properties;
    if (!(std::isfinite(mp.mass_kg) && mp.mass_kg > 0.0))
      return Fail(why, "mass_properties.mass_kg = " + FormatNumber17(mp.mass_kg) +
                           ": must be finite and > 0");
    if (!std::isfinite(mp.balance_point_m))
      return Fail(why, "mass_properties.balance_point_m = " + FormatNumber17(mp.balance_point_m) +
                           ": must be finite");
    if (!(std::isfinite(mp.moi_centroid_kg_m2) && mp.moi_centroid_kg_m2 > 0.0))
      return Fail(why, "mass_properties.moi_centroid_kg_m2 = " +
                           FormatNumber17(mp.moi_centroid_kg_m2) + ": must be finite and > 0");
    if (!std::isfinite(mp.moi_knob_kg_m2))
      return Fail(why, "mass_properties.moi_knob_kg_m2 = " + FormatNumber17(mp.moi_knob_kg_m2) +
                           ": must be finite");
  }
  if (!ball.IsValid(why) || !swing.IsValid(why)) return false;
  if (cor.has_value() && !(std::isfinite(*cor) && *cor >= 0.0 && *cor <= 1.0))
    return Fail(why, "cor = " + FormatNumber17(*cor) + ": must be in [0, 1]");
  if (outputs.empty()) return Fail(why, "outputs: empty: name at least one output");
  return true;
}

bool SceneOptions::IsValid(std::string* why) const {
  if (!nlopt.IsValid(why)) return false;
  if (!(std::isfinite(sweet_zone_tolerance) && sweet_zone_tolerance >= 0.0))
    return Fail(
        why, "sweet_zone_tolerance = " + FormatNumber17(sweet_zone_tolerance) + ": must be >= 0");
  if (max_curve_points < 2)
    return Fail(why, "max_curve_points = " + std::to_string(max_curve_points) + ": must be >= 2");
  if (curve_positions_from_knob_m.empty() &&
      (curve_samples < 2 || curve_samples > max_curve_points))
    return Fail(why, "curve_samples = " + std::to_string(curve_samples) + ": must be in [2, " +
                         std::to_string(max_curve_points) + "]");
  if (curve_positions_from_knob_m.size() > static_cast<size_t>(max_curve_points))
    return Fail(
        why, "curve_positions_from_knob_m: " + std::to_string(curve_positions_from_knob_m.size()) +
                 " positions: must be at most " + std::to_string(max_curve_points));
  for (size_t i = 0; i < curve_positions_from_knob_m.size(); ++i) {
    if (!std::isfinite(curve_positions_from_knob_m[i]))
      return Fail(why, "curve_positions_from_knob_m[" + std::to_string(i) + "] = " +
                           FormatNumber17(curve_positions_from_knob_m[i]) + ": must be finite");
  }
  if (!hertz.IsValid(why)) return false;
  return flexible.IsValid(why);
}

bool FlexibleOptions::IsValid(std::string* why) const {
  if (!(std::isfinite(frequency_tolerance) && frequency_tolerance >= 1e-9 &&
        frequency_tolerance <= 0.1))
    return Fail(why, "flexible.frequency_tolerance = " + FormatNumber17(frequency_tolerance) +
                         ": must be in [1e-9, 0.1]");
  if (max_elements < 2 || max_elements > 4096)
    return Fail(
        why, "flexible.max_elements = " + std::to_string(max_elements) + ": must be in [2, 4096]");
  if (sting_samples < 3 || sting_samples > 1001)
    return Fail(why, "flexible.sting_samples = " + std::to_string(sting_samples) +
                         ": must be in [3, 1001]");
  if (!(std::isfinite(sting_zone_fraction) && sting_zone_fraction > 0.0 &&
        sting_zone_fraction <= 1.0))
    return Fail(why, "flexible.sting_zone_fraction = " + FormatNumber17(sting_zone_fraction) +
                         ": must be in (0, 1]");
  return impact.IsValid(why);
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

std::optional<CollisionModel> ParseCollisionModel(std::string_view name) {
  for (CollisionModel m :
       {CollisionModel::kAuto, CollisionModel::kRigidPivot, CollisionModel::kFreeBat,
        CollisionModel::kHertz, CollisionModel::kFlexible}) {
    if (name == CollisionModelName(m)) return m;
  }
  return std::nullopt;
}

}  // namespace sweetspot::core
