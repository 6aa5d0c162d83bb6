#include "core/sweet_spot/vibration_node.hpp"

namespace sweetspot::core {

bool VibrationNodeFrom(const BatModes& modes, bool cache_hit, VibrationNodeResult* out,
                       std::string* error) {
  if (!modes.summary.IsSolutionUsable()) {
    *error = modes.summary.message;
    return false;
  }
  if (modes.modes.size() < 2) {
    *error = "the modes computation returned fewer than two modes";
    return false;
  }
  const BeamMode& m1 = modes.modes[0];
  const BeamMode& m2 = modes.modes[1];
  if (m1.nodes_from_knob_m.empty()) {
    *error = "the fundamental bending mode has no node on the bat";
    return false;
  }
  out->position_from_knob_m = m1.nodes_from_knob_m.back();
  out->other_node_from_knob_m = m1.nodes_from_knob_m.front();
  out->frequency_hz = m1.frequency_hz;
  out->error_estimate_hz = m1.error_estimate_hz;
  out->error_estimate_m = m1.nodes_error_estimate_m;
  out->second_mode_frequency_hz = m2.frequency_hz;
  out->second_mode_nodes_from_knob_m = m2.nodes_from_knob_m;
  out->second_mode_error_estimate_hz = m2.error_estimate_hz;
  out->relative_tolerance = modes.tolerance;
  out->elements = modes.Elements();
  out->refinement_elements = modes.refinement_elements;
  out->theory = BeamTheoryName(modes.theory);
  out->cache_hit = cache_hit;
  out->summary = modes.summary;
  return true;
}

}  // namespace sweetspot::core
