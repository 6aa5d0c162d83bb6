// The models a scene runs within one request: the flexible beam's modes (each set computed once,
// or taken from the caller's cross-request cache) and the exit speed along the bat under one
// collision model. Both time their work in the request's TimingBook.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/collision/exit_speed_profile.hpp"
#include "core/flexible/modes.hpp"
#include "core/numerics/timing_book.hpp"
#include "core/scene/resolved_scene.hpp"
#include "core/scene/scene.hpp"
#include "core/sweet_spot/numeric.hpp"

namespace sweetspot::core {

/// The flexible beam's modes within one request, timed under "flexible_beam". Needs scene.bat.
class FlexibleModes {
 public:
  /// `scene`, `options` and `book` must outlive this object.
  FlexibleModes(const Scene& scene, const FlexibleOptions& options, TimingBook* book)
      : scene_(scene), options_(options), book_(book) {}
  /// The modes of flexible impacts (computed on first use).
  const std::shared_ptr<const BatModes>& Impact();
  /// The modes of vibration_node (computed on first use).
  const std::shared_ptr<const BatModes>& Vibration();
  /// Impact()'s modes came from the cross-request cache.
  bool impact_hit() const { return impact_hit_; }
  /// Vibration()'s modes came from the cross-request cache.
  bool vibration_hit() const { return vibration_hit_; }

 private:
  std::shared_ptr<const BatModes> Get(const BeamModesOptions& o, bool* hit);
  const Scene& scene_;
  const FlexibleOptions& options_;
  TimingBook* book_;
  std::shared_ptr<const BatModes> impact_, vibration_;
  bool impact_hit_ = false, vibration_hit_ = false;
};

/// For model = flexible: when `modes` are not usable, sets *summary's termination (invalid
/// input, or failure) and message (an invalid input's keeps the modes' message first: it names
/// the field) and returns true.
bool FlexibleModesRefused(const BatModes& modes, Summary* summary);

/// The exit speed along the bat under one collision model (not kAuto); the closed-form models
/// (rigid_pivot, free_bat) carry their profile. Each evaluation is timed under the model's name.
class ExitSpeedModel : public ExitSpeedFunction {
 public:
  /// `scene`, `resolved` (its COR resolved) and `book` must outlive this object; `flexible` and
  /// `modes` are needed for kFlexible.
  ExitSpeedModel(CollisionModel model, const Scene& scene, const ResolvedScene& resolved,
                 const HertzOptions& hertz, TimingBook* book,
                 const FlexibleOptions* flexible = nullptr,
                 std::shared_ptr<const BatModes> modes = nullptr);
  const char* name() const override { return CollisionModelName(model_); }
  bool has_gradient() const override { return profile_.has_value(); }
  bool Eval(double s, double* v, double* grad, double* err, std::string* why) override;
  /// flexible: one impact without the refinement check and the hands' loads (the value Eval
  /// gives; the noise is the integration tolerance's share); other models: Eval.
  bool EvalFast(double s, double* v, double* noise, std::string* why) override;
  /// The closed-form profile (rigid_pivot, free_bat), or nullopt.
  const std::optional<ExitSpeedProfile>& profile() const { return profile_; }
  /// The flexible impact modes (kFlexible), or null.
  const BatModes* modes() const { return modes_.get(); }
  /// The models' warnings so far, each once.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  void AddWarning(const std::string& w);
  CollisionModel model_;
  const Scene& scene_;
  const ResolvedScene& r_;
  HertzOptions hertz_;
  TimingBook* book_;
  const FlexibleOptions* flexible_;
  std::shared_ptr<const BatModes> modes_;
  std::optional<ExitSpeedProfile> profile_;
  std::vector<std::string> warnings_;
};

}  // namespace sweetspot::core
