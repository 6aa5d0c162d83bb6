// The sweet spots the paper names (maximum exit speed, centre of percussion, node of the
// fundamental bending mode), the sweet zone and the exit-speed curve: result types and
// the closed forms. The numeric definitions are in numeric.hpp, least_sting.hpp and
// vibration_node.hpp beside this file; the orchestration (which model, which method) is
// core/scene/evaluate_scene.hpp.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/collision/exit_speed_profile.hpp"
#include "core/summary.hpp"

namespace sweetspot::core {

/// The former refusal of vibration_node (kept for callers that quote it; no longer returned).
inline constexpr char kVibrationNodeRefusal[] =
    "vibration_node needs the flexible beam model, which is not available yet";
/// The name of the flexible beam's modal model (in models_used and timings).
inline constexpr char kFlexibleBeamModel[] = "flexible_beam";

/// Where an optimum lies relative to the bat.
enum class Placement {
  kOnBat,       ///< Inside [0, L].
  kBeyondTip,   ///< The unconstrained optimum is beyond the tip: the tip is reported.
  kBeforeKnob,  ///< The unconstrained optimum is before the knob: the knob is reported.
};

/// Stable name: "on_bat", "beyond_tip", "before_knob".
const char* PlacementName(Placement placement);

/// The max_exit_speed output.
struct MaxExitSpeedResult {
  double position_from_knob_m = 0.0;        ///< The sweet spot on the bat, m from the knob.
  double exit_speed_mps = 0.0;              ///< The exit speed there, m/s.
  Placement placement = Placement::kOnBat;  ///< kBeyondTip / kBeforeKnob: clamped to the bat.
  double unconstrained_position_from_knob_m =
      0.0;  ///< The unconstrained maximiser (closed form), m; equals position_from_knob_m for
            ///< searches.
  double error_estimate_m = 0.0;    ///< Estimated error of the position, m.
  double error_estimate_mps = 0.0;  ///< Estimated error of the speed, m/s.
  std::string model;                ///< The exit-speed model, e.g. "rigid_pivot".
  std::string method;               ///< "closed_form" or "nlopt:<ALGORITHM>".
  Summary summary;                  ///< The solve's report (NLopt counts for searches).
};

/// The center_of_percussion output: for a pivot at the hands h,
/// CoP = h + I_h / (M (C - h)), I_h the moment of inertia about the hands.
struct CenterOfPercussionResult {
  double position_from_knob_m = 0.0;  ///< The centre of percussion, m from the knob.
  double hands_from_knob_m = 0.0;     ///< The hands it refers to, m from the knob.
  double moi_hands_kg_m2 = 0.0;       ///< I_h, kg m^2.
  Placement placement =
      Placement::kOnBat;          ///< kBeyondTip when CoP > L (the value is still reported).
  double error_estimate_m = 0.0;  ///< Rounding bound, m.
};

/// The sweet_zone output.
struct SweetZoneResult {
  double from_knob_m = 0.0;       ///< Start of the zone, m from the knob.
  double to_knob_m = 0.0;         ///< End of the zone, m from the knob.
  double tolerance_mps = 0.0;     ///< The tolerance applied, m/s (percentages converted).
  double threshold_mps = 0.0;     ///< max exit speed - tolerance, m/s.
  bool clipped_at_knob = false;   ///< The zone would extend before the knob.
  bool clipped_at_tip = false;    ///< The zone would extend beyond the tip.
  double error_estimate_m = 0.0;  ///< Estimated error of each end, m.
  std::string method;             ///< "closed_form" or "root_finding".
};

/// One point of the exit-speed curve.
struct CurvePoint {
  double position_from_knob_m = 0.0;  ///< Impact position, m from the knob.
  double exit_speed_mps = 0.0;        ///< Exit speed, m/s.
};

/// The exit_speed_curve output.
struct ExitSpeedCurveResult {
  std::vector<CurvePoint> points;   ///< In the order requested (samples: knob to tip).
  double error_estimate_mps = 0.0;  ///< Largest estimated error over the points, m/s.
  std::string model;                ///< The exit-speed model.
};

/// The vibration_node output: the nodes of the free-free bat's first two bending modes
/// (core/flexible/modes.hpp). The sweet spot is the barrel-side node of the fundamental: an
/// impact there excites it least, so the hands get the least vibration energy.
struct VibrationNodeResult {
  double position_from_knob_m = 0.0;      ///< Barrel-side node of mode 1, m from the knob.
  double frequency_hz = 0.0;              ///< Mode 1's natural frequency, Hz.
  double other_node_from_knob_m = 0.0;    ///< Handle-side node of mode 1, m from the knob.
  double second_mode_frequency_hz = 0.0;  ///< Mode 2's natural frequency, Hz.
  std::vector<double> second_mode_nodes_from_knob_m;  ///< Mode 2's nodes, m from the knob.
  double error_estimate_m = 0.0;                      ///< Estimated error of the node positions, m.
  double error_estimate_hz = 0.0;                     ///< Estimated error of frequency_hz, Hz.
  double second_mode_error_estimate_hz = 0.0;  ///< Estimated error of mode 2's frequency, Hz.
  double relative_tolerance = 0.0;             ///< The requested relative frequency tolerance.
  int elements = 0;                            ///< Elements of the final mesh.
  std::vector<int> refinement_elements;        ///< Elements of every mesh solved.
  std::string theory;                          ///< "timoshenko" or "euler_bernoulli".
  bool cache_hit = false;                      ///< The modes came from the cross-request cache.
  Summary summary;                             ///< The modes computation's report.
};

/// One impact of the least_sting_zone sweep: the flexible and the rigid (free bat) models.
struct StingPoint {
  double position_from_knob_m = 0.0;      ///< Impact position, m from the knob.
  double exit_speed_mps = 0.0;            ///< Flexible bat, m/s.
  double rigid_exit_speed_mps = 0.0;      ///< Free rigid bat (same e and mass properties), m/s.
  double vibration_energy_j = 0.0;        ///< Energy left in the bending modes, J.
  double hands_vibration_energy_j = 0.0;  ///< Of which in the grip segment at the hands, J.
  double hands_peak_shear_force_n = 0.0;  ///< Peak shear force at the hands' section, N.
  double hands_peak_bending_moment_n_m = 0.0;  ///< Peak bending moment there, N m.
  double contact_time_s = 0.0;                 ///< Contact time, s.
  double error_estimate_exit_speed_mps = 0.0;  ///< m/s.
  double error_estimate_hands_energy_j = 0.0;  ///< J.
};

/// The least_sting_zone output: flexible impacts swept from the hands to the tip; the zone is
/// the connected interval around the least-sting impact where the hands' vibration energy
/// E(s) <= E_min + fraction (E_max - E_min) (E_max: the largest over the sweep).
struct LeastStingZoneResult {
  double from_knob_m = 0.0;               ///< Start of the zone, m from the knob.
  double to_knob_m = 0.0;                 ///< End of the zone, m from the knob.
  double min_position_from_knob_m = 0.0;  ///< The least-sting impact, m from the knob.
  double min_hands_energy_j = 0.0;        ///< E there, J.
  double max_hands_energy_j = 0.0;        ///< Largest E over the sweep, J.
  double threshold_j = 0.0;               ///< E_min + fraction (E_max - E_min), J.
  double fraction = 0.0;                  ///< The fraction used.
  double exit_speed_at_min_mps = 0.0;     ///< Flexible exit speed at the least-sting impact, m/s.
  bool clipped_at_hands = false;          ///< The zone reaches the start of the sweep.
  bool clipped_at_tip = false;            ///< The zone reaches the tip.
  double error_estimate_m = 0.0;          ///< Estimated error of the ends and the minimum, m.
  std::vector<StingPoint> curve;          ///< The sweep, knob to tip order.
  int modes_used = 0;                     ///< Most bending modes used by an impact.
  int elements = 0;                       ///< Elements of the beam mesh.
  std::string theory;                     ///< The beam theory.
};

/// The numbers of the closed-form sweet spot over the bat, without the result's strings
/// (ClosedFormMaxExitSpeed's, which it fills from these): a sweep's designs.
struct ClosedFormMaximum {
  double position_from_knob_m = 0.0;                ///< The sweet spot on the bat, m from the knob.
  double exit_speed_mps = 0.0;                      ///< The exit speed there, m/s.
  double unconstrained_position_from_knob_m = 0.0;  ///< The unconstrained maximiser, m.
  Placement placement = Placement::kOnBat;          ///< Where the unconstrained one lies.
  bool flat = false;                ///< The exit speed is the same everywhere (ProfileMaximum).
  double error_estimate_m = 0.0;    ///< As MaxExitSpeedResult's.
  double error_estimate_mps = 0.0;  ///< As MaxExitSpeedResult's.
};

/// The closed-form sweet spot of `profile` over the bat [0, length_m] (candidates: the clamped
/// unconstrained maximiser and both ends, so it is the maximum over the bat in every case).
ClosedFormMaximum ClosedFormMaximumOnBat(const ExitSpeedProfile& profile, double length_m);

/// ClosedFormMaximumOnBat as a max_exit_speed result (method, summary, warnings).
MaxExitSpeedResult ClosedFormMaxExitSpeed(const ExitSpeedProfile& profile, double length_m);

/// The closed-form sweet zone: the connected interval around `max.position_from_knob_m` where
/// the exit speed is >= max.exit_speed_mps - tolerance_mps, clipped to [0, length_m].
SweetZoneResult ClosedFormSweetZone(const ExitSpeedProfile& profile, double length_m,
                                    const MaxExitSpeedResult& max, double tolerance_mps);

/// The centre of percussion relative to the hands, or nullopt with the reason in *why when it
/// does not exist (the balance point is not beyond the hands).
std::optional<CenterOfPercussionResult> CenterOfPercussion(const MassProperties& mass_properties,
                                                           double hands_from_knob_m,
                                                           double length_m, std::string* why);
/// CenterOfPercussion with the reason as data (field "swing.hands_from_knob_m") in *why.
std::optional<CenterOfPercussionResult> CenterOfPercussion(const MassProperties& mass_properties,
                                                           double hands_from_knob_m,
                                                           double length_m, Refusal* why);

}  // namespace sweetspot::core
