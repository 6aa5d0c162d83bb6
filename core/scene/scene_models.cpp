#include "core/scene/scene_models.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "core/geometry_format.hpp"
#include "core/numerics/limits.hpp"

namespace sweetspot::core {

const std::shared_ptr<const BatModes>& FlexibleModes::Impact() {
  if (!impact_) impact_ = Get(options_.ImpactModes(), &impact_hit_);
  return impact_;
}

const std::shared_ptr<const BatModes>& FlexibleModes::Vibration() {
  if (!vibration_) vibration_ = Get(options_.VibrationModes(), &vibration_hit_);
  return vibration_;
}

std::shared_ptr<const BatModes> FlexibleModes::Get(const BeamModesOptions& o, bool* hit) {
  const auto t0 = std::chrono::steady_clock::now();
  auto modes = CachedBatModes(*scene_.bat, o, options_.modes_cache, hit);
  book_->Add(kFlexibleBeamModel, SecondsSince(t0), 1);
  // Here the mesh bound is the scene's flexible.max_elements: name it so (a refusal's
  // message starts with its field, which the API reports).
  if (modes && modes->summary.termination == Termination::kInvalidInput &&
      modes->summary.refusal.has_value() && modes->summary.refusal->field == "max_elements") {
    auto renamed = std::make_shared<BatModes>(*modes);
    renamed->summary.SetRefusal(Prefixed("flexible.", *modes->summary.refusal));
    modes = std::move(renamed);
  }
  return modes;
}

bool FlexibleModesRefused(const BatModes& modes, Summary* summary) {
  if (modes.summary.IsSolutionUsable()) return false;
  const bool invalid = modes.summary.termination == Termination::kInvalidInput;
  if (invalid && modes.summary.refusal.has_value()) {
    summary->SetRefusal(Noted(*modes.summary.refusal, " (model = flexible)"));
    return true;
  }
  summary->termination = invalid ? Termination::kInvalidInput : Termination::kFailure;
  summary->message = invalid ? modes.summary.message + " (model = flexible)"
                             : "model = flexible: the bat's modes: " + modes.summary.message;
  return true;
}

ExitSpeedModel::ExitSpeedModel(CollisionModel model, const Scene& scene,
                               const ResolvedScene& resolved, const HertzOptions& hertz,
                               TimingBook* book, const FlexibleOptions* flexible,
                               std::shared_ptr<const BatModes> modes)
    : model_(model),
      scene_(scene),
      r_(resolved),
      hertz_(hertz),
      book_(book),
      flexible_(flexible),
      modes_(std::move(modes)) {
  if (model == CollisionModel::kRigidPivot) {
    profile_ = RigidPivotProfile(RigidPivotInputsFor(scene, resolved));
  } else if (model == CollisionModel::kFreeBat) {
    profile_ = FreeBatProfile(FreeBatInputsFor(scene, resolved));
  }
}

bool ExitSpeedModel::Eval(double s, double* v, double* grad, double* err, std::string* why) {
  const auto t0 = book_->Now();
  bool ok = true;
  if (profile_.has_value()) {
    const double x = s - profile_->origin_from_knob_m;
    *v = profile_->ExitSpeedMps(x);
    if (grad != nullptr) *grad = profile_->DerivativePerS(x);
    if (err != nullptr) *err = 8.0 * kEps * (profile_->ball_speed_mps + std::abs(*v));
  } else if (model_ == CollisionModel::kFlexible) {
    const FlexibleImpactResult fr = SolveFlexibleImpact(
        *scene_.bat, *modes_, FlexibleImpactInputsFor(scene_, r_, s, hertz_), flexible_->impact);
    for (auto& w : fr.summary.warnings) AddWarning(w);
    if (!fr.summary.IsSolutionUsable()) {
      ok = false;
      if (why != nullptr) {
        *why = "flexible at " + FormatNumber17(s) + " m from the knob: " + fr.summary.message;
      }
    } else {
      *v = fr.exit_speed_mps;
      if (err != nullptr) *err = fr.error_estimate_exit_speed_mps;
    }
  } else {
    std::vector<std::string> warnings;
    const HertzImpact hi =
        SolveHertzImpact(HertzProblemFor(scene_, r_, s, hertz_, &warnings), hertz_.solver);
    for (auto& w : warnings) AddWarning(w);
    for (auto& w : hi.summary.warnings) AddWarning(w);
    if (!hi.summary.IsSolutionUsable()) {
      ok = false;
      if (why != nullptr) {
        *why = "hertz at " + FormatNumber17(s) + " m from the knob: " + hi.summary.message;
      }
    } else {
      *v = hi.exit_speed_mps;
      if (err != nullptr) {
        *err = hertz_.solver.refine_check
                   ? hi.error_estimate_exit_speed_mps
                   : hertz_.solver.relative_tolerance * (scene_.ball.speed_mps + std::abs(*v));
      }
    }
  }
  book_->Add(name(), book_->Since(t0), 1);
  return ok;
}

bool ExitSpeedModel::EvalFast(double s, double* v, double* noise, std::string* why) {
  if (model_ != CollisionModel::kFlexible) return Eval(s, v, nullptr, noise, why);
  const auto t0 = std::chrono::steady_clock::now();
  FlexibleImpactOptions fast = flexible_->impact;
  fast.refine_check = false;
  fast.hands_loads = false;
  const FlexibleImpactResult fr = SolveFlexibleImpact(
      *scene_.bat, *modes_, FlexibleImpactInputsFor(scene_, r_, s, hertz_), fast);
  for (auto& w : fr.summary.warnings) AddWarning(w);
  const bool ok = fr.summary.IsSolutionUsable();
  if (!ok) {
    if (why != nullptr) {
      *why = "flexible at " + FormatNumber17(s) + " m from the knob: " + fr.summary.message;
    }
  } else {
    *v = fr.exit_speed_mps;
    if (noise != nullptr) *noise = fr.error_estimate_exit_speed_mps;
  }
  book_->Add(name(), SecondsSince(t0), 1);
  return ok;
}

void ExitSpeedModel::AddWarning(const std::string& w) {
  if (std::find(warnings_.begin(), warnings_.end(), w) == warnings_.end()) warnings_.push_back(w);
}

}  // namespace sweetspot::core
