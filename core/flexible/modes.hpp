// The free-free bending modes of a bat: K phi = omega^2 M phi by Eigen's generalized
// self-adjoint eigensolver on the beam of core/flexible/beam_model.hpp, with the mesh refined
// (every element split in two) until the requested frequencies agree with their
// Richardson-extrapolated values within a relative tolerance; the error estimate is reported.
//
// Solver: shift-invert Lanczos on the sparse banded K + sigma M (Eigen's SimplicialLDLT,
// natural ordering: no fill outside the band), in the M inner product, kept M-orthogonal to the
// two rigid modes (known exactly: K's null space) and fully reorthogonalised; the Ritz values
// theta of the tridiagonal give lambda = 1/theta - sigma. Started from the sum of the seed
// vectors: on the first mesh cosines, with sigma from a uniform beam of the bat's mean section;
// on every finer mesh the coarser mesh's Ritz vectors prolonged exactly onto the nested mesh,
// sigma = its first bending eigenvalue. Accepted when every wanted mode's residual
// |(lambda + sigma) (K + sigma M)^-1 M x - x| is below 1e-9 |x| (or stalls at round-off below
// 1e-6) and a Sturm count (the negative pivots of K - mu M, mu just above the last wanted
// eigenvalue) confirms that no mode below was missed. The answer is then, as the former
// solver's, a Rayleigh-Ritz step of (K, M) on (K + sigma M)^-1 M applied to the Ritz vectors
// (1/theta - sigma itself carries the solves' rounding: ~2e-8 on 1700-DOF meshes, where the
// Rayleigh quotients of shift-inverted vectors stay at the floor below). Otherwise the former
// solver runs:
// shift-invert subspace iteration from the same seeds with a Rayleigh-Ritz step on the small
// projected problem, to the same residual rule. (A dense generalized solve of the whole mesh
// is accurate only to ~eps lambda_max / lambda_k relative, which a stiff shear term makes
// useless; it remains a last fallback for small meshes.) Cost: one banded solve and O(n j)
// reorthogonalisation per Lanczos step, ~2 num_modes + 8 steps per mesh.
//
// Accuracy control: on nested meshes h, h/2, h/4 the frequencies converge as h^p (p = 4 for
// Hermite cubics and for the interdependent Timoshenko element). With the last two meshes the
// error of the finer one is estimated as |f_h/2 - f_h| / (2^p - 1), p the order observed on
// the last three meshes clamped to [1, 4] (2 when only two meshes exist): never more optimistic
// than the theoretical order. The first num_modes modes must all meet the tolerance.
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/bat/bat.hpp"
#include "core/flexible/beam_model.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// Options of ComputeBatModes.
struct BeamModesOptions {
  BeamTheory theory = BeamTheory::kTimoshenko;  ///< Beam theory.
  int num_modes = 4;  ///< Flexible modes computed and held to the tolerance, in [1, 50].
  double relative_tolerance = 1e-4;  ///< Estimated relative frequency error, in [1e-9, 0.1].
  int initial_elements = 8;  ///< First mesh: max(this, 2 num_modes + 4) elements, in [1, 4096].
  int max_elements = 512;    ///< No mesh beyond this many elements (no_convergence), in [2, 4096].
  bool rotary_inertia = true;  ///< Timoshenko: include rho I (false only to compare theories).

  /// True when every field is in range; otherwise the refusal in *refusal (if
  /// non-null): field, value and rule, its Message() "field = value: rule".
  bool Validate(Refusal* refusal) const;
};

/// One flexible mode.
struct BeamMode {
  double frequency_hz = 0.0;       ///< Natural frequency on the finest mesh, Hz.
  double error_estimate_hz = 0.0;  ///< Estimated error of frequency_hz, Hz.
  double observed_order = 0.0;     ///< Convergence order seen on the last 3 meshes (0 = n/a).
  /// Zeros of the displacement, m from the knob, increasing (root bracketing on the FE
  /// interpolant).
  std::vector<double> nodes_from_knob_m;
  double nodes_error_estimate_m = 0.0;  ///< Largest estimated error of a node position, m.
  /// Mass-normalised DOF vector (w in m/sqrt(kg), theta in rad/sqrt(kg) per node): phi' M phi
  /// = 1; the sign makes the tip displacement positive.
  Eigen::VectorXd vector;
};

/// The modes of one bat on its final mesh.
struct BatModes {
  /// termination, message, backend "eigen:generalized_self_adjoint", time; evaluations = the
  /// shift-invert steps (Lanczos steps, subspace iterations; 1 for a dense solve) of every mesh.
  Summary summary;
  BeamTheory theory = BeamTheory::kTimoshenko;  ///< The theory used.
  bool rotary_inertia = true;                   ///< Whether rho I is in M (Timoshenko).
  double length_m = 0.0;                        ///< The bat's length, m.
  std::vector<double> nodes_m;                  ///< Final mesh nodes, m from the knob.
  std::vector<double> breakpoints_m;     ///< Section breakpoints (for integrals over the bat), m.
  std::vector<int> refinement_elements;  ///< Elements of every mesh solved, in order.
  double tolerance = 0.0;                ///< The requested relative frequency tolerance.
  double max_relative_error = 0.0;  ///< Largest error_estimate_hz / frequency_hz over the modes.
  double mass_kg = 0.0;             ///< Rigid-body mass of the FE mass matrix, kg.
  double balance_point_m = 0.0;     ///< Its centroid, m from the knob.
  /// Its moment about the centroid, kg m^2 (with rho I for Timoshenko = the rigid-body MOI;
  /// without = the slender-rod MOI).
  double moi_centroid_kg_m2 = 0.0;
  std::vector<BeamMode> modes;  ///< Flexible modes, ascending frequency (num_modes of them).
  /// The final mesh's element parts of K, M t and M r0 (BeamElementPartsOf), which the static
  /// flexibility under inertia relief reuses for the elements its mesh keeps (empty: none).
  std::vector<BeamElementParts> element_parts;

  /// Number of elements of the final mesh.
  int Elements() const { return nodes_m.empty() ? 0 : static_cast<int>(nodes_m.size()) - 1; }
  /// Displacement of the DOF vector `v` at x (m from the knob, clamped to the bat).
  double Displacement(const Eigen::VectorXd& v, double x_m) const;
  /// Rotation theta = w_b' of `v` at x (rad per unit of v).
  double Rotation(const Eigen::VectorXd& v, double x_m) const;
  /// Mass-normalised rigid translation (w = 1/sqrt(M) everywhere).
  Eigen::VectorXd TranslationMode() const;
  /// Mass-normalised rigid rotation about the centroid (w = (x - C)/sqrt(I_cm), theta =
  /// 1/sqrt(I_cm)).
  Eigen::VectorXd RotationMode() const;
};

/// The first options.num_modes flexible modes of `bat` (free-free). Never throws. Refuses
/// (invalid_input) an invalid bat, invalid options, and a bat too short to be a beam
/// (length < 4 x its largest outer radius). Reaching max_elements before the tolerance is
/// no_convergence with the finest mesh's modes and their error estimates.
BatModes ComputeBatModes(const Bat& bat, const BeamModesOptions& options);

/// Zeros of `v`'s displacement along the bat, m from the knob (sign changes on 8 samples per
/// element, then TOMS 748 on the interpolant to full precision).
std::vector<double> DisplacementZeros(const BatModes& modes, const Eigen::VectorXd& v);

}  // namespace sweetspot::core
