// The id of a scene output: what a scene can be asked for. Each output is declared once, in
// core/scene/outputs_*.cpp (its name, the models it needs, whether it needs a COR, its
// workload class and how it is computed), and registered in the one table of
// core/scene/output_registry.cpp; the api declares its rendering, explore columns and direct
// accessors against the same id (api/outputs/). Names are listed in id order.
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>

namespace sweetspot::core {

/// What a scene can be asked for (an output's id; its declaration says the rest).
enum class SceneOutput {
  kMaxExitSpeed,        ///< The impact position of maximum exit speed, and that speed.
  kCenterOfPercussion,  ///< The impact position leaving no reaction impulse at the hands.
  kVibrationNode,   ///< The node of the fundamental bending mode (needs the flexible beam model).
  kSweetZone,       ///< Positions whose exit speed is within a tolerance of the maximum.
  kExitSpeedCurve,  ///< Exit speed along the bat.
  kLeastStingZone,  ///< Flexible impacts swept along the bat: where the hands get least vibration.
  kBarrel,          ///< A hollow barrel's hoop mode, stiffness and effective COR (trampoline).
  kBbcor,           ///< BBCOR by the NCAA protocol (core/collision/barrel.hpp).
  /// BBCOR along the barrel by the flexible model and its maximum (core/collision/bbcor_scan.hpp).
  kBbcorScan,
  /// The batted ball at the max-exit-speed point: the oblique impact, then its flight
  /// (core/collision/oblique_impact.hpp, core/flight/flight.hpp).
  kBattedBall,
  /// The impact position and undercut that carry the ball farthest (core/scene/batted_ball.hpp).
  kDistanceSweetSpot,
  /// The carry over a grid of impact positions x undercuts (core/scene/batted_ball.hpp).
  kCarryMap,
};

/// The number of outputs (ids run from 0 to kSceneOutputCount - 1).
inline constexpr std::size_t kSceneOutputCount =
    static_cast<std::size_t>(SceneOutput::kCarryMap) + 1;

/// Stable name, the declaration's: "max_exit_speed", "center_of_percussion", "vibration_node",
/// "sweet_zone", "exit_speed_curve", "least_sting_zone", "barrel", "bbcor", "bbcor_scan",
/// "batted_ball", "distance_sweet_spot", "carry_map".
const char* SceneOutputName(SceneOutput output);
/// The output called `name`, or nullopt.
std::optional<SceneOutput> ParseSceneOutput(std::string_view name);

}  // namespace sweetspot::core
