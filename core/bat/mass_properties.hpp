// Exact (closed-form) mass properties of a bat: the integrands are polynomials
// on each profile segment, so they are integrated exactly, not by quadrature.
// Each segment is integrated about its own midpoint and the centroidal moment
// is summed about the centroid directly (never as I_knob - M C^2), so tiny
// segments, steps and nearly equal radii lose no accuracy. Exact gradients
// with respect to every design parameter come from the same integrals
// (forward-mode automatic differentiation with fixed-size derivative vectors).
#pragma once

#include <string>

#include <Eigen/Core>

#include "core/bat/bat.hpp"
#include "core/units.hpp"

namespace sweetspot::core {

/// Which moment of inertia to compute.
enum class InertiaModel {
  /// Full rigid-body value: includes each cross-section's own moment about a
  /// diameter (ρπr⁴/4 per unit length, ρπ(r_o⁴ − r_i⁴)/4 for a shell).
  kRigidBody,
  kSlenderRod,  ///< The paper's integral J = ∫ ρ π r² x² dx (disk term omitted).
};

/// Mass properties of a bat. Moments are about axes perpendicular to the bat.
struct MassProperties {
  InertiaModel inertia_model = InertiaModel::kRigidBody;  ///< How the moments were computed.
  /// Volume of material (bat material + non-empty fill; an end cap or knob adds none), m³.
  double volume_m3 = 0.0;
  double mass_kg = 0.0;             ///< Total mass, kg.
  double balance_point_m = 0.0;     ///< Centroid from the knob, m.
  double moi_knob_kg_m2 = 0.0;      ///< About the knob (x = 0), kg·m² (= MoiAboutKgM2(0)).
  double moi_centroid_kg_m2 = 0.0;  ///< About the centroid, kg·m².

  /// About a pivot at p metres from the knob (negative = behind the knob),
  /// kg·m²: I_cm + M (p − C)² (both terms positive: no cancellation).
  double MoiAboutKgM2(double pivot_from_knob_m) const;
  /// About the standard pivot 6 in (0.1524 m) from the knob, kg·m².
  double MoiSixInchKgM2() const { return MoiAboutKgM2(kSixInchPivotM); }
};

/// Largest distance of a pivot from the knob, either way, m (no bat swings about a point
/// 100 m away).
inline constexpr double kMaxPivotFromKnobM = 100.0;

/// True when `pivot_from_knob_m` (a pivot for MoiAboutKgM2, m from the knob) is finite and
/// within ±kMaxPivotFromKnobM; otherwise "pivot_from_knob_m = value: must be in [-100, 100]"
/// in *refusal (if non-null).
bool ValidatePivotFromKnob(double pivot_from_knob_m, Refusal* refusal);

/// Mass properties of `bat` (precondition: bat.Validate(nullptr); for an
/// invalid bat every field is NaN). Never throws, never allocates; O(knots).
MassProperties ComputeMassProperties(const Bat& bat, InertiaModel model = InertiaModel::kRigidBody);
/// ComputeMassProperties of a bat the caller has checked (Bat::Validate passed, or
/// ValidateGeometry with its materials known valid): the same numbers, without checking the bat
/// again (a sweep's designs, validated once each). Undefined for an invalid bat.
MassProperties ComputeMassPropertiesOfValidBat(const Bat& bat,
                                               InertiaModel model = InertiaModel::kRigidBody);

/// A test probe, not a statistic: how many mass-property computations (each
/// ComputeMassPropertiesOfValidBat, which ComputeMassProperties and
/// ComputeMassPropertiesWithGradient call, and each ComputeMassPropertiesOfBothModels) have run
/// on the calling thread since it started. Thread-local, so the core keeps no mutable state
/// shared between threads; only tests read it (tests/api/computed_once_test.cpp: one
/// computation per request and per bat), by differences around a call on the same thread.
long long MassPropertiesComputationsOnThisThread();

/// A bat's mass properties under both inertia models from one computation (the mass, volume
/// and balance point are the same in both; only the centroidal moment differs): the same
/// numbers as ComputeMassProperties(bat, kRigidBody) and (bat, kSlenderRod). Precondition as
/// ComputeMassProperties (for an invalid bat every field is NaN).
struct MassPropertiesOfBothModels {
  MassProperties rigid_body;   ///< InertiaModel::kRigidBody.
  MassProperties slender_rod;  ///< InertiaModel::kSlenderRod.

  /// The properties under `model`.
  const MassProperties& Of(InertiaModel model) const {
    return model == InertiaModel::kSlenderRod ? slender_rod : rigid_body;
  }
};
MassPropertiesOfBothModels ComputeMassPropertiesOfBothModels(const Bat& bat);

/// Where each design parameter sits in a gradient vector, for a bat with
/// num_knots knots. The layout is always 2 * num_knots + 5 long:
///   [0, K)        "knots[i].radius_m"   (m)
///   [K, 2K)       "knots[i].x_m"        (m; knots[0].x_m must stay 0 for a valid
///                                        bat, its derivative is still exact)
///   2K            "density_kg_m3"       (the bat's material)
///   2K + 1        "wall_thickness_m"    (0 for a solid bat: wall = 0 → solid is a
///                                        jump, not a derivative)
///   2K + 2        "fill.diameter_m"
///   2K + 3        "fill.depth_m"
///   2K + 4        "fill.density_kg_m3"  (the three fill entries are 0 for a bat
///                                        without fill)
struct DesignParameterLayout {
  int num_knots = 0;  ///< K, the number of knots.

  /// Index of knots[i].radius_m.
  int KnotRadius(int i) const { return i; }
  /// Index of knots[i].x_m.
  int KnotPosition(int i) const { return num_knots + i; }
  /// Index of the bat material's density.
  int Density() const { return 2 * num_knots; }
  /// Index of the wall thickness.
  int WallThickness() const { return 2 * num_knots + 1; }
  /// Index of the fill's diameter.
  int FillDiameter() const { return 2 * num_knots + 2; }
  /// Index of the fill's depth.
  int FillDepth() const { return 2 * num_knots + 3; }
  /// Index of the fill material's density.
  int FillDensity() const { return 2 * num_knots + 4; }
  /// Length of a parameter or gradient vector.
  int Size() const { return 2 * num_knots + 5; }
  /// The parameter's name, e.g. "knots[3].radius_m", "fill.depth_m"; "" if out of range.
  std::string Name(int index) const;
};

/// The design parameters of `bat` in DesignParameterLayout order (fill
/// entries 0 without a fill).
Eigen::VectorXd DesignParameters(const Bat& bat);
/// `bat` with its design parameters replaced by `parameters` (DesignParameterLayout
/// order, size 2K + 5; returns `bat` unchanged for a wrong size). The fill
/// entries are applied only when `bat` has a fill. The result is not validated.
Bat WithDesignParameters(const Bat& bat, const Eigen::VectorXd& parameters);

/// Mass properties and their exact gradients with respect to the design
/// parameters (DesignParameterLayout). Each gradient entry is in the
/// property's unit per the parameter's unit (e.g. kg per m for ∂mass/∂x_i).
struct MassPropertiesWithGradient {
  MassProperties properties;               ///< The values (identical to ComputeMassProperties).
  DesignParameterLayout layout;            ///< How the gradients are indexed.
  Eigen::VectorXd volume_gradient;         ///< ∂volume_m3 / ∂θ.
  Eigen::VectorXd mass_gradient;           ///< ∂mass_kg / ∂θ.
  Eigen::VectorXd balance_point_gradient;  ///< ∂balance_point_m / ∂θ.
  Eigen::VectorXd moi_knob_gradient;       ///< ∂moi_knob_kg_m2 / ∂θ.
  Eigen::VectorXd moi_centroid_gradient;   ///< ∂moi_centroid_kg_m2 / ∂θ.

  /// ∂MoiAboutKgM2(pivot) / ∂θ for a fixed pivot p metres from the knob.
  Eigen::VectorXd MoiAboutGradient(double pivot_from_knob_m) const;
  /// ∂MoiSixInchKgM2() / ∂θ.
  Eigen::VectorXd MoiSixInchGradient() const { return MoiAboutGradient(kSixInchPivotM); }
};

/// Mass properties of `bat` with exact gradients. For an invalid bat every
/// value and gradient entry is NaN (gradients sized for bat.knots.size()); for a two-piece bat
/// (bat.handle: the design model has no handle) the values and NaN gradients.
/// Never throws; allocates only the gradient vectors.
MassPropertiesWithGradient ComputeMassPropertiesWithGradient(
    const Bat& bat, InertiaModel model = InertiaModel::kRigidBody);

/// Mass properties in the bat industry's units.
struct ImperialProperties {
  double length_in = 0.0;  ///< Length, in.
  double weight_oz = 0.0;  ///< Weight (mass), oz.
  /// Length in inches minus weight in ounces (3 for a 33-in, 30-oz bat, sold as "drop −3").
  double drop = 0.0;
  double balance_point_in = 0.0;     ///< Balance point from the knob, in.
  double moi_knob_oz_in2 = 0.0;      ///< MOI about the knob, oz·in².
  double moi_six_inch_oz_in2 = 0.0;  ///< MOI about the 6-in pivot, oz·in².
  double moi_centroid_oz_in2 = 0.0;  ///< MOI about the centroid, oz·in².
};

/// Imperial view of `properties` for a bat of length `length_m` (metres).
ImperialProperties ToImperial(const MassProperties& properties, double length_m);

}  // namespace sweetspot::core
