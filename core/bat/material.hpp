// Materials of bats and fills, and the built-in catalogue with its sources.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/refusal.hpp"

namespace sweetspot::core {

// The magnitudes a material given from outside (a request) is held to, by ValidateSize.
// Core's numerics work beyond them (tests/hard_cases: 1e6 kg/m³, E x 1e6).
/// Largest density of a material, kg/m³ (osmium, the densest element, has 22,590).
inline constexpr double kMaxDensityKgM3 = 1e5;
/// Largest Young's or shear modulus of a material, Pa (diamond's is about 1.2e12).
inline constexpr double kMaxModulusPa = 1e13;

/// What a material is, for league rules and the catalogue listing.
enum class MaterialKind {
  kWood,       ///< Solid wood of one species.
  kMetal,      ///< A metal (an alloy shell).
  kComposite,  ///< A fibre composite.
  kFill,       ///< A fill (cork, rubber): inside a bat, never the bat itself.
};

/// Stable name: "wood", "metal", "composite", "fill".
const char* MaterialKindName(MaterialKind kind);

/// An isotropic material (for wood: the longitudinal modulus and the
/// longitudinal-radial shear modulus and Poisson's ratio). All values SI.
struct Material {
  std::string name;  ///< Catalogue name ("ash") or "custom".
  /// What it is; unset for a custom material given without a base (its kind is not known).
  std::optional<MaterialKind> kind;
  /// The catalogue entry its properties start from: its own name for a catalogue entry, the
  /// base of a request's {"base": NAME, ...overrides}; "" for a custom material without one.
  std::string base;
  /// True when neither shear_modulus_pa nor poissons_ratio was given (a custom material
  /// without a base): poissons_ratio is the default 0.3, and G = E / 2.6 from it; scenes warn.
  bool poissons_ratio_assumed = false;
  /// Density, kg/m³ (> 0; 0 only as a fill's material, meaning an empty bore).
  double density_kg_m3 = 0.0;
  double youngs_modulus_pa = 0.0;  ///< Young's modulus along the bat's axis, Pa (> 0).
  double shear_modulus_pa = 0.0;   ///< Shear modulus, Pa (>= 0); 0 = derive from Poisson's ratio.
  double poissons_ratio = 0.3;     ///< Poisson's ratio, dimensionless, in (-1, 0.5).
  /// Default coefficient of restitution against a baseball, in [0, 1], if known.
  std::optional<double> cor;
  /// Lower end of the density range the source gives, kg/m³ (0 = none; informational).
  double density_min_kg_m3 = 0.0;
  /// Upper end of the density range the source gives, kg/m³ (0 = none; informational).
  double density_max_kg_m3 = 0.0;
  std::string source;  ///< Where the numbers come from (citation).

  /// True when every field is finite and in its physical range; otherwise
  /// stores the refusal in *refusal (if non-null): field, value and rule, its Message()
  /// "field = value: rule". Rules: density > 0,
  /// E > 0, G >= 0, -1 < nu < 0.5, 0 <= cor <= 1, range bounds >= 0 and
  /// min <= max when both are given. The density range is informational: a
  /// density outside it is accepted (sweeps and custom materials use that).
  bool Validate(Refusal* refusal) const;
  /// Validate, then the plausible magnitudes: density in (0, kMaxDensityKgM3], E in
  /// (0, kMaxModulusPa], G in [0, kMaxModulusPa] ("density_kg_m3 = 2e+05: must be in
  /// (0, 1e+05]"); for a material given from outside.
  bool ValidateSize(Refusal* refusal) const;
  /// Shear modulus in Pa: shear_modulus_pa if set, else E / (2 (1 + nu)).
  double EffectiveShearModulusPa() const;
};

/// The built-in catalogue (immutable, thread-safe to read). Entries: "ash",
/// "hard-maple", "yellow-birch", "maple-bat-billet", "paper-wood", "aluminium-7046",
/// "aluminium-7050", "carbon-epoxy-fabric", "cork", "rubber"; each with its source.
const std::vector<Material>& MaterialCatalogue();
/// The catalogue entry called `name` or one of its aliases (MaterialAliases), or nullopt.
std::optional<Material> FindMaterial(std::string_view name);
/// The common names accepted for catalogue entry `name` ("hard-maple": {"maple"}); empty when
/// it has none.
std::vector<std::string> MaterialAliases(std::string_view name);
/// The catalogue names and aliases, comma-separated ("ash, hard-maple (maple), ..."): for
/// messages.
std::string MaterialNamesList();
/// The "material" of an empty bore (name "empty", every number 0). It is not
/// a valid Material on its own; Bat::IsValid accepts it as a fill's material.
Material EmptyFillMaterial();

}  // namespace sweetspot::core
