// The least_sting_zone definition: flexible impacts swept from the hands to the tip; the zone
// is the connected interval around the least-sting impact where the vibration energy reaching
// the hands is within a fraction of its range above the minimum (see LeastStingZoneResult).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "core/collision/flexible_impact.hpp"
#include "core/sweet_spot/sweet_spot.hpp"

namespace sweetspot::core {

/// One flexible impact s m from the knob; `refine` = with the solver's refinement check (the
/// samples), without it for the minimum's and the edges' searches.
using StingImpact = std::function<FlexibleImpactResult(double s, bool refine)>;

/// Sweeps `samples` impacts evenly from `from_knob_m` to `to_knob_m` (> from_knob_m), refines
/// the minimum of the hands' vibration energy (Brent) and the zone's edges (TOMS 748) with
/// `fraction` in (0, 1]. Fills *out except its mesh fields (elements, theory); collects the
/// impacts' warnings once each in *warnings. False with the reason in *error when an impact
/// failed or a search threw.
bool LeastStingZone(const StingImpact& solve, double from_knob_m, double to_knob_m, int samples,
                    double fraction, std::vector<std::string>* warnings, LeastStingZoneResult* out,
                    std::string* error);

}  // namespace sweetspot::core
