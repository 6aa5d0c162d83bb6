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

/// What one impact of the sweep is for, and so what it must compute.
enum class StingRun {
  kSample,   ///< A curve point: every output, without the refinement check.
  kSearch,   ///< A step of the minimum's or the edges' search: the hands' vibration energy only
             ///< (no hands' loads, no refinement check).
  kChecked,  ///< The least-sting impact: every output, with the refinement check (if enabled).
};

/// One flexible impact s m from the knob, computed as `run` asks.
using StingImpact = std::function<FlexibleImpactResult(double s, StingRun run)>;

/// Sweeps `samples` impacts evenly from `from_knob_m` to `to_knob_m` (> from_knob_m), refines
/// the minimum of the hands' vibration energy (Brent) and the zone's edges (TOMS 748) to
/// `x_tolerance_m` (m, > 0) with `fraction` in (0, 1], and checks the least-sting impact once
/// with the refinement check: its error estimate of the hands' energy stands for the sweep's
/// in the zone's error estimate. Fills *out except its mesh fields (elements, theory); collects
/// the impacts' warnings once each in *warnings. False with the reason in *error when an
/// impact failed or a search threw.
bool LeastStingZone(const StingImpact& solve, double from_knob_m, double to_knob_m, int samples,
                    double fraction, double x_tolerance_m, std::vector<std::string>* warnings,
                    LeastStingZoneResult* out, std::string* error);

}  // namespace sweetspot::core
