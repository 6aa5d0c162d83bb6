// Exact (closed-form) mass properties of a bat: the integrands are polynomials
// on each profile segment, so they are integrated exactly, not by quadrature.
#pragma once

#include "core/bat.hpp"
#include "core/units.hpp"

namespace sweetspot::core {

/// Which moment of inertia to compute.
enum class InertiaModel {
  kRigidBody,   ///< Full rigid-body value: includes each cross-section's r²/4 term.
  kSlenderRod,  ///< The paper's integral J = ∫ ρ π r² x² dx (disk term omitted).
};

/// Mass properties of a bat. Moments are about axes perpendicular to the bat.
struct MassProperties {
  InertiaModel inertia_model = InertiaModel::kRigidBody;  ///< How the moments were computed.
  double volume_m3 = 0.0;           ///< Volume of material (bat material + fill), m³.
  double mass_kg = 0.0;             ///< Total mass, kg.
  double balance_point_m = 0.0;     ///< Centroid from the knob, m.
  double moi_knob_kg_m2 = 0.0;      ///< About the knob (x = 0), kg·m².
  double moi_centroid_kg_m2 = 0.0;  ///< About the centroid, kg·m².

  /// About a pivot at p metres from the knob (negative = behind the knob), kg·m².
  double MoiAboutKgM2(double pivot_from_knob_m) const;
  /// About the standard pivot 6 in (0.1524 m) from the knob, kg·m².
  double MoiSixInchKgM2() const { return MoiAboutKgM2(kSixInchPivotM); }
};

/// Mass properties of `bat` (precondition: bat.IsValid(nullptr); for an
/// invalid bat every field is NaN). Never throws.
MassProperties ComputeMassProperties(const Bat& bat,
                                     InertiaModel model = InertiaModel::kRigidBody);

}  // namespace sweetspot::core
