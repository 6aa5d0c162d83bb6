// The vibration_node definition: the barrel-side node of the free-free bat's fundamental
// bending mode, read from its modes (core/flexible/modes.hpp).
#pragma once

#include <string>

#include "core/flexible/modes.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {

/// vibration_node from `modes` (at least two usable bending modes); `cache_hit` says whether
/// they came from the cross-request cache. False with the reason in *error otherwise.
bool VibrationNodeFrom(const BatModes& modes, bool cache_hit, VibrationNodeResult* out,
                       std::string* error);

}  // namespace sweetspot::core
