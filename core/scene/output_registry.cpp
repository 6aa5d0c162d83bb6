#include "core/scene/output_registry.hpp"

#include <algorithm>
#include <stdexcept>

namespace sweetspot::core {

// Each output's declaration (core/scene/outputs_*.cpp).
extern const SceneOutputDecl kMaxExitSpeedOutput, kSweetZoneOutput, kExitSpeedCurveOutput,
    kCenterOfPercussionOutput, kVibrationNodeOutput, kLeastStingZoneOutput, kBarrelOutput,
    kBbcorOutput, kBbcorScanOutput, kBattedBallOutput, kDistanceSweetSpotOutput, kCarryMapOutput;

const std::vector<const SceneOutputDecl*>& SceneOutputTable() {
  // THE table: one row per output, in the order they are computed (an output another reads,
  // needs_output, comes before it). Adding an output: its declaration, and its row here.
  static const std::vector<const SceneOutputDecl*> table = {
      &kMaxExitSpeedOutput,  &kSweetZoneOutput,      &kCenterOfPercussionOutput,
      &kVibrationNodeOutput, &kLeastStingZoneOutput, &kBarrelOutput,
      &kBbcorOutput,         &kBbcorScanOutput,      &kExitSpeedCurveOutput,
      &kBattedBallOutput,    &kDistanceSweetSpotOutput, &kCarryMapOutput,
  };
  return table;
}

namespace {

Termination WorseTermination(Termination a, Termination b) {
  auto rank = [](Termination t) {
    switch (t) {
      case Termination::kConverged:
        return 0;
      case Termination::kNoConvergence:
        return 1;
      case Termination::kInfeasible:
        return 2;
      case Termination::kFailure:
        return 3;
      case Termination::kInvalidInput:
        return 4;
    }
    return 3;
  };
  return rank(a) >= rank(b) ? a : b;
}

// The declarations by id; every id has exactly one (checked once).
const std::array<const SceneOutputDecl*, kSceneOutputCount>& ById() {
  static const std::array<const SceneOutputDecl*, kSceneOutputCount> by_id = [] {
    std::array<const SceneOutputDecl*, kSceneOutputCount> out{};
    for (const SceneOutputDecl* d : SceneOutputTable()) {
      const auto i = static_cast<std::size_t>(d->id);
      if (i >= kSceneOutputCount || out[i] != nullptr) {
        throw std::logic_error("output registry: a duplicate or out-of-range id");
      }
      out[i] = d;
    }
    for (const SceneOutputDecl* d : out) {
      if (d == nullptr) throw std::logic_error("output registry: an id without a declaration");
    }
    return out;
  }();
  return by_id;
}

}  // namespace

const SceneOutputDecl& SceneOutputDeclaration(SceneOutput id) {
  return *ById()[static_cast<std::size_t>(id)];
}

const char* SceneOutputName(SceneOutput output) {
  const auto i = static_cast<std::size_t>(output);
  return i < kSceneOutputCount ? ById()[i]->name : "max_exit_speed";
}

std::optional<SceneOutput> ParseSceneOutput(std::string_view name) {
  for (const SceneOutputDecl* d : ById()) {
    if (name == d->name) return d->id;
  }
  return std::nullopt;
}

const std::string& SceneOutputNameList() {
  static const std::string list = [] {
    std::string out;
    for (const SceneOutputDecl* d : ById()) out.append(out.empty() ? "" : ", ").append(d->name);
    return out;
  }();
  return list;
}

bool IsClosedFormModel(CollisionModel model) {
  return model == CollisionModel::kRigidPivot || model == CollisionModel::kFreeBat;
}

OutputWorkload WorkloadOf(SceneOutput output, CollisionModel exit_model) {
  if (exit_model == CollisionModel::kAuto) exit_model = CollisionModel::kFreeBat;
  const OutputWorkload w = SceneOutputDeclaration(output).workload;
  if (w != OutputWorkload::kAsExitModel) return w;
  return IsClosedFormModel(exit_model) ? OutputWorkload::kLight : OutputWorkload::kCompute;
}

std::vector<std::string> ModelsFor(SceneOutput output, CollisionModel exit_model) {
  if (exit_model == CollisionModel::kAuto) exit_model = CollisionModel::kFreeBat;
  const SceneOutputDecl& d = SceneOutputDeclaration(output);
  std::vector<std::string> models;
  if (d.uses_exit_model) {
    if (exit_model == CollisionModel::kFlexible) {
      models = {"mass_properties", kFlexibleBeamModel, "flexible"};
    } else {
      models = {"mass_properties", CollisionModelName(exit_model)};
    }
  }
  // Then its own (a flight output: the exit-speed model's, then "flight"), each once.
  for (const char* m : d.models) {
    if (m == nullptr) break;
    if (std::find(models.begin(), models.end(), m) == models.end()) models.emplace_back(m);
  }
  return models;
}

void OutputContext::Note(Termination termination, std::string what) {
  Summary& s = out.summary;
  s.termination = WorseTermination(s.termination, termination);
  if (!what.empty()) messages_->push_back(std::move(what));
}

void OutputContext::Refuse(Refusal why) {
  Note(Termination::kInvalidInput, why.Message());
  if (!out.summary.refusal.has_value()) out.summary.refusal = std::move(why);
}

void OutputContext::Warn(SceneOutput output, const std::string& warning) {
  out.summary.warnings.push_back(std::string(SceneOutputName(output)) + ": " + warning);
}

}  // namespace sweetspot::core
