// The ball catalogue: regulation baseballs and softballs with their mass, radius, COR and its
// dependence on impact speed, and contact stiffness, each with its source (the rule books and
// the ASTM F1887 / F1888 test conditions; docs/models.md, "Balls"). SI throughout; a scene
// selects an entry with `ball.preset` (core/scene/scene.hpp, ApplyBallPreset).
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/refusal.hpp"

namespace sweetspot::core {

/// A ball's COR against a rigid solid-wood surface as a function of the normal impact speed:
/// e(v) = cor_at_reference - slope_per_mps (clamp(v, min_speed_mps, max_speed_mps) -
/// reference_speed_mps). Constant outside [min_speed_mps, max_speed_mps]; non-increasing in v
/// when slope_per_mps >= 0.
struct BallCorLaw {
  double cor_at_reference = 0.5;     ///< e0: the COR at the test speed, in [0, 1].
  double reference_speed_mps = 0.0;  ///< v0: the test speed, m/s (> 0).
  double slope_per_mps = 0.0;        ///< k: COR lost per m/s above v0, 1/(m/s) (>= 0).
  double min_speed_mps = 0.0;        ///< Lower end of the law's range, m/s (the COR is held below).
  double max_speed_mps = 0.0;        ///< Upper end of the law's range, m/s (the COR is held above).

  /// The COR at normal impact speed speed_mps (m/s, finite), clamped to [0, 1].
  double CorAt(double speed_mps) const;
  /// True when every field is finite and in range (min <= v0 <= max, e(v) in [0, 1] over the
  /// range); otherwise the refusal "ball.cor_law.field = value: rule" in *refusal (if non-null).
  bool Validate(Refusal* refusal) const;
};

/// One catalogue ball. The contact law is the one the contact models use, F = k delta^p
/// (core/collision/contact_law.hpp), with delta the ball's compression against a rigid surface.
struct BallPreset {
  std::string name;          ///< Catalogue name ("mlb", "ncaa-nfhs", ...).
  std::string description;   ///< One line: what ball, which rule.
  double mass_kg = 0.0;      ///< Nominal mass, kg (the midpoint of the rule's range).
  double mass_min_kg = 0.0;  ///< The rule's smallest mass, kg.
  double mass_max_kg = 0.0;  ///< The rule's largest mass, kg.
  double radius_m = 0.0;     ///< Nominal radius, m (from the midpoint of the rule's circumference).
  double circumference_min_m = 0.0;  ///< The rule's smallest circumference, m.
  double circumference_max_m = 0.0;  ///< The rule's largest circumference, m.
  BallCorLaw cor_law;                ///< The COR against solid wood and its speed dependence.
  std::string cor_test;              ///< The COR test: standard, speed and surface.
  double stiffness = 0.0;            ///< k in F = k delta^p, N/m^p.
  double stiffness_exponent = 1.5;   ///< p (dimensionless).
  std::string stiffness_basis;       ///< How k was obtained (measurement, rule, calibration).
  std::string source;                ///< Where every number comes from (citations).
};

/// The built-in catalogue (immutable, thread-safe to read): "mlb", "ncaa-nfhs",
/// "softball-12-fastpitch", "softball-12-slowpitch-44", "softball-12-slowpitch-52"; each with
/// its source.
const std::vector<BallPreset>& BallCatalogue();
/// The catalogue entry called `name`, or nullopt.
std::optional<BallPreset> FindBallPreset(std::string_view name);
/// The catalogue's names, comma separated, in catalogue order ("mlb, ncaa-nfhs, ...").
std::string BallPresetNames();

/// k of F = k (delta/2)^p from a static two-plate compression test (ASTM F1888: the force
/// force_n, N, that shortens the ball's diameter by displacement_m, m, i.e. delta/2 at each
/// plate), for exponent p. A quasi-static stiffness: a ball is stiffer at impact rates.
double StiffnessFromStaticCompression(double force_n, double displacement_m, double exponent);

/// The power-law k (N/m^p, exponent p) whose rigid-wall impact at speed_mps (m/s) of a ball of
/// mass_kg (kg) has the peak force of a linear spring of ASTM F2845's dynamic stiffness
/// DS = F_peak^2 / (m v^2), dynamic_stiffness_n_m (N/m): k = F^(p+1) / ((p+1) m v^2 / 2)^p.
double StiffnessFromDynamicStiffness(double dynamic_stiffness_n_m, double mass_kg, double speed_mps,
                                     double exponent);

/// The inverse of StiffnessFromDynamicStiffness: ASTM F2845's DS (N/m) of a ball with the power
/// law (stiffness, exponent) and mass mass_kg (kg) hitting a rigid wall at speed_mps (m/s).
double DynamicStiffnessOf(double stiffness, double exponent, double mass_kg, double speed_mps);

}  // namespace sweetspot::core
