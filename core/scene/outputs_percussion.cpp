// The center_of_percussion output: a closed form of the mass properties and the hands
// (core/sweet_spot/sweet_spot.hpp's CenterOfPercussion).
#include <string>

#include "core/geometry_format.hpp"
#include "core/scene/output_registry.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {
namespace outputs_percussion {
namespace {

void ComputeCenterOfPercussion(OutputContext& c) {
  Refusal why;
  auto cop = CenterOfPercussion(c.resolved.mass_properties, c.scene.swing.hands_from_knob_m,
                                c.resolved.length_m, &why);
  if (!cop.has_value()) {
    // The core message first ("swing.hands_from_knob_m = ...: rule"): it names the field.
    c.Refuse(Noted(std::move(why), " (center_of_percussion)"));
    return;
  }
  if (cop->placement == Placement::kBeyondTip) {
    c.Warn(SceneOutput::kCenterOfPercussion,
           "beyond the tip (" + FormatNumber17(cop->position_from_knob_m) + " m from the knob)");
  }
  c.out.center_of_percussion = cop;
}

}  // namespace
}  // namespace outputs_percussion

extern const SceneOutputDecl kCenterOfPercussionOutput{
    SceneOutput::kCenterOfPercussion,
    "center_of_percussion",
    /*uses_exit_model=*/false,
    /*models=*/{"mass_properties"},
    /*needs_geometry=*/false,
    /*needs_cor=*/false,
    OutputModes::kNone,
    "",
    /*needs_output=*/SceneOutput::kCenterOfPercussion,
    OutputWorkload::kLight,
    outputs_percussion::ComputeCenterOfPercussion,
    SlotPresent<&SceneOutputResults::center_of_percussion>,
    ResetSlot<&SceneOutputResults::center_of_percussion>,
    nullptr,
};

}  // namespace sweetspot::core
