// Materials of bats and fills, and the built-in catalogue with its sources.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace sweetspot::core {

/// An isotropic material. All values SI.
struct Material {
  std::string name;                 ///< Catalogue name ("ash") or "custom".
  double density_kg_m3 = 0.0;       ///< Density, kg/m³ (> 0; 0 allowed only for an empty fill).
  double youngs_modulus_pa = 0.0;   ///< Young's modulus along the bat's axis, Pa (> 0).
  double shear_modulus_pa = 0.0;    ///< Shear modulus, Pa; 0 = derive from Poisson's ratio.
  double poissons_ratio = 0.3;      ///< Poisson's ratio, dimensionless, in (-1, 0.5).
  std::optional<double> cor;        ///< Default coefficient of restitution against a baseball, if known.
  double density_min_kg_m3 = 0.0;   ///< Lower end of the density range the source gives (0 = none).
  double density_max_kg_m3 = 0.0;   ///< Upper end of the density range the source gives (0 = none).
  std::string source;               ///< Where the numbers come from (citation).

  /// True when every field is finite and in its physical range; otherwise
  /// writes "field = value: rule" to *why (if non-null).
  bool IsValid(std::string* why) const;
  /// Shear modulus in Pa: shear_modulus_pa if set, else E / (2 (1 + nu)).
  double EffectiveShearModulusPa() const;
};

/// The built-in catalogue (immutable, thread-safe to read).
const std::vector<Material>& MaterialCatalogue();
/// The catalogue entry called `name`, or nullopt.
std::optional<Material> FindMaterial(std::string_view name);

}  // namespace sweetspot::core
