// Named bats: the paper's bat and realistic modern bats, each with where its
// numbers come from.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/bat/bat.hpp"

namespace sweetspot::core {

/// A named, ready-to-use bat.
struct BatPreset {
  std::string name;         ///< Identifier, e.g. "paper-wood".
  Bat bat;                  ///< The bat (valid).
  std::string description;  ///< One line for humans (length, weight, shape).
  std::string source;       ///< Where every number comes from.
};

/// The built-in presets (immutable, thread-safe to read):
/// - "paper-wood": the paper's three-segment bat with 7 cm and 2.5 cm read as
///   diameters (r1 = 0.0125 m, r2 = 0.035 m), x1 = 0.3459 m, x2 = 0.6423 m,
///   L = 0.855 m, material "paper-wood" (649 kg/m³): M = 1.0078 kg, C = 0.6090 m.
/// - "paper-wood-m885": the same shape at 569.9 kg/m³, which weighs the
///   paper's 0.885 kg.
/// - "wood-34-ash": a 34-in solid white-ash bat, 2.61-in barrel, 31.5 oz.
/// - "wood-34-maple-turned": a 34-in solid maple bat turned to a medium-handle pro model,
///   bat-grade maple billet ("maple-bat-billet"), 2.50-in barrel, 32.0 oz.
/// - "bbcor-33-aluminium": a 33-in hollow 7050-aluminium BBCOR bat, 2 5/8-in
///   barrel, 30 oz (drop 3), wall thickness solved for the weight.
const std::vector<BatPreset>& BatPresets();
/// The preset called `name`, or nullopt.
std::optional<BatPreset> FindPreset(std::string_view name);
/// The preset called `name` where BatPresets() keeps it (for the process's life), or null:
/// FindPreset without the copy.
const BatPreset* PresetNamed(std::string_view name);

/// The paper's three-segment shape (diameter reading; see "paper-wood").
ThreeSegmentShape PaperThreeSegmentShape();

}  // namespace sweetspot::core
