// bbcor_scan: the BBCOR along the barrel by the flexible model, and its maximum (issue 18 item 2;
// docs/models.md, "BBCOR scan").
//
// The NCAA BBCOR standard certifies a bat at its maximum-BBCOR location, found by testing along
// the barrel. ComputeBbcor (barrel.hpp) evaluates one fixed point (6 in from the tip) with a rigid
// pivoted bat, whose BBCOR rises monotonically toward the handle (no bending loss): a rigid model
// has no maximum to find. Here every point of a range is struck by the flexible model
// (flexible_impact.hpp: the free-free modal beam, the ball's nonlinear contact, the residual
// static compliance and, for a hollow bat, the barrel's spring 1/k_b from BarrelWallAt in series
// with the contact, elastic):
// - the protocol's ball (its catalogue mass, stiffness and COR law at the protocol's speed) at
//   the protocol's speed onto the bat at rest;
// - e_A = rebound speed / incoming speed, and BBCOR(x) = e_A (1 + r) + r with
//   r = m z^2 / I_pivot, z = x - pivot: the lab's conversion, which assumes the rigid bat
//   pivoted at 6 in from the knob. The flexible bat is free-free during the ~1 ms contact (the
//   pivot's reaction does not reach the barrel in that time), so a rigid free bat converted the
//   same way does not give the ball's COR exactly: each point also reports that rigid free-bat
//   value (rigid_value) so the bending loss can be told from the free/pivoted difference.
// - The range (default 4.0 to 8.0 in from the tip every 0.5 in) is this service's choice; no
//   source gives it (the standard certifies "at the maximum BBCOR location", found by testing
//   along the barrel; its own search is not reproduced). The maximum is found on that grid, then
//   POLISHED on the model: when the largest point is interior, successive parabolic
//   interpolation strikes the bat at the vertex of the parabola through the bracket (the
//   largest point and its neighbours), keeps the bracket around the largest struck point, and
//   stops when the vertex moves less than 0.002 in (at most 6 impacts). The maximum reported is
//   a struck point's value, never an interpolation.
// - CertifiedBbcorOf: that maximum is THE BBCOR of this service (issue 35): the `bbcor` output,
//   `rules: bbcor` and the optimiser's BBCOR constraints; ComputeBbcor's fixed point (rigid
//   pivoted bat 6 in from the tip, quasi-static trampoline) is kept beside it as the labelled
//   fast estimate, with its error against the scan.
// The bat's modes are computed once by the caller and reused for every point; when a
// point uses all of them and its mode cutoff lies above twice the highest (the protocol's
// 136 mph impact on a solid wood bat), the scan computes twice as many (at most 50) once and
// scans again with them.
#pragma once

#include <string>
#include <vector>

#include "core/bat/bat.hpp"
#include "core/collision/barrel.hpp"
#include "core/collision/flexible_impact.hpp"
#include "core/flexible/modes.hpp"

namespace sweetspot::core {

/// One point of the scan.
struct BbcorScanPoint {
  double position_from_tip_m = 0.0;   ///< m from the barrel end.
  double position_from_knob_m = 0.0;  ///< m from the knob.
  double apparent_cor = 0.0;          ///< e_A = rebound / incoming ball speed (dimensionless).
  double value = 0.0;                 ///< BBCOR = e_A (1 + r) + r (dimensionless).
  /// The rigid free bat's BBCOR by the same conversion (same e, same mass properties; the
  /// barrel spring absent), dimensionless.
  double rigid_value = 0.0;
  double barrel_stiffness_n_m = 0.0;  ///< k_b in series with the contact (0 for a solid bat), N/m.
  double error_estimate = 0.0;        ///< The impact's exit-speed error estimate on the BBCOR.
  int modes_used = 0;                 ///< Bending modes in the superposition.
};

/// The BBCOR along the barrel and its maximum.
struct BbcorScan {
  bool ok = false;                    ///< False: invalid input or a model failure (message).
  std::string message;                ///< Why not.
  std::vector<std::string> warnings;  ///< The impacts' warnings (deduplicated).
  std::string method = "flexible_free_free";  ///< The model that gives e_A.
  std::string ball;                           ///< Ball used.
  double ball_speed_mps = 0.0;                ///< m/s.
  double ball_cor = 0.0;                      ///< The ball's COR at that speed.
  double pivot_from_knob_m = 0.0;             ///< m.
  std::vector<BbcorScanPoint> points;  ///< Every point, from the tip end of the range inwards.
  int max_index = -1;                  ///< The grid point with the largest BBCOR.
  /// The struck point with the largest BBCOR (a grid point or a polishing impact).
  BbcorScanPoint max_point;
  double max_value = 0.0;              ///< The maximum BBCOR (max_point's value), dimensionless.
  double max_from_tip_m = 0.0;         ///< Its location, m from the barrel end.
  double max_from_knob_m = 0.0;        ///< The same, m from the knob.
  /// "polished" (the grid's largest point refined by successive parabolic interpolation on the
  /// model, the file comment) or "none" (the largest grid point at an end of the range: a
  /// warning says so; or no curvature to polish on).
  std::string refinement;
  int polish_impacts = 0;  ///< Impacts of the polish (beyond the grid's points).
  /// ComputeBbcor's value (rigid pivoted bat at the fixed point), beside it.
  double fixed_point_value = 0.0;
  double fixed_point_from_tip_m = 0.0;  ///< Its point, m from the barrel end.
  std::string fixed_point_method;       ///< ComputeBbcor's method.
  double error_estimate = 0.0;          ///< Largest point error estimate (dimensionless).
  int elements = 0;                     ///< Beam mesh elements.
  int steps = 0;                        ///< Integrator steps over all impacts (polish included).
  double solve_time_s = 0.0;            ///< Wall time, s.
};

/// The scan range's rule: false, with the refusal ("protocol.field") in *why (if non-null),
/// when out of range.
bool BbcorScanRangeValidate(const BbcorProtocol& protocol, Refusal* why);

/// BBCOR of `bat` at every point of `protocol`'s scan range by the flexible model with the
/// bat's `modes` (ComputeBatModes on that bat) and `impact` options (the hands' loads are not
/// computed); `barrel` gives k_b for a hollow bat and the fixed-point value. Never throws.
/// `rigid_body_properties`: the bat's mass properties under InertiaModel::kRigidBody when the
/// caller has computed them (a scene's, once per request); null: computed here.
BbcorScan ComputeBbcorScan(const Bat& bat, const BatModes& modes,
                           const BbcorProtocol& protocol = {},
                           const FlexibleImpactOptions& impact = {},
                           const BarrelOptions& barrel = {},
                           const MassProperties* rigid_body_properties = nullptr);

/// THE BBCOR of `scan` (ok): value = scan.max_value (method "flexible_scan_max", the impact
/// point the maximum's), the fixed-point estimate beside it (estimate_value,
/// estimate_error = estimate - value). A failed scan gives ok = false with its message.
BbcorResult CertifiedBbcorOf(const BbcorScan& scan);

}  // namespace sweetspot::core
