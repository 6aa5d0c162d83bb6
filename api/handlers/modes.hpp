// POST /v1/bat/modes: the free-free bending modes of a bat (the flexible beam of
// core/flexible/*): frequencies, mode shapes, nodes, with the mesh's error estimates.
#pragma once

#include "api/router.hpp"

namespace sweetspot::api {

/// POST /v1/bat/modes. Request: {"bat": BAT (required), "theory": "timoshenko" (default) |
/// "euler_bernoulli", "modes": 1..20 (default 4), "tolerance": relative frequency tolerance in
/// [1e-9, 0.1] (default 1e-4), "shape_samples": 2..1001 (default 41), "max_elements": 2..4096
/// (default 512)}. Answer 200: frequencies_hz, modes [{mode, frequency_hz, error_estimate_hz,
/// nodes_from_knob_m, shape [{position_from_knob_m, displacement}], ...}], vibration_node,
/// elements, error_estimate, theory, rigid_body, summary, timing_s. 400 for an invalid request
/// or a bat that is no beam (named field); 200 with summary.termination = "no_convergence"
/// when max_elements stops the refinement first. Uses context.modes_cache when set.
Response HandleBatModes(const Request& request, const Context& context);

}  // namespace sweetspot::api
