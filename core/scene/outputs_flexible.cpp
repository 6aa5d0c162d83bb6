// The outputs of the flexible beam: vibration_node (its first two modes) and least_sting_zone
// (flexible impacts swept from the hands to the tip; core/sweet_spot/least_sting.hpp).
#include <chrono>
#include <string>
#include <vector>

#include "core/geometry_format.hpp"
#include "core/scene/output_registry.hpp"
#include "core/sweet_spot/least_sting.hpp"
#include "core/sweet_spot/vibration_node.hpp"

namespace sweetspot::core {
namespace outputs_flexible {
namespace {

void ComputeVibrationNode(OutputContext& c) {
  VibrationNodeResult node;
  std::string error;
  if (!VibrationNodeFrom(*c.modes, c.modes_cache_hit, &node, &error)) {
    c.Note(Termination::kFailure, "vibration_node: " + error);  // the modes are usable
    return;
  }
  if (c.modes->summary.termination == Termination::kNoConvergence) {
    c.Note(Termination::kNoConvergence, "vibration_node: " + c.modes->summary.message);
  }
  c.out.vibration_node = std::move(node);
}

// least_sting_zone: the sweep from the hands to the tip with this scene's flexible impacts.
bool StingZone(const Scene& scene, const ResolvedScene& r, const SceneOptions& options,
               const BatModes& modes, TimingBook* book, std::vector<std::string>* warnings,
               LeastStingZoneResult* out, std::string* error) {
  const FlexibleOptions& fo = options.flexible;
  const double hands = scene.swing.hands_from_knob_m;
  if (!(r.length_m > hands)) {
    *error = "swing.hands_from_knob_m = " + FormatNumber17(hands) +
             ": the sweep runs from the hands to the tip, so the hands must be before the tip";
    return false;
  }
  FlexibleImpactOptions sample = fo.impact;
  sample.refine_check = false;  // the refinement check runs at the least-sting impact
  FlexibleImpactOptions search = sample;
  search.hands_loads = false;  // the searches read the hands' energy only
  const StingImpact impact = [&](double s, StingRun run) {
    const auto t0 = std::chrono::steady_clock::now();
    FlexibleImpactResult fr =
        SolveFlexibleImpact(*scene.bat, modes, FlexibleImpactInputsFor(scene, r, s, options.hertz),
                            run == StingRun::kChecked  ? fo.impact
                            : run == StingRun::kSample ? sample
                                                       : search);
    book->Add(CollisionModelName(CollisionModel::kFlexible), SecondsSince(t0), 1);
    return fr;
  };
  if (!LeastStingZone(impact, hands, r.length_m, fo.sting_samples, fo.sting_zone_fraction,
                      fo.search.x_tolerance_m, warnings, out, error)) {
    return false;
  }
  out->elements = modes.Elements();
  out->theory = BeamTheoryName(modes.theory);
  return true;
}

void ComputeLeastStingZone(OutputContext& c) {
  LeastStingZoneResult zone;
  std::string error;
  std::vector<std::string> warnings;
  const bool ok =
      StingZone(c.scene, c.resolved, c.options, *c.modes, &c.book, &warnings, &zone, &error);
  for (const auto& w : warnings) c.Warn(SceneOutput::kLeastStingZone, w);
  if (ok) {
    c.out.least_sting_zone = std::move(zone);
  } else {
    c.Note(Termination::kFailure, "least_sting_zone: " + error);
  }
}

double VibrationNodeError(const SceneOutputResults& r) {
  return r.vibration_node->error_estimate_m;
}
double LeastStingZoneError(const SceneOutputResults& r) {
  return r.least_sting_zone->error_estimate_m;
}

}  // namespace
}  // namespace outputs_flexible

extern const SceneOutputDecl kVibrationNodeOutput{
    SceneOutput::kVibrationNode,
    "vibration_node",
    /*uses_exit_model=*/false,
    /*models=*/{kFlexibleBeamModel},
    /*needs_geometry=*/true,
    /*needs_cor=*/false,
    OutputModes::kVibration,
    /*modes_failure=*/"",
    /*needs_output=*/SceneOutput::kVibrationNode,
    OutputWorkload::kCompute,
    outputs_flexible::ComputeVibrationNode,
    SlotPresent<&SceneOutputResults::vibration_node>,
    ResetSlot<&SceneOutputResults::vibration_node>,
    outputs_flexible::VibrationNodeError,
};

extern const SceneOutputDecl kLeastStingZoneOutput{
    SceneOutput::kLeastStingZone,
    "least_sting_zone",
    /*uses_exit_model=*/false,
    /*models=*/{"mass_properties", kFlexibleBeamModel, "flexible"},
    /*needs_geometry=*/true,
    /*needs_cor=*/true,
    OutputModes::kImpact,
    /*modes_failure=*/"the bat's modes: ",
    /*needs_output=*/SceneOutput::kLeastStingZone,
    OutputWorkload::kCompute,
    outputs_flexible::ComputeLeastStingZone,
    SlotPresent<&SceneOutputResults::least_sting_zone>,
    ResetSlot<&SceneOutputResults::least_sting_zone>,
    outputs_flexible::LeastStingZoneError,
};

}  // namespace sweetspot::core
