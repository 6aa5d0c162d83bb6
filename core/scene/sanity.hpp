// Sanity warnings (issue 19): a bat, ball or swing far outside anything real is still
// computed, but the answer says which value looks like a slip of units ("bat length = 33 m:
// no bat is longer than 1.2 m (47 in); inches given as metres?"). The bat's mass is read from
// the mass properties the request computed once (never computed again here).
#pragma once

#include <string>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/bat/mass_properties.hpp"
#include "core/scene/scene.hpp"

namespace sweetspot::core {

/// The bounds of "real" (documented in docs/api.md, "Sanity warnings").
struct SanityBounds {
  double max_bat_length_m = 1.2;        ///< The longest bats (fungo, softball) are ~0.94 m.
  double max_bat_radius_m = 0.05;       ///< The widest barrels: 2 3/4 in diameter (0.035 m).
  double min_bat_mass_kg = 0.3;         ///< Youth bats weigh ~0.45 kg (16 oz).
  double max_bat_mass_kg = 2.0;         ///< The heaviest (~1.6 kg, 56 oz, historical).
  double max_ball_speed_mps = 60.0;     ///< The fastest pitches are ~47 m/s (105 mph).
  double max_ball_mass_kg = 0.25;       ///< A 12 in softball is 0.19 kg (7 oz).
  double max_ball_radius_m = 0.06;      ///< A 12 in softball's radius is 0.0485 m.
  double max_bat_tip_speed_mps = 60.0;  ///< Elite bat speeds are ~40 m/s (90 mph).
};

/// The warnings for `bat` (may be null) with its `bat_properties` (the request's, computed
/// once; null: the mass is not checked), `ball` and `swing` (null: not part of the request),
/// each naming the quantity, its value and the likely slip. Empty for real equipment.
std::vector<std::string> SanityWarnings(const Bat* bat, const MassProperties* bat_properties,
                                        const Ball* ball, const Swing* swing,
                                        const SanityBounds& bounds = SanityBounds{});

/// SanityWarnings of a scene (its bat when given, with `bat_properties`, its ball and swing).
std::vector<std::string> SceneSanityWarnings(const Scene& scene,
                                             const MassProperties& bat_properties);

}  // namespace sweetspot::core
