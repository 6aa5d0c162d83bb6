// EvaluateScene: the sweet spots of a scene. Value-in/value-out, never throws, and runs only
// the models the request needs: each output declares its models (ModelsFor), the scene is
// resolved once per request (core/scene/resolved_scene.hpp), and the result lists
// models_used, an error estimate per output and the time spent per model.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "core/bat/mass_properties.hpp"
#include "core/collision/barrel.hpp"
#include "core/collision/bbcor_scan.hpp"
#include "core/collision/oblique_impact.hpp"
#include "core/flight/flight.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/scene/batted_ball.hpp"
#include "core/scene/scene.hpp"
#include "core/summary.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {

/// The models an output needs with `exit_model` as the exit-speed model, in run order
/// (e.g. {"mass_properties", "rigid_pivot"}; vibration_node: {"flexible_beam"};
/// least_sting_zone, or any exit output with model flexible: {"mass_properties",
/// "flexible_beam", "flexible"}): its declaration's (core/scene/output_registry.hpp).
std::vector<std::string> ModelsFor(SceneOutput output, CollisionModel exit_model);

/// The name of the barrel model (in models_used and timings).
inline constexpr char kBarrelModel[] = "barrel";

/// One slot per output: its result, empty when not requested (or not computed). An output's
/// declaration names its slot (core/scene/output_registry.hpp), which resets it.
struct SceneOutputResults {
  std::optional<MaxExitSpeedResult> max_exit_speed;              ///< max_exit_speed.
  std::optional<CenterOfPercussionResult> center_of_percussion;  ///< center_of_percussion.
  std::optional<SweetZoneResult> sweet_zone;                     ///< sweet_zone.
  std::optional<ExitSpeedCurveResult> exit_speed_curve;          ///< exit_speed_curve.
  std::optional<VibrationNodeResult> vibration_node;             ///< vibration_node.
  std::optional<LeastStingZoneResult> least_sting_zone;          ///< least_sting_zone.
  std::optional<BarrelOutput> barrel;                            ///< barrel.
  std::optional<BbcorResult> bbcor;                              ///< bbcor.
  std::optional<BbcorScan> bbcor_scan;                           ///< bbcor_scan.
  std::optional<BattedBallResult> batted_ball;                   ///< batted_ball.
  std::optional<DistanceSweetSpotResult> distance_sweet_spot;    ///< distance_sweet_spot.
  std::optional<CarryMapResult> carry_map;                       ///< carry_map.
};

/// The answer of EvaluateScene: what every evaluation reports, and the outputs' slots
/// (SceneOutputResults). Outputs not requested (or not computed) are empty.
struct SceneResult : SceneOutputResults {
  Summary summary;            ///< Overall: termination, message, models_used, total time.
  std::string missing_model;  ///< Set (e.g. "flexible_beam") when refused for a missing model.
  std::string refused_field;  ///< The request field the refusal is about (e.g. "outputs").
  std::optional<double> cor;  ///< The COR used; unset when no wanted output needs one.
  /// "scene", "ball:<preset>" or "material:<name>" (ResolvedScene); "" when `cor` is unset.
  std::string cor_source;
  /// With cor_source "ball:...": the impact speed the ball's COR law was evaluated at, m/s.
  std::optional<double> cor_impact_speed_mps;
  MassProperties mass_properties;  ///< The properties used (when refused: as computed, or zero).
  double length_m = 0.0;           ///< The bat length used, m.
  /// The swing used, its angular speed resolved (from bat_speed_mps when given); the default
  /// swing when refused before it was resolved.
  Swing swing;
  std::string exit_speed_model;  ///< The exit-speed model used ("" when none was needed).
  std::string model_reason;      ///< Why that model (auto).
  std::vector<ModelTiming> timings;  ///< Time per model, in first-use order.

  /// Every field as a default-constructed result has it, the strings and vectors keeping their
  /// buffers (a sweep writes each design's result over the previous one's); each output's slot
  /// by its declaration.
  void Reset();
};

/// Evaluates scenes with one set of options, validated once: a sweep's designs. Each result is
/// written over the previous one, reusing its buffers, so a closed-form design allocates
/// little. Not thread-safe: one per thread.
class SceneEvaluator {
 public:
  /// An evaluator of scenes under `options` (validated here, once).
  explicit SceneEvaluator(SceneOptions options);
  /// What EvaluateScene(scene, options()) returns, into *out (every field set again; what a
  /// previous call left there is reused as buffers only). Never throws.
  void Evaluate(const Scene& scene, SceneResult* out);
  /// The options every evaluation uses.
  const SceneOptions& options() const { return options_; }

 private:
  // Evaluate's work inside its frame: the outputs the scene asks for, one loop over the table.
  void EvaluateOutputs(const Scene& scene, SceneResult* out);
  SceneOptions options_;
  std::optional<Refusal> options_refusal_;  // set when the options are invalid
  TimingBook book_;
  std::vector<SceneOutput> wanted_;  // the scene's outputs without duplicates (scratch)
  std::vector<std::string> messages_;  // the outputs' failure messages (scratch)
};

/// Computes the requested outputs (SceneEvaluator(options).Evaluate). Never throws.
SceneResult EvaluateScene(const Scene& scene, const SceneOptions& options);

}  // namespace sweetspot::core
